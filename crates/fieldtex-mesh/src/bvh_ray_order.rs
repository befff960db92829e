//! Ray reordering for batch queries: rays are sorted by a Morton key of where they
//! enter the scene box and of their direction, so consecutive rays traverse nearly the
//! same BVH nodes and triangles and find them in cache (Pharr, Kolb, Gershbein &
//! Hanrahan 1997, "Rendering Complex Scenes with Memory-Coherent Ray Tracing"; the key
//! follows Moon et al. 2010, "Cache-Oblivious Ray Reordering", which orders by hit point;
//! here the box entry point stands in for the not yet known hit point).
//!
//! The order only changes speed, never results: every ray is still answered on its own.

use super::Ray;
use fieldtex_core::vec3::V3;
use glam::Vec3A;
use rayon::prelude::*;

/// Rays answered together by one task.
const CHUNK: usize = 256;
/// Batches below this size are answered in input order (sorting would not pay off).
const MIN_SORTED: usize = 8192;
/// Rays sorted together (positions must fit the low 32 bits of a sort key).
const BLOCK: usize = 1 << 31;
/// Bits per key dimension (5 dimensions: entry point x, y, z, octahedral direction u, v).
const BITS: u32 = 6;
/// Fixed input parts for the parallel bucket passes.
const PARTS: usize = 16;
/// Key bits below the bucket digit (the top 10 bits pick one of 1024 buckets).
const LOW: u32 = 5 * BITS - 10;

/// `SPREAD[b]` holds the bits of `b` at every fifth position (5-D Morton interleave).
const SPREAD: [u32; 1 << BITS] = {
    let mut t = [0u32; 1 << BITS];
    let mut b = 0;
    while b < t.len() {
        let mut j = 0;
        while j < BITS {
            t[b] |= (((b >> j) & 1) as u32) << (5 * j);
            j += 1;
        }
        b += 1;
    }
    t
};

/// `f` applied to every ray, in parallel over fixed chunks of a coherent ray order;
/// results in input order. The scene box has centre `centre` and half extents
/// `1 / inv_half` (all positive).
///
/// Large arrays are only read or written in sequential streams (at most one per bucket):
/// rays are first copied into 1024 buckets by the top key bits, each bucket is sorted on
/// its own, and results go back through the same buckets. Random access into the whole
/// batch (slow on virtual machines with small pages) is avoided.
pub(super) fn map_coherent<T: Copy + Send + Sync>(
    rays: &[Ray],
    centre: V3,
    inv_half: V3,
    f: impl Fn(&Ray) -> T + Sync + Send,
) -> Vec<T> {
    if rays.len() < MIN_SORTED {
        return rays.par_iter().with_min_len(CHUNK).map(f).collect();
    }
    let c = Vec3A::new(centre[0] as f32, centre[1] as f32, centre[2] as f32);
    let ih = Vec3A::new(inv_half[0] as f32, inv_half[1] as f32, inv_half[2] as f32);
    let mut out = Vec::with_capacity(rays.len());
    for block in rays.chunks(BLOCK) {
        map_block(block, c, ih, &f, &mut out);
    }
    out
}

