//! Regularised canonical correlation analysis (Hotelling 1936).
//!
//! Given paired samples `x` (`N × p`) and `y` (`N × q`), CCA finds directions `a_k`
//! (`p` entries) and `b_k` (`q` entries) such that the projections `x·a_k` and `y·b_k`
//! have maximal correlation `ρ_k`, each pair uncorrelated with the previous ones. It is
//! computed here as the singular value decomposition of the whitened cross-covariance
//! `M = Cxx^{-1/2} Cxy Cyy^{-1/2}` (`p × q`): with `M = U Σ Vᵀ`, `ρ_k = σ_k`,
//! `a_k = Cxx^{-1/2} u_k`, `b_k = Cyy^{-1/2} v_k`. The SVD of the thin `M` is taken from
//! the eigendecomposition of `MᵀM` (`q × q`), `u_k = M v_k / σ_k`.
//!
//! Regularisation (ridge): `Cxx + λ · mean(diag Cxx) · I` and likewise for `Cyy`, so
//! constant or collinear descriptors do not make the whitening singular.
//!
//! Normalisation: projections `x·a_k` have unit variance under the regularised
//! covariance. `d = min(p, q)` pairs are returned, correlations descending. Signs: the
//! largest-magnitude entry of each `b_k` is positive.
//!
//! Paper B (Mertens, Kautz, Chen, Bekaert & Durand 2006, §3.3) uses the `x` side
//! (geometric descriptors → 3-D guidance, `d = 3` for RGB).

use super::{STATS_CHUNK, column_means};
use crate::{LinalgError, symmetric_eigen};
use rayon::prelude::*;

/// Options of [`cca`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CcaOptions {
    /// Ridge `λ` relative to the mean variance of each side. Default `1e-3`.
    pub regularization: f64,
}

impl Default for CcaOptions {
    fn default() -> Self {
        Self { regularization: 1e-3 }
    }
}

/// The result of [`cca`].
#[derive(Debug, Clone, PartialEq)]
pub struct Cca {
    /// `p` means of `x`.
    pub x_mean: Vec<f64>,
    /// `q` means of `y`.
    pub y_mean: Vec<f64>,
    /// `d` directions `a_k` (`p` entries each).
    pub x_weights: Vec<Vec<f64>>,
    /// `d` directions `b_k` (`q` entries each).
    pub y_weights: Vec<Vec<f64>>,
    /// `d` canonical correlations, descending, in `[0, 1]`.
    pub correlations: Vec<f64>,
}

impl Cca {
    /// Projects row-major `x` (`m × p`) to `out` (`m × d`): `(x − mean)·a_k`.
    /// Panics on mismatched lengths (programmer error).
    pub fn project_x(&self, x: &[f64], out: &mut [f64]) {
        project(&self.x_mean, &self.x_weights, x, out);
    }

    /// Projects row-major `y` (`m × q`) to `out` (`m × d`).
    pub fn project_y(&self, y: &[f64], out: &mut [f64]) {
        project(&self.y_mean, &self.y_weights, y, out);
    }
}

fn project(mean: &[f64], w: &[Vec<f64>], x: &[f64], out: &mut [f64]) {
    let (p, d) = (mean.len(), w.len());
    assert!(
        x.len().is_multiple_of(p) && out.len() == x.len() / p * d,
        "Cca::project: x must hold m × p values and out m × d"
    );
    out.par_chunks_mut(d).zip(x.par_chunks(p)).for_each(|(o, row)| {
        for (ok, wk) in o.iter_mut().zip(w) {
            *ok = row.iter().zip(mean).zip(wk).map(|((v, m), c)| (v - m) * c).sum();
        }
    });
}

/// Covariance blocks of the stacked `[x y]` (`(p+q)²`, `1/N`), fixed-order sums.
fn joint_covariance(x: &[f64], p: usize, y: &[f64], q: usize, mx: &[f64], my: &[f64]) -> Vec<f64> {
    let d = p + q;
    let n = x.len() / p;
    let chunks: Vec<Vec<f64>> = (0..n.div_ceil(STATS_CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut s = vec![0.0; d * d];
            let mut z = vec![0.0; d];
            for i in c * STATS_CHUNK..((c + 1) * STATS_CHUNK).min(n) {
                for k in 0..p {
                    z[k] = x[i * p + k] - mx[k];
                }
                for k in 0..q {
                    z[p + k] = y[i * q + k] - my[k];
                }
                for a in 0..d {
                    for b in a..d {
                        s[a * d + b] += z[a] * z[b];
                    }
                }
            }
            s
        })
        .collect();
    let mut cov = vec![0.0; d * d];
    for s in &chunks {
        for (a, v) in cov.iter_mut().zip(s) {
            *a += v;
        }
    }
    for a in 0..d {
        for b in a..d {
            let v = cov[a * d + b] / n as f64;
            cov[a * d + b] = v;
            cov[b * d + a] = v;
        }
    }
    cov
}

