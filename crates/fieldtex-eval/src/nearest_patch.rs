//! Exact nearest-neighbour search between all `N×N` patches of two images: the core of
//! [`coherence`](crate::coherence()) and [`completeness`](crate::completeness()).
//!
//! Distance: sum of squared differences over the `N·N·C` values of two patches. The
//! search is **exact** (the minimum over every database patch, up to `f32` rounding)
//! but avoids most of the brute-force work:
//! 1. a few leading principal directions of the database patches (`patch_pca`) give
//!    every patch `k` coordinates; since the directions are orthonormal, the squared
//!    distance of two patches' coordinates is a lower bound of their true distance;
//! 2. a kd-tree over those coordinates is searched with that bound (a subtree or a
//!    point is skipped only when its bound exceeds the best distance found so far,
//!    with a relative slack of 1e-3 against rounding);
//! 3. each query starts from the best match of its left and upper neighbours, shifted
//!    by one pixel (coherent outputs make this nearly optimal at once);
//! 4. true distances stop accumulating once they exceed the best.
//!
//! The result is the same for any thread count (each query's minimum is an exact
//! minimum of deterministically computed sums). Run time depends on the data: outputs
//! made of exemplar pieces are fast; outputs unlike the exemplar (noise) approach a
//! brute-force scan.

use crate::EvalError;
use crate::image_view::ImageView;
use crate::patch_pca::leading_directions;
use rayon::prelude::*;
use serde::Serialize;
use std::borrow::Cow;

/// Options shared by coherence and completeness.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PatchDistanceOptions {
    /// Patch side `N` in pixels (odd or even). Default 7.
    pub patch_size: usize,
    /// Treat the exemplar as tileable: its patches wrap around the edges. Default
    /// false (only patches fully inside the exemplar).
    pub wrap_exemplar: bool,
    /// Principal directions used for pruning (does not change the result). Default 12.
    pub pruning_dims: usize,
}

impl Default for PatchDistanceOptions {
    fn default() -> Self {
        Self { patch_size: 7, wrap_exemplar: false, pruning_dims: 12 }
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
    pub(crate) fn validate(&self) -> Result<(), EvalError> {
        if self.patch_size == 0 || self.patch_size > 64 {
            return Err(EvalError::InvalidOption {
                name: "patch_size",
                value: self.patch_size.to_string(),
                reason: "must be in 1..=64 pixels",
            });
        }
        if self.pruning_dims == 0 || self.pruning_dims > 64 {
            return Err(EvalError::InvalidOption {
                name: "pruning_dims",
                value: self.pruning_dims.to_string(),
                reason: "must be in 1..=64",
            });
        }
        Ok(())
    }
}

/// All `n × n` patches of an image, addressed by their top-left pixel.
pub(crate) struct PatchGrid<'a> {
    data: Cow<'a, [f32]>,
    /// Row length of `data` in pixels.
    stride: usize,
    channels: usize,
    n: usize,
    /// Patch positions along x and y.
    pub cols: usize,
    pub rows: usize,
}

impl<'a> PatchGrid<'a> {
    /// Patches of `img`; with `wrap`, every pixel anchors a patch that wraps around.
    pub fn new(
        img: &ImageView<'a>,
        n: usize,
        wrap: bool,
        what: &'static str,
    ) -> Result<Self, EvalError> {
        let (w, h, c) = (img.width, img.height, img.channels);
        if w < n || h < n || w == 0 || h == 0 {
            return Err(EvalError::TooSmall { what, width: w, height: h, min: n });
        }
        if !wrap {
            return Ok(Self {
                data: Cow::Borrowed(img.data),
                stride: w,
                channels: c,
                n,
                cols: w - n + 1,
                rows: h - n + 1,
            });
        }
        let (pw, ph) = (w + n - 1, h + n - 1);
        let mut data = Vec::with_capacity(pw * ph * c);
        for y in 0..ph {
            for x in 0..pw {
                let i = ((y % h) * w + (x % w)) * c;
                data.extend_from_slice(&img.data[i..i + c]);
            }
        }
        Ok(Self { data: Cow::Owned(data), stride: pw, channels: c, n, cols: w, rows: h })
    }

    pub fn count(&self) -> usize {
        self.cols * self.rows
    }

    /// Values of row `r` of the patch at `(x, y)`: `n · channels` floats.
    #[inline]
    fn row(&self, x: usize, y: usize, r: usize) -> &[f32] {
        let s = ((y + r) * self.stride + x) * self.channels;
        &self.data[s..s + self.n * self.channels]
    }

