//! kd-tree over row-major `f32` points with exact and approximate (best-bin-first)
//! nearest-neighbour queries (Friedman, Bentley & Finkel 1977; best-bin-first after
//! Beis & Lowe 1997, as used by the ANN library of Arya et al. 1998 that paper B §6.2
//! names for its non-parametric synthesis).
//!
//! Construction splits at the median of the coordinate with the widest spread, down to
//! leaves of at most [`KD_LEAF`] points; ties in the median order are broken by point
//! index, so the tree is a pure function of the points (no thread count dependence).
//! A query visits nodes in increasing order of a priority: the sum of the squared
//! distances to the split planes crossed on the way to the node. That sum is a lower
//! bound only while each plane is on a different axis (Arya & Mount's incremental
//! distance replaces an axis's term instead of adding it); when one axis is split twice
//! it can overestimate, so it only orders the visits and prunes the approximate search
//! (`max_checks` points examined: the answer is a true point and its true distance, so
//! never closer than the exact nearest one). The exact search prunes with a bound that
//! always holds, the largest single-plane term crossed, and keeps popping until every
//! pending node is provably farther than the best point found. Ties between equal
//! distances keep the smaller point index.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Largest leaf.
pub const KD_LEAF: usize = 8;

#[derive(Debug, Clone)]
enum Node {
    /// `order[start..end]`.
    Leaf {
        start: u32,
        end: u32,
    },
    Split {
        axis: u32,
        value: f32,
        left: u32,
        right: u32,
    },
}

/// A kd-tree (module docs). Holds a copy of the points.
#[derive(Debug, Clone)]
pub struct KdTree {
    points: Vec<f32>,
    dim: usize,
    /// Point indices, leaves hold contiguous ranges.
    order: Vec<u32>,
    nodes: Vec<Node>,
}

/// Search state reused across queries (one per thread).
#[derive(Debug, Default)]
pub struct KdScratch {
    heap: BinaryHeap<Pending>,
    /// The single-nearest result buffer of [`KdTree::nearest`] (no allocation per query).
    best: Vec<(usize, f32)>,
}

