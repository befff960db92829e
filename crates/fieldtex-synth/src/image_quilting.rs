//! Multi-scale image quilting with graph-cut seams: Efros & Freeman 2001 (patches placed
//! in raster order, chosen by the error on their overlap with what is already there,
//! among the candidates within a tolerance of the best) with the minimum-cost seam of
//! Kwatra, Schödl, Essa, Turk & Bobick 2003 (max-flow over the overlap,
//! [`crate::graph_cut::MaxFlow`]), and the multi-scale choice of Wang et al. 2005 §4.2:
//! each patch takes its exemplar level from the mean inverse conformal factor `τ` under
//! it — weighted towards the texels that show the most surface (`patch_tau`).
//!
//! Where `τ` changes fast (a patch over a zero point of the conformal map, or over two
//! neighbouring charts of different scale), one level cannot suit the whole patch: a
//! patch whose `τ` spans more than `split_spread` (max / min) is placed as 2 × 2
//! half-size patches in raster order (side `(b + o) / 2`, overlapping by `o`), each with
//! its own level, candidates and cut — the "smaller patches" refinement of session 13
//! (our addition; the paper uses one patch size).
//!
//! Canvas texels are *unknown*, *synthesised* or *fixed*. Before a patch is placed, every
//! unknown texel of its region that has an already known partner (a texel showing the
//! same surface point elsewhere, e.g. across a periodic side of a geometry image) is
//! copied from it, and both become fixed (§4.2, boundary consistency): fixed texels enter the
//! overlap error and are tied to the old side of the cut, so the new patch continues
//! them. Synthesised texels on the outer ring of the region are also tied to the old
//! side, unknown texels to the new patch.
//!
//! Substitutes (documented): candidates are `candidates` random exemplar positions per
//! patch (from `stream(seed, "quilt", patch)`) instead of every position; old seams are
//! not re-cut (Kwatra's seam nodes). Colours are compared in the exemplar's sRGB values.
//! Candidate errors are computed in parallel into per-candidate slots, so the result
//! does not depend on the thread count.

use crate::graph_cut::MaxFlow;
use fieldtex_core::{Image, Progress, stream};
use rand::RngExt;
use rayon::prelude::*;
use serde::Serialize;
use std::ops::Range;

/// Options of [`quilt`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct QuiltingOptions {
    /// Patch side in texels (paper: 30–50). Default 40.
    pub patch_size: usize,
    /// Overlap between neighbouring patches in texels. Default 8.
    pub overlap: usize,
    /// Random candidate positions tried per patch. Default 400.
    pub candidates: usize,
    /// Relative tolerance over the best overlap error (Efros & Freeman: 0.1).
    pub tolerance: f64,
    /// A patch whose texels' `τ` spans more than this factor (max / min) is placed as
    /// 2 × 2 half-size patches, each with its own level ([`f64::INFINITY`] = never).
    /// Default never.
    pub split_spread: f64,
    pub seed: u64,
}

impl Default for QuiltingOptions {
    fn default() -> Self {
        Self {
            patch_size: 40,
            overlap: 8,
            candidates: 400,
            tolerance: 0.1,
            split_spread: f64::INFINITY,
            seed: 1,
        }
    }
}

/// Appends the texels that show the same surface point as texel `(x, y)`.
pub type PartnerFn<'a> = dyn Fn(usize, usize, &mut Vec<(usize, usize)>) + Sync + 'a;

/// Per-texel information the quilting reads.
pub struct QuiltTarget<'a> {
    pub width: usize,
    pub height: usize,
    /// `width × height` inverse conformal factors (`NaN` = none).
    pub tau: &'a [f32],
    /// Level index for a mean `τ` (and for a region without `τ`: `level_for(NaN)`).
    pub level_for: &'a (dyn Fn(f64) -> usize + Sync),
    /// Texels showing the same surface point as `(x, y)`, appended to the vector.
    pub partners: &'a PartnerFn<'a>,
}

