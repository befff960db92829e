//! Dense symmetric eigendecomposition and principal component analysis, on faer.
//!
//! Conventions: dense matrices are row-major `n × n` slices; eigenvalues are returned in
//! **descending** order and eigenvector `k` is **column** `k` of the row-major output
//! (`vecs[i * n + k]`). Each eigenvector's sign is fixed so that its largest-magnitude
//! component (first one on ties) is positive, which makes results reproducible.

use faer::{Mat, Par, Side};
use rayon::prelude::*;

use crate::LinalgError;

/// Eigen-decomposition of the symmetric row-major `n × n` matrix `a`:
/// `(values, vectors)` with values descending and unit eigenvectors as columns of the
/// row-major `n × n` `vectors`. Errors on wrong length, non-finite or asymmetric input
/// (relative tolerance `1e-10`).
pub fn symmetric_eigen(a: &[f64], n: usize) -> Result<(Vec<f64>, Vec<f64>), LinalgError> {
    LinalgError::check_len("dense symmetric matrix (n²)", n * n, a.len())?;
    if let Some(index) = a.iter().position(|v| !v.is_finite()) {
        return Err(LinalgError::NonFinite { what: "dense symmetric matrix", index });
    }
    for i in 0..n {
        for j in 0..i {
            let (x, y) = (a[i * n + j], a[j * n + i]);
            if (x - y).abs() > 1e-10 * x.abs().max(y.abs()) {
                return Err(LinalgError::NotSymmetric { row: i, col: j, value: x, mirror: y });
            }
        }
    }
    if n == 0 {
        return Ok((Vec::new(), Vec::new()));
    }
    let m = Mat::<f64>::from_fn(n, n, |i, j| a[i * n + j]);
    let evd = m.self_adjoint_eigen(Side::Lower).map_err(|e| LinalgError::FactorizationFailed {
        size: n,
        reason: format!("symmetric eigendecomposition did not converge: {e:?}"),
    })?;
    let s = evd.S().column_vector();
    let u = evd.U();
    let mut values = Vec::with_capacity(n);
    let mut vectors = vec![0.0; n * n];
    for k in 0..n {
        let src = n - 1 - k; // faer sorts ascending
        values.push(s[src]);
        let mut best = 0;
        for i in 0..n {
            if u[(i, src)].abs() > u[(best, src)].abs() {
                best = i;
            }
        }
        let sign = if u[(best, src)] < 0.0 { -1.0 } else { 1.0 };
        for i in 0..n {
            vectors[i * n + k] = sign * u[(i, src)];
        }
    }
    if values.iter().chain(&vectors).any(|v| !v.is_finite()) {
        return Err(LinalgError::FactorizationFailed {
            size: n,
            reason: "eigendecomposition produced non-finite values".into(),
        });
    }
    Ok((values, vectors))
}

/// Principal component analysis of row-major `N × dim` samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Pca {
    /// Sample mean, `dim` entries.
    pub mean: Vec<f64>,
    /// `k` unit principal directions (each `dim` entries), by decreasing variance.
    pub components: Vec<Vec<f64>>,
    /// Variance along each component (covariance eigenvalue, `1/(N−1)` normalisation;
    /// `1/N` when `N = 1`), `k` entries, descending.
    pub variances: Vec<f64>,
}

/// Rows per covariance chunk: fixed, so the summation order (and result) does not depend
/// on the thread count.
const PCA_CHUNK: usize = 4096;

impl Pca {
    /// Fits the `k` leading components of `samples` (row-major `N × dim`, `N ≥ 1`,
    /// `1 ≤ k ≤ dim`). The covariance is accumulated in `f64` per fixed chunk of rows
    /// (faer GEMM, sequential inside a chunk, chunks in parallel, summed in order).
    pub fn fit(samples: &[f32], dim: usize, k: usize) -> Result<Pca, LinalgError> {
        if dim == 0 || samples.is_empty() || !samples.len().is_multiple_of(dim) {
            return Err(LinalgError::Dimension {
                what: "PCA samples (a non-empty multiple of dim)",
                expected: dim.max(1) * (samples.len() / dim.max(1)).max(1),
                found: samples.len(),
            });
        }
        if k == 0 || k > dim {
            return Err(LinalgError::InvalidArgument {
                what: "PCA component count k",
                value: k as f64,
                reason: "must be between 1 and dim",
            });
        }
        if let Some(index) = samples.iter().position(|v| !v.is_finite()) {
            return Err(LinalgError::NonFinite { what: "PCA sample", index });
        }
        let count = samples.len() / dim;
        let chunk_sums: Vec<Vec<f64>> = samples
            .par_chunks(PCA_CHUNK * dim)
            .map(|c| {
                let mut s = vec![0.0; dim];
                for row in c.chunks_exact(dim) {
                    for (a, &v) in s.iter_mut().zip(row) {
                        *a += v as f64;
                    }
                }
                s
            })
            .collect();
        let mut mean = vec![0.0; dim];
        for s in &chunk_sums {
            for (m, v) in mean.iter_mut().zip(s) {
                *m += v;
            }
        }
        mean.iter_mut().for_each(|m| *m /= count as f64);
        let covs: Vec<Mat<f64>> = samples
            .par_chunks(PCA_CHUNK * dim)
            .map(|c| {
                let rows = c.len() / dim;
                let x = Mat::<f64>::from_fn(rows, dim, |i, j| c[i * dim + j] as f64 - mean[j]);
                let mut cov = Mat::<f64>::zeros(dim, dim);
                faer::linalg::matmul::matmul(
                    cov.as_mut(),
                    faer::Accum::Replace,
                    x.transpose(),
                    x.as_ref(),
                    1.0,
                    Par::Seq,
                );
                cov
            })
            .collect();
        let mut cov = vec![0.0; dim * dim];
        for c in &covs {
            for i in 0..dim {
                for j in 0..dim {
                    cov[i * dim + j] += c[(i, j)];
                }
            }
        }
        let denom = if count > 1 { (count - 1) as f64 } else { 1.0 };
        // Symmetrise exactly (GEMM may round the two triangles differently).
        for i in 0..dim {
            for j in 0..i {
                let v = 0.5 * (cov[i * dim + j] + cov[j * dim + i]) / denom;
                cov[i * dim + j] = v;
                cov[j * dim + i] = v;
            }
            cov[i * dim + i] /= denom;
        }
        let (values, vectors) = symmetric_eigen(&cov, dim)?;
        let components = (0..k).map(|c| (0..dim).map(|i| vectors[i * dim + c]).collect()).collect();
        let variances = values[..k].iter().map(|v| v.max(0.0)).collect();
        Ok(Pca { mean, components, variances })
    }

