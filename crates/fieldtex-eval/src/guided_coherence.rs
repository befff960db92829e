//! Guided coherence: the texture-optimisation energy of [`coherence`](crate::coherence())
//! with the output patches taken in the local frame of a direction field.
//!
//! For field-guided synthesis (`fieldtex orient`, Kwatra et al. 2005 eq. 1 as extended
//! to guided synthesis by Lefebvre & Hoppe 2006 §4 and paper D §4) the energy compares
//! the exemplar with output neighbourhoods *in the field's frame*: the exemplar's x axis
//! follows the field vector `d = (dx, dy)` (pixel units, x right, y down) and its y axis
//! the perpendicular `(−dy, dx)`. The plain metric compares axis-aligned output patches
//! and so penalises every rotated region, even an exact rotated copy of the exemplar.
//!
//! Method, per query pixel `p` on a regular grid with step [`stride`] (or, with
//! [`sampled_queries`], at seeded random pixels: see below):
//! 1. **Output patch** (`N×N`, `N` = [`patch_size`], default 7 like the plain metric):
//!    samples at `p + (½, ½) + u_i·d + u_j·d⊥`, `u = i − (N−1)/2`, read with bilinear
//!    interpolation. Queries whose samples leave the output, or where the field is zero
//!    or not finite, are skipped and counted.
//! 2. **Exemplar patches** go through the *same* bilinear sampler: at every exemplar
//!    pixel `c` (all `W·H` positions, toroidal when [`wrap_exemplar`]), samples at
//!    `c + (½, ½) + (u_i, u_j)`, i.e. the 2×2 box means. Fairness: centring both sides
//!    on a half pixel makes the 0°, 90°, 180° and 270° frames compare exactly the same
//!    filtered values (an exact copy scores 0), and for other angles the output's
//!    interpolation phases scatter around the half-pixel phase of the exemplar
//!    patches, which is the phase closest on average (squared blur mismatch `1/12`
//!    of the pixel-difference variance per axis, against `1/3` for sharp exemplar
//!    patches). The price: both sides are slightly blurred, so the numbers are a bit
//!    lower than the plain metric's; compare guided coherence with guided coherence
//!    (an unguided output with a constant 0° field), not with `coherence`.
//! 3. **Distance**: sum of squared differences over the `N·N·C` values divided by
//!    `N·N·C` (the normalisation of [`crate::PatchDistanceReport::mean`]). With
//!    [`sign_free`] (default, orientation fields are 2-RoSy: `d` and `−d` are the same
//!    line) the output patch is also compared rotated by 180°, and the smaller
//!    distance counts.
//! 4. **Exact nearest search** over all exemplar patches, rayon over query rows, with
//!    early exit when the partial sum of a candidate (checked after each patch row)
//!    reaches the best so far. Each query starts from the best candidate of its left
//!    neighbour; the minimum is exact and every candidate's sum is taken in the same
//!    order, so the result is bit-identical for any thread count.
//!
//! Cost: `queries × W·H × 2` candidate tests with early exit after each patch row.
//! Measured (`examples/bench_guided_coherence`, shared busy 2-core VM): stride 4 on a
//! 512² orient output vs the 116² stripes exemplar (15 876 queries) took 29–34 s
//! wall, ≈ 2 ms per query — so the default stride is 8 (≈ 4 000 queries, ≈ 8 s);
//! stride 16 takes ≈ 2 s. Stride 1 evaluates every pixel (64× the default). TODO: a
//! faster exact search (e.g. the displacement scan of `nearest_patch` per angle bin).
//!
//! **Sampled queries** ([`sampled_queries`] > 0; the pipelines' default reports use
//! [`SAMPLED_QUERIES`]): the query pixels are drawn uniformly with replacement (a seeded
//! hash) from the pixels at least `⌈(N−1)/√2⌉ + 1` from every edge, where the rotated
//! patch stays inside at any angle, and the report carries the standard error of the
//! sample mean (`sd / √queries`, simple random sampling). A substitute for the grid
//! whose measured gap to the exact grid mean is pinned by `tests/approximate_metrics.rs`
//! (`docs/first-hour.md`): half the queries of the default stride-8 grid at 512², and
//! no aliasing with a texture's period.
//!
//! Not implemented: anisotropic scale (the field is taken as unit length: its
//! magnitude is ignored), mirror frames, and per-sample frames (one frame per patch,
//! taken from the field at `p`).
//!
//! [`stride`]: GuidedCoherenceOptions::stride
//! [`patch_size`]: GuidedCoherenceOptions::patch_size
//! [`wrap_exemplar`]: GuidedCoherenceOptions::wrap_exemplar
//! [`sign_free`]: GuidedCoherenceOptions::sign_free
//! [`sampled_queries`]: GuidedCoherenceOptions::sampled_queries

