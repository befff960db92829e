//! The nearest-patch metrics (coherence, completeness, the coherence map): options,
//! report, and the choice between the exact displacement scan of
//! [`crate::nearest_patch`] and the approximate search of
//! [`crate::approximate_nearest_patch`] (PCA + kd-tree; an upper bound of the exact
//! distances, measured within +5 % on the test exemplars). With the approximate search,
//! coherence and completeness by default average a seeded sample of query patches
//! ([`crate::query_sampling`]) and report the standard error of that sample mean
//! (`tests/approximate_metrics.rs`, `docs/perf/orient.md`).

use crate::EvalError;
use crate::approximate_nearest_patch::{
    ApproximateSearchOptions, ERROR_BOUND_PERCENT, PatchBasis, PatchIndex, PatchSource,
};
use crate::image_view::ImageView;
use crate::nearest_patch::{PatchGrid, nearest_patch_ssd};
use crate::query_sampling::{RUN_LENGTH, run_standard_error, sampled_runs};
use rayon::prelude::*;
use serde::Serialize;

/// Options shared by coherence and completeness.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PatchDistanceOptions {
    /// Patch side `N` in pixels (odd or even). Default 7.
    pub patch_size: usize,
    /// Treat the exemplar as tileable: its patches wrap around the edges. Default
    /// false (only patches fully inside the exemplar).
    pub wrap_exemplar: bool,
    /// Refuse comparisons of more patch pairs than this (the cost is linear in it:
    /// about 3 ns per pair per core). Default 2·10¹⁰ (512² vs 256² is 1.6·10¹⁰).
    /// Exact search only.
    pub max_pairs: u64,
    /// `Some`: the approximate search of [`crate::approximate_nearest_patch`] (PCA +
    /// kd-tree, bounded cost, an upper bound on the exact distances); `None`: the exact
    /// displacement scan. Default `None` (exact) for the library; the pipelines' default
    /// reports use the approximate search and offer the exact one as an option.
    pub approximate: Option<ApproximateSearchOptions>,
}

impl Default for PatchDistanceOptions {
    fn default() -> Self {
        Self { patch_size: 7, wrap_exemplar: false, max_pairs: 20_000_000_000, approximate: None }
    }
}

impl PatchDistanceOptions {
    pub fn with_patch_size(mut self, n: usize) -> Self {
        self.patch_size = n;
        self
    }
    pub fn with_wrap_exemplar(mut self, wrap: bool) -> Self {
        self.wrap_exemplar = wrap;
        self
    }
    /// The approximate search (`Some`) or the exact scan (`None`).
    pub fn with_approximate(mut self, approximate: Option<ApproximateSearchOptions>) -> Self {
        self.approximate = approximate;
        self
    }
    pub(crate) fn validate(&self) -> Result<(), EvalError> {
        if self.patch_size == 0 || self.patch_size > 64 {
            return Err(EvalError::InvalidOption {
                name: "patch_size",
                value: self.patch_size.to_string(),
                reason: "must be in 1..=64 pixels",
            });
        }
        Ok(())
    }
}

