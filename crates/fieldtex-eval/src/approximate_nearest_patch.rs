//! Approximate nearest-patch search: PCA projection + a kd-tree searched best-bin-first
//! with a bounded budget, then an exact re-ranking of the best few in full dimension.
//!
//! Used by the metrics' default (fast) mode; the exact displacement scan of
//! [`crate::nearest_patch`] stays available (`exact`). Method:
//! 1. **PCA** (`fieldtex_linalg::Pca`) of the database patch vectors (`N·N·C` values,
//!    row, column, channel order) fitted on at most [`PCA_SAMPLES`] of them taken on a
//!    regular index stride, keeping [`ApproximateSearchOptions::pca_dims`] components.
//!    Patch appearance concentrates in few components (Lefebvre & Hoppe 2006 use 8 for
//!    synthesis), so near neighbours in the projection are near in full dimension.
//!    The basis can be shared between the two images of a comparison
//!    ([`PatchIndex::build_with_basis`]: the metrics fit it once, on the exemplar), and
//!    a source may project all its patches in bulk ([`PatchSource::project_all`]: the
//!    patch grid does it row by row, vectorised). 4 096 samples give the same measured
//!    error as the earlier 20 000 at a fifth of the fitting cost (`docs/perf/orient.md`).
//! 2. **kd-tree** over the projected database (split at the median of the widest
//!    coordinate, leaves of at most [`LEAF_SIZE`] points; ties broken by index, so the
//!    tree is the same for any thread count).
//! 3. **Best-bin-first search** (Beis & Lowe 1997): nodes are visited in the order of a
//!    lower bound on their projected distance; the search stops when the bound exceeds
//!    the `rerank`-th best found or after [`ApproximateSearchOptions::max_checks`]
//!    points. The cost per query is bounded whatever the data (the earlier exact
//!    PCA + kd-tree search was data-dependent: minutes on noise).
//! 4. **Re-ranking**: the `rerank` best candidates in the projection get their exact
//!    full-dimensional SSD; the smallest is the answer.
//!
//! The answer is the true distance to *some* database patch, so it is never below the
//! exact nearest distance: the approximate metrics are upper bounds. The measured gap
//! on the test exemplars is in `docs/first-hour.md` and pinned by a test
//! (`tests/approximate_metrics.rs`).

use fieldtex_linalg::Pca;
use rayon::prelude::*;
use serde::Serialize;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Most database patches used to fit the PCA basis (a regular index stride over all).
pub const PCA_SAMPLES: usize = 4_096;
/// Largest kd-tree leaf.
pub const LEAF_SIZE: usize = 12;
/// The stated bound of the approximate metrics: their means are at most this many
/// per cent above the exact ones on the test exemplars (`tests/approximate_metrics.rs`
/// fails above it; measured values in `docs/perf/orient.md`). Reported in
/// `PatchDistanceReport::error_bound_percent`.
pub const ERROR_BOUND_PERCENT: f64 = 5.0;

/// Options of the approximate search.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ApproximateSearchOptions {
    /// PCA components kept. Default 12.
    pub pca_dims: usize,
    /// Candidates re-ranked in full dimension. Default 12.
    pub rerank: usize,
    /// Most database points examined per query. Default 256 (the metrics add a
    /// coherent candidate per query, see `nearest_patch_metrics`).
    pub max_checks: usize,
    /// Query patches are taken every `query_stride` positions along x and y (the
    /// mean over a regular sub-grid estimates the mean over all). Applies to the
    /// direction whose queries are the larger image. Default 3 (4 aliases with the
    /// 16-pixel blocks of the test patchworks: −12 to −18 %, `docs/perf/orient.md`).
    /// Used by the coherence map, and by coherence when `sampled_queries` is 0.
    pub query_stride: usize,
    /// Coherence and completeness estimate their means from at most this many query
    /// patches per direction, drawn as seeded runs ([`crate::query_sampling`]), and
    /// report the standard error of the estimate; 0: every query (completeness) or the
    /// `query_stride` grid (coherence). Default 8 192.
    pub sampled_queries: usize,
    /// Seed of the query sample. Default 1.
    pub seed: u64,
}

impl Default for ApproximateSearchOptions {
    fn default() -> Self {
        Self {
            pca_dims: 12,
            rerank: 12,
            max_checks: 256,
            query_stride: 3,
            sampled_queries: 8_192,
            seed: 1,
        }
    }
}

/// A PCA basis of patch vectors (mean, `k × dim` row-major components, and
/// `component · mean`), shareable between indices of the same patch size so that the
/// patches of both images are fitted once (`PatchIndex::build_with_basis`).
#[derive(Debug, Clone)]
pub(crate) struct PatchBasis {
    mean: Vec<f32>,
    basis: Vec<f32>,
    offset: Vec<f32>,
    k: usize,
}

