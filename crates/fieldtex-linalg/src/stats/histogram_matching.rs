//! Histogram matching: 1-D by cumulative histograms, and n-D by iterated random
//! rotations (Pitié, Kokaram & Dahyot 2005, "N-dimensional probability density function
//! transfer and its application to colour transfer").
//!
//! 1-D: both sets are binned into `bins` equal bins over their own range; each value is
//! mapped through its set's cumulative histogram (linear inside a bin) and back through
//! the reference's inverse cumulative histogram (linear inside a bin). The result has the
//! reference's distribution up to the bin width.
//!
//! n-D: each iteration draws a random orthonormal basis `R` (Gram–Schmidt of a Gaussian
//! matrix from `hash_unit(seed, "pdf-transfer-rotation", …)`), projects both sets on its
//! axes, matches every axis in 1-D and moves each point by `R (matched − projected)`.
//! The iteration converges to the reference's n-D distribution (Pitié et al. Thm. 1);
//! the marginals along the last rotation's axes are matched exactly up to the bins.

use super::hashed_normal;
use crate::LinalgError;
use rayon::prelude::*;

/// Options of [`match_histograms_nd`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HistogramMatchOptions {
    /// Random rotations. Default 12.
    pub iterations: usize,
    /// Bins of the 1-D cumulative histograms. Default 512.
    pub bins: usize,
    pub seed: u64,
}

impl Default for HistogramMatchOptions {
    fn default() -> Self {
        Self { iterations: 12, bins: 512, seed: 0 }
    }
}

/// What [`match_histograms_nd`] did: the mean over the coordinate axes of the mean
/// absolute difference between the quantiles (at 64 probabilities) of the data and of
/// the reference, before and after.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HistogramMatchStats {
    pub iterations: usize,
    pub marginal_distance_before: f64,
    pub marginal_distance_after: f64,
}

/// A cumulative histogram over `[lo, hi]`.
struct Cumulative {
    lo: f64,
    width: f64,
    /// `bins + 1` cumulative fractions, `c[0] = 0`, `c[bins] = 1`.
    c: Vec<f64>,
}