/// Squared distance of two patch vectors.
#[inline]
fn ssd(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// Approximate nearest squared distances of the `queries` patches (indices into `q`)
/// to the database `db` (module `approximate_nearest_patch`), and the PCA basis used
/// (`basis`: reuse one fitted on patches of the same size, e.g. the other direction's
/// database; `None`: fit one on `db`), with coherent candidates: the match of the
/// previous query of the same chunk, shifted by the displacement between the two
/// queries, is compared exactly too (Ashikhmin 2001; the propagation step of
/// PatchMatch, Barnes et al. 2009). Neighbouring patches of a texture tend to match
/// neighbouring patches, so this candidate is often better than what a small tree
/// budget finds. Every answer is the true distance to some database patch (an upper
/// bound of the exact one). Chunks of 256 queries are fixed, so the result does not
/// depend on the thread count.
fn approximate_ssd(
    q: &PatchGrid,
    queries: &[usize],
    db: &PatchGrid,
    options: &ApproximateSearchOptions,
    basis: Option<&PatchBasis>,
) -> Result<(Vec<f32>, PatchBasis), EvalError> {
    let built = match basis {
        Some(b) => PatchIndex::build_with_basis(db, options, b),
        None => PatchIndex::build(db, options),
    };
    let index = built.map_err(|_| EvalError::InvalidOption {
        name: "approximate",
        value: format!("{options:?}"),
        reason: "the patch PCA failed (constant or degenerate patches?)",
    })?;
    let dim = q.dim();
    let dists = queries
        .par_chunks(256)
        .flat_map_iter(|chunk| {
            let mut buf = vec![0f32; dim];
            let mut cand = vec![0f32; dim];
            let mut scratch = crate::approximate_nearest_patch::SearchScratch::default();
            // (query position, its match position) of the previous query.
            let mut prev: Option<((isize, isize), (isize, isize))> = None;
            chunk
                .iter()
                .map(|&i| {
                    q.fill(i, &mut buf);
                    let (mut best, mut at) = index.nearest(&buf, &mut scratch);
                    let here = ((i % q.cols) as isize, (i / q.cols) as isize);
                    if let Some((p, m)) = prev {
                        let (x, y) = (m.0 + here.0 - p.0, m.1 + here.1 - p.1);
                        if x >= 0 && y >= 0 && (x as usize) < db.cols && (y as usize) < db.rows {
                            let j = y as usize * db.cols + x as usize;
                            if j != at {
                                db.fill(j, &mut cand);
                                let d = ssd(&buf, &cand);
                                if d < best {
                                    (best, at) = (d, j);
                                }
                            }
                        }
                    }
                    prev = Some((here, ((at % db.cols) as isize, (at / db.cols) as isize)));
                    best
                })
                .collect::<Vec<f32>>()
        })
        .collect();
    Ok((dists, index.basis()))
}

/// Indices of the patches of `g` on a regular sub-grid of step `stride`.
fn strided(g: &PatchGrid, stride: usize) -> Vec<usize> {
    let s = stride.max(1);
    (0..g.rows)
        .step_by(s)
        .flat_map(|y| (0..g.cols).step_by(s).map(move |x| y * g.cols + x))
        .collect()
}

/// The coherence queries of the approximate search: seeded runs when
/// `sampled_queries > 0` (`Some(whole grid?)`, stride 1), else the `query_stride` grid.
fn coherence_queries(
    out: &PatchGrid,
    a: &ApproximateSearchOptions,
) -> (Vec<usize>, Option<bool>, usize) {
    if a.sampled_queries == 0 {
        return (strided(out, a.query_stride), None, a.query_stride);
    }
    let runs = a.sampled_queries.div_ceil(RUN_LENGTH);
    let qs = sampled_runs(out.cols, out.rows, runs, a.seed, "coherence-queries");
    let whole = qs.len() == out.count();
    (qs, Some(whole), 1)
}

/// The completeness queries (exemplar patches): seeded runs when `sampled_queries > 0`,
/// else all.
fn completeness_queries(
    ex: &PatchGrid,
    a: &ApproximateSearchOptions,
) -> (Vec<usize>, Option<bool>) {
    if a.sampled_queries == 0 {
        return ((0..ex.count()).collect(), None);
    }
    let runs = a.sampled_queries.div_ceil(RUN_LENGTH);
    let qs = sampled_runs(ex.cols, ex.rows, runs, a.seed, "completeness-queries");
    let whole = qs.len() == ex.count();
    (qs, Some(whole))
}

/// Summary of per-query nearest-patch distances, normalised per pixel and channel.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PatchDistanceReport {
    /// Mean over query patches of `min SSD / (N·N·C)`: a mean squared error per value
    /// (sRGB units²), comparable across image and patch sizes.
    pub mean: f64,
    /// `sqrt(mean)`, in sRGB units.
    pub rms: f64,
    /// 95th percentile of the per-query normalised distances.
    pub p95: f64,
    /// Largest per-query normalised distance.
    pub max: f64,
    /// Query patches (one per valid position).
    pub queries: usize,
    /// Database patches searched.
    pub candidates: usize,
    pub patch_size: usize,
    /// Patch pairs compared (`queries · candidates` for the exact scan; at most
    /// `queries · (max_checks + rerank)` for the approximate search).
    pub pairs_compared: u64,
    /// `"exact"` or `"approximate"` (an upper bound of the exact values; see
    /// `docs/first-hour.md` for the measured gap).
    pub search: String,
    /// Step of the query sub-grid (1 = every patch).
    pub query_stride: usize,
    /// For the approximate search: the stated bound of its error, in per cent above
    /// the exact mean (measured on the test exemplars, `docs/perf/orient.md`); absent
    /// for the exact search.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_bound_percent: Option<f64>,
    /// For a mean estimated on a seeded sample of query patches
    /// ([`crate::query_sampling`]): the standard error of `mean` against the mean over
    /// every query patch (the estimate is within ±1.96 of it with about 95 %
    /// probability); absent when every query (or the stride grid) was searched. `p95`
    /// and `max` are then those of the sample.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub standard_error: Option<f64>,
}

