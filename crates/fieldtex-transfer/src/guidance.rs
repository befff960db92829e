//! The guidance field (paper B §3.3): descriptors reduced to 3 dimensions by canonical
//! correlation analysis against the source colours (`fieldtex_linalg::stats::cca`), the
//! same projection applied to the target. `Reduction::Pca` replaces CCA by the 3 leading
//! principal components of the source descriptors (the ablation of the paper's Fig. 6).
//!
//! Descriptors are first standardised with the source's mean and standard deviation
//! (usable samples only), so that the reported weights are comparable across
//! descriptors: `descriptor_weights[d]` is `|a₁[d]| / Σ|a₁|` for the first canonical
//! direction `a₁` (paper Fig. 4).
//!
//! **Correlation weighting** (`Reduction::CcaWeighted`, the default): guidance dimension `k` is the
//! canonical variate scaled by its canonical correlation `ρ_k`, i.e. `√Λ W_xᵀ x` of the
//! paper's relation `√Λ W_xᵀ x ≈ W_yᵀ y` (§3.3): the guidance then predicts the colour's
//! canonical variates, and a direction that explains nothing (`ρ ≈ 0`) shrinks to
//! nothing instead of weighing as much as the informative one in k-means, in feature
//! matching (whose random rotations would otherwise mix it into the informative axis)
//! and in neighbourhood distances. Measured (`docs/transfer.md`): it is the best setting
//! on the known-answer benchmark and the one with which feature matching helps when the
//! shapes differ. `Reduction::Cca` keeps unit-variance canonical variates; PCA
//! dimensions are the principal components scaled to unit variance.

use crate::TransferError;
use crate::descriptors::N_DESCRIPTORS;
use fieldtex_linalg::Pca;
use fieldtex_linalg::stats::{CcaOptions, cca};
use serde::Serialize;

/// Dimensionality reduction of the descriptors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Reduction {
    /// Canonical correlation analysis with the colours: unit-variance canonical variates
    /// (default).
    Cca,
    /// Canonical variates weighted by their canonical correlations (module docs).
    #[serde(rename = "cca-weighted")]
    CcaWeighted,
    /// Principal components of the descriptors (ablation).
    Pca,
}

/// Guidance on source and target.
#[derive(Debug, Clone, PartialEq)]
pub struct Guidance {
    /// `#source × 3`.
    pub source: Vec<f64>,
    /// `#target × 3`.
    pub target: Vec<f64>,
    /// Canonical correlations (CCA) or explained variance fractions (PCA), 3 entries.
    pub strengths: Vec<f64>,
    /// The 3 projection directions on the standardised descriptors (12 entries each).
    pub directions: Vec<Vec<f64>>,
    /// Normalised magnitudes of the first direction, 12 entries summing to 1.
    pub descriptor_weights: Vec<f64>,
}

/// Source standard deviation below which a descriptor counts as constant.
const CONSTANT_DESCRIPTOR_SD: f64 = 1e-6;

