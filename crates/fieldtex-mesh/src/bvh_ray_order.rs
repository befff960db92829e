//! Ray reordering for batch queries: rays are sorted by a Morton key of where they
//! enter the scene box and of their direction, so consecutive rays traverse nearly the
//! same BVH nodes and triangles and find them in cache (Pharr, Kolb, Gershbein &
//! Hanrahan 1997, "Rendering Complex Scenes with Memory-Coherent Ray Tracing"; the key
//! follows Moon et al. 2010, "Cache-Oblivious Ray Reordering", which orders by hit point;
//! here the box entry point stands in for the not yet known hit point).
//!
//! The order only changes speed, never results: every ray is still answered on its own.
//!
//! Moving rays and results into and out of that order is a random gather and scatter
//! over arrays of tens of MB, and in this virtual machine with 4 KiB pages nearly every
//! such access was also a TLB miss. Measured on one thread (1M rays, 388K triangles):
//! keys 50 ms, sort 25 ms, gather of the rays from the caller's slice 100–120 ms,
//! traversal 530–680 ms, scatter of the results 63–80 ms. Now the rays are copied in
//! input order onto huge pages, one per cache line, in the pass that computes the keys;
//! the gather prefetches 16 rays ahead; the output lies on huge pages, is written without
//! a pre-fill, and the lines of a chunk's results are prefetched before the chunk is
//! answered: gather ~58 ms, scatter 17–32 ms. Gathering straight from the caller's slice
//! with the same prefetching was slower than staging (1-thread rates 1.15–1.22 vs
//! 1.33–1.35 M rays/s, machine loaded).

use super::Ray;
use super::bvh_wide::{huge_with_capacity, prefetch_bytes};
use fieldtex_core::vec3::V3;
use glam::Vec3A;
use rayon::prelude::*;

/// Rays answered together by one task.
const CHUNK: usize = 256;
/// Batches below this size are answered in input order (sorting would not pay off).
const MIN_SORTED: usize = 8192;
/// Bits per key dimension (5 dimensions: entry point x, y, z, octahedral direction u, v).
const BITS: u32 = 6;
/// Bits per radix-sort pass (three passes cover the 30-bit key).
const RADIX: u32 = 10;

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

/// `f` applied to every ray (`f(rays, results)` answers a chunk of rays), in parallel over
/// fixed chunks of a coherent ray order;
/// results in input order. The scene box has centre `centre` and half extents
/// `1 / inv_half` (all positive).
///
/// Sort keys `key << 32 | index` are radix sorted (stable, so equal keys keep the input
/// order); every chunk gathers its rays first (independent loads that overlap), answers
/// them and writes each result straight to its input position. Batches of more than
/// `u32::MAX` rays are answered in blocks.
pub(super) fn map_coherent<T: Copy + Default + Send + Sync>(
    rays: &[Ray],
    centre: V3,
    inv_half: V3,
    f: impl Fn(&[Ray], &mut [T]) + Sync + Send,
) -> Vec<T> {
    if rays.len() < MIN_SORTED {
        let mut out = vec![T::default(); rays.len()];
        out.par_chunks_mut(CHUNK).zip(rays.par_chunks(CHUNK)).for_each(|(o, r)| f(r, o));
        return out;
    }
    let c = Vec3A::new(centre[0] as f32, centre[1] as f32, centre[2] as f32);
    let ih = Vec3A::new(inv_half[0] as f32, inv_half[1] as f32, inv_half[2] as f32);
    let mut out = huge_with_capacity(rays.len());
    for block in rays.chunks(u32::MAX as usize) {
        map_block(block, c, ih, &f, &mut out);
    }
    out
}