impl PatchBasis {
    /// Fits the basis on at most [`PCA_SAMPLES`] patches of `source` (a regular index
    /// stride), keeping `pca_dims` components.
    pub fn fit<S: PatchSource>(source: &S, pca_dims: usize) -> Result<Self, String> {
        let (n, dim) = (source.len(), source.dim());
        if n == 0 || dim == 0 {
            return Err("empty patch database".into());
        }
        let k = pca_dims.clamp(1, dim);
        let step = n.div_ceil(PCA_SAMPLES).max(1);
        let picked: Vec<usize> = (0..n).step_by(step).collect();
        let mut samples = vec![0f32; picked.len() * dim];
        samples.par_chunks_mut(dim).zip(&picked).for_each(|(row, &i)| source.fill(i, row));
        let pca = Pca::fit(&samples, dim, k).map_err(|e| e.to_string())?;
        let mean: Vec<f32> = pca.mean.iter().map(|&v| v as f32).collect();
        let basis: Vec<f32> = pca.components.iter().flatten().map(|&v| v as f32).collect();
        let k = basis.len() / dim;
        if k == 0 {
            return Err("no principal component".into());
        }
        let offset: Vec<f32> = basis.chunks_exact(dim).map(|b| dot(b, &mean)).collect();
        Ok(Self { mean, basis, offset, k })
    }
}

/// A source of fixed-length patch vectors, addressed `0..len()`.
pub(crate) trait PatchSource: Sync {
    fn len(&self) -> usize;
    fn dim(&self) -> usize;
    /// Writes patch `i` into `out` (`dim()` values).
    fn fill(&self, i: usize, out: &mut [f32]);
    /// `Some(len() × k values)`: every patch projected on the `k` rows of `basis`
    /// (`k × dim()`) minus `offset`, where the source has a faster way than `fill` and
    /// one dot product per component (the result may differ from that in rounding).
    fn project_all(&self, _basis: &[f32], _offset: &[f32], _k: usize) -> Option<Vec<f32>> {
        None
    }
}

/// Dense row-major patch vectors.
pub(crate) struct DensePatches<'a> {
    pub data: &'a [f32],
    pub dim: usize,
}

impl PatchSource for DensePatches<'_> {
    fn len(&self) -> usize {
        self.data.len() / self.dim
    }
    fn dim(&self) -> usize {
        self.dim
    }
    fn fill(&self, i: usize, out: &mut [f32]) {
        out.copy_from_slice(&self.data[i * self.dim..(i + 1) * self.dim]);
    }
}

#[derive(Debug, Clone)]
enum Node {
    Leaf { start: u32, end: u32 },
    Split { dim: u16, value: f32, left: u32, right: u32 },
}

/// A searchable database of patches (module docs).
pub(crate) struct PatchIndex<'a, S: PatchSource> {
    source: &'a S,
    mean: Vec<f32>,
    /// `k × dim`, row-major.
    basis: Vec<f32>,
    /// `basis_c · mean` per component.
    offset: Vec<f32>,
    k: usize,
    /// Projected database, `len × k`, in tree order.
    points: Vec<f32>,
    /// Database index of each point in tree order.
    order: Vec<u32>,
    nodes: Vec<Node>,
    options: ApproximateSearchOptions,
}

impl<'a, S: PatchSource> PatchIndex<'a, S> {
    /// Fits the PCA and builds the tree over every patch of `source` (`len() ≥ 1`).
    pub fn build(source: &'a S, options: &ApproximateSearchOptions) -> Result<Self, String> {
        let basis = PatchBasis::fit(source, options.pca_dims)?;
        Self::build_with_basis(source, options, &basis)
    }

    /// The basis this index projects with.
    pub fn basis(&self) -> PatchBasis {
        PatchBasis {
            mean: self.mean.clone(),
            basis: self.basis.clone(),
            offset: self.offset.clone(),
            k: self.k,
        }
    }