use crate::EvalError;
use crate::image_view::{FieldView, ImageView};
use rayon::prelude::*;
use serde::Serialize;

/// Options of [`guided_coherence`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GuidedCoherenceOptions {
    /// Patch side `N` in pixels. Default 7 (as [`crate::PatchDistanceOptions`]).
    pub patch_size: usize,
    /// Step between query pixels along x and y. Default 8 (a 512² output has about
    /// 4 000 queries: ≈ 8 s on the shared 2-core VM against a 116² exemplar).
    pub stride: usize,
    /// Exemplar patches wrap around its edges (tileable exemplar), as the facade's
    /// plain coherence. Default true.
    pub wrap_exemplar: bool,
    /// Also compare the output patch rotated by 180° (for 2-RoSy orientation fields,
    /// where `d` and `−d` are the same direction). Default true.
    pub sign_free: bool,
    /// `Some`: approximate nearest search (PCA + kd-tree, an upper bound of the exact
    /// distances, [`crate::approximate_nearest_patch`]; its `query_stride` and
    /// `sampled_queries` are not used: `stride` and `sampled_queries` here are); `None`:
    /// the exact search. Default `None`.
    pub approximate: Option<crate::ApproximateSearchOptions>,
    /// `> 0`: the mean is estimated from this many query pixels drawn uniformly (with
    /// replacement, a seeded hash of `seed`) from the pixels whose rotated patch stays
    /// inside the output at any angle, instead of the `stride` grid, and the report
    /// carries its standard error (a substitute for the grid with a measured error:
    /// `tests/approximate_metrics.rs`). 0: the grid. Default 0; the pipelines'
    /// default reports use [`SAMPLED_QUERIES`].
    pub sampled_queries: usize,
    /// Seed of the query sample. Default 1.
    pub seed: u64,
}

/// Query pixels of the pipelines' default (sampled) guided coherence.
pub const SAMPLED_QUERIES: usize = 2_048;

impl Default for GuidedCoherenceOptions {
    fn default() -> Self {
        Self {
            patch_size: 7,
            stride: 8,
            wrap_exemplar: true,
            sign_free: true,
            approximate: None,
            sampled_queries: 0,
            seed: 1,
        }
    }
}

impl GuidedCoherenceOptions {
    fn validate(&self) -> Result<(), EvalError> {
        if self.patch_size == 0 || self.patch_size > 64 {
            return Err(EvalError::InvalidOption {
                name: "patch_size",
                value: self.patch_size.to_string(),
                reason: "must be in 1..=64 pixels",
            });
        }
        if self.stride == 0 || self.stride > 4096 {
            return Err(EvalError::InvalidOption {
                name: "stride",
                value: self.stride.to_string(),
                reason: "must be in 1..=4096 pixels",
            });
        }
        Ok(())
    }
}

/// Summary of the per-query nearest distances (normalised per value, sRGB units²).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GuidedCoherenceReport {
    /// Mean over queries of `min SSD / (N·N·C)`.
    pub mean: f64,
    /// Median of the same.
    pub median: f64,
    /// 95th percentile of the same.
    pub p95: f64,
    /// Largest of the same.
    pub max: f64,
    /// Query pixels evaluated.
    pub queries: usize,
    /// Query pixels skipped because their rotated patch leaves the output.
    pub skipped_border: usize,
    /// Query pixels skipped because the field is zero or not finite there.
    pub skipped_no_direction: usize,
    /// Exemplar patches searched per query.
    pub candidates: usize,
    pub patch_size: usize,
    pub stride: usize,
    pub sign_free: bool,
    /// `"exact"` or `"approximate"`.
    pub search: String,
    /// Query pixels drawn at random ([`GuidedCoherenceOptions::sampled_queries`]); 0
    /// when the `stride` grid was used.
    pub sampled_queries: usize,
    /// For a sampled mean: its standard error (sample standard deviation / √queries;
    /// the estimate is within ±1.96 of the mean over every eligible pixel with about
    /// 95 % probability); absent for the grid.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub standard_error: Option<f64>,
}