/// What [`quilt`] did.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct QuiltStats {
    pub patches: usize,
    /// Patches per exemplar level.
    pub level_histogram: Vec<usize>,
    /// Texels copied from partners and held fixed.
    pub fixed_texels: usize,
    /// Sum over patches of the minimum cut cost (colour difference units).
    pub seam_cost: f64,
    /// Texels on a seam (cut) between patches.
    pub seam_texels: usize,
    /// Patches placed as 2 × 2 half-size patches (`split_spread`).
    pub split_patches: usize,
}

const SCALE: f64 = 4096.0;
const INF: i64 = i64::MAX / 8;

/// Synthesises a `width × height` image from the exemplar `levels` (see module docs).
pub fn quilt(
    levels: &[Image],
    target: &QuiltTarget,
    options: &QuiltingOptions,
    progress: &dyn Progress,
) -> (Image, QuiltStats) {
    let (w, h) = (target.width, target.height);
    let b = options.patch_size.max(4);
    let o = options.overlap.min(b / 2).max(1);
    let step = b - o;
    let pix = vec![[0.0f32; 3]; w * h];
    let state = vec![0u8; w * h]; // 0 unknown, 1 synthesised, 2 fixed
    let stats = QuiltStats { level_histogram: vec![0; levels.len()], ..Default::default() };
    let xs: Vec<usize> = positions(w, b, step);
    let ys: Vec<usize> = positions(h, b, step);
    progress.stage("quilting", (xs.len() * ys.len()) as u64);
    let mut canvas = Canvas { w, pix, state, stats, buf: Vec::new() };
    // Sub-patches of a split patch: side `(b + o) / 2`, so two of them overlap by `o`.
    let bs = (b + o) / 2;
    let halves = |lo: usize, hi: usize| -> Vec<(usize, usize)> {
        if hi - lo <= bs { vec![(lo, hi)] } else { vec![(lo, lo + bs), (hi - bs, hi)] }
    };
    let mut patch_index = 0u64;
    for &y0 in &ys {
        for &x0 in &xs {
            patch_index += 1;
            progress.advance(1);
            let (x1, y1) = ((x0 + b).min(w), (y0 + b).min(h));
            if bs > o && tau_spread(target.tau, w, x0..x1, y0..y1) > options.split_spread {
                canvas.stats.split_patches += 1;
                let mut k = 0u64;
                for &(sy0, sy1) in &halves(y0, y1) {
                    for &(sx0, sx1) in &halves(x0, x1) {
                        let rng = stream(options.seed, "quilt-split", 4 * patch_index + k);
                        k += 1;
                        canvas.place(levels, target, options, sx0..sx1, sy0..sy1, rng);
                    }
                }
            } else {
                let rng = stream(options.seed, "quilt", patch_index);
                canvas.place(levels, target, options, x0..x1, y0..y1, rng);
            }
        }
    }
    progress.finish_stage();
    let mut out = Image::new(w, h, [0.0, 0.0, 0.0, 1.0]);
    for (i, p) in canvas.pix.iter().enumerate() {
        out.pixels[i] = [p[0], p[1], p[2], 1.0];
    }
    (out, canvas.stats)
}

/// The canvas being quilted: colours, texel states, statistics.
struct Canvas {
    w: usize,
    pix: Vec<[f32; 3]>,
    state: Vec<u8>,
    stats: QuiltStats,
    buf: Vec<(usize, usize)>,
}

