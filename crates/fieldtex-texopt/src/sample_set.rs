//! The sample set `X†`: carriers whose patches are matched, by dart throwing.
//!
//! Paper A §5.1 (after Chen et al. 2009) samples the surface at spacing `r·w` (patch
//! width `w`, `r = 0.25`): first along the salient curves, then near them, then in
//! between. Here the candidates are the carriers themselves, visited in a fixed order
//! and accepted when no accepted sample lies within `spacing` (Euclidean distance,
//! exact through a [`UniformGrid`]-like hash of accepted samples). The order is
//! - with a priority (per-carrier distance to the salient curves): carriers in bands
//!   `d < spacing/2` (on the curves), `d < w/2` (near), and the rest, each band in a
//!   seeded random order; on-curve carriers are additionally ordered by nothing but the
//!   random key, so the curves are covered at spacing `spacing` first;
//! - without: one seeded random order (`hash_unit(seed, "texopt-samples", carrier)`).
//!
//! So every pair of samples is at least `spacing` apart and every carrier lies within
//! `spacing` of a sample (maximality over the carriers). Sequential acceptance;
//! deterministic for any thread count.
//!
//! [`UniformGrid`]: crate::UniformGrid

use crate::SurfaceDomain;
use fieldtex_core::rng::stream_seed;
use rayon::prelude::*;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A cheap deterministic hasher for integer cell keys (SplitMix64 finaliser).
#[derive(Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        fieldtex_core::rng::mix64(self.0)
    }
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.0 = (self.0.rotate_left(5) ^ u64::from_le_bytes(word))
                .wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    fn write_i64(&mut self, v: i64) {
        self.0 = self.0.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ v as u64;
    }
}

/// Neighbour cell offsets, the own cell first (most rejections happen there).
const OFFSETS: [[i64; 3]; 27] = {
    let mut o = [[0i64; 3]; 27];
    let mut n = 1;
    let mut z = -1;
    while z <= 1 {
        let mut y = -1;
        while y <= 1 {
            let mut x = -1;
            while x <= 1 {
                if !(x == 0 && y == 0 && z == 0) {
                    o[n] = [x, y, z];
                    n += 1;
                }
                x += 1;
            }
            y += 1;
        }
        z += 1;
    }
    o
};

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
    if !(spacing.is_finite() && spacing > 0.0) {
        return keyed.into_iter().map(|(_, c)| c).collect();
    }
    let inv = 1.0 / spacing;
    let cell_of = |p: [f64; 3]| {
        [(p[0] * inv).floor() as i64, (p[1] * inv).floor() as i64, (p[2] * inv).floor() as i64]
    };
    let mut cells: HashMap<[i64; 3], Vec<u32>, BuildHasherDefault<CellHasher>> = HashMap::default();
    let mut accepted = Vec::new();
    let r2 = spacing * spacing;
    for &(_, c) in &keyed {
        let p = pos[c as usize];
        let k = cell_of(p);
        let mut free = true;
        'search: for o in OFFSETS {
            if let Some(list) = cells.get(&[k[0] + o[0], k[1] + o[1], k[2] + o[2]]) {
                for &s in list {
                    let q = pos[s as usize];
                    let d2 = (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2);
                    if d2 < r2 {
                        free = false;
                        break 'search;
                    }
                }
            }
        }
        if free {
            cells.entry(k).or_default().push(c);
            accepted.push(c);
        }
    }
    accepted
}