/// Bilinear sample of all channels at `(x, y)` (pixel centres at integers), with
/// coordinates already known to lie in `[0, w−1] × [0, h−1]`.
#[inline]
fn bilinear(img: &ImageView, x: f64, y: f64, out: &mut [f32]) {
    let (w, h, c) = (img.width, img.height, img.channels);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
    let (x0, y0) = ((x0 as usize).min(w - 1), (y0 as usize).min(h - 1));
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let px = |xx: usize, yy: usize| (yy * w + xx) * c;
    let (a, b, cc, d) = (px(x0, y0), px(x1, y0), px(x0, y1), px(x1, y1));
    for (ch, o) in out.iter_mut().enumerate() {
        let top = img.data[a + ch] * (1.0 - fx) + img.data[b + ch] * fx;
        let bottom = img.data[cc + ch] * (1.0 - fx) + img.data[d + ch] * fx;
        *o = top * (1.0 - fy) + bottom * fy;
    }
}

/// All exemplar patches through the half-pixel bilinear sampler (2×2 box means), each
/// a contiguous `N·N·C` vector ordered row, column, channel. Returns the patch count.
fn exemplar_patches(ex: &ImageView, n: usize, wrap: bool) -> (Vec<f32>, usize) {
    let (w, h, c) = (ex.width, ex.height, ex.channels);
    let (cols, rows) = if wrap { (w, h) } else { (w - n, h - n) };
    let dim = n * n * c;
    let mut data = vec![0f32; cols * rows * dim];
    data.par_chunks_mut(cols * dim).enumerate().for_each(|(cy, row)| {
        for cx in 0..cols {
            let patch = &mut row[cx * dim..(cx + 1) * dim];
            for j in 0..n {
                let (ya, yb) = ((cy + j) % h, (cy + j + 1) % h);
                for i in 0..n {
                    let (xa, xb) = ((cx + i) % w, (cx + i + 1) % w);
                    for ch in 0..c {
                        let v = ex.at(xa, ya, ch) + ex.at(xb, ya, ch);
                        let v2 = ex.at(xa, yb, ch) + ex.at(xb, yb, ch);
                        patch[(j * n + i) * c + ch] = 0.25 * (v + v2);
                    }
                }
            }
        }
    });
    (data, cols * rows)
}

/// Outcome of sampling one query patch.
enum Query {
    Ok,
    Border,
    NoDirection,
}

/// The output patch at query pixel `(px, py)` in the field frame, into `q` (and its
/// 180° rotation into `q_flip`).
fn sample_query(
    out: &ImageView,
    field: &FieldView,
    px: usize,
    py: usize,
    n: usize,
    q: &mut [f32],
    q_flip: &mut [f32],
) -> Query {
    let [dx, dy] = field.at(px, py);
    let (dx, dy) = (dx as f64, dy as f64);
    let len = (dx * dx + dy * dy).sqrt();
    if !len.is_finite() || len < 1e-12 {
        return Query::NoDirection;
    }
    let (ax, ay) = (dx / len, dy / len);
    let (bx, by) = (-ay, ax);
    let (cx, cy) = (px as f64 + 0.5, py as f64 + 0.5);
    let half = (n as f64 - 1.0) / 2.0;
    let (wmax, hmax) = ((out.width - 1) as f64, (out.height - 1) as f64);
    let c = out.channels;
    for j in 0..n {
        let v = j as f64 - half;
        for i in 0..n {
            let u = i as f64 - half;
            let x = cx + u * ax + v * bx;
            let y = cy + u * ay + v * by;
            // Round-off may put an axis-aligned sample a hair outside: snap it.
            let (x, y) = (snap(x), snap(y));
            if !(0.0..=wmax).contains(&x) || !(0.0..=hmax).contains(&y) {
                return Query::Border;
            }
            let k = (j * n + i) * c;
            bilinear(out, x, y, &mut q[k..k + c]);
        }
    }
    // 180° rotation: sample (i, j) ↔ (N−1−i, N−1−j).
    let m = n * n;
    for s in 0..m {
        let t = m - 1 - s;
        q_flip[t * c..(t + 1) * c].copy_from_slice(&q[s * c..(s + 1) * c]);
    }
    Query::Ok
}

/// Rounds values within 1e-9 of an integer to it (exact frames stay exact).
#[inline]
fn snap(x: f64) -> f64 {
    let r = x.round();
    if (x - r).abs() < 1e-9 { r } else { x }
}

/// SSD of `q` and `p` (rows of `row_len` values), giving up once it reaches `best`
/// (checked after each row); returns the full sum or a value `≥ best`.
#[inline]
fn ssd_bounded(q: &[f32], p: &[f32], row_len: usize, best: f32) -> f32 {
    let mut s = 0f32;
    for (qr, pr) in q.chunks_exact(row_len).zip(p.chunks_exact(row_len)) {
        let mut r = 0f32;
        for (a, b) in qr.iter().zip(pr) {
            let d = a - b;
            r += d * d;
        }
        s += r;
        if s >= best {
            return s;
        }
    }
    s
}

