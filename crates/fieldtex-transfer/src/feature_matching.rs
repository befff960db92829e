//! Feature matching (paper B §4): make the target guidance follow the source guidance's
//! statistics when the shapes differ.
//!
//! - `None`: the target guidance as projected.
//! - `Marginals` (§4.1): n-D histogram matching of the 3-D guidance by random rotations
//!   (Pitié, Kokaram & Dahyot 2005; `fieldtex_linalg::stats::match_histograms_nd`).
//! - `Multiscale` (§4.2, default): the same on every level of the Laplacian pyramids of
//!   the guidance over the sample pyramids (target band `l` matched to source band `l`),
//!   then the reconstructed values matched once more, as Heeger & Bergen do.

use crate::TransferError;
use crate::surface_samples::SamplePyramid;
use fieldtex_linalg::stats::{HistogramMatchOptions, match_histograms_nd};
use serde::Serialize;

/// Which feature matching runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum MatchMode {
    None,
    Marginals,
    Multiscale,
}

/// Statistics of one matching step, for the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MatchStep {
    /// `"band0"`, `"band1"`, … or `"values"`.
    pub what: String,
    pub marginal_distance_before: f64,
    pub marginal_distance_after: f64,
}

/// Matches the level-0 target guidance `gt` (`#target × 3`) to the source guidance `gs`
/// in place (module docs).
pub fn match_features(
    gt: &mut Vec<f64>,
    gs: &[f64],
    source: &SamplePyramid,
    target: &SamplePyramid,
    mode: MatchMode,
    seed: u64,
) -> Result<Vec<MatchStep>, TransferError> {
    let dim = 3;
    let opts = |i: u64| HistogramMatchOptions {
        seed: fieldtex_core::rng::stream_seed(seed, "transfer-feature-matching", i),
        ..Default::default()
    };
    let mut steps = Vec::new();
    let mut run = |x: &mut [f64], r: &[f64], what: String, i: u64| -> Result<(), TransferError> {
        let s = match_histograms_nd(x, r, dim, &opts(i))
            .map_err(|e| TransferError::numeric("feature matching", e))?;
        steps.push(MatchStep {
            what,
            marginal_distance_before: s.marginal_distance_before,
            marginal_distance_after: s.marginal_distance_after,
        });
        Ok(())
    };
    match mode {
        MatchMode::None => {}
        MatchMode::Marginals => run(gt, gs, "values".into(), 0)?,
        MatchMode::Multiscale => {
            let levels = source.n_levels().min(target.n_levels());
            let mut bt = target.laplacian(gt, dim);
            let bs = source.laplacian(gs, dim);
            // Pyramids of different depth: compare the bands that both have; the target's
            // coarsest level is matched to the source's band of the same index.
            for l in 0..levels {
                run(&mut bt[l], &bs[l], format!("band{l}"), 1 + l as u64)?;
            }
            *gt = target.reconstruct(&bt, dim);
            run(gt, gs, "values".into(), 100)?;
        }
    }
    Ok(steps)
}