    /// Builds the tree over every patch of `source` projected on a given `basis` (of
    /// patches of the same dimension).
    pub fn build_with_basis(
        source: &'a S,
        options: &ApproximateSearchOptions,
        basis: &PatchBasis,
    ) -> Result<Self, String> {
        let (n, dim) = (source.len(), source.dim());
        if n == 0 || dim == 0 || basis.mean.len() != dim {
            return Err("empty patch database or basis of another patch size".into());
        }
        let PatchBasis { mean, basis, offset, k } = basis.clone();
        let mut index = Self {
            source,
            mean,
            basis,
            offset,
            k,
            points: Vec::new(),
            order: Vec::new(),
            nodes: Vec::new(),
            options: options.clone(),
        };
        // Project every patch (per-item slots: thread-count independent), through the
        // source's own bulk projection where it has one.
        let proj = source.project_all(&index.basis, &index.offset, k).unwrap_or_else(|| {
            let mut proj = vec![0f32; n * k];
            proj.par_chunks_mut(k * 256).enumerate().for_each(|(chunk, out)| {
                let mut buf = vec![0f32; dim];
                for (r, o) in out.chunks_mut(k).enumerate() {
                    source.fill(chunk * 256 + r, &mut buf);
                    index.project(&buf, o);
                }
            });
            proj
        });
        let mut order: Vec<u32> = (0..n as u32).collect();
        index.nodes = build_subtree(&proj, k, &mut order, 0);
        index.points = order
            .iter()
            .flat_map(|&i| proj[i as usize * k..(i as usize + 1) * k].iter().copied())
            .collect();
        index.order = order;
        Ok(index)
    }

    /// `out[c] = basis_c · patch − basis_c · mean`.
    fn project(&self, patch: &[f32], out: &mut [f32]) {
        let dim = self.mean.len();
        for (c, o) in out.iter_mut().enumerate() {
            *o = dot(&self.basis[c * dim..(c + 1) * dim], patch) - self.offset[c];
        }
    }

    /// The approximate nearest squared distance (full dimension) of `query` (`dim`
    /// values) and its database index; `scratch` is reused between queries.
    pub fn nearest(&self, query: &[f32], scratch: &mut SearchScratch) -> (f32, usize) {
        let k = self.k;
        let mut q = [0f32; 64];
        let q = &mut q[..k.min(64)];
        self.project(query, q);
        let m = self.options.rerank.max(1);
        // Max-heap of the m best (projected distance, point) so far.
        let SearchScratch { best, queue, cands, patch } = scratch;
        best.clear();
        queue.clear();
        cands.clear();
        patch.resize(query.len(), 0.0);
        queue.push(std::cmp::Reverse((OrdF32(0.0), 0)));
        let mut checks = 0usize;
        while let Some(std::cmp::Reverse((OrdF32(bound), node))) = queue.pop() {
            if best.len() == m && bound >= best.peek().map_or(f32::INFINITY, |b| b.0.0) {
                break;
            }
            if checks >= self.options.max_checks && best.len() == m {
                break;
            }
            // Descend to a leaf, queueing the far sides.
            let mut node = node as usize;
            loop {
                match self.nodes[node] {
                    Node::Split { dim, value, left, right } => {
                        let diff = q[dim as usize] - value;
                        let (near, far) = if diff < 0.0 { (left, right) } else { (right, left) };
                        let far_bound = bound.max(diff * diff);
                        let worst = best.peek().map_or(f32::INFINITY, |b| b.0.0);
                        if best.len() < m || far_bound < worst {
                            queue.push(std::cmp::Reverse((OrdF32(far_bound), far)));
                        }
                        node = near as usize;
                    }
                    Node::Leaf { start, end } => {
                        // The current m-th best, refreshed only when the heap changes.
                        let mut worst = if best.len() < m {
                            f32::INFINITY
                        } else {
                            best.peek().map_or(f32::INFINITY, |b| b.0.0)
                        };
                        for p in start as usize..end as usize {
                            let d = if k == 12 {
                                // The default size, unrolled (same summation order).
                                let pt: &[f32; 12] =
                                    self.points[p * 12..p * 12 + 12].try_into().unwrap();
                                let mut d = 0f32;
                                for j in 0..12 {
                                    d += (pt[j] - q[j]) * (pt[j] - q[j]);
                                }
                                d
                            } else {
                                let pt = &self.points[p * k..(p + 1) * k];
                                pt.iter().zip(q.iter()).map(|(a, b)| (a - b) * (a - b)).sum()
                            };
                            if best.len() < m {
                                best.push((OrdF32(d), p as u32));
                                if best.len() == m {
                                    worst = best.peek().map_or(f32::INFINITY, |b| b.0.0);
                                }
                            } else if d < worst {
                                best.pop();
                                best.push((OrdF32(d), p as u32));
                                worst = best.peek().map_or(f32::INFINITY, |b| b.0.0);
                            }
                        }
                        checks += (end - start) as usize;
                        break;
                    }
                }
            }
        }
        // Exact re-ranking, in a fixed order (by database index) for determinism.
        cands.extend(best.drain().map(|(_, p)| self.order[p as usize] as usize));
        cands.sort_unstable();
        let mut out = (f32::INFINITY, 0usize);
        for &i in cands.iter() {
            self.source.fill(i, patch);
            let d: f32 = query.iter().zip(patch.iter()).map(|(a, b)| (a - b) * (a - b)).sum();
            if d < out.0 {
                out = (d, i);
            }
        }
        out
    }
}

