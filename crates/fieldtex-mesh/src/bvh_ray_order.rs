//! Ray reordering for batch queries: rays are sorted by a Morton key of where they
//! enter the scene box and of their direction, so consecutive rays traverse nearly the
//! same BVH nodes and triangles and find them in cache (Pharr, Kolb, Gershbein &
//! Hanrahan 1997, "Rendering Complex Scenes with Memory-Coherent Ray Tracing"; the key
//! follows Moon et al. 2010, "Cache-Oblivious Ray Reordering", which orders by hit point;
//! here the box entry point stands in for the not yet known hit point).
//!
//! The order only changes speed, never results: every ray is still answered on its own.

use super::Ray;
use fieldtex_core::vec3::{self, V3};
use rayon::prelude::*;

/// Rays answered together by one task.
const CHUNK: usize = 256;
/// Batches below this size are answered in input order (sorting would not pay off).
const MIN_SORTED: usize = 8192;
/// Rays sorted together (the in-block index fills the low 24 bits of the sort key).
const BLOCK: usize = 1 << 24;
/// Bits per key dimension (5 dimensions: entry point x, y, z, octahedral direction u, v).
const BITS: u32 = 8;

/// `SPREAD[b]` holds the bits of `b` at every fifth position (5-D Morton interleave).
const SPREAD: [u64; 256] = {
    let mut t = [0u64; 256];
    let mut b = 0;
    while b < 256 {
        let mut j = 0;
        while j < BITS {
            t[b] |= (((b >> j) & 1) as u64) << (5 * j);
            j += 1;
        }
        b += 1;
    }
    t
};

/// `f` applied to every ray, in parallel over fixed chunks of a coherent ray order;
/// results in input order. The scene box has centre `centre` and half extents
/// `1 / inv_half` (all positive).
pub(super) fn map_coherent<T: Copy + Send + Sync>(
    rays: &[Ray],
    centre: V3,
    inv_half: V3,
    f: impl Fn(&Ray) -> T + Sync + Send,
) -> Vec<T> {
    if rays.len() < MIN_SORTED {
        return rays.par_iter().with_min_len(CHUNK).map(f).collect();
    }
    let mut out = Vec::with_capacity(rays.len());
    for block in rays.chunks(BLOCK) {
        let mut keys: Vec<u64> = block
            .par_iter()
            .enumerate()
            .with_min_len(4096)
            .map(|(i, r)| (ray_key(r, centre, inv_half) << 24) | i as u64)
            .collect();
        keys.par_sort_unstable();
        let sorted: Vec<T> = keys
            .par_chunks(CHUNK)
            .flat_map_iter(|c| {
                // Gather first: independent loads overlap, unlike loads inside traversal.
                let local: Vec<Ray> = c.iter().map(|&k| block[(k & 0xff_ffff) as usize]).collect();
                local.iter().map(&f).collect::<Vec<T>>()
            })
            .collect();
        let mut pos = vec![0u32; block.len()];
        for (s, &k) in keys.iter().enumerate() {
            pos[(k & 0xff_ffff) as usize] = s as u32;
        }
        out.par_extend(pos.par_iter().with_min_len(4096).map(|&s| sorted[s as usize]));
    }
    out
}

/// 40-bit Morton key of the ray's box entry point and direction; rays missing the box or
/// with a degenerate direction get the largest key (they finish without traversal).
fn ray_key(r: &Ray, centre: V3, inv_half: V3) -> u64 {
    const MISS: u64 = (1 << (5 * BITS)) - 1;
    // Ray in box coordinates, box = [-1, 1]³.
    let o = [0, 1, 2].map(|k| (r.origin[k] - centre[k]) * inv_half[k]);
    let d = [0, 1, 2].map(|k| r.dir[k] * inv_half[k]);
    let (mut t0, mut t1) = (r.tmin.max(0.0), r.tmax);
    for k in 0..3 {
        let inv = 1.0 / d[k];
        let (a, b) = ((-1.0 - o[k]) * inv, (1.0 - o[k]) * inv);
        let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
        // NaN bounds (origin on a slab of a zero direction component) keep the range.
        t0 = if lo > t0 { lo } else { t0 };
        t1 = if hi < t1 { hi } else { t1 };
    }
    let s = r.dir[0].abs() + r.dir[1].abs() + r.dir[2].abs();
    if !(t0 <= t1 && s > 0.0 && s.is_finite() && vec3::is_finite(o)) {
        return MISS;
    }
    let q = |x: f64| SPREAD[(((x.clamp(-1.0, 1.0) + 1.0) * 127.5) as usize).min(255)];
    // Octahedral map of the direction to [-1, 1]².
    let (x, y) = (r.dir[0] / s, r.dir[1] / s);
    let (u, v) = if r.dir[2] >= 0.0 {
        (x, y)
    } else {
        ((1.0 - y.abs()).copysign(x), (1.0 - x.abs()).copysign(y))
    };
    let p = |k: usize| o[k] + t0 * d[k];
    (q(p(0)) << 4) | (q(p(1)) << 3) | (q(p(2)) << 2) | (q(u) << 1) | q(v)
}
