//! Conjugates of harmonic 1-forms by the Hodge star and the holomorphic 1-form basis
//! (Gu & Yau 2003, §4.3).
//!
//! For a basis `ω_1 … ω_m` (`m = 2g`) of harmonic 1-forms, the conjugate `⋆ω_k` is
//! again harmonic, so `⋆ω_k = Σ_j c_kj ω_j`. Wedging with `ω_i` and integrating gives the
//! `m × m` system `Σ_j c_kj ∫ω_i∧ω_j = ∫ω_i∧⋆ω_k = ∫⟨ω_i, ω_k⟩`, assembled from the
//! per-face vectors `X` of the forms: `∫ω_i∧ω_j = Σ_f A_f n_f·(X_i × X_j)`,
//! `∫⟨ω_i, ω_k⟩ = Σ_f A_f X_i·X_k`. The holomorphic basis is `ω_k + i ⋆ω_k`.
//! The reported residual is how far `n × X_k` (the pointwise conjugate) is from the
//! span, area-weighted and relative.
#![allow(clippy::needless_range_loop)] // index loops over parallel per-face tables

use super::cotan_system::conformal_error;
use crate::ParamError;
use fieldtex_core::vec3;

/// Conjugation coefficients and their fit.
#[derive(Debug, Clone)]
pub struct Conjugates {
    /// `m × m`: `⋆ω_k = Σ_j coefficients[k][j] ω_j`.
    pub coefficients: Vec<Vec<f64>>,
    /// Relative area-weighted distance of `n × X_k` to `Σ_j c_kj X_j`, worst `k`.
    pub residual: f64,
}

/// Computes the conjugates of the forms whose face vectors are `x[k]` (`#F` each).
pub fn conjugates(
    x: &[Vec<[f64; 3]>],
    areas: &[f64],
    normals: &[[f64; 3]],
) -> Result<Conjugates, ParamError> {
    let m = x.len();
    let nf = areas.len();
    let mut wedge = vec![vec![0.0; m]; m];
    let mut gram = vec![vec![0.0; m]; m];
    for f in 0..nf {
        for i in 0..m {
            for j in 0..m {
                wedge[i][j] += areas[f] * vec3::dot(normals[f], vec3::cross(x[i][f], x[j][f]));
                gram[i][j] += areas[f] * vec3::dot(x[i][f], x[j][f]);
            }
        }
    }
    let mut coefficients = Vec::with_capacity(m);
    let mut residual: f64 = 0.0;
    for k in 0..m {
        let rhs: Vec<f64> = (0..m).map(|i| gram[i][k]).collect();
        let c = dense_solve(wedge.clone(), rhs).ok_or_else(|| {
            conformal_error("the wedge-product matrix of the harmonic 1-forms is singular (degenerate homology basis)")
        })?;
        let (mut num, mut den) = (0.0, 0.0);
        for f in 0..nf {
            let star = vec3::cross(normals[f], x[k][f]);
            let mut fit = [0.0; 3];
            for j in 0..m {
                fit = vec3::add(fit, vec3::scale(x[j][f], c[j]));
            }
            num += areas[f] * vec3::norm2(vec3::sub(star, fit));
            den += areas[f] * vec3::norm2(star);
        }
        if den > 0.0 {
            residual = residual.max((num / den).sqrt());
        }
        coefficients.push(c);
    }
    Ok(Conjugates { coefficients, residual })
}

/// Gaussian elimination with partial pivoting for a small dense system (`None` when
/// singular). Sizes here are `2g ≤ a few dozen`.
pub fn dense_solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    let scale = a.iter().flatten().fold(0.0f64, |s, v| s.max(v.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() <= 1e-13 * scale {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for r in col + 1..n {
            let fct = a[r][col] / a[col][col];
            if fct != 0.0 {
                for c in col..n {
                    a[r][c] -= fct * a[col][c];
                }
                b[r] -= fct * b[col];
            }
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|c| a[r][c] * x[c]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dense_solve_small_system() {
        let a = vec![vec![0.0, 2.0], vec![-2.0, 0.0]];
        let x = dense_solve(a, vec![4.0, 2.0]).unwrap();
        assert!((x[0] + 1.0).abs() < 1e-12 && (x[1] - 2.0).abs() < 1e-12);
        assert!(dense_solve(vec![vec![1.0, 1.0], vec![1.0, 1.0]], vec![1.0, 2.0]).is_none());
    }
}