/// [`map_coherent`] for at most `u32::MAX` rays, results appended to `out`.
///
/// All large buffers live on huge pages ([`huge_with_capacity`]): the gather of the rays
/// and the scatter of the results touch them at random, and with 4 KiB pages nearly
/// every such access is also a TLB miss (a costly one in a virtual machine). The rays are
/// therefore first copied, in input order, into such a buffer (in the same pass as the
/// keys), and the results are written straight into `out`'s reserved memory.
fn map_block<T: Copy + Default + Send + Sync>(
    block: &[Ray],
    c: Vec3A,
    ih: Vec3A,
    f: &(impl Fn(&[Ray], &mut [T]) + Sync + Send),
    out: &mut Vec<T>,
) {
    const PART: usize = 4096;
    let n = block.len();
    let mut keys: Vec<u64> = huge_with_capacity(n);
    let mut staged: Vec<Line> = huge_with_capacity(n);
    block
        .par_chunks(PART)
        .zip(keys.spare_capacity_mut()[..n].par_chunks_mut(PART))
        .zip(staged.spare_capacity_mut()[..n].par_chunks_mut(PART))
        .enumerate()
        .for_each(|(ci, ((rs, ks), ss))| {
            for (j, ((r, k), s)) in rs.iter().zip(ks).zip(ss).enumerate() {
                k.write((u64::from(ray_key(r, c, ih)) << 32) | (ci * PART + j) as u64);
                s.write(Line(*r));
            }
        });
    // SAFETY: the chunks above cover `0..n` of both buffers, so every element is written.
    unsafe {
        keys.set_len(n);
        staged.set_len(n);
    }
    let keys = radix_sort(keys);
    // Answer in sorted order, each result written straight to its input position.
    let base = out.len();
    out.reserve(n);
    let dst = OutPtr(out.spare_capacity_mut()[..n].as_mut_ptr().cast::<T>());
    keys.par_chunks(CHUNK).for_each(|ks| {
        // Gather first: independent loads that overlap (helped by prefetching ahead),
        // unlike loads inside traversal.
        const AHEAD: usize = 16;
        for &k in &ks[..AHEAD.min(ks.len())] {
            prefetch_bytes((&raw const staged[k as u32 as usize]).cast(), size_of::<Line>());
        }
        let mut local = [Ray::new([0.0; 3], [0.0; 3]); CHUNK];
        for (j, (l, &k)) in local.iter_mut().zip(ks).enumerate() {
            if let Some(&a) = ks.get(j + AHEAD) {
                prefetch_bytes((&raw const staged[a as u32 as usize]).cast(), size_of::<Line>());
            }
            *l = staged[k as u32 as usize].0;
        }
        // Ask for the lines of this chunk's results now: they arrive while it is answered.
        for &k in ks {
            prefetch_bytes(dst.0.wrapping_add(k as u32 as usize).cast(), size_of::<T>());
        }
        let mut res = [T::default(); CHUNK];
        f(&local[..ks.len()], &mut res[..ks.len()]);
        for (&r, &k) in res.iter().zip(ks) {
            // SAFETY: the indices of the sorted keys are a permutation of `0..n` (radix
            // sorting permutes them), so every element is written by one task only, and
            // `out` is not otherwise accessed until `for_each` returns.
            unsafe { dst.write(k as u32 as usize, n, r) };
        }
    });
    // SAFETY: the `n` elements after `base` were all written (the indices of the keys are
    // a permutation of `0..n`, and a panic in `f` would have ended this function before).
    unsafe { out.set_len(base + n) };
}

/// A ray on its own cache line (staged rays are read at random: one line each).
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Line(Ray);

/// The output of a batch, written by all tasks at disjoint positions.
#[derive(Clone, Copy)]
struct OutPtr<T>(*mut T);

impl<T: Copy> OutPtr<T> {
    /// Writes element `i` of the `n` elements the pointer points to (panics unless
    /// `i < n`).
    ///
    /// # Safety
    /// The `n` elements must stay allocated, and no other task may read or write element
    /// `i` meanwhile.
    #[inline(always)]
    unsafe fn write(&self, i: usize, n: usize, value: T) {
        assert!(i < n);
        // SAFETY: in bounds (`i < n`) and exclusive (the caller's contract); `T: Copy`
        // has no drop to skip.
        unsafe { self.0.add(i).write(value) };
    }
}
// SAFETY: tasks write disjoint elements only (the contract of `OutPtr::write`); `T: Send`.
unsafe impl<T: Send> Send for OutPtr<T> {}
// SAFETY: as above; the pointer itself is never used to read.
unsafe impl<T: Send> Sync for OutPtr<T> {}

/// Stable least-significant-digit radix sort of `key << 32 | index` values by their
/// upper 30 bits (the key), [`RADIX`] bits per pass. Each pass counts digits over fixed
/// parts of the input in parallel, then every part moves its values to its own ranges
/// (the order is the sequential one, for any thread count).
fn radix_sort(mut a: Vec<u64>) -> Vec<u64> {
    const NB: usize = 1 << RADIX;
    const PARTS: usize = 16;
    let n = a.len();
    let part = n.div_ceil(PARTS).max(1);
    let mut b: Vec<u64> = huge_with_capacity(n);
    b.resize(n, 0);
    for pass in 0..(5 * BITS).div_ceil(RADIX) {
        let shift = 32 + pass * RADIX;
        let digit = |x: u64| ((x >> shift) as usize) & (NB - 1);
        let mut starts: Vec<Vec<usize>> = a
            .par_chunks(part)
            .map(|p| {
                let mut h = vec![0usize; NB];
                for &x in p {
                    h[digit(x)] += 1;
                }
                h
            })
            .collect();
        // First position of every (digit, part) range, digits major: stable.
        let mut sum = 0;
        for d in 0..NB {
            for h in starts.iter_mut() {
                (h[d], sum) = (sum, sum + h[d]);
            }
        }
        let dst = OutPtr(b.as_mut_ptr());
        a.par_chunks(part).zip(starts).for_each(|(p, mut h)| {
            for &x in p {
                let d = digit(x);
                // SAFETY: the (digit, part) ranges are disjoint and each position in a
                // range is written once; `b` is not otherwise accessed until
                // `for_each` returns.
                unsafe { dst.write(h[d], n, x) };
                h[d] += 1;
            }
        });
        std::mem::swap(&mut a, &mut b);
    }
    a
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
    let q = |x: f32| SPREAD[(((x.clamp(-1.0, 1.0) + 1.0) * 32.0) as i32).clamp(0, 63) as usize];
    // Octahedral map of the direction to [-1, 1]².
    let (x, y) = (dir.x / s, dir.y / s);
    let (u, w) = if dir.z >= 0.0 {
        (x, y)
    } else {
        ((1.0 - y.abs()).copysign(x), (1.0 - x.abs()).copysign(y))
    };
    (q(p.x) << 4) | (q(p.y) << 3) | (q(p.z) << 2) | (q(u) << 1) | q(w)
}