impl Canvas {
    /// Places one patch over the region `xs × ys`: partner copies, level choice,
    /// candidate search, minimum-cut seam (see the module docs).
    fn place(
        &mut self,
        levels: &[Image],
        target: &QuiltTarget,
        options: &QuiltingOptions,
        xs: std::ops::Range<usize>,
        ys: std::ops::Range<usize>,
        mut rng: impl rand::Rng,
    ) {
        let w = self.w;
        let (x0, x1, y0, y1) = (xs.start, xs.end, ys.start, ys.end);
        let (rw, rh) = (x1 - x0, y1 - y0);
        let (pix, state, stats, buf) =
            (&mut self.pix, &mut self.state, &mut self.stats, &mut self.buf);
        // Boundary consistency: copy known partners into unknown texels.
        for y in y0..y1 {
            for x in x0..x1 {
                let i = y * w + x;
                if state[i] != 0 {
                    continue;
                }
                buf.clear();
                (target.partners)(x, y, buf);
                if let Some(&(px, py)) = buf.iter().find(|&&(px, py)| state[py * w + px] != 0) {
                    pix[i] = pix[py * w + px];
                    state[i] = 2;
                    state[py * w + px] = 2; // both copies are locked from now on
                    stats.fixed_texels += 1;
                }
            }
        }
        let mut unknown = 0;
        let mut known: Vec<(usize, usize, [f32; 3])> = Vec::new();
        for y in y0..y1 {
            for x in x0..x1 {
                let i = y * w + x;
                if state[i] == 0 {
                    unknown += 1;
                } else {
                    known.push((x - x0, y - y0, pix[i]));
                }
            }
        }
        if unknown == 0 {
            return;
        }
        let level =
            (target.level_for)(patch_tau(target.tau, w, x0..x1, y0..y1)).min(levels.len() - 1);
        let ex = &levels[level];
        stats.patches += 1;
        stats.level_histogram[level] += 1;
        let (mx, my) = (ex.width.saturating_sub(rw) + 1, ex.height.saturating_sub(rh) + 1);
        let cands: Vec<(usize, usize)> = (0..options.candidates.max(1))
            .map(|_| (rng.random_range(0..mx), rng.random_range(0..my)))
            .collect();
        let errors: Vec<f64> = cands
            .par_iter()
            .map(|&(cx, cy)| {
                let mut e = 0.0f64;
                for &(dx, dy, a) in &known {
                    let p = ex.get((cx + dx).min(ex.width - 1), (cy + dy).min(ex.height - 1));
                    for c in 0..3 {
                        let d = (p[c] - a[c]) as f64;
                        e += d * d;
                    }
                }
                e
            })
            .collect();
        let best = errors.iter().cloned().fold(f64::INFINITY, f64::min);
        let ok: Vec<usize> = (0..cands.len())
            .filter(|&k| errors[k] <= best * (1.0 + options.tolerance) + 1e-12)
            .collect();
        let pick = if ok.is_empty() { 0 } else { ok[rng.random_range(0..ok.len())] };
        let (cx, cy) = cands[pick];
        let patch = |dx: usize, dy: usize| {
            let p = ex.get((cx + dx).min(ex.width - 1), (cy + dy).min(ex.height - 1));
            [p[0], p[1], p[2]]
        };
        if known.is_empty() {
            for y in y0..y1 {
                for x in x0..x1 {
                    pix[y * w + x] = patch(x - x0, y - y0);
                    state[y * w + x] = 1;
                }
            }
            return;
        }
        // Minimum-cost seam over the region.
        let node = |x: usize, y: usize| (y - y0) * rw + (x - x0);
        let diff = |x: usize, y: usize| -> f64 {
            let i = y * w + x;
            if state[i] == 0 {
                return 0.0;
            }
            let p = patch(x - x0, y - y0);
            (0..3).map(|c| (p[c] - pix[i][c]).abs() as f64).sum()
        };
        let mut g = MaxFlow::new(rw * rh);
        for y in y0..y1 {
            for x in x0..x1 {
                let i = y * w + x;
                let n = node(x, y);
                let ring = x == x0 || y == y0 || x + 1 == x1 || y + 1 == y1;
                match state[i] {
                    0 => g.add_terminal(n, 0, INF),
                    2 => g.add_terminal(n, INF, 0),
                    _ if ring => g.add_terminal(n, INF, 0),
                    _ => {}
                }
                if x + 1 < x1 {
                    let c = ((diff(x, y) + diff(x + 1, y)) * SCALE) as i64 + 1;
                    g.add_edge(n, node(x + 1, y), c, c);
                }
                if y + 1 < y1 {
                    let c = ((diff(x, y) + diff(x, y + 1)) * SCALE) as i64 + 1;
                    g.add_edge(n, node(x, y + 1), c, c);
                }
            }
        }
        let flow = g.solve();
        stats.seam_cost += flow as f64 / SCALE;
        for y in y0..y1 {
            for x in x0..x1 {
                let i = y * w + x;
                let n = node(x, y);
                if !g.source_side(n) {
                    if state[i] != 0 {
                        // Was known and is replaced: count seam texels at the cut.
                        if x > x0 && g.source_side(node(x - 1, y))
                            || y > y0 && g.source_side(node(x, y - 1))
                        {
                            stats.seam_texels += 1;
                        }
                    }
                    pix[i] = patch(x - x0, y - y0);
                    state[i] = 1;
                }
            }
        }
    }
}

