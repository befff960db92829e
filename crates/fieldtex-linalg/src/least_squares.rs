//! Sparse linear least squares `min ‖A x − b‖₂` through the normal equations
//! `AᵀA x = Aᵀb`, solved with the sparse [`Cholesky`].
//!
//! The normal equations square the condition number of `A`; they are fine for the
//! well-posed, mesh-sized systems of fieldtex (e.g. least-squares conformal maps with
//! pinned vertices, weighted soft constraints). No regularisation is added: a
//! rank-deficient `A` (e.g. a free translation left unpinned) is reported as
//! [`LinalgError::FactorizationFailed`] so the caller can pin or regularise explicitly
//! (e.g. append rows `√ε · I` to `A`). The residual check is applied to the normal
//! equations, `‖AᵀA x − Aᵀb‖ / ‖Aᵀb‖`.

use crate::{Cholesky, LinalgError, SparseMatrix};

/// Least-squares solution of `A x ≈ b` (`A` is `m × n`, `m ≥ n` with full column rank,
/// `b` has `m` entries); returns `x` with `n` entries.
pub fn least_squares(a: &SparseMatrix, b: &[f64]) -> Result<Vec<f64>, LinalgError> {
    LinalgError::check_len("least-squares right-hand side", a.nrows(), b.len())?;
    if let Some(index) = a.first_non_finite() {
        return Err(LinalgError::NonFinite { what: "least-squares matrix value", index });
    }
    if let Some(index) = b.iter().position(|v| !v.is_finite()) {
        return Err(LinalgError::NonFinite { what: "least-squares right-hand side", index });
    }
    let normal = a.ata();
    let rhs = a.transpose_mul_vec(b);
    let chol = Cholesky::factor(&normal)?;
    chol.solve(&rhs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_a_line() {
        // y = 2 + 3 t plus noise orthogonal to (1, t): the fit recovers (2, 3) exactly.
        let ts = [0.0, 1.0, 2.0, 3.0];
        let noise = [0.1, -0.1, -0.1, 0.1];
        let mut trip = Vec::new();
        let mut b = Vec::new();
        for (i, &t) in ts.iter().enumerate() {
            trip.push((i, 0, 1.0));
            trip.push((i, 1, t));
            b.push(2.0 + 3.0 * t + noise[i]);
        }
        let a = SparseMatrix::from_triplets(4, 2, &trip).unwrap();
        let x = least_squares(&a, &b).unwrap();
        assert!((x[0] - 2.0).abs() < 1e-12 && (x[1] - 3.0).abs() < 1e-12, "{x:?}");
    }

    #[test]
    fn rank_deficient_is_an_error() {
        let a =
            SparseMatrix::from_triplets(3, 2, &[(0, 0, 1.0), (1, 0, 1.0), (2, 0, 1.0)]).unwrap();
        let err = least_squares(&a, &[1.0, 2.0, 3.0]).unwrap_err();
        assert!(matches!(err, LinalgError::FactorizationFailed { .. }), "{err}");
    }
}
