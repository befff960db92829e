//! The guidance field (paper B §3.3): descriptors reduced to 3 dimensions by canonical
//! correlation analysis against the source colours (`fieldtex_linalg::stats::cca`), the
//! same projection applied to the target. `Reduction::Pca` replaces CCA by the 3 leading
//! principal components of the source descriptors (the ablation of the paper's Fig. 6).
//!
//! Descriptors are first standardised with the source's mean and standard deviation
//! (usable samples only), so that the reported weights are comparable across
//! descriptors: `descriptor_weights[d]` is `|a₁[d]| / Σ|a₁|` for the first canonical
//! direction `a₁` (paper Fig. 4). Guidance dimensions have unit variance on the source.

use crate::TransferError;
use crate::descriptors::N_DESCRIPTORS;
use fieldtex_linalg::Pca;
use fieldtex_linalg::stats::{CcaOptions, cca};
use serde::Serialize;

/// Dimensionality reduction of the descriptors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Reduction {
    /// Canonical correlation analysis with the colours (default).
    Cca,
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
    sd.iter_mut().for_each(|s| *s = (*s / rows.len() as f64).sqrt().max(1e-9));
    let standardise = |x: &[f64]| -> Vec<f64> {
        x.chunks_exact(d).flat_map(|r| (0..d).map(|k| (r[k] - mean[k]) / sd[k])).collect()
    };
    let zs = standardise(xs);
    let zt = standardise(xt);
    let fit_x: Vec<f64> =
        rows.iter().flat_map(|&i| zs[i * d..(i + 1) * d].iter().copied()).collect();
    let (directions, offsets, strengths) = match reduction {
        Reduction::Cca => {
            let fit_y: Vec<f64> =
                rows.iter().flat_map(|&i| ys[i * 3..i * 3 + 3].iter().copied()).collect();
            let c = cca(&fit_x, d, &fit_y, 3, &CcaOptions::default())
                .map_err(|e| TransferError::numeric("CCA", e))?;
            let offsets: Vec<f64> = c
                .x_weights
                .iter()
                .map(|w| w.iter().zip(&c.x_mean).map(|(a, m)| a * m).sum())
                .collect();
            (c.x_weights, offsets, c.correlations)
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
    let first = &directions[0];
    let total: f64 = first.iter().map(|v| v.abs()).sum::<f64>().max(1e-300);
    let descriptor_weights = first.iter().map(|v| v.abs() / total).collect();
    Ok(Guidance { source, target, strengths, directions, descriptor_weights })
}