/// The `τ` a patch takes its level from: the mean of `τ` over the patch weighted by
/// `τ^-p` (`p` = [`TAU_WEIGHT_POWER`]; `NaN` when no texel has a `τ`).
///
/// Wang et al. 2005 §4.2 take "the mean τ under the patch". A texel covers surface area
/// `∝ τ⁻²`, so a plain texel mean lets the few texels of a region the map compressed
/// (small `τ`, much surface) take the level of their large-`τ` neighbours, and their
/// features come out far too large on the surface. With one level `s` for the patch,
/// the feature period on the surface is `∝ s/τ` per texel; the `s` that minimises its
/// surface-area-weighted variance around the target `1/τ_ref`-scaled period is
/// `s ∝ Σ τ⁻³ / Σ τ⁻⁴`, the mean of `τ` weighted by `τ⁻⁴` (`p = 4`); `p = 2` is the
/// surface-area-weighted mean, `p = 0` the plain texel mean.
fn patch_tau(tau: &[f32], width: usize, xs: Range<usize>, ys: Range<usize>) -> f64 {
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for t in region_taus(tau, width, xs, ys) {
        let t = t as f64;
        let wgt = t.powf(-TAU_WEIGHT_POWER);
        num += wgt * t;
        den += wgt;
    }
    if den > 0.0 && num.is_finite() { num / den } else { f64::NAN }
}

/// `max τ / min τ` over the texels of the region that have a `τ` (1 without any).
fn tau_spread(tau: &[f32], width: usize, xs: Range<usize>, ys: Range<usize>) -> f64 {
    let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
    for t in region_taus(tau, width, xs, ys) {
        lo = lo.min(t);
        hi = hi.max(t);
    }
    if hi > 0.0 { (hi / lo) as f64 } else { 1.0 }
}

/// The finite positive `τ` of the texels in `xs × ys`, row by row.
fn region_taus(
    tau: &[f32],
    width: usize,
    xs: Range<usize>,
    ys: Range<usize>,
) -> impl Iterator<Item = f32> + '_ {
    ys.flat_map(move |y| tau[y * width + xs.start..y * width + xs.end].iter().copied())
        .filter(|t| t.is_finite() && *t > 0.0)
}

/// Power `p` of the `τ^-p` weights of a patch's level choice (`patch_tau`).
pub const TAU_WEIGHT_POWER: f64 = 4.0;