/// Guided coherence of `output` against `exemplar` with the frame of `field` (see the
/// module docs). `field` must have the output's size; `output` and `exemplar` the
/// same channel count. Errors when the exemplar is too small for one patch.
pub fn guided_coherence(
    output: &ImageView,
    exemplar: &ImageView,
    field: &FieldView,
    options: &GuidedCoherenceOptions,
) -> Result<GuidedCoherenceReport, EvalError> {
    options.validate()?;
    let n = options.patch_size;
    if output.channels != exemplar.channels {
        return Err(EvalError::ChannelMismatch {
            what: "guided coherence",
            a: output.channels,
            b: exemplar.channels,
        });
    }
    if field.width != output.width || field.height != output.height {
        return Err(EvalError::SizeMismatch {
            what: "guided coherence field vs output",
            expected_width: output.width,
            expected_height: output.height,
            found_width: field.width,
            found_height: field.height,
        });
    }
    let min_ex = if options.wrap_exemplar { n } else { n + 1 };
    if exemplar.width < min_ex || exemplar.height < min_ex {
        return Err(EvalError::TooSmall {
            what: "exemplar",
            width: exemplar.width,
            height: exemplar.height,
            min: min_ex,
        });
    }
    if output.width < n || output.height < n {
        return Err(EvalError::TooSmall {
            what: "output",
            width: output.width,
            height: output.height,
            min: n,
        });
    }
    let c = output.channels;
    let dim = n * n * c;
    let row_len = n * c;
    let (db, count) = exemplar_patches(exemplar, n, options.wrap_exemplar);
    let dense = crate::approximate_nearest_patch::DensePatches { data: &db, dim };
    let index = match &options.approximate {
        Some(a) => {
            Some(crate::approximate_nearest_patch::PatchIndex::build(&dense, a).map_err(|_| {
                EvalError::InvalidOption {
                    name: "approximate",
                    value: format!("{a:?}"),
                    reason: "the patch PCA failed (constant or degenerate exemplar?)",
                }
            })?)
        }
        None => None,
    };
    let s = options.stride;
    let sampled = sampled_positions(output.width, output.height, n, options);
    let rows: Vec<Vec<(usize, usize)>> = match &sampled {
        // Fixed chunks of the sample: the result does not depend on the thread count.
        Some(p) => p.chunks(64).map(|c| c.to_vec()).collect(),
        None => {
            let xs: Vec<usize> = (s / 2..output.width).step_by(s).collect();
            (s / 2..output.height)
                .step_by(s)
                .map(|py| xs.iter().map(|&px| (px, py)).collect())
                .collect()
        }
    };
    // Per query row (or chunk of the sample): (distances, border skips, no-direction
    // skips), in order.
    let per_row: Vec<(Vec<f32>, usize, usize)> = rows
        .par_iter()
        .map(|row| {
            let mut q = vec![0f32; dim];
            let mut q_flip = vec![0f32; dim];
            let mut scratch = crate::approximate_nearest_patch::SearchScratch::default();
            let mut dists = Vec::with_capacity(row.len());
            let (mut border, mut no_dir) = (0, 0);
            let mut hint = 0usize;
            for &(px, py) in row {
                match sample_query(output, field, px, py, n, &mut q, &mut q_flip) {
                    Query::Border => border += 1,
                    Query::NoDirection => no_dir += 1,
                    Query::Ok if index.is_some() => {
                        let idx = index.as_ref().expect("checked");
                        let mut d = idx.nearest(&q, &mut scratch).0;
                        if options.sign_free {
                            d = d.min(idx.nearest(&q_flip, &mut scratch).0);
                        }
                        dists.push(d);
                    }
                    Query::Ok => {
                        let (d, arg) = nearest(
                            &q,
                            options.sign_free.then_some(&q_flip[..]),
                            &db,
                            dim,
                            row_len,
                            hint,
                        );
                        hint = arg;
                        dists.push(d);
                    }
                }
            }
            (dists, border, no_dir)
        })
        .collect();
    let mut all = Vec::new();
    let (mut border, mut no_dir) = (0, 0);
    for (d, b, nd) in per_row {
        all.extend(d);
        border += b;
        no_dir += nd;
    }
    let norm = 1.0 / dim as f64;
    let mut v: Vec<f64> = all.iter().map(|&d| d.max(0.0) as f64 * norm).collect();
    let mean = if v.is_empty() { f64::NAN } else { v.iter().sum::<f64>() / v.len() as f64 };
    let standard_error = sampled.as_ref().map(|_| {
        let m = v.len();
        if m < 2 {
            return 0.0;
        }
        let var = v.iter().map(|d| (d - mean) * (d - mean)).sum::<f64>() / (m - 1) as f64;
        (var / m as f64).sqrt()
    });
    v.sort_by(|a, b| a.total_cmp(b));
    let pick = |f: f64| {
        v.get(((v.len() as f64 * f) as usize).min(v.len().saturating_sub(1)))
            .copied()
            .unwrap_or(f64::NAN)
    };
    Ok(GuidedCoherenceReport {
        mean,
        median: pick(0.5),
        p95: pick(0.95),
        max: v.last().copied().unwrap_or(f64::NAN),
        queries: v.len(),
        skipped_border: border,
        skipped_no_direction: no_dir,
        candidates: count,
        patch_size: n,
        stride: s,
        sign_free: options.sign_free,
        search: if options.approximate.is_some() { "approximate" } else { "exact" }.into(),
        sampled_queries: sampled.as_ref().map_or(0, |p| p.len()),
        standard_error,
    })
}

