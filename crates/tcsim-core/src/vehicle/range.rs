//! The allowed values of a vehicle file's numbers, and the names of its fields: shared by the
//! parameters ([`super::parameters`]) and the components they configure ([`super::shift`]).

use crate::error::{CoreError, CoreResult};

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
            ends.push(if closed { format!("at least {lo}") } else { format!("greater than {lo}") });
        }
        if let Some((hi, closed)) = self.high {
            ends.push(if closed { format!("at most {hi}") } else { format!("less than {hi}") });
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
