//! The toolkit's error type.

use thiserror::Error;

/// What went wrong when building a distribution or running a statistical test.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// A distribution was given no values.
    #[error("{what}: no values given")]
    Empty {
        /// What was being built.
        what: &'static str,
    },
    /// A value is negative, NaN or infinite.
    #[error("{what}: value {value} at index {index} is not a finite non-negative number")]
    InvalidValue {
        /// What was being built.
        what: &'static str,
        /// Position of the offending value.
        index: usize,
        /// The value itself.
        value: f64,
    },
    /// A parameter is out of its range.
    #[error("{what}: {message}")]
    InvalidParameter {
        /// What was being built.
        what: &'static str,
        /// What was expected.
        message: String,
    },
}

/// Result with the toolkit's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
