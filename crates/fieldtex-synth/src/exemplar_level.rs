//! The exemplar side of one level of the parallel synthesis
//! ([`crate::parallel_synthesis`]; Lefebvre & Hoppe 2006 §3, the per-pixel
//! neighbourhood vectors of appearance space): the four-corner neighbourhood vector of
//! every exemplar pixel for both copies `Ẽ₀`, `Ẽ₁` (paper D §4), tabulated so that a
//! candidate costs one aligned 32-byte load, the k-coherence targets, and the valid
//! pixel range.

use rayon::prelude::*;

use crate::exemplar_analysis::{APPEARANCE_DIMS, ExemplarAnalysis};
use crate::lattice_domain::CORNERS;

/// Lanes of a four-corner neighbourhood vector: 4 corners × [`APPEARANCE_DIMS`].
pub(crate) const NV: usize = 4 * APPEARANCE_DIMS;

/// One tabulated four-corner neighbourhood vector, aligned to its 32 bytes so that no
/// entry straddles two cache lines (unaligned, every other entry of the table did: the
/// candidate loads are the correction's cache misses).
#[derive(Clone, Copy)]
#[repr(C, align(32))]
pub(crate) struct NvEntry(pub(crate) [i8; NV]);

/// Squared distance between a quantised neighbourhood vector `a` and a target `t` given
/// in units of `a / 6`, over the lanes whose mask is `−1` (exact integer arithmetic:
/// `|6a − t| ≤ 1524`, 32 squares fit `i32` easily). Written so that it vectorises
/// (`pmaddwd`).
#[inline]
pub(crate) fn dist_nv(a: &[i8; NV], t: &[i16; NV], mask: &[i16; NV]) -> i32 {
    let mut acc = 0i32;
    for i in 0..NV {
        let d = ((a[i] as i16) * 6 - t[i]) & mask[i];
        acc += d as i32 * d as i32;
    }
    acc
}

/// The exemplar side of one level.
pub(crate) struct ExemplarLevel {
    pub(crate) w: usize,
    h: usize,
    wf: f32,
    hf: f32,
    /// Four-corner neighbourhood vectors of every pixel for `[Ẽ₀, Ẽ₁]`: `nv[f][pix]`
    /// holds, for corner `ci` of [`CORNERS`] in lanes `8 ci .. 8 ci + 8`, the quantised
    /// appearance `Ẽ_f[pix + (−1)^f h Δ_ci]` (toroidal). One 32-byte load per candidate.
    pub(crate) nv: [Vec<NvEntry>; 2],
    /// k-coherence targets as pixel coordinates (`W × H × k_store`).
    pub(crate) coherence: Vec<[f32; 2]>,
    pub(crate) k_store: usize,
    /// Valid pixel range `[margin, W − margin) × [margin, H − margin)`.
    pub(crate) x_lo: usize,
    pub(crate) x_hi: usize,
    pub(crate) y_lo: usize,
    pub(crate) y_hi: usize,
}

#[inline]
fn wrap1(v: f32, size: f32) -> f32 {
    let r = if v < 0.0 {
        v + size
    } else if v >= size {
        v - size
    } else {
        return v;
    };
    if (0.0..size).contains(&r) {
        return r;
    }
    let r = v.rem_euclid(size);
    if r >= size || r.is_nan() { 0.0 } else { r }
}

impl ExemplarLevel {
    pub(crate) fn new(analysis: &ExemplarAnalysis, level: usize, rosy: bool) -> Self {
        let an = analysis.level(level);
        let (w, h) = (analysis.width(), analysis.height());
        let sp = an.spacing as i64;
        let wrap_i = |v: i64, n: usize| v.rem_euclid(n as i64) as usize;
        // Neighbourhood vectors (the flipped copy only when the 2-RoSy fix needs it).
        let nv_of = |f: usize| -> Vec<NvEntry> {
            let app = &an.appearance_q.data[f];
            let sign = if f == 1 { -1 } else { 1 };
            let mut out = vec![NvEntry([0i8; NV]); w * h];
            out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
                for (x, o) in row.iter_mut().enumerate() {
                    for (ci, c) in CORNERS.iter().enumerate() {
                        let cx = wrap_i(x as i64 + sign * c[0] as i64 * sp, w);
                        let cy = wrap_i(y as i64 + sign * c[1] as i64 * sp, h);
                        o.0[ci * APPEARANCE_DIMS..(ci + 1) * APPEARANCE_DIMS]
                            .copy_from_slice(&app[cy * w + cx]);
                    }
                }
            });
            out
        };
        Self {
            w,
            h,
            wf: w as f32,
            hf: h as f32,
            nv: [nv_of(0), if rosy { nv_of(1) } else { Vec::new() }],
            coherence: an
                .coherence
                .iter()
                .map(|&v| [(v as usize % w) as f32, (v as usize / w) as f32])
                .collect(),
            k_store: analysis.k(),
            x_lo: an.margin.min(w / 2),
            x_hi: w - an.margin.min(w / 2),
            y_lo: an.margin.min(h / 2),
            y_hi: h - an.margin.min(h / 2),
        }
    }

    #[inline]
    pub(crate) fn wrap(&self, u: [f32; 2]) -> [f32; 2] {
        [wrap1(u[0], self.wf), wrap1(u[1], self.hf)]
    }

    /// Column and row of a wrapped coordinate.
    #[inline]
    pub(crate) fn cell(&self, u: [f32; 2]) -> (usize, usize) {
        // `u` is wrapped (non-negative, finite): the i32 conversion is the floor and a
        // single instruction, unlike the one to usize.
        ((u[0] as i32 as usize).min(self.w - 1), (u[1] as i32 as usize).min(self.h - 1))
    }

    /// Pixel of a wrapped coordinate.
    #[inline]
    pub(crate) fn pixel(&self, u: [f32; 2]) -> usize {
        let (x, y) = self.cell(u);
        y * self.w + x
    }

    /// Asks the CPU to fetch the k-coherence targets of the wrapped coordinate `u` into
    /// the cache ahead of their use (no effect on results). The correction calls it for
    /// every neighbour before it builds the neighbourhood target, so these misses
    /// overlap that work instead of stalling the candidate gathering after it.
    #[inline(always)]
    pub(crate) fn prefetch_coherence(&self, u: [f32; 2]) {
        if let Some(v) = self.coherence.get(self.pixel(u) * self.k_store) {
            crate::prefetch::prefetch_read(v);
        }
    }
}