    /// Dimension of a patch vector.
    pub fn dim(&self) -> usize {
        self.n * self.n * self.channels
    }

    fn gather(&self, x: usize, y: usize, out: &mut Vec<f32>) {
        out.clear();
        for r in 0..self.n {
            out.extend_from_slice(self.row(x, y, r));
        }
    }
}

/// `Σ (a − b)²` with eight fixed accumulators (vectorisable, fixed order).
#[inline]
fn sq_diff_sum(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [0f32; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..8 {
            let d = x[k] - y[k];
            acc[k] += d * d;
        }
    }
    let mut s = ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]));
    for (x, y) in ra.iter().zip(rb) {
        s += (x - y) * (x - y);
    }
    s
}

#[inline]
fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [0f32; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..8 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut s = ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]));
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}

/// Squared distance of two patches, stopping early once it exceeds `limit`.
#[inline]
fn patch_ssd(
    a: &PatchGrid,
    ax: usize,
    ay: usize,
    b: &PatchGrid,
    bx: usize,
    by: usize,
    limit: f32,
) -> f32 {
    let mut acc = 0f32;
    for r in 0..a.n {
        acc += sq_diff_sum(a.row(ax, ay, r), b.row(bx, by, r));
        if acc > limit {
            return acc;
        }
    }
    acc
}

/// Principal directions (rows of `k × dim`, `f32`) of a sample of `grid`'s patches.
fn pruning_basis(grid: &PatchGrid, k: usize) -> Vec<f32> {
    let d = grid.dim();
    let total = grid.count();
    let step = (total / 4096).max(1);
    let ids: Vec<usize> = (0..total).step_by(step).collect();
    let chunks: Vec<(Vec<f64>, Vec<f64>)> = ids
        .par_chunks(256)
        .map(|chunk| {
            let mut sum = vec![0f64; d];
            let mut outer = vec![0f64; d * d];
            let mut v = Vec::with_capacity(d);
            for &id in chunk {
                grid.gather(id % grid.cols, id / grid.cols, &mut v);
                for i in 0..d {
                    let vi = v[i] as f64;
                    sum[i] += vi;
                    let row = &mut outer[i * d..(i + 1) * d];
                    for (o, &vj) in row.iter_mut().zip(&v) {
                        *o += vi * vj as f64;
                    }
                }
            }
            (sum, outer)
        })
        .collect();
    let mut sum = vec![0f64; d];
    let mut cov = vec![0f64; d * d];
    for (s, o) in &chunks {
        sum.iter_mut().zip(s).for_each(|(a, b)| *a += b);
        cov.iter_mut().zip(o).for_each(|(a, b)| *a += b);
    }
    let n = ids.len() as f64;
    for i in 0..d {
        for j in 0..d {
            cov[i * d + j] = cov[i * d + j] / n - (sum[i] / n) * (sum[j] / n);
        }
    }
    leading_directions(&cov, d, k).into_iter().flatten().map(|v| v as f32).collect()
}

/// Pruning coordinates (`count × k`) of every patch of `grid`.
fn project_all(grid: &PatchGrid, basis: &[f32], k: usize) -> Vec<f32> {
    let d = grid.dim();
    let mut out = vec![0f32; grid.count() * k];
    out.par_chunks_mut(grid.cols * k).enumerate().for_each(|(y, row)| {
        let mut v = Vec::with_capacity(d);
        for x in 0..grid.cols {
            grid.gather(x, y, &mut v);
            for j in 0..k {
                row[x * k + j] = dot(&v, &basis[j * d..(j + 1) * d]);
            }
        }
    });
    out
}

/// Kd-tree over `k`-dimensional points, leaves of at most `LEAF` points stored
/// contiguously.
struct KdTree {
    k: usize,
    points: Vec<f32>,
    ids: Vec<u32>,
    nodes: Vec<Node>,
}

enum Node {
    Leaf { start: u32, end: u32 },
    Split { dim: u32, value: f32, left: u32, right: u32 },
}

const LEAF: usize = 12;

impl KdTree {
    fn build(coords: &[f32], k: usize) -> Self {
        let n = coords.len() / k;
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::new();
        Self::build_node(coords, k, &mut order, 0, &mut nodes);
        let mut points = Vec::with_capacity(n * k);
        for &i in &order {
            points.extend_from_slice(&coords[i as usize * k..(i as usize + 1) * k]);
        }
        Self { k, points, ids: order, nodes }
    }