#[derive(Debug, PartialEq)]
struct Pending {
    /// Visit priority (sum of the crossed planes' squared distances).
    bound: f32,
    /// A true lower bound on the squared distance to any point under `node`.
    lower: f32,
    node: u32,
}
impl Eq for Pending {}
impl Ord for Pending {
    fn cmp(&self, o: &Self) -> Ordering {
        // Min-heap on the bound, then on the node id (deterministic).
        o.bound.total_cmp(&self.bound).then(o.node.cmp(&self.node))
    }
}
impl PartialOrd for Pending {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl KdTree {
    /// Builds the tree over `points` (row-major `N × dim`, `dim ≥ 1`). Non-finite
    /// coordinates are allowed but never win a query.
    pub fn build(points: &[f32], dim: usize) -> Self {
        assert!(dim >= 1 && points.len().is_multiple_of(dim), "KdTree::build: N × dim points");
        let n = points.len() / dim;
        let mut t = Self {
            points: points.to_vec(),
            dim,
            order: (0..n as u32).collect(),
            nodes: Vec::with_capacity(2 * n / KD_LEAF + 2),
        };
        if n > 0 {
            t.build_node(0, n);
        }
        t
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len() / self.dim
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Point `i`.
    pub fn point(&self, i: usize) -> &[f32] {
        &self.points[i * self.dim..(i + 1) * self.dim]
    }

    fn build_node(&mut self, start: usize, end: usize) -> u32 {
        let id = self.nodes.len() as u32;
        if end - start <= KD_LEAF {
            self.nodes.push(Node::Leaf { start: start as u32, end: end as u32 });
            return id;
        }
        let d = self.dim;
        let mut best = (0usize, -1.0f32);
        for a in 0..d {
            let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
            for &i in &self.order[start..end] {
                let v = self.points[i as usize * d + a];
                if v.is_finite() {
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
            if hi - lo > best.1 {
                best = (a, hi - lo);
            }
        }
        let axis = best.0;
        let mid = (start + end) / 2;
        let pts = &self.points;
        let key = |i: &u32| (pts[*i as usize * d + axis], *i);
        self.order[start..end].select_nth_unstable_by(mid - start, |a, b| {
            let (x, y) = (key(a), key(b));
            x.0.total_cmp(&y.0).then(x.1.cmp(&y.1))
        });
        let value = self.points[self.order[mid] as usize * d + axis];
        self.nodes.push(Node::Leaf { start: 0, end: 0 }); // placeholder
        let left = self.build_node(start, mid);
        let right = self.build_node(mid, end);
        self.nodes[id as usize] = Node::Split { axis: axis as u32, value, left, right };
        id
    }

    fn dist2(&self, i: usize, q: &[f32]) -> f32 {
        let p = &self.points[i * self.dim..(i + 1) * self.dim];
        let mut s = 0.0f32;
        for (a, b) in p.iter().zip(q) {
            let t = a - b;
            s += t * t;
        }
        if s.is_nan() { f32::INFINITY } else { s }
    }

    /// The nearest point to `query` examining at most `max_checks` points
    /// (`usize::MAX`: exact), as `(index, squared distance)`; `None` on an empty tree.
    pub fn nearest(
        &self,
        query: &[f32],
        max_checks: usize,
        scratch: &mut KdScratch,
    ) -> Option<(usize, f32)> {
        let KdScratch { heap, best } = scratch;
        self.search(query, 1, max_checks, heap, best);
        best.first().copied()
    }

    /// The `k` nearest points to `query` into `out` (cleared first), nearest first, as
    /// `(index, squared distance)`, ties to the smaller index; examining at most
    /// `max_checks` points once `k` are found (`usize::MAX`: exact). With `k = 1` this is
    /// [`Self::nearest`]. Fewer than `k` only when the tree holds fewer points.
    pub fn k_nearest(
        &self,
        query: &[f32],
        k: usize,
        max_checks: usize,
        scratch: &mut KdScratch,
        out: &mut Vec<(usize, f32)>,
    ) {
        self.search(query, k, max_checks, &mut scratch.heap, out);
    }

    /// [`Self::k_nearest`] with the heap and the result buffer given separately.
    fn search(
        &self,
        query: &[f32],
        k: usize,
        max_checks: usize,
        heap: &mut BinaryHeap<Pending>,
        out: &mut Vec<(usize, f32)>,
    ) {
        assert_eq!(query.len(), self.dim, "KdTree::nearest: query of the tree's dimension");
        out.clear();
        if self.nodes.is_empty() || k == 0 {
            return;
        }
        heap.clear();
        heap.push(Pending { bound: 0.0, lower: 0.0, node: 0 });
        let exact = max_checks == usize::MAX;
        // The k-th distance so far (infinite until k are found).
        let kth =
            |out: &Vec<(usize, f32)>| if out.len() < k { f32::INFINITY } else { out[k - 1].1 };
        let mut checked = 0usize;
        while let Some(Pending { bound, lower, node }) = heap.pop() {
            let worst = kth(out);
            if exact {
                if lower > worst {
                    continue;
                }
            } else if bound > worst || (checked >= max_checks && out.len() >= k) {
                break;
            }
            // Descend to a leaf, queueing the far sides with their bounds.
            let mut id = node;
            loop {
                match self.nodes[id as usize] {
                    Node::Leaf { start, end } => {
                        for &i in &self.order[start as usize..end as usize] {
                            let d2 = self.dist2(i as usize, query);
                            let i = i as usize;
                            if out.len() < k
                                || d2 < out[k - 1].1
                                || (d2 == out[k - 1].1 && i < out[k - 1].0)
                            {
                                let at = out.partition_point(|&(j, e)| (e, j) <= (d2, i));
                                out.insert(at, (i, d2));
                                out.truncate(k);
                            }
                            checked += 1;
                        }
                        break;
                    }
                    Node::Split { axis, value, left, right } => {
                        let diff = query[axis as usize] - value;
                        let (near, far) = if diff < 0.0 { (left, right) } else { (right, left) };
                        let far_bound = bound + diff * diff;
                        let far_lower = lower.max(diff * diff);
                        if (if exact { far_lower } else { far_bound }) <= kth(out) {
                            heap.push(Pending { bound: far_bound, lower: far_lower, node: far });
                        }
                        id = near;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_core::rng::hash_unit;

    fn brute(p: &[f32], d: usize, q: &[f32]) -> (usize, f32) {
        let mut best = (0, f32::INFINITY);
        for (i, r) in p.chunks_exact(d).enumerate() {
            let s: f32 = r.iter().zip(q).map(|(a, b)| (a - b) * (a - b)).sum();
            if s < best.1 {
                best = (i, s);
            }
        }
        best
    }

    #[test]
    fn exact_k_nearest_equals_brute_force() {
        let d = 5;
        let n = 2000;
        let pts: Vec<f32> = (0..n * d).map(|i| hash_unit(5, "kdk", i as u64) as f32).collect();
        let tree = KdTree::build(&pts, d);
        let mut sc = KdScratch::default();
        let mut out = Vec::new();
        for q in 0..50 {
            let query: Vec<f32> =
                (0..d).map(|k| hash_unit(6, "kdkq", (q * d + k) as u64) as f32).collect();
            let mut all: Vec<(usize, f32)> = pts
                .chunks_exact(d)
                .enumerate()
                .map(|(i, r)| (i, r.iter().zip(&query).map(|(a, b)| (a - b) * (a - b)).sum()))
                .collect();
            all.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
            tree.k_nearest(&query, 8, usize::MAX, &mut sc, &mut out);
            let want: Vec<usize> = all[..8].iter().map(|p| p.0).collect();
            assert_eq!(out.iter().map(|p| p.0).collect::<Vec<_>>(), want);
            // Approximate: true points, sorted, never closer than the exact k-th.
            tree.k_nearest(&query, 8, 64, &mut sc, &mut out);
            assert_eq!(out.len(), 8);
            assert!(out.windows(2).all(|w| w[0].1 <= w[1].1));
            assert!(out[7].1 >= all[7].1);
        }
    }

    #[test]
    fn exact_search_equals_brute_force_and_approximate_is_an_upper_bound() {
        let d = 6;
        let n = 3000;
        let pts: Vec<f32> = (0..n * d).map(|i| hash_unit(3, "kd", i as u64) as f32).collect();
        let tree = KdTree::build(&pts, d);
        let mut sc = KdScratch::default();
        let mut hits = 0;
        for q in 0..200 {
            let query: Vec<f32> =
                (0..d).map(|k| hash_unit(4, "kdq", (q * d + k) as u64) as f32).collect();
            let (bi, bd) = brute(&pts, d, &query);
            let (ei, ed) = tree.nearest(&query, usize::MAX, &mut sc).unwrap();
            assert_eq!(ei, bi);
            assert!((ed - bd).abs() < 1e-6);
            let (ai, ad) = tree.nearest(&query, 64, &mut sc).unwrap();
            assert!(ad >= bd - 1e-6);
            let true_d: f32 =
                tree.point(ai).iter().zip(&query).map(|(a, b)| (a - b) * (a - b)).sum();
            assert!((true_d - ad).abs() < 1e-6);
            hits += usize::from(ai == bi);
        }
        // Best-bin-first with 64 checks finds the exact neighbour most of the time.
        assert!(hits > 100, "approximate hits {hits}/200");
        assert!(KdTree::build(&[], 3).nearest(&[0.0; 3], 10, &mut sc).is_none());
    }

    #[test]
    fn exact_search_holds_when_one_axis_is_split_many_times() {
        // Two dimensions with a long x range: nearly every split is on x, so the sum of
        // crossed-plane terms overestimates far-of-far nodes; the exact search must
        // still equal brute force, also for queries outside the points' box.
        let d = 2;
        let n = 400;
        let pts: Vec<f32> = (0..n)
            .flat_map(|i| {
                let x = 100.0 * hash_unit(5, "kdx", i as u64) as f32;
                let y = 40.0 * hash_unit(5, "kdy", i as u64) as f32;
                [x, y]
            })
            .collect();
        let tree = KdTree::build(&pts, d);
        let mut sc = KdScratch::default();
        for q in 0..2000u64 {
            let query = [
                300.0 * hash_unit(6, "qx", q) as f32 - 100.0,
                120.0 * hash_unit(6, "qy", q) as f32 - 40.0,
            ];
            let (bi, bd) = brute(&pts, d, &query);
            let (ei, ed) = tree.nearest(&query, usize::MAX, &mut sc).unwrap();
            assert!((ed - bd).abs() <= 1e-5 * bd.max(1.0), "query {q}: {ed} vs {bd}");
            if (ed - bd).abs() == 0.0 {
                assert_eq!(ei, bi, "query {q}");
            }
        }
    }
}
