//! Statistics on dense data for texture transfer (paper B, Mertens et al. 2006):
//! canonical correlation analysis, k-means, 1-D and n-D histogram matching,
//! weighted quantile functions, the weighted quantile and a kd-tree for (approximate)
//! nearest neighbours.
//! One algorithm per file.
//!
//! Conventions: samples are row-major `N × dim` `f64` slices; every reduction over
//! samples is done per fixed chunk of rows and summed in chunk order, so results are
//! identical for any thread count; randomness comes from
//! `fieldtex_core::rng::hash_unit(seed, stage, index)`.

// Small dense kernels index several arrays with one loop variable.
#![allow(clippy::needless_range_loop)]

mod cca;
mod histogram_matching;
mod kd_tree;
mod kmeans;
mod pearson;
mod quantile_function;
mod weighted_quantile;

pub use cca::{Cca, CcaOptions, cca};
pub use histogram_matching::{
    HistogramMatchOptions, HistogramMatchStats, match_histogram_1d, match_histograms_nd,
    random_rotation,
};
pub use kd_tree::{KD_LEAF, KdScratch, KdTree};
pub use kmeans::{KMeans, KMeansOptions, kmeans};
pub use pearson::pearson;
pub use quantile_function::QuantileFunction;
pub use weighted_quantile::weighted_quantile;

/// Rows per reduction chunk (fixed: the summation order does not depend on threads).
pub(crate) const STATS_CHUNK: usize = 8192;

/// Column means of row-major `N × dim` `x` (fixed-order chunked sum).
pub(crate) fn column_means(x: &[f64], dim: usize) -> Vec<f64> {
    use rayon::prelude::*;
    let n = x.len() / dim.max(1);
    let sums: Vec<Vec<f64>> = x
        .par_chunks(STATS_CHUNK * dim)
        .map(|c| {
            let mut s = vec![0.0; dim];
            for row in c.chunks_exact(dim) {
                for (a, v) in s.iter_mut().zip(row) {
                    *a += v;
                }
            }
            s
        })
        .collect();
    let mut m = vec![0.0; dim];
    for s in &sums {
        for (a, v) in m.iter_mut().zip(s) {
            *a += v;
        }
    }
    m.iter_mut().for_each(|v| *v /= n.max(1) as f64);
    m
}

/// A standard normal number from two hashed uniforms (Box–Muller).
pub(crate) fn hashed_normal(seed: u64, stage: &str, index: u64) -> f64 {
    use fieldtex_core::rng::hash_unit;
    let u1 = hash_unit(seed, stage, 2 * index).max(1e-300);
    let u2 = hash_unit(seed, stage, 2 * index + 1);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}