pub(crate) fn summarize(
    dists: &[f32],
    dim: usize,
    candidates: usize,
    n: usize,
) -> PatchDistanceReport {
    let norm = 1.0 / dim as f64;
    let mut v: Vec<f64> = dists.iter().map(|&d| d.max(0.0) as f64 * norm).collect();
    let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
    v.sort_by(|a, b| a.total_cmp(b));
    let p95 = v
        .get(((v.len() as f64 * 0.95) as usize).min(v.len().saturating_sub(1)))
        .copied()
        .unwrap_or(f64::NAN);
    PatchDistanceReport {
        mean,
        rms: mean.sqrt(),
        p95,
        max: v.last().copied().unwrap_or(f64::NAN),
        queries: dists.len(),
        candidates,
        patch_size: n,
        pairs_compared: dists.len() as u64 * candidates as u64,
        search: "exact".into(),
        query_stride: 1,
        error_bound_percent: None,
        standard_error: None,
    }
}

/// The report of an approximate search; `sampled` is `Some(whole_grid)` when the queries
/// came from [`sampled_runs`] (adds the standard error, 0 when the sample was the whole
/// grid), `None` for a strided grid of queries.
fn approximate_sampled_report(
    dists: &[f32],
    dim: usize,
    candidates: usize,
    n: usize,
    stride: usize,
    options: &ApproximateSearchOptions,
    sampled: Option<bool>,
) -> PatchDistanceReport {
    let mut r = summarize(dists, dim, candidates, n);
    if let Some(whole_grid) = sampled {
        let norm = 1.0 / dim as f64;
        let v: Vec<f64> = dists.iter().map(|&d| d.max(0.0) as f64 * norm).collect();
        r.standard_error = Some(run_standard_error(&v, whole_grid));
    }
    r.search = "approximate".into();
    r.query_stride = stride;
    r.error_bound_percent = Some(ERROR_BOUND_PERCENT);
    r.pairs_compared =
        dists.len() as u64 * candidates.min(options.max_checks + options.rerank) as u64;
    r
}

/// The two patch grids of a comparison, checked.
fn grids(
    output: &ImageView,
    exemplar: &ImageView,
    options: &PatchDistanceOptions,
    what: &'static str,
) -> Result<(PatchGrid, PatchGrid), EvalError> {
    options.validate()?;
    if output.channels != exemplar.channels {
        return Err(EvalError::ChannelMismatch { what, a: output.channels, b: exemplar.channels });
    }
    let out = PatchGrid::new(output, options.patch_size, false, "output")?;
    let ex = PatchGrid::new(exemplar, options.patch_size, options.wrap_exemplar, "exemplar")?;
    let pairs = out.count() as u64 * ex.count() as u64;
    if options.approximate.is_none() && pairs > options.max_pairs {
        return Err(EvalError::TooLarge { what, pairs, limit: options.max_pairs });
    }
    Ok((out, ex))
}

