//! The crate's error type.

use thiserror::Error;

/// Result alias of this crate.
pub type Result<T, E = OptimError> = std::result::Result<T, E>;

/// Invalid settings or calls.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum OptimError {
    /// A setting is out of range.
    #[error("invalid {field}: {problem}")]
    InvalidOption {
        /// The setting.
        field: &'static str,
        /// What is wrong with it.
        problem: String,
    },
    /// `tell` got a different number of values than `ask` handed out.
    #[error("tell got {got} fitness values for {expected} candidates")]
    WrongFitnessCount {
        /// Candidates handed out.
        expected: usize,
        /// Values received.
        got: usize,
    },
    /// `tell` without a matching `ask`.
    #[error("tell called without a pending ask")]
    NoPendingAsk,
}

pub(crate) fn invalid(field: &'static str, problem: impl Into<String>) -> OptimError {
    OptimError::InvalidOption {
        field,
        problem: problem.into(),
    }
}

/// Checks that every `(field, value)` is positive and finite.
pub(crate) fn positive(values: &[(&'static str, f64)]) -> Result<()> {
    for &(field, v) in values {
        if !(v.is_finite() && v > 0.0) {
            return Err(invalid(field, "must be positive and finite"));
        }
    }
    Ok(())
}