    /// Input dimension.
    pub fn dim(&self) -> usize {
        self.mean.len()
    }

    /// Number of components.
    pub fn k(&self) -> usize {
        self.components.len()
    }

    /// Projects row-major samples `x` (`m × dim`) onto the components: `out` (`m × k`)
    /// gets `(x − mean) · component`. Panics if the lengths do not match (programmer
    /// error: `out.len() / k` must equal `x.len() / dim`).
    pub fn project(&self, x: &[f32], out: &mut [f32]) {
        let (d, k) = (self.dim(), self.k());
        assert!(
            x.len().is_multiple_of(d) && out.len() == x.len() / d * k,
            "Pca::project: x must hold m × dim values and out m × k"
        );
        for (row, o) in x.chunks_exact(d).zip(out.chunks_exact_mut(k)) {
            for (c, oc) in self.components.iter().zip(o.iter_mut()) {
                let mut s = 0.0f64;
                for ((&xi, &mi), &ci) in row.iter().zip(&self.mean).zip(c) {
                    s += (xi as f64 - mi) * ci;
                }
                *oc = s as f32;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigen_of_known_matrix() {
        // [[2,1],[1,2]]: eigenvalues 3 (1,1)/√2 and 1 (1,−1)/√2.
        let (vals, vecs) = symmetric_eigen(&[2.0, 1.0, 1.0, 2.0], 2).unwrap();
        assert!((vals[0] - 3.0).abs() < 1e-12 && (vals[1] - 1.0).abs() < 1e-12);
        let h = 0.5f64.sqrt();
        assert!((vecs[0] - h).abs() < 1e-12 && (vecs[2] - h).abs() < 1e-12);
        assert!((vecs[1].abs() - h).abs() < 1e-12 && (vecs[1] + vecs[3]).abs() < 1e-12);
    }

    #[test]
    fn eigen_reconstructs_random_matrix() {
        let n = 7;
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..=i {
                let v = ((i * 31 + j * 17) % 11) as f64 - 5.0;
                a[i * n + j] = v;
                a[j * n + i] = v;
            }
        }
        let (vals, vecs) = symmetric_eigen(&a, n).unwrap();
        assert!(vals.windows(2).all(|w| w[0] >= w[1]));
        for i in 0..n {
            for j in 0..n {
                let r: f64 = (0..n).map(|k| vecs[i * n + k] * vals[k] * vecs[j * n + k]).sum();
                assert!((r - a[i * n + j]).abs() < 1e-10);
            }
        }
    }

    #[test]
    fn eigen_rejects_bad_input() {
        assert!(symmetric_eigen(&[1.0, 2.0, 3.0], 2).is_err());
        assert!(symmetric_eigen(&[1.0, f64::NAN, f64::NAN, 1.0], 2).is_err());
        assert!(matches!(
            symmetric_eigen(&[1.0, 2.0, 0.0, 1.0], 2),
            Err(LinalgError::NotSymmetric { .. })
        ));
    }

    #[test]
    fn pca_finds_dominant_direction() {
        // Points along (3, 4)/5 with small orthogonal noise.
        let mut s = Vec::new();
        for i in 0..501 {
            let t = (i as f32 - 250.0) * 0.1;
            let e = if i % 2 == 0 { 0.01 } else { -0.01 };
            s.extend_from_slice(&[1.0 + 0.6 * t - 0.8 * e, -2.0 + 0.8 * t + 0.6 * e]);
        }
        let pca = Pca::fit(&s, 2, 1).unwrap();
        let c = &pca.components[0];
        assert!((c[0].abs() - 0.6).abs() < 1e-4 && (c[1].abs() - 0.8).abs() < 1e-4, "{c:?}");
        assert!((pca.mean[0] - 1.0).abs() < 1e-3 && (pca.mean[1] + 2.0).abs() < 1e-3);
        let mut out = [0.0f32; 2];
        pca.project(&[1.0 + 0.6, -2.0 + 0.8, 1.0, -2.0], &mut out);
        assert!((out[0].abs() - 1.0).abs() < 0.01 && out[1].abs() < 0.01, "{out:?}");
        assert!(Pca::fit(&s, 2, 3).is_err());
        assert!(Pca::fit(&s[..3], 2, 1).is_err());
        assert!(Pca::fit(&[f32::NAN, 0.0], 2, 1).is_err());
    }

    #[test]
    fn pca_is_thread_count_independent() {
        let s: Vec<f32> = (0..3 * 9000).map(|i| ((i * 7919) % 1000) as f32 * 0.001).collect();
        let fit = |t| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .unwrap()
                .install(|| Pca::fit(&s, 3, 2).unwrap())
        };
        assert_eq!(fit(1), fit(2));
    }
}