fn positions(len: usize, b: usize, step: usize) -> Vec<usize> {
    if len <= b {
        return vec![0];
    }
    let mut v: Vec<usize> = (0..).map(|k| k * step).take_while(|&p| p + b < len).collect();
    v.push(len - b);
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_core::NoProgress;

    fn exemplar() -> Image {
        let mut im = Image::new(64, 64, [0.0; 4]);
        for y in 0..64 {
            for x in 0..64 {
                let v =
                    ((x as f32 * 0.4).sin() * (y as f32 * 0.3).cos() * 0.5 + 0.5).clamp(0.0, 1.0);
                im.set(x, y, [v, 1.0 - v, 0.5 * v, 1.0]);
            }
        }
        im
    }

    #[test]
    fn periodic_margins_match_their_partners() {
        // A 100-texel-wide canvas whose columns x and x + 80 show the same point.
        let (w, h) = (100, 50);
        let tau = vec![f32::NAN; w * h];
        let level_for = |_: f64| 0usize;
        let partners = move |x: usize, y: usize, out: &mut Vec<(usize, usize)>| {
            if x + 80 < w {
                out.push((x + 80, y));
            }
            if x >= 80 {
                out.push((x - 80, y));
            }
        };
        let target = QuiltTarget {
            width: w,
            height: h,
            tau: &tau,
            level_for: &level_for,
            partners: &partners,
        };
        let opts =
            QuiltingOptions { patch_size: 24, overlap: 6, candidates: 64, ..Default::default() };
        let (im, st) = quilt(&[exemplar()], &target, &opts, &NoProgress);
        assert!(st.fixed_texels > 0);
        for y in 0..h {
            for x in 80..w {
                assert_eq!(im.get(x, y), im.get(x - 80, y), "texel ({x}, {y})");
            }
        }
    }

    /// A 10 × 10 patch whose one texel shows 100× more surface than each of the others
    /// (`τ` 1 against 10): the plain texel mean (9.91) would give the whole patch the
    /// large-`τ` level; the `τ⁻⁴`-weighted mean stays near the compressed texel's `τ`.
    /// Texels without `τ` are ignored, and a patch without any has none.
    #[test]
    fn compressed_texels_choose_the_patch_level() {
        let mut tau = vec![10.0f32; 12 * 10];
        tau[3 * 12 + 4] = 1.0;
        tau[5 * 12 + 5] = f32::NAN;
        let t = patch_tau(&tau, 12, 0..10, 0..10);
        assert!(t > 1.0 && t < 1.2, "{t}");
        assert!(patch_tau(&[f32::NAN; 4], 2, 0..2, 0..2).is_nan());
    }

    /// A 40 × 40 canvas whose 16 left columns have `τ` 1 and the others 4 (level 0 below
    /// 2, level 1 above): one whole patch takes one level (the `τ⁻⁴` weights favour the
    /// compressed side); with `split_spread` 2 it is placed as four 24-px patches, and
    /// the right two (columns 16–39, all `τ` 4) take level 1. A uniform canvas is never
    /// split.
    #[test]
    fn patches_over_a_fast_tau_change_are_split() {
        let (w, h) = (40, 40);
        let tau: Vec<f32> = (0..w * h).map(|i| if i % w < 16 { 1.0 } else { 4.0 }).collect();
        let level_for = |t: f64| if t < 2.0 { 0 } else { 1 };
        let partners = |_: usize, _: usize, _: &mut Vec<(usize, usize)>| {};
        let levels = [exemplar(), crate::exemplar_scales::resample(&exemplar(), 3.0)];
        let run = |tau: &[f32], split: f64| {
            let target = QuiltTarget {
                width: w,
                height: h,
                tau,
                level_for: &level_for,
                partners: &partners,
            };
            let opts = QuiltingOptions {
                patch_size: 40,
                overlap: 8,
                candidates: 32,
                split_spread: split,
                ..Default::default()
            };
            quilt(&levels, &target, &opts, &NoProgress).1
        };
        let whole = run(&tau, f64::INFINITY);
        assert_eq!((whole.patches, whole.split_patches), (1, 0));
        assert_eq!(whole.level_histogram, vec![1, 0]);
        let split = run(&tau, 2.0);
        assert_eq!((split.patches, split.split_patches), (4, 1));
        assert_eq!(split.level_histogram, vec![2, 2]);
        let uniform = run(&vec![4.0; w * h], 2.0);
        assert_eq!((uniform.patches, uniform.split_patches), (1, 0));
    }

    #[test]
    fn same_output_for_one_and_two_threads() {
        let (w, h) = (70, 60);
        let tau: Vec<f32> = (0..w * h).map(|i| 1.0 + (i % w) as f32 / w as f32).collect();
        let level_for = |t: f64| if t > 1.5 { 1 } else { 0 };
        let partners = |_: usize, _: usize, _: &mut Vec<(usize, usize)>| {};
        let levels = [exemplar(), crate::exemplar_scales::resample(&exemplar(), 1.5)];
        let run = |n: usize| {
            let target = QuiltTarget {
                width: w,
                height: h,
                tau: &tau,
                level_for: &level_for,
                partners: &partners,
            };
            let pool = rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap();
            pool.install(|| {
                quilt(
                    &levels,
                    &target,
                    &QuiltingOptions {
                        patch_size: 20,
                        overlap: 5,
                        split_spread: 1.2,
                        ..Default::default()
                    },
                    &NoProgress,
                )
            })
        };
        let (a, sa) = run(1);
        let (b, sb) = run(2);
        assert_eq!(a, b);
        assert_eq!(sa, sb);
        assert!(sa.level_histogram[0] > 0 && sa.level_histogram[1] > 0);
        assert!(sa.split_patches > 0);
    }
}
