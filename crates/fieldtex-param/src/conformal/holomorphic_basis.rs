//! Conjugates of harmonic 1-forms by the Hodge star and the holomorphic 1-form basis
//! (Gu & Yau 2003, §4.3), with the discrete exterior calculus inner product.
//!
//! For a basis `ω_1 … ω_m` (`m = 2g`) of harmonic 1-forms the smooth conjugate `⋆ω_k`
//! is again harmonic, so `⋆ω_k = Σ_j c_kj ω_j`. On a mesh the pointwise conjugate of a
//! piecewise-linear form (face vector `n × X_k`) is not in the span of the discrete
//! harmonic forms, so `c_k` has to be chosen. Gu & Yau wedge with `ω_i` and solve
//! `Σ_j c_kj ∫ω_i∧ω_j = ∫⟨ω_i, ω_k⟩` (a Petrov–Galerkin condition with test forms
//! `⋆ω_i`). Here the conjugate is the **orthogonal projection of `⋆ω_k` onto the
//! harmonic space** in the DEC inner product `⟨α, β⟩ = Σ_e ⋆1_e α_e β_e`, with the
//! same unclamped cotan `⋆1` the forms were made harmonic with (the values of
//! [`fieldtex_mesh::hodge_star1`] without a clamp; one source, so the projection is
//! orthogonal to the exact forms the harmonic projection removed): the Gram system
//! `Σ_j ⟨ω_i, ω_j⟩ c_kj = ⟨ω_i, ⋆ω_k⟩ = ∫ω_k∧ω_i`. The pointwise conjugate `n × X_k`
//! is L²-orthogonal to every piecewise-linear gradient (its pairing with `∇φ_v` is half
//! the circulation of `ω_k` around the link of `v`, zero for a closed form), so this
//! projection is the closest closed piecewise-linear form to `⋆ω_k` — the minimiser of
//! the conformal energy `∫|∇v − n × ∇u|²` for `u = ∫ω_k` — and its residual is never
//! above the wedge system's. The wedges are the exact integrals of the Whitney forms,
//! `∫ω_i∧ω_j = Σ_f A_f n_f·(X_i × X_j)`. The holomorphic basis is `ω_k + i ⋆ω_k`.
//! Both residuals (relative, area-weighted distance of `n × X_k` to `Σ_j c_kj X_j`,
//! worst `k`) are returned so the choice is measured.
#![allow(clippy::needless_range_loop)] // index loops over parallel per-face tables

use super::cotan_system::conformal_error;
use crate::ParamError;
use fieldtex_core::vec3;

/// Conjugation coefficients and their fit.
#[derive(Debug, Clone)]
pub struct Conjugates {
    /// `m × m`: `⋆ω_k = Σ_j coefficients[k][j] ω_j` (the DEC projection).
    pub coefficients: Vec<Vec<f64>>,
    /// Relative area-weighted distance of `n × X_k` to `Σ_j c_kj X_j`, worst `k`.
    pub residual: f64,
    /// The same distance for Gu & Yau's wedge system, for comparison.
    pub residual_wedge_system: f64,
}

/// Computes the conjugates of the harmonic forms `forms[k]` (`#E` each, indexed like
/// `topology.edges`) whose face vectors are `x[k]` (`#F` each); `star1` is the DEC
/// Hodge star on edges (`#E`), `areas`/`normals` per face.
pub fn conjugates(
    forms: &[Vec<f64>],
    star1: &[f64],
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
            }
        }
    }
    for i in 0..m {
        for j in i..m {
            let g: f64 = star1.iter().enumerate().map(|(e, s)| s * forms[i][e] * forms[j][e]).sum();
            gram[i][j] = g;
            gram[j][i] = g;
        }
    }
    let singular = || {
        conformal_error(
            "the inner-product matrix of the harmonic 1-forms is singular (degenerate homology basis)",
        )
    };
    let fit_residual = |k: usize, c: &[f64]| {
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
        if den > 0.0 { (num / den).sqrt() } else { 0.0 }
    };
    let mut coefficients = Vec::with_capacity(m);
    let (mut residual, mut residual_wedge_system) = (0.0f64, 0.0f64);
    for k in 0..m {
        // ⟨ω_i, ⋆ω_k⟩ = ∫ω_k ∧ ω_i.
        let rhs: Vec<f64> = (0..m).map(|i| wedge[k][i]).collect();
        let c = dense_solve(gram.clone(), rhs).ok_or_else(singular)?;
        residual = residual.max(fit_residual(k, &c));
        let rhs_wedge: Vec<f64> = (0..m).map(|i| gram[i][k]).collect();
        if let Some(cw) = dense_solve(wedge.clone(), rhs_wedge) {
            residual_wedge_system = residual_wedge_system.max(fit_residual(k, &cw));
        } else {
            residual_wedge_system = f64::INFINITY;
        }
        coefficients.push(c);
    }
    Ok(Conjugates { coefficients, residual, residual_wedge_system })
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
