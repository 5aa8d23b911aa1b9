//! The one error type of the core: which field, which value, what was expected.
//!
//! The binding raises it as `tcsim._core.CoreInputError(message, field, value, expected)`, which
//! the Python layer turns into a user-input error (exit code 2) with the file name; the FMU reports
//! it through its logger. The core never panics on bad input.

use std::fmt;

#[derive(Debug, Clone, PartialEq)]
pub struct CoreError {
    /// The parameter, column or operating-point quantity at fault, e.g. `flow_area_m2`.
    pub field: String,
    /// The offending value, formatted.
    pub value: String,
    /// What was expected instead.
    pub expected: String,
}

impl CoreError {
    pub fn new(field: impl Into<String>, value: impl fmt::Display, expected: impl Into<String>) -> Self {
        Self { field: field.into(), value: value.to_string(), expected: expected.into() }
    }
}

impl fmt::Display for CoreError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {}: expected {}", self.field, self.value, self.expected)
    }
}

impl std::error::Error for CoreError {}

pub type CoreResult<T> = Result<T, CoreError>;