/// `C^{-1/2}` of a symmetric positive definite row-major `n × n` matrix.
fn inverse_sqrt(c: &[f64], n: usize) -> Result<Vec<f64>, LinalgError> {
    let (vals, vecs) = symmetric_eigen(c, n)?;
    let mut out = vec![0.0; n * n];
    for k in 0..n {
        if vals[k] <= 0.0 {
            return Err(LinalgError::FactorizationFailed {
                size: n,
                reason: format!("covariance eigenvalue {:e} is not positive", vals[k]),
            });
        }
        let s = 1.0 / vals[k].sqrt();
        for i in 0..n {
            for j in 0..n {
                out[i * n + j] += vecs[i * n + k] * s * vecs[j * n + k];
            }
        }
    }
    Ok(out)
}

/// Canonical correlation analysis of `x` (`N × p`) against `y` (`N × q`), module docs.
/// Errors on `N < 2`, mismatched lengths, non-finite input or an invalid `λ`.
pub fn cca(
    x: &[f64],
    p: usize,
    y: &[f64],
    q: usize,
    options: &CcaOptions,
) -> Result<Cca, LinalgError> {
    if p == 0 || q == 0 || !x.len().is_multiple_of(p) || !y.len().is_multiple_of(q) {
        return Err(LinalgError::Dimension {
            what: "CCA samples (multiples of p and q)",
            expected: p.max(1) * (x.len() / p.max(1)),
            found: x.len(),
        });
    }
    let n = x.len() / p;
    LinalgError::check_len("CCA paired rows", n, y.len() / q)?;
    if n < 2 {
        return Err(LinalgError::Dimension {
            what: "CCA sample count (≥ 2)",
            expected: 2,
            found: n,
        });
    }
    if let Some(index) = x.iter().position(|v| !v.is_finite()) {
        return Err(LinalgError::NonFinite { what: "CCA x", index });
    }
    if let Some(index) = y.iter().position(|v| !v.is_finite()) {
        return Err(LinalgError::NonFinite { what: "CCA y", index });
    }
    let lambda = options.regularization;
    if !(lambda.is_finite() && lambda > 0.0) {
        return Err(LinalgError::InvalidArgument {
            what: "CCA regularization",
            value: lambda,
            reason: "must be finite and positive",
        });
    }
    let mx = column_means(x, p);
    let my = column_means(y, q);
    let d = p + q;
    let cov = joint_covariance(x, p, y, q, &mx, &my);
    let block = |r0: usize, c0: usize, r: usize, c: usize| -> Vec<f64> {
        let mut b = vec![0.0; r * c];
        for i in 0..r {
            for j in 0..c {
                b[i * c + j] = cov[(r0 + i) * d + c0 + j];
            }
        }
        b
    };
    let ridge = |mut m: Vec<f64>, n: usize| -> Vec<f64> {
        let mean_var = (0..n).map(|i| m[i * n + i]).sum::<f64>() / n as f64;
        let add = lambda * mean_var.max(f64::MIN_POSITIVE) + 1e-300;
        for i in 0..n {
            m[i * n + i] += add;
        }
        m
    };
    let cxx = ridge(block(0, 0, p, p), p);
    let cyy = ridge(block(p, p, q, q), q);
    let cxy = block(0, p, p, q);
    let wx = inverse_sqrt(&cxx, p)?;
    let wy = inverse_sqrt(&cyy, q)?;
    // M = Wx Cxy Wy (p × q).
    let mut t = vec![0.0; p * q];
    for i in 0..p {
        for j in 0..q {
            t[i * q + j] = (0..p).map(|k| wx[i * p + k] * cxy[k * q + j]).sum();
        }
    }
    let mut m = vec![0.0; p * q];
    for i in 0..p {
        for j in 0..q {
            m[i * q + j] = (0..q).map(|k| t[i * q + k] * wy[k * q + j]).sum();
        }
    }
    let mut mtm = vec![0.0; q * q];
    for a in 0..q {
        for b in 0..q {
            mtm[a * q + b] = (0..p).map(|i| m[i * q + a] * m[i * q + b]).sum();
        }
    }
    for a in 0..q {
        for b in 0..a {
            let v = 0.5 * (mtm[a * q + b] + mtm[b * q + a]);
            mtm[a * q + b] = v;
            mtm[b * q + a] = v;
        }
    }
    let (vals, vecs) = symmetric_eigen(&mtm, q)?;
    let dd = p.min(q);
    let mut x_weights = Vec::with_capacity(dd);
    let mut y_weights = Vec::with_capacity(dd);
    let mut correlations = Vec::with_capacity(dd);
    for k in 0..dd {
        let sigma = vals[k].max(0.0).sqrt();
        let v: Vec<f64> = (0..q).map(|j| vecs[j * q + k]).collect();
        let u: Vec<f64> = if sigma > 1e-12 {
            (0..p).map(|i| (0..q).map(|j| m[i * q + j] * v[j]).sum::<f64>() / sigma).collect()
        } else {
            vec![0.0; p]
        };
        let a: Vec<f64> = (0..p).map(|i| (0..p).map(|k2| wx[i * p + k2] * u[k2]).sum()).collect();
        let b: Vec<f64> = (0..q).map(|i| (0..q).map(|k2| wy[i * q + k2] * v[k2]).sum()).collect();
        x_weights.push(a);
        y_weights.push(b);
        correlations.push(sigma.min(1.0));
    }
    Ok(Cca { x_mean: mx, y_mean: my, x_weights, y_weights, correlations })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::{hashed_normal, pearson};

    /// Planted correlation: y0 = x1 + 0.5 x3 + noise; y1 = x0 + large noise; y2 pure
    /// noise. CCA's first pair must recover the planted direction, its correlation must
    /// equal the empirical correlation of the projections, and a dense brute-force search
    /// over directions must not find a larger correlation.
    #[test]
    fn cca_recovers_planted_correlation_against_dense_reference() {
        let (n, p, q) = (20_000, 5, 3);
        let mut x = vec![0.0; n * p];
        let mut y = vec![0.0; n * q];
        for i in 0..n {
            for k in 0..p {
                // Different scales per column: CCA is scale-invariant.
                x[i * p + k] = hashed_normal(1, "x", (i * p + k) as u64) * (1.0 + k as f64);
            }
            let e = |s: &str| hashed_normal(2, s, i as u64);
            y[i * q] = x[i * p + 1] / 2.0 + 0.5 * x[i * p + 3] / 4.0 + 0.2 * e("e0");
            y[i * q + 1] = x[i * p] + 3.0 * e("e1");
            y[i * q + 2] = e("e2");
        }
        let r = cca(&x, p, &y, q, &CcaOptions { regularization: 1e-9 }).unwrap();
        // Analytic ρ1: column k has standard deviation 1 + k, so the signal
        // x1/2 + x3/8 has variance 1 + 0.25 = 1.25; the noise 0.04.
        let rho1 = (1.25f64 / (1.25 + 0.04)).sqrt();
        assert!((r.correlations[0] - rho1).abs() < 0.01, "{:?} vs {rho1}", r.correlations);
        // Second: y1 vs x0: 1/sqrt(1+9).
        assert!((r.correlations[1] - (0.1f64).sqrt()).abs() < 0.03, "{:?}", r.correlations);
        assert!(r.correlations[2] < 0.05);
        // Direction: a_1 ∝ (0, 1/2, 0, 1/8, 0) on the raw scale.
        let a = &r.x_weights[0];
        let ratio = a[3] / a[1];
        assert!((ratio - 0.25).abs() < 0.03, "{a:?}");
        assert!(a[0].abs() < 0.02 * a[1].abs() && a[2].abs() < 0.02 * a[1].abs());
        // Empirical correlation of the projections equals ρ.
        let mut px = vec![0.0; n * q];
        let mut py = vec![0.0; n * q];
        r.project_x(&x, &mut px);
        r.project_y(&y, &mut py);
        for k in 0..2 {
            let a: Vec<f64> = (0..n).map(|i| px[i * q + k]).collect();
            let b: Vec<f64> = (0..n).map(|i| py[i * q + k]).collect();
            assert!((pearson(&a, &b) - r.correlations[k]).abs() < 1e-6);
        }
        // Dense reference: for random directions a, the best b is the least-squares
        // regression of x·a on y; no such pair beats ρ1.
        for t in 0..200u64 {
            let a: Vec<f64> = (0..p).map(|k| hashed_normal(9, "a", t * 8 + k as u64)).collect();
            let xa: Vec<f64> = (0..n).map(|i| (0..p).map(|k| x[i * p + k] * a[k]).sum()).collect();
            for j in 0..q {
                let yj: Vec<f64> = (0..n).map(|i| y[i * q + j]).collect();
                assert!(pearson(&xa, &yj).abs() <= r.correlations[0] + 1e-9);
            }
        }
    }

    #[test]
    fn cca_rejects_bad_input() {
        assert!(cca(&[1.0, 2.0], 2, &[1.0], 1, &CcaOptions::default()).is_err());
        assert!(
            cca(&[1.0, f64::NAN, 2.0, 3.0], 2, &[1.0, 2.0], 1, &CcaOptions::default()).is_err()
        );
        // Constant columns are handled by the ridge.
        let x: Vec<f64> = (0..100).flat_map(|i| [i as f64, 1.0]).collect();
        let y: Vec<f64> = (0..100).map(|i| 2.0 * i as f64).collect();
        let r = cca(&x, 2, &y, 1, &CcaOptions::default()).unwrap();
        assert!(r.correlations[0] > 0.99);
    }
}
