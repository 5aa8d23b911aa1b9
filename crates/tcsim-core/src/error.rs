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
        Self { source, field: field.into(), value: value.to_string(), expected: expected.into() }
    }

    /// The same error, about the input `source` (for checks shared by several inputs, such as a
    /// signal's, attributed by their caller).
    pub fn about(self, source: InputSource) -> Self {
        Self { source, ..self }
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
    fn source_is_data_not_text() {
        let e = CoreError::new("flow_area_m2", -1.0, "a positive area");
        assert_eq!(e.source, InputSource::Converter);
        let e = e.about(InputSource::Drive);
        assert_eq!(e.source, InputSource::Drive);
        assert_eq!(e.to_string(), "flow_area_m2 = -1: expected a positive area");
        let keys: Vec<_> = InputSource::ALL.iter().map(|s| s.key()).collect();
        assert_eq!(keys, ["converter", "drive", "initial", "scenario", "vehicle", "options"]);
    }
}