/// Coherence and completeness from one scan (half the cost of calling
/// [`coherence`](crate::coherence()) and [`completeness`](crate::completeness())).
pub fn coherence_and_completeness(
    output: &ImageView,
    exemplar: &ImageView,
    options: &PatchDistanceOptions,
) -> Result<(PatchDistanceReport, PatchDistanceReport), EvalError> {
    let (out, ex) = grids(output, exemplar, options, "coherence/completeness")?;
    let n = options.patch_size;
    if let Some(a) = &options.approximate {
        let (qs, c_sampled, c_stride) = coherence_queries(&out, a);
        // One PCA basis (fitted on the exemplar's patches) for both directions.
        let (to_ex, basis) = approximate_ssd(&out, &qs, &ex, a, None)?;
        let (ps, p_sampled) = completeness_queries(&ex, a);
        let (to_out, _) = approximate_ssd(&ex, &ps, &out, a, Some(&basis))?;
        return Ok((
            approximate_sampled_report(&to_ex, out.dim(), ex.count(), n, c_stride, a, c_sampled),
            approximate_sampled_report(&to_out, ex.dim(), out.count(), n, 1, a, p_sampled),
        ));
    }
    let (to_ex, to_out) = nearest_patch_ssd(&out, &ex, true, true);
    Ok((summarize(&to_ex, out.dim(), ex.count(), n), summarize(&to_out, ex.dim(), out.count(), n)))
}

/// Output → exemplar distances only (coherence).
pub(crate) fn coherence_distances(
    output: &ImageView,
    exemplar: &ImageView,
    options: &PatchDistanceOptions,
    map: bool,
) -> Result<(PatchDistanceReport, Vec<f32>, usize, usize), EvalError> {
    let (out, ex) = grids(output, exemplar, options, "coherence")?;
    if let Some(a) = &options.approximate {
        // A map needs the strided grid of queries; a mean takes the seeded sample.
        let (qs, sampled, stride) = if map {
            (strided(&out, a.query_stride), None, a.query_stride)
        } else {
            coherence_queries(&out, a)
        };
        let (to_ex, _) = approximate_ssd(&out, &qs, &ex, a, None)?;
        let report = approximate_sampled_report(
            &to_ex,
            out.dim(),
            ex.count(),
            options.patch_size,
            stride,
            a,
            sampled,
        );
        let (cols, rows) = if map {
            (out.cols.div_ceil(stride.max(1)), out.rows.div_ceil(stride.max(1)))
        } else {
            (0, 0)
        };
        return Ok((report, to_ex, cols, rows));
    }
    let (to_ex, _) = nearest_patch_ssd(&out, &ex, true, false);
    let report = summarize(&to_ex, out.dim(), ex.count(), options.patch_size);
    Ok((report, to_ex, out.cols, out.rows))
}

/// Exemplar → output distances only (completeness).
pub(crate) fn completeness_distances(
    output: &ImageView,
    exemplar: &ImageView,
    options: &PatchDistanceOptions,
) -> Result<PatchDistanceReport, EvalError> {
    let (out, ex) = grids(output, exemplar, options, "completeness")?;
    if let Some(a) = &options.approximate {
        let (ps, sampled) = completeness_queries(&ex, a);
        let (to_out, _) = approximate_ssd(&ex, &ps, &out, a, None)?;
        return Ok(approximate_sampled_report(
            &to_out,
            ex.dim(),
            out.count(),
            options.patch_size,
            1,
            a,
            sampled,
        ));
    }
    let (_, to_out) = nearest_patch_ssd(&out, &ex, false, true);
    Ok(summarize(&to_out, ex.dim(), out.count(), options.patch_size))
}

/// Per-patch normalised nearest-exemplar distance of every output patch (a heat map
/// for coherence): `(map, map_width, map_height)` where entry `(x, y)` belongs to the
/// patch whose top-left pixel is `(x, y)`, i.e. centred at `(x + N/2, y + N/2)`.
pub fn coherence_map(
    output: &ImageView,
    exemplar: &ImageView,
    options: &PatchDistanceOptions,
) -> Result<(Vec<f32>, usize, usize), EvalError> {
    let (_, d, w, h) = coherence_distances(output, exemplar, options, true)?;
    let norm = 1.0 / (options.patch_size * options.patch_size * output.channels) as f32;
    Ok((d.iter().map(|v| v.max(0.0) * norm).collect(), w, h))
}
