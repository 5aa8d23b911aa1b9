//! The allowed values of a vehicle file's numbers, and the names of its fields: shared by the
//! parameters ([`super::parameters`]) and the components they configure ([`super::shift`]).

use crate::error::{sig, CoreError, CoreResult};

/// The name of a vehicle file's field as the file writes it: `[section].key`.
pub fn field(section: &str, key: &str) -> String {
    format!("[{section}].{key}")
}

/// The allowed values of a finite number: each end is open (excluded), closed (included) or
/// absent (unbounded).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// The lower end and whether it is included.
    pub low: Option<(f64, bool)>,
    /// The upper end and whether it is included.
    pub high: Option<(f64, bool)>,
}

impl Range {
    /// Greater than 0.
    pub const POSITIVE: Range = Range { low: Some((0.0, false)), high: None };
    /// At least 0.
    pub const NON_NEGATIVE: Range = Range { low: Some((0.0, true)), high: None };
    /// From 0 to 1, both included.
    pub const FRACTION: Range = Range { low: Some((0.0, true)), high: Some((1.0, true)) };
    /// Greater than 0, at most 1 (an efficiency).
    pub const EFFICIENCY: Range = Range { low: Some((0.0, false)), high: Some((1.0, true)) };
    /// At least 1.
    pub const AT_LEAST_ONE: Range = Range { low: Some((1.0, true)), high: None };

    /// Whether `v` is finite and inside.
    pub fn contains(&self, v: f64) -> bool {
        let above = match self.low {
            Some((lo, true)) => v >= lo,
            Some((lo, false)) => v > lo,
            None => true,
        };
        let below = match self.high {
            Some((hi, true)) => v <= hi,
            Some((hi, false)) => v < hi,
            None => true,
        };
        v.is_finite() && above && below
    }

    /// What is expected, in words: `a finite number greater than 0 and at most 1`.
    pub fn expected(&self) -> String {
        let mut ends = Vec::new();
        if let Some((lo, closed)) = self.low {
            ends.push(if closed { format!("at least {}", sig(lo)) } else { format!("greater than {}", sig(lo)) });
        }
        if let Some((hi, closed)) = self.high {
            ends.push(if closed { format!("at most {}", sig(hi)) } else { format!("less than {}", sig(hi)) });
        }
        match ends.is_empty() {
            true => "a finite number".into(),
            false => format!("a finite number {}", ends.join(" and ")),
        }
    }

    /// `v` if it is inside, else the error naming `name`.
    pub fn check(&self, name: &str, v: f64) -> CoreResult<f64> {
        if self.contains(v) {
            Ok(v)
        } else {
            Err(CoreError::new(name, v, self.expected()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bounds in a message: six significant digits, the exponent form far from 1 (Rust's `{}`
    /// wrote 1e-9 as 0.000000001 and 1e7 as 10000000).
    #[test]
    fn the_bounds_are_written_as_numbers_are_in_messages() {
        let r = Range { low: Some((1e-9, false)), high: Some((1e7, true)) };
        assert_eq!(r.expected(), "a finite number greater than 1e-9 and at most 1e7");
        let r = Range { low: Some((-50.0, true)), high: Some((250.0 / 3.6, false)) };
        assert_eq!(r.expected(), "a finite number at least -50 and less than 69.4444");
        assert_eq!(Range { low: None, high: None }.expected(), "a finite number");
    }
}