/// Builds the guidance (module docs). `xs` is `#source × 12`, `ys` `#source × 3` (RGB),
/// `valid` marks the source samples used for fitting, `xt` is `#target × 12`.
pub fn build_guidance(
    xs: &[f64],
    ys: &[f64],
    valid: &[bool],
    xt: &[f64],
    reduction: Reduction,
) -> Result<Guidance, TransferError> {
    let d = N_DESCRIPTORS;
    let rows: Vec<usize> = (0..valid.len()).filter(|&i| valid[i]).collect();
    if rows.len() < 16 {
        return Err(TransferError::TooFewSamples { found: rows.len(), needed: 16 });
    }
    let mut mean = vec![0.0; d];
    for &i in &rows {
        for k in 0..d {
            mean[k] += xs[i * d + k];
        }
    }
    mean.iter_mut().for_each(|m| *m /= rows.len() as f64);
    let mut sd = vec![0.0; d];
    for &i in &rows {
        for k in 0..d {
            sd[k] += (xs[i * d + k] - mean[k]).powi(2);
        }
    }
    // A descriptor (nearly) constant on the source cannot explain its colour, and
    // dividing by its rounding-level spread would blow its target values up by orders of
    // magnitude: it is standardised to 0 on both meshes (weight 0). The descriptors are
    // all O(1) (height in [0, 1], unit normals, fractions, SH of a visibility function).
    let scale: Vec<f64> = sd
        .iter()
        .map(|s| {
            let s = (*s / rows.len() as f64).sqrt();
            if s > CONSTANT_DESCRIPTOR_SD { 1.0 / s } else { 0.0 }
        })
        .collect();
    let standardise = |x: &[f64]| -> Vec<f64> {
        x.chunks_exact(d).flat_map(|r| (0..d).map(|k| (r[k] - mean[k]) * scale[k])).collect()
    };
    let zs = standardise(xs);
    let zt = standardise(xt);
    let fit_x: Vec<f64> =
        rows.iter().flat_map(|&i| zs[i * d..(i + 1) * d].iter().copied()).collect();
    let (directions, offsets, strengths) = match reduction {
        Reduction::Cca | Reduction::CcaWeighted => {
            let fit_y: Vec<f64> =
                rows.iter().flat_map(|&i| ys[i * 3..i * 3 + 3].iter().copied()).collect();
            let c = cca(&fit_x, d, &fit_y, 3, &CcaOptions::default())
                .map_err(|e| TransferError::numeric("CCA", e))?;
            let weighted = reduction == Reduction::CcaWeighted;
            let dirs: Vec<Vec<f64>> = c
                .x_weights
                .iter()
                .zip(&c.correlations)
                .map(|(w, &rho)| {
                    let f = if weighted { rho.max(0.0) } else { 1.0 };
                    w.iter().map(|v| v * f).collect()
                })
                .collect();
            let offsets: Vec<f64> =
                dirs.iter().map(|w| w.iter().zip(&c.x_mean).map(|(a, m)| a * m).sum()).collect();
            (dirs, offsets, c.correlations)
        }
        Reduction::Pca => {
            let f32s: Vec<f32> = fit_x.iter().map(|&v| v as f32).collect();
            let p = Pca::fit(&f32s, d, 3).map_err(|e| TransferError::numeric("PCA", e))?;
            let total: f64 = (d as f64).max(1e-12); // standardised: total variance = d
            let dirs: Vec<Vec<f64>> = p
                .components
                .iter()
                .zip(&p.variances)
                .map(|(c, v)| c.iter().map(|x| x / v.max(1e-12).sqrt()).collect())
                .collect();
            let offsets: Vec<f64> =
                dirs.iter().map(|w| w.iter().zip(&p.mean).map(|(a, m)| a * m).sum()).collect();
            (dirs, offsets, p.variances.iter().map(|v| v / total).collect())
        }
    };
    let project = |z: &[f64]| -> Vec<f64> {
        z.chunks_exact(d)
            .flat_map(|r| {
                directions
                    .iter()
                    .zip(&offsets)
                    .map(|(w, o)| r.iter().zip(w).map(|(a, b)| a * b).sum::<f64>() - o)
                    .collect::<Vec<_>>()
            })
            .collect()
    };
    let source = project(&zs);
    let target = project(&zt);
    // Weights from the unscaled first direction (a positive factor does not change them).
    let first = &directions[0];
    let total: f64 = first.iter().map(|v| v.abs()).sum::<f64>().max(1e-300);
    let descriptor_weights = first.iter().map(|v| v.abs() / total).collect();
    Ok(Guidance { source, target, strengths, directions, descriptor_weights })
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_core::rng::hash_unit;

    /// Colour depends on descriptor 0 only: weighting by the canonical correlations keeps
    /// the first guidance dimension and shrinks the two uninformative ones; unweighted
    /// CCA gives all three unit variance.
    #[test]
    fn correlation_weighting_shrinks_uninformative_directions() {
        let n = 4000;
        let d = N_DESCRIPTORS;
        let xs: Vec<f64> =
            (0..n * d).map(|i| hash_unit(11, "guidance-test", i as u64) - 0.5).collect();
        let ys: Vec<f64> = (0..n)
            .flat_map(|i| {
                let v = 0.5 + 0.8 * xs[i * d];
                // Independent noise per channel: the colours have full rank.
                let e = |c: u64| 0.1 * (hash_unit(12, "noise", 3 * i as u64 + c) - 0.5);
                [v + e(0), 0.7 * v + e(1), 0.4 * v + e(2)]
            })
            .collect();
        let valid = vec![true; n];
        let var = |g: &[f64], k: usize| {
            let m = g.iter().skip(k).step_by(3).sum::<f64>() / n as f64;
            g.iter().skip(k).step_by(3).map(|v| (v - m).powi(2)).sum::<f64>() / n as f64
        };
        let plain = build_guidance(&xs, &ys, &valid, &xs, Reduction::Cca).unwrap();
        let weighted = build_guidance(&xs, &ys, &valid, &xs, Reduction::CcaWeighted).unwrap();
        assert!(plain.strengths[0] > 0.99 && plain.strengths[1] < 0.2, "{:?}", plain.strengths);
        for k in 0..3 {
            assert!(
                (var(&plain.source, k) - 1.0).abs() < 0.05,
                "unweighted dim {k}: {}",
                var(&plain.source, k)
            );
        }
        assert!(var(&weighted.source, 0) > 0.95);
        assert!(var(&weighted.source, 1) < 0.05 && var(&weighted.source, 2) < 0.05);
        for (a, b) in plain.descriptor_weights.iter().zip(&weighted.descriptor_weights) {
            assert!((a - b).abs() < 1e-12, "weights {a} vs {b}");
        }
        assert!(weighted.descriptor_weights[0] > 0.5);
    }
}