/// The nodes of the subtree over `order` (whose first entry is entry `base` of the whole
/// order), in preorder with indices relative to its root: a split at the median of the
/// widest coordinate (judged on at most 64 evenly spaced points), ties by index. Large
/// halves are built in parallel; the node array is the same as a serial preorder
/// build's, whatever the thread count.
fn build_subtree(proj: &[f32], k: usize, order: &mut [u32], base: usize) -> Vec<Node> {
    let len = order.len();
    if len <= LEAF_SIZE {
        return vec![Node::Leaf { start: base as u32, end: (base + len) as u32 }];
    }
    let mut best = (0usize, -1f32);
    let step = len.div_ceil(64).max(1);
    for d in 0..k {
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for &i in order.iter().step_by(step) {
            let v = proj[i as usize * k + d];
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if hi - lo > best.1 {
            best = (d, hi - lo);
        }
    }
    let d = best.0;
    let mid = len / 2;
    let key = |i: &u32| (proj[*i as usize * k + d], *i);
    order.select_nth_unstable_by(mid, |a, b| {
        let (va, ia) = key(a);
        let (vb, ib) = key(b);
        va.total_cmp(&vb).then(ia.cmp(&ib))
    });
    let value = proj[order[mid] as usize * k + d];
    let (lo, hi) = order.split_at_mut(mid);
    let (left, right) = if len > 8192 {
        rayon::join(|| build_subtree(proj, k, lo, base), || build_subtree(proj, k, hi, base + mid))
    } else {
        (build_subtree(proj, k, lo, base), build_subtree(proj, k, hi, base + mid))
    };
    let shift = |node: Node, by: u32| match node {
        Node::Split { dim, value, left, right } => {
            Node::Split { dim, value, left: left + by, right: right + by }
        }
        leaf => leaf,
    };
    let right_root = 1 + left.len() as u32;
    let mut nodes = Vec::with_capacity(1 + left.len() + right.len());
    nodes.push(Node::Split { dim: d as u16, value, left: 1, right: right_root });
    nodes.extend(left.into_iter().map(|n| shift(n, 1)));
    nodes.extend(right.into_iter().map(|n| shift(n, right_root)));
    nodes
}

/// Dot product with eight partial sums (vectorisable), summed in a fixed order.
#[inline]
fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [0f32; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for i in 0..8 {
            acc[i] += x[i] * y[i];
        }
    }
    let mut s = ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}

/// Buffers of [`PatchIndex::nearest`], reused across the queries of one worker.
#[derive(Default)]
pub(crate) struct SearchScratch {
    best: BinaryHeap<(OrdF32, u32)>,
    queue: BinaryHeap<std::cmp::Reverse<(OrdF32, u32)>>,
    cands: Vec<usize>,
    patch: Vec<f32>,
}

/// `f32` with a total order (for the heaps).
#[derive(Debug, Clone, Copy, PartialEq)]
struct OrdF32(f32);

impl Eq for OrdF32 {}

impl PartialOrd for OrdF32 {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for OrdF32 {
    fn cmp(&self, other: &Self) -> Ordering {
        self.0.total_cmp(&other.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_exact_copies_and_never_beats_the_exact_minimum() {
        let dim = 12;
        let n = 3000;
        let data: Vec<f32> = (0..n * dim)
            .map(|i| fieldtex_core::rng::hash_unit(5, "ann-test", i as u64) as f32)
            .collect();
        let src = DensePatches { data: &data, dim };
        let idx = PatchIndex::build(&src, &ApproximateSearchOptions::default()).unwrap();
        let mut scratch = SearchScratch::default();
        for i in (0..n).step_by(97) {
            let q = &data[i * dim..(i + 1) * dim];
            let (d, _) = idx.nearest(q, &mut scratch);
            assert_eq!(d, 0.0, "copy of {i} found");
        }
        for t in 0..20u64 {
            let q: Vec<f32> = (0..dim)
                .map(|j| fieldtex_core::rng::hash_unit(9, "ann-q", t * 100 + j as u64) as f32)
                .collect();
            let exact = (0..n)
                .map(|i| {
                    data[i * dim..(i + 1) * dim]
                        .iter()
                        .zip(&q)
                        .map(|(a, b)| (a - b) * (a - b))
                        .sum::<f32>()
                })
                .fold(f32::INFINITY, f32::min);
            let (d, arg) = idx.nearest(&q, &mut scratch);
            assert!(d >= exact - 1e-6, "{d} < exact {exact}");
            let direct: f32 = data[arg * dim..(arg + 1) * dim]
                .iter()
                .zip(&q)
                .map(|(a, b)| (a - b) * (a - b))
                .sum();
            assert!((direct - d).abs() < 1e-5);
        }
    }
}
