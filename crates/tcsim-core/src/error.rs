//! The one error type of the core: which input, which field, which value, what was expected.
//!
//! The binding raises it as `tcsim._core.CoreInputError(message, field, value, expected, source)`,
//! which the Python layer turns into a user-input error (exit code 2) naming the file that
//! [`CoreError::source`] designates; the FMU reports it through its logger. The core never panics
//! on bad input.

use std::fmt;

/// Which of a run's inputs an error is about: the layer above maps it to a file or a name without
/// reading the message.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum InputSource {
    /// The converter's data: a model specification, its geometry, table, inertias, shape effects.
    Converter,
    /// The drive of an isolated run: its signals, load and output times.
    Drive,
    /// The initial state of an isolated run.
    Initial,
    /// A launch scenario: pedals, logged engine torque, end time.
    Scenario,
    /// The vehicle's parameters.
    Vehicle,
    /// Solver and output options.
    Options,
}

impl InputSource {
    pub const ALL: [InputSource; 6] = [
        InputSource::Converter,
        InputSource::Drive,
        InputSource::Initial,
        InputSource::Scenario,
        InputSource::Vehicle,
        InputSource::Options,
    ];

    /// The name the binding passes to Python: `converter`, `drive`, `initial`, `scenario`,
    /// `vehicle` or `options`.
    pub fn key(self) -> &'static str {
        match self {
            InputSource::Converter => "converter",
            InputSource::Drive => "drive",
            InputSource::Initial => "initial",
            InputSource::Scenario => "scenario",
            InputSource::Vehicle => "vehicle",
            InputSource::Options => "options",
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct CoreError {
    /// Which input the error is about.
    pub source: InputSource,
    /// The parameter, column or operating-point quantity at fault, e.g. `flow_area_m2`.
    pub field: String,
    /// The offending value, formatted.
    pub value: String,
    /// What was expected instead.
    pub expected: String,
}

impl CoreError {
    /// An error about the converter's data ([`InputSource::Converter`], the inputs most checks
    /// are about); errors about another input say so with [`CoreError::about`] or
    /// [`CoreError::of`].
    pub fn new(field: impl Into<String>, value: impl fmt::Display, expected: impl Into<String>) -> Self {
        Self::of(InputSource::Converter, field, value, expected)
    }

    /// An error about the input `source`.
    pub fn of(
        source: InputSource,
        field: impl Into<String>,
        value: impl fmt::Display,
        expected: impl Into<String>,
    ) -> Self {
        Self { source, field: field.into(), value: compact(value.to_string()), expected: expected.into() }
    }

    /// The same error, about the input `source` (for checks shared by several inputs, such as a
    /// signal's, attributed by their caller).
    pub fn about(self, source: InputSource) -> Self {
        Self { source, ..self }
    }
}

/// A number for a message: six significant digits (`%.6g`), the exponent form for magnitudes
/// outside 1e-5 to 1e6, `NaN`, `inf` and `-inf` as such. Every number the core prints in a message
/// (solver states, bounds) goes through here, never `{}` of an f64, which writes 1e300 with 301
/// digits.
pub fn sig(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let digits = 5 - x.abs().log10().floor() as i32;
    if (0..=10).contains(&digits) {
        let s = format!("{:.*}", digits.max(0) as usize, x);
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        let s = format!("{x:.5e}");
        match s.split_once('e') {
            Some((m, e)) if m.contains('.') => format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.')),
            _ => s,
        }
    }
}

/// The value of an error as the core writes it: a number whose shortest round-trip form is longer
/// than 24 characters (Rust writes 1e300 with 301 digits) in the exponent form, exact; other text as
/// it is.
fn compact(text: String) -> String {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && text.len() > 24 => format!("{x:e}"),
        _ => text,
    }
}

impl fmt::Display for CoreError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {}: expected {}", self.field, self.value, self.expected)
    }
}

impl std::error::Error for CoreError {}

pub type CoreResult<T> = Result<T, CoreError>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_messages_are_short() {
        assert_eq!(sig(1e300), "1e300");
        assert_eq!(sig(-1.234567891e-300), "-1.23457e-300");
        assert_eq!(sig(0.0613917123), "0.0613917");
        assert_eq!(sig(999_999.0), "999999");
        assert_eq!(sig(1_000_000.0), "1e6");
        assert_eq!(sig(2.5e11), "2.5e11");
        assert_eq!(sig(2.5e16), "2.5e16");
        assert_eq!(sig(f64::NAN), "NaN");
        assert_eq!(sig(f64::NEG_INFINITY), "-inf");
        assert!((0..2000).map(|i| sig(1.7f64.powi(i - 1000))).all(|s| s.len() <= 13));
    }

    #[test]
    fn source_is_data_not_text() {
        let e = CoreError::new("flow_area_m2", -1.0, "a positive area");
        assert_eq!(e.source, InputSource::Converter);
        let e = e.about(InputSource::Drive);
        assert_eq!(e.source, InputSource::Drive);
        assert_eq!(e.to_string(), "flow_area_m2 = -1: expected a positive area");
        let e = CoreError::of(InputSource::Initial, "pump_speed_rad_s", 1e300, "a finite speed");
        assert_eq!(e.value, "1e300");
        assert_eq!(e.value.parse::<f64>(), Ok(1e300));
        assert_eq!(CoreError::new("x", 0.1 + 0.2, "y").value, "0.30000000000000004");
        assert_eq!(CoreError::new("x", f64::NAN, "y").value, "NaN");
        let keys: Vec<_> = InputSource::ALL.iter().map(|s| s.key()).collect();
        assert_eq!(keys, ["converter", "drive", "initial", "scenario", "vehicle", "options"]);
    }
}