/// [`map_coherent`] for at most [`BLOCK`] rays, results appended to `out`.
fn map_block<T: Copy + Send + Sync>(
    block: &[Ray],
    c: Vec3A,
    ih: Vec3A,
    f: &(impl Fn(&Ray) -> T + Sync + Send),
    out: &mut Vec<T>,
) {
    const NB: usize = 1 << 10;
    let n = block.len();
    let keys: Vec<u32> = block.par_iter().with_min_len(4096).map(|r| ray_key(r, c, ih)).collect();
    let digit = |k: u32| (k >> LOW) as usize;
    // Bucket counts per fixed part of the input (independent of the thread count), then
    // each part's first position in every bucket.
    let part_len = n.div_ceil(PARTS);
    let mut cursors: Vec<Vec<usize>> = keys
        .par_chunks(part_len)
        .map(|ks| {
            let mut h = vec![0usize; NB];
            for &k in ks {
                h[digit(k)] += 1;
            }
            h
        })
        .collect();
    let mut start = vec![0usize; NB + 1];
    for b in 0..NB {
        let mut sum = start[b];
        for h in cursors.iter_mut() {
            (h[b], sum) = (sum, sum + h[b]);
        }
        start[b + 1] = sum;
    }
    // Input index of every bucket position (stable), then rays and sort keys by bucket:
    // the gathers read the input in one ascending stream per bucket.
    let mut src = vec![0u32; n];
    let mut cur = start.clone();
    for (i, &k) in keys.iter().enumerate() {
        let d = digit(k);
        src[cur[d]] = i as u32;
        cur[d] += 1;
    }
    let brays: Vec<Ray> = src.par_iter().with_min_len(4096).map(|&i| block[i as usize]).collect();
    let mut bkeys: Vec<u64> = src
        .par_iter()
        .enumerate()
        .with_min_len(4096)
        .map(|(q, &i)| (u64::from(keys[i as usize] & ((1 << LOW) - 1)) << 32) | q as u64)
        .collect();
    drop(src);
    let mut parts = Vec::with_capacity(NB);
    let mut rest = bkeys.as_mut_slice();
    for b in 0..NB {
        let (head, tail) = rest.split_at_mut(start[b + 1] - start[b]);
        parts.push(head);
        rest = tail;
    }
    parts.into_par_iter().with_min_len(16).for_each(|p| p.sort_unstable());
    // Answer in sorted order; the gathers stay inside one bucket.
    let sorted: Vec<T> = bkeys
        .par_chunks(CHUNK)
        .flat_map_iter(|ch| {
            // Gather first: independent loads overlap, unlike loads inside traversal.
            let local: Vec<Ray> = ch.iter().map(|&k| brays[k as u32 as usize]).collect();
            local.iter().map(f).collect::<Vec<T>>()
        })
        .collect();
    drop(brays);
    // Sorted index of each bucket position, then results in input order, by part.
    let mut pos = vec![0u32; n];
    for (j, &k) in bkeys.iter().enumerate() {
        pos[k as u32 as usize] = j as u32;
    }
    out.par_extend(keys.par_chunks(part_len).zip(cursors).flat_map_iter(|(ks, mut cur)| {
        let (sorted, pos) = (&sorted, &pos);
        ks.iter().map(move |&k| {
            let d = digit(k);
            cur[d] += 1;
            sorted[pos[cur[d] - 1] as usize]
        })
    }));
}

/// 30-bit Morton key of the ray's box entry point and direction (`f32` is plenty for an
/// order); rays missing the box or with a degenerate direction get the largest key (they
/// finish without traversal).
fn ray_key(r: &Ray, centre: Vec3A, inv_half: Vec3A) -> u32 {
    const MISS: u32 = (1 << (5 * BITS)) - 1;
    let v = |a: V3| Vec3A::new(a[0] as f32, a[1] as f32, a[2] as f32);
    // Ray in box coordinates, box = [-1, 1]³.
    let o = (v(r.origin) - centre) * inv_half;
    let dir = v(r.dir);
    let d = dir * inv_half;
    let inv = d.recip();
    let (a, b) = ((Vec3A::NEG_ONE - o) * inv, (Vec3A::ONE - o) * inv);
    let t0 = a.min(b).max_element().max(r.tmin.max(0.0) as f32);
    let t1 = a.max(b).min_element().min(r.tmax as f32);
    let s = dir.abs().element_sum();
    if !(t0 <= t1 && s > 0.0 && s.is_finite() && o.is_finite()) {
        return MISS;
    }
    let p = o + d * t0;
    let q = |x: f32| SPREAD[(((x.clamp(-1.0, 1.0) + 1.0) * 32.0) as usize).min(63)];
    // Octahedral map of the direction to [-1, 1]².
    let (x, y) = (dir.x / s, dir.y / s);
    let (u, w) = if dir.z >= 0.0 {
        (x, y)
    } else {
        ((1.0 - y.abs()).copysign(x), (1.0 - x.abs()).copysign(y))
    };
    (q(p.x) << 4) | (q(p.y) << 3) | (q(p.z) << 2) | (q(u) << 1) | q(w)
}
