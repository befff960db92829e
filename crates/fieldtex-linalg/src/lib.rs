//! Sparse and dense linear algebra for fieldtex; the only crate that names `faer`.
//!
//! No `faer` type appears in the public API: matrices are [`SparseMatrix`]
//! (compressed sparse columns, `f64`) and plain row-major slices.
//!
//! # Contents
//! - [`SparseMatrix`]: CSC matrix built from triplets (duplicates summed), products,
//!   transposes, `AᵀA`, sums.
//! - [`SymbolicCholesky`] / [`Cholesky`]: sparse symmetric positive definite solver
//!   (faer's supernodal or simplicial `LLᵀ` after an AMD fill-reducing ordering). The
//!   symbolic analysis is reusable across numeric factorisations of matrices with the
//!   same pattern. Every solve checks its relative residual (see [`CholeskyOptions`]).
//! - Rank-1 update/downdate of a factorisation, `A ± w wᵀ`, for adding and removing
//!   penalty constraints without refactoring ([`Cholesky::update`],
//!   [`Cholesky::add_diagonal_penalty`]; Davis & Hager 1999).
//! - [`least_squares`]: sparse least squares through the normal equations.
//! - [`symmetric_eigen`] and [`Pca`]: dense symmetric eigendecomposition and PCA.
//! - [`stats`]: CCA, k-means, 1-D / n-D histogram matching, quantile functions.
//!
//! # Conventions
//! - Sparse SPD inputs are *full* symmetric matrices (both triangles stored). The
//!   factorisation reads the lower triangle; [`Cholesky::factor`] refuses matrices whose
//!   two triangles disagree.
//! - Nothing is ever returned as NaN silently: non-finite input, failed factorisations
//!   and solves whose residual is too large are typed [`LinalgError`]s.
//! - Determinism: numeric factorisation runs faer with the current rayon pool; solves run
//!   sequentially per block of up to [`MAX_BLOCK`] right-hand sides (blocks in
//!   parallel), and every reduction
//!   has a fixed order, so results do not depend on the thread count.

mod blocked_update;
mod cholesky;
mod cholesky_update;
mod conjugate_gradients;
mod dense;
mod grid_nested_dissection;
mod least_squares;
mod multi_rhs_solve;
mod multiple_rank_update;
mod partial_solve;
mod sparse_matrix;
pub mod stats;
mod subtree_schedule;
mod supernodal_solve;
#[cfg(test)]
mod test_support;

pub use cholesky::{Cholesky, CholeskyOptions, FactorLayout, SymbolicCholesky};
pub use cholesky_update::UpdateSign;
pub use conjugate_gradients::conjugate_gradients;
pub use dense::{Pca, symmetric_eigen};
pub use grid_nested_dissection::grid_nested_dissection;
pub use least_squares::least_squares;
pub use multi_rhs_solve::MAX_BLOCK;
pub use sparse_matrix::SparseMatrix;

use thiserror::Error;

/// Failures of factorisations and solves. Never a silent NaN.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum LinalgError {
    #[error(
        "factorisation of a {size}×{size} matrix failed: {reason} (is the matrix symmetric positive definite, without empty rows?)"
    )]
    FactorizationFailed { size: usize, reason: String },
    #[error(
        "solve of a {size}×{size} system left relative residual {residual:e} (tolerance {tolerance:e}); the matrix is too badly conditioned for this tolerance"
    )]
    SolveFailed { size: usize, residual: f64, tolerance: f64 },
    #[error("dimension mismatch: {what}: expected {expected}, found {found}")]
    Dimension { what: &'static str, expected: usize, found: usize },
    #[error("non-finite value in {what} at index {index}")]
    NonFinite { what: &'static str, index: usize },
    #[error("index ({row}, {col}) out of range for a {nrows}×{ncols} matrix")]
    IndexOutOfRange { row: usize, col: usize, nrows: usize, ncols: usize },
    #[error(
        "matrix is not symmetric: entry ({row}, {col}) = {value:e} but its mirror = {mirror:e}; pass both triangles of a symmetric matrix"
    )]
    NotSymmetric { row: usize, col: usize, value: f64, mirror: f64 },
    #[error(
        "sparsity pattern differs from the one the symbolic analysis was made for ({what}); run SymbolicCholesky::analyze on this matrix"
    )]
    PatternMismatch { what: &'static str },
    #[error("rank-1 {kind} failed at column {column}: {reason}; the factor is unchanged")]
    UpdateFailed { kind: &'static str, column: usize, reason: String },
    #[error("invalid argument {what} = {value:e}: {reason}")]
    InvalidArgument { what: &'static str, value: f64, reason: &'static str },
}

impl LinalgError {
    /// `Ok` when `found == expected`, else [`LinalgError::Dimension`] naming `what`.
    pub(crate) fn check_len(what: &'static str, expected: usize, found: usize) -> Result<(), Self> {
        if found == expected { Ok(()) } else { Err(Self::Dimension { what, expected, found }) }
    }
}

/// Every solver failure is internal: the workspace builds its matrices itself, so a
/// failed factorisation or a bad argument is our bug or a numerical breakdown.
impl fieldtex_core::HasErrorKind for LinalgError {
    fn kind(&self) -> fieldtex_core::ErrorKind {
        fieldtex_core::ErrorKind::Internal
    }
}
