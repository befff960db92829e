//! Sparse and dense linear algebra for fieldtex; the only crate that names `faer`.

use thiserror::Error;

/// Failures of factorisations and solves. Never a silent NaN.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum LinalgError {
    #[error("factorisation of a {size}×{size} matrix failed: {reason}")]
    FactorizationFailed { size: usize, reason: String },
    #[error("solve of a {size}×{size} system left relative residual {residual:e} (tolerance {tolerance:e})")]
    SolveFailed { size: usize, residual: f64, tolerance: f64 },
    #[error("dimension mismatch: {what}: expected {expected}, found {found}")]
    Dimension { what: &'static str, expected: usize, found: usize },
    #[error("non-finite value in {what} at index {index}")]
    NonFinite { what: &'static str, index: usize },
}