    fn build_node(
        coords: &[f32],
        k: usize,
        ids: &mut [u32],
        offset: usize,
        nodes: &mut Vec<Node>,
    ) -> u32 {
        let me = nodes.len() as u32;
        if ids.len() <= LEAF {
            nodes.push(Node::Leaf { start: offset as u32, end: (offset + ids.len()) as u32 });
            return me;
        }
        // Split the dimension of largest spread at its median.
        let mut best = (0usize, -1f32);
        for dim in 0..k {
            let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
            for &i in ids.iter() {
                let v = coords[i as usize * k + dim];
                lo = lo.min(v);
                hi = hi.max(v);
            }
            if hi - lo > best.1 {
                best = (dim, hi - lo);
            }
        }
        let dim = best.0;
        let mid = ids.len() / 2;
        ids.select_nth_unstable_by(mid, |&a, &b| {
            coords[a as usize * k + dim].total_cmp(&coords[b as usize * k + dim]).then(a.cmp(&b))
        });
        let value = coords[ids[mid] as usize * k + dim];
        nodes.push(Node::Leaf { start: 0, end: 0 }); // placeholder
        let (l, r) = ids.split_at_mut(mid);
        let left = Self::build_node(coords, k, l, offset, nodes);
        let right = Self::build_node(coords, k, r, offset + mid, nodes);
        nodes[me as usize] = Node::Split { dim: dim as u32, value, left, right };
        me
    }
}

/// Best match so far: squared distance and database id.
#[derive(Clone, Copy)]
struct Best {
    dist: f32,
    id: u32,
}

impl Best {
    #[inline]
    fn bound(&self) -> f32 {
        self.dist * 1.001 + 1e-6
    }
    #[inline]
    fn offer(&mut self, dist: f32, id: u32) {
        if dist < self.dist || (dist == self.dist && id < self.id) {
            *self = Best { dist, id };
        }
    }
}

struct Search<'s> {
    tree: &'s KdTree,
    q: &'s [f32],
    offsets: Vec<f32>,
    exact: &'s mut dyn FnMut(u32, f32) -> f32,
    evaluations: u64,
}

impl Search<'_> {
    fn visit(&mut self, node: u32, rd: f32, best: &mut Best) {
        match self.tree.nodes[node as usize] {
            Node::Leaf { start, end } => {
                let k = self.tree.k;
                for slot in start as usize..end as usize {
                    let p = &self.tree.points[slot * k..(slot + 1) * k];
                    let lb = sq_diff_sum(p, self.q);
                    if lb > best.bound() {
                        continue;
                    }
                    let id = self.tree.ids[slot];
                    let d = (self.exact)(id, best.dist);
                    self.evaluations += 1;
                    best.offer(d, id);
                }
            }
            Node::Split { dim, value, left, right } => {
                let dim = dim as usize;
                let diff = self.q[dim] - value;
                let (near, far) = if diff < 0.0 { (left, right) } else { (right, left) };
                self.visit(near, rd, best);
                let old = self.offsets[dim];
                let far_rd = rd - old * old + diff * diff;
                if far_rd <= best.bound() {
                    self.offsets[dim] = diff;
                    self.visit(far, far_rd, best);
                    self.offsets[dim] = old;
                }
            }
        }
    }
}