/// The query pixels of a sampled estimate ([`GuidedCoherenceOptions::sampled_queries`]):
/// drawn uniformly with replacement from the pixels at least `⌈(N−1)/√2⌉ + 1` from
/// every edge, where an `N×N` patch in any frame stays inside the output; `None` for
/// the grid (no sample asked for, or an output too small for that margin).
fn sampled_positions(
    width: usize,
    height: usize,
    n: usize,
    options: &GuidedCoherenceOptions,
) -> Option<Vec<(usize, usize)>> {
    let count = options.sampled_queries;
    // Half the patch diagonal, (N−1)/2·√2, rounded up, plus one pixel for the
    // half-pixel centre and the bilinear footprint.
    let margin = ((n as f64 - 1.0) / std::f64::consts::SQRT_2).ceil() as usize + 1;
    if count == 0 || width <= 2 * margin || height <= 2 * margin {
        return None;
    }
    let (span_x, span_y) = (width - 2 * margin, height - 2 * margin);
    let pick = |i: u64, span: usize| {
        let u = fieldtex_core::rng::hash_unit(options.seed, "guided-queries", i);
        margin + ((u * span as f64) as usize).min(span - 1)
    };
    Some((0..count as u64).map(|i| (pick(2 * i, span_x), pick(2 * i + 1, span_y))).collect())
}

/// Smallest SSD of `q` (and `q_flip` when given) to any patch of `db`, and the index
/// of a patch attaining it; `hint` is tried first to tighten the bound early.
fn nearest(
    q: &[f32],
    q_flip: Option<&[f32]>,
    db: &[f32],
    dim: usize,
    row_len: usize,
    hint: usize,
) -> (f32, usize) {
    let mut best = f32::INFINITY;
    let mut arg = 0;
    let count = db.len() / dim;
    let order = std::iter::once(hint.min(count - 1)).chain(0..count);
    for k in order {
        let p = &db[k * dim..(k + 1) * dim];
        let d = ssd_bounded(q, p, row_len, best);
        if d < best {
            best = d;
            arg = k;
        }
        if let Some(qf) = q_flip {
            let d = ssd_bounded(qf, p, row_len, best);
            if d < best {
                best = d;
                arg = k;
            }
        }
    }
    (best, arg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn early_exit_search_finds_the_exact_minimum() {
        let (dim, row_len, count) = (5 * 5 * 3, 15, 300);
        let v = |i: usize| fieldtex_core::rng::hash_unit(9, "gc-test", i as u64) as f32;
        let db: Vec<f32> = (0..dim * count).map(v).collect();
        let q: Vec<f32> = (0..dim).map(|i| v(dim * count + i)).collect();
        let qf: Vec<f32> = q.iter().rev().copied().collect();
        let full = |a: &[f32], k: usize| {
            ssd_bounded(a, &db[k * dim..(k + 1) * dim], row_len, f32::INFINITY)
        };
        let naive = (0..count).map(|k| full(&q, k).min(full(&qf, k))).fold(f32::INFINITY, f32::min);
        for hint in [0, 17, 299] {
            let (d, arg) = nearest(&q, Some(&qf), &db, dim, row_len, hint);
            assert_eq!(d, naive);
            assert_eq!(d, full(&q, arg).min(full(&qf, arg)));
        }
    }
}
