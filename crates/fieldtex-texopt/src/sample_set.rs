//! The sample set `X†`: carriers whose patches are matched, by dart throwing.
//!
//! Paper A §5.1 (after Chen et al. 2009) samples the surface at spacing `r·w` (patch
//! width `w`, `r = 0.25`): first along the salient curves, then near them, then in
//! between. Here the candidates are the carriers themselves, visited in a fixed order
//! and accepted by the workspace's one dart thrower ([`fieldtex_mesh::dart_throwing`]:
//! accepted when no accepted sample lies within `spacing`, Euclidean distance, exact).
//! The order is
//! - with a priority (per-carrier distance to the salient curves): carriers in bands
//!   `d < spacing/2` (on the curves), `d < w/2` (near), and the rest, each band in a
//!   seeded random order; on-curve carriers are additionally ordered by nothing but the
//!   random key, so the curves are covered at spacing `spacing` first;
//! - without: one seeded random order (`hash_unit(seed, "texopt-samples", carrier)`).
//!
//! So every pair of samples is at least `spacing` apart and every carrier lies within
//! `spacing` of a sample (maximality over the carriers). Sequential acceptance;
//! deterministic for any thread count.

use crate::SurfaceDomain;
use fieldtex_core::rng::stream_seed;
use fieldtex_mesh::dart_throwing;
use rayon::prelude::*;

/// Carrier indices of a maximal `spacing`-separated sample set; see the module docs.
/// `priority` (`#C`, surface distance to the salient curves) puts curve carriers first;
/// `near` is the distance under which a carrier counts as near a curve (use `w·h/2`).
pub fn sample_set(
    domain: &SurfaceDomain,
    spacing: f64,
    priority: Option<&[f64]>,
    near: f64,
    seed: u64,
) -> Vec<u32> {
    let pos = domain.positions();
    let mut keyed: Vec<(u64, u32)> = (0..pos.len() as u32)
        .into_par_iter()
        .map(|c| {
            let band = match priority.map(|p| p[c as usize]) {
                Some(d) if d < 0.5 * spacing => 0u64,
                Some(d) if d < near => 1,
                Some(_) => 2,
                None => 0,
            };
            // Two band bits on top, 62 random bits below: a fixed total order.
            let r = stream_seed(seed, "texopt-samples", c as u64) >> 2;
            ((band << 62) | r, c)
        })
        .collect();
    keyed.par_sort_unstable();
    let order: Vec<u32> = keyed.into_iter().map(|(_, c)| c).collect();
    dart_throwing(pos, &order, spacing)
}