impl Cumulative {
    fn new(values: &[f64], bins: usize) -> Self {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &v in values {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if hi <= lo {
            hi = lo + 1e-12_f64.max(lo.abs() * 1e-12);
        }
        let width = (hi - lo) / bins as f64;
        let mut h = vec![0.0f64; bins];
        for &v in values {
            let b = (((v - lo) / width) as usize).min(bins - 1);
            h[b] += 1.0;
        }
        let n = values.len().max(1) as f64;
        let mut c = Vec::with_capacity(bins + 1);
        c.push(0.0);
        let mut acc = 0.0;
        for x in h {
            acc += x;
            c.push(acc / n);
        }
        Self { lo, width, c }
    }

    fn cdf(&self, v: f64) -> f64 {
        let bins = self.c.len() - 1;
        let x = ((v - self.lo) / self.width).clamp(0.0, bins as f64);
        let b = (x as usize).min(bins - 1);
        let t = x - b as f64;
        self.c[b] + t * (self.c[b + 1] - self.c[b])
    }

    fn inverse(&self, p: f64) -> f64 {
        let bins = self.c.len() - 1;
        // First bin whose upper cumulative value reaches p (skips empty bins).
        let b = self.c[1..].partition_point(|&x| x < p).min(bins - 1);
        let (c0, c1) = (self.c[b], self.c[b + 1]);
        let t = if c1 > c0 { ((p - c0) / (c1 - c0)).clamp(0.0, 1.0) } else { 0.5 };
        self.lo + (b as f64 + t) * self.width
    }
}

/// Matches the distribution of `values` to that of `reference` in place (module docs).
/// Non-finite values are left unchanged; empty inputs do nothing.
pub fn match_histogram_1d(values: &mut [f64], reference: &[f64], bins: usize) {
    let bins = bins.max(2);
    let fin = |v: &[f64]| v.iter().copied().filter(|x| x.is_finite()).collect::<Vec<_>>();
    let (a, r) = (fin(values), fin(reference));
    if a.is_empty() || r.is_empty() {
        return;
    }
    let (ca, cr) = (Cumulative::new(&a, bins), Cumulative::new(&r, bins));
    values.par_iter_mut().filter(|v| v.is_finite()).for_each(|v| *v = cr.inverse(ca.cdf(*v)));
}

/// A random orthonormal `dim × dim` basis, row-major, rows are the axes.
pub fn random_rotation(dim: usize, seed: u64, index: u64) -> Vec<f64> {
    let mut m = vec![0.0; dim * dim];
    for (k, v) in m.iter_mut().enumerate() {
        *v = hashed_normal(seed, "pdf-transfer-rotation", index * (dim * dim) as u64 + k as u64);
    }
    for i in 0..dim {
        for j in 0..i {
            let d: f64 = (0..dim).map(|k| m[i * dim + k] * m[j * dim + k]).sum();
            for k in 0..dim {
                m[i * dim + k] -= d * m[j * dim + k];
            }
        }
        let norm = (0..dim).map(|k| m[i * dim + k].powi(2)).sum::<f64>().sqrt();
        if norm < 1e-9 {
            // Degenerate draw (probability ~0): fall back to the unit axis.
            for k in 0..dim {
                m[i * dim + k] = if k == i { 1.0 } else { 0.0 };
            }
        } else {
            for k in 0..dim {
                m[i * dim + k] /= norm;
            }
        }
    }
    m
}

/// Mean over axes of the mean absolute quantile difference (see [`HistogramMatchStats`]).
fn marginal_distance(x: &[f64], reference: &[f64], dim: usize) -> f64 {
    use super::QuantileFunction;
    let mut total = 0.0;
    for k in 0..dim {
        let a: Vec<f64> = x.iter().skip(k).step_by(dim).copied().collect();
        let b: Vec<f64> = reference.iter().skip(k).step_by(dim).copied().collect();
        let (Some(qa), Some(qb)) =
            (QuantileFunction::from_samples(&a, 64), QuantileFunction::from_samples(&b, 64))
        else {
            continue;
        };
        total += qa.values.iter().zip(&qb.values).map(|(u, v)| (u - v).abs()).sum::<f64>() / 64.0;
    }
    total / dim as f64
}

/// Moves the row-major `N × dim` points `x` so that their n-D distribution matches that
/// of `reference` (`M × dim`), module docs. Errors on mismatched shapes or non-finite
/// input.
pub fn match_histograms_nd(
    x: &mut [f64],
    reference: &[f64],
    dim: usize,
    options: &HistogramMatchOptions,
) -> Result<HistogramMatchStats, LinalgError> {
    if dim == 0 || !x.len().is_multiple_of(dim) || !reference.len().is_multiple_of(dim) {
        return Err(LinalgError::Dimension {
            what: "histogram matching rows (multiples of dim)",
            expected: dim.max(1),
            found: x.len(),
        });
    }
    if let Some(index) = x.iter().position(|v| !v.is_finite()) {
        return Err(LinalgError::NonFinite { what: "histogram matching data", index });
    }
    if let Some(index) = reference.iter().position(|v| !v.is_finite()) {
        return Err(LinalgError::NonFinite { what: "histogram matching reference", index });
    }
    let before = marginal_distance(x, reference, dim);
    if x.is_empty() || reference.is_empty() {
        return Ok(HistogramMatchStats {
            iterations: 0,
            marginal_distance_before: before,
            marginal_distance_after: before,
        });
    }
    let n = x.len() / dim;
    let m = reference.len() / dim;
    let project = |data: &[f64], rows: usize, r: &[f64], axis: usize| -> Vec<f64> {
        (0..rows)
            .into_par_iter()
            .map(|i| (0..dim).map(|k| data[i * dim + k] * r[axis * dim + k]).sum())
            .collect()
    };
    for it in 0..options.iterations {
        let r = random_rotation(dim, options.seed, it as u64);
        for axis in 0..dim {
            let px = project(x, n, &r, axis);
            let pr = project(reference, m, &r, axis);
            let mut matched = px.clone();
            match_histogram_1d(&mut matched, &pr, options.bins);
            x.par_chunks_mut(dim).enumerate().for_each(|(i, row)| {
                let d = matched[i] - px[i];
                for k in 0..dim {
                    row[k] += d * r[axis * dim + k];
                }
            });
        }
    }
    // A final pass on the coordinate axes makes the reported marginals exact up to bins.
    for axis in 0..dim {
        let mut col: Vec<f64> = x.iter().skip(axis).step_by(dim).copied().collect();
        let refc: Vec<f64> = reference.iter().skip(axis).step_by(dim).copied().collect();
        match_histogram_1d(&mut col, &refc, options.bins);
        for (i, v) in col.into_iter().enumerate() {
            x[i * dim + axis] = v;
        }
    }
    let after = marginal_distance(x, reference, dim);
    Ok(HistogramMatchStats {
        iterations: options.iterations,
        marginal_distance_before: before,
        marginal_distance_after: after,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::QuantileFunction;

    #[test]
    fn one_d_matching_reproduces_the_reference_quantiles() {
        let mut a: Vec<f64> = (0..20_000u64).map(|i| hashed_normal(1, "a", i)).collect();
        // Reference: exponential.
        let r: Vec<f64> = (0..30_000u64)
            .map(|i| -(1.0 - fieldtex_core::rng::hash_unit(2, "r", i)).ln())
            .collect();
        match_histogram_1d(&mut a, &r, 1024);
        let qa = QuantileFunction::from_samples(&a, 50).unwrap();
        let qr = QuantileFunction::from_samples(&r, 50).unwrap();
        for (x, y) in qa.values.iter().zip(&qr.values) {
            assert!((x - y).abs() < 0.03 * (1.0 + y.abs()), "{x} vs {y}");
        }
    }

    /// n-D matching: a correlated Gaussian blob onto an L-shaped 3-D mixture. The
    /// matched marginals equal the reference's within tolerance, and the joint
    /// distribution moved too (the covariance between axes approaches the reference's).
    #[test]
    fn nd_matching_equalises_marginals_and_joint() {
        let dim = 3;
        let n = 20_000u64;
        let mut x: Vec<f64> = Vec::new();
        for i in 0..n {
            let g = hashed_normal(3, "g", i);
            x.push(g);
            x.push(0.5 * g + hashed_normal(3, "h", i));
            x.push(2.0 + 0.3 * hashed_normal(3, "k", i));
        }
        let mut r: Vec<f64> = Vec::new();
        for i in 0..n {
            let u = |s: &str| fieldtex_core::rng::hash_unit(4, s, i);
            if i % 2 == 0 {
                r.extend([u("a") * 4.0, 0.2 * u("b"), -1.0 + 0.2 * u("c")]);
            } else {
                r.extend([0.2 * u("a"), u("b") * 3.0, 1.0 + 0.2 * u("c")]);
            }
        }
        let stats = match_histograms_nd(
            &mut x,
            &r,
            dim,
            &HistogramMatchOptions { iterations: 20, bins: 512, seed: 7 },
        )
        .unwrap();
        assert!(stats.marginal_distance_before > 0.5, "{stats:?}");
        assert!(stats.marginal_distance_after < 0.02, "{stats:?}");
        for k in 0..dim {
            let a: Vec<f64> = x.iter().skip(k).step_by(dim).copied().collect();
            let b: Vec<f64> = r.iter().skip(k).step_by(dim).copied().collect();
            let (qa, qb) = (
                QuantileFunction::from_samples(&a, 20).unwrap(),
                QuantileFunction::from_samples(&b, 20).unwrap(),
            );
            for (u, v) in qa.values.iter().zip(&qb.values) {
                assert!((u - v).abs() < 0.05, "axis {k}: {u} vs {v}");
            }
        }
        // Joint: in the reference, axis 0 large ⇒ axis 2 ≈ −1; check the matched data.
        let mut z_when_x_large = Vec::new();
        for i in 0..n as usize {
            if x[i * dim] > 1.0 {
                z_when_x_large.push(x[i * dim + 2]);
            }
        }
        let mean = z_when_x_large.iter().sum::<f64>() / z_when_x_large.len() as f64;
        assert!(mean < -0.5, "joint structure not transferred: {mean}");
    }

    #[test]
    fn rotations_are_orthonormal() {
        let r = random_rotation(4, 1, 2);
        for i in 0..4 {
            for j in 0..4 {
                let d: f64 = (0..4).map(|k| r[i * 4 + k] * r[j * 4 + k]).sum();
                assert!((d - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
    }
}