/// For every query patch (row-major over the query grid), the smallest squared
/// distance to any database patch; plus the number of full distance evaluations.
pub(crate) fn nearest_patch_ssd(query: &PatchGrid, db: &PatchGrid, k: usize) -> (Vec<f32>, u64) {
    let k = k.min(db.dim()).max(1);
    let basis = pruning_basis(db, k);
    let db_coords = project_all(db, &basis, k);
    let q_coords = project_all(query, &basis, k);
    let tree = KdTree::build(&db_coords, k);
    const CHUNK: usize = 4;
    let chunks: Vec<(Vec<f32>, u64)> = (0..query.rows.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let (y0, y1) = (c * CHUNK, ((c + 1) * CHUNK).min(query.rows));
            let mut out = Vec::with_capacity((y1 - y0) * query.cols);
            let mut evals = 0u64;
            let mut prev_row: Vec<u32> = Vec::new();
            let mut this_row: Vec<u32> = Vec::with_capacity(query.cols);
            for qy in y0..y1 {
                this_row.clear();
                for qx in 0..query.cols {
                    let mut exact = |id: u32, limit: f32| {
                        let id = id as usize;
                        patch_ssd(query, qx, qy, db, id % db.cols, id / db.cols, limit)
                    };
                    let mut best = Best { dist: f32::INFINITY, id: u32::MAX };
                    // Shifted matches of the left and upper neighbours.
                    let mut seeds = [u32::MAX; 2];
                    if let Some(&l) = this_row.last()
                        && (l as usize % db.cols) + 1 < db.cols
                    {
                        seeds[0] = l + 1;
                    }
                    if let Some(&u) = prev_row.get(qx)
                        && (u as usize / db.cols) + 1 < db.rows
                    {
                        seeds[1] = u + db.cols as u32;
                    }
                    for s in seeds.into_iter().filter(|&s| s != u32::MAX) {
                        let d = exact(s, best.dist);
                        evals += 1;
                        best.offer(d, s);
                    }
                    let q = &q_coords[(qy * query.cols + qx) * k..(qy * query.cols + qx + 1) * k];
                    let mut search = Search {
                        tree: &tree,
                        q,
                        offsets: vec![0.0; k],
                        exact: &mut exact,
                        evaluations: 0,
                    };
                    search.visit(0, 0.0, &mut best);
                    evals += search.evaluations;
                    out.push(best.dist);
                    this_row.push(best.id);
                }
                std::mem::swap(&mut prev_row, &mut this_row);
            }
            (out, evals)
        })
        .collect();
    let mut all = Vec::with_capacity(query.count());
    let mut evals = 0;
    for (v, e) in chunks {
        all.extend(v);
        evals += e;
    }
    (all, evals)
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
    /// Full patch distances computed (diagnostic of the pruning; brute force would be
    /// `queries · candidates`).
    pub distance_evaluations: u64,
}

pub(crate) fn summarize(
    dists: &[f32],
    dim: usize,
    candidates: usize,
    n: usize,
    evals: u64,
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
        distance_evaluations: evals,
    }
}

/// Per-pixel normalised nearest-exemplar distance of every output patch (a heat map
/// for `coherence`): `(map, map_width, map_height)` where entry `(x, y)` belongs to the
/// patch whose top-left pixel is `(x, y)`, i.e. centred at `(x + N/2, y + N/2)`.
pub fn coherence_map(
    output: &ImageView,
    exemplar: &ImageView,
    options: &PatchDistanceOptions,
) -> Result<(Vec<f32>, usize, usize), EvalError> {
    options.validate()?;
    if output.channels != exemplar.channels {
        return Err(EvalError::ChannelMismatch {
            what: "coherence",
            a: output.channels,
            b: exemplar.channels,
        });
    }
    let q = PatchGrid::new(output, options.patch_size, false, "coherence output")?;
    let db =
        PatchGrid::new(exemplar, options.patch_size, options.wrap_exemplar, "coherence exemplar")?;
    let (d, _) = nearest_patch_ssd(&q, &db, options.pruning_dims);
    let norm = 1.0 / q.dim() as f32;
    Ok((d.iter().map(|v| v.max(0.0) * norm).collect(), q.cols, q.rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(w: usize, h: usize, c: usize, seed: u64) -> Vec<f32> {
        (0..w * h * c)
            .map(|i| fieldtex_core::rng::hash_unit(seed, "test-noise", i as u64) as f32)
            .collect()
    }

    #[test]
    fn matches_brute_force() {
        let (w, h, c, n) = (23, 19, 3, 5);
        let a = noise(w, h, c, 1);
        // Database: smooth-ish image so the PCA is meaningful.
        let b: Vec<f32> = (0..31 * 27 * c)
            .map(|i| {
                ((i as f32 * 0.37).sin() * 0.5 + 0.5) * 0.6
                    + 0.4 * fieldtex_core::rng::hash_unit(2, "t", i as u64) as f32
            })
            .collect();
        let va = ImageView::new(&a, w, h, c).unwrap();
        let vb = ImageView::new(&b, 31, 27, c).unwrap();
        for wrap in [false, true] {
            let q = PatchGrid::new(&va, n, false, "q").unwrap();
            let db = PatchGrid::new(&vb, n, wrap, "db").unwrap();
            let (fast, evals) = nearest_patch_ssd(&q, &db, 6);
            for (i, &f) in fast.iter().enumerate() {
                let (qx, qy) = (i % q.cols, i / q.cols);
                let mut best = f32::INFINITY;
                for j in 0..db.count() {
                    best = best.min(patch_ssd(
                        &q,
                        qx,
                        qy,
                        &db,
                        j % db.cols,
                        j / db.cols,
                        f32::INFINITY,
                    ));
                }
                assert_eq!(f, best, "query {i} wrap {wrap}");
            }
            assert!(evals > 0);
        }
    }
}
