//! A uniform spatial grid over axis-aligned boxes, for "what lies near this point"
//! queries in the curve-matching code (coverage metric, endpoint joining), so none of them is `O(n²)`.
//!
//! Layout: every item is entered in each cell its box overlaps, as a `(cell key, item)`
//! pair; the pairs are sorted by key, so a cell is one binary search away and the grid
//! is deterministic (no hashing). The number of cells per axis is capped at `2^20`; a
//! cell size that would exceed it is enlarged. An item spanning more than
//! `MAX_ITEM_CELLS` cells is kept in a short list visited by every query instead, so a
//! few huge triangles among tiny ones cannot blow up memory; callers split long
//! segments first (see [`split_segment`]) so that this stays rare.

use fieldtex_core::vec3::{self, V3};

const MAX_CELLS_PER_AXIS: f64 = (1u64 << 20) as f64;
const MAX_ITEM_CELLS: u64 = 512;

/// A sorted-key uniform grid of item boxes.
#[derive(Debug, Clone)]
pub(crate) struct BoxGrid {
    origin: V3,
    cell: f64,
    dims: [u64; 3],
    entries: Vec<(u64, u32)>,
    /// Items too large for the cells, checked by every query.
    large: Vec<u32>,
}

impl BoxGrid {
    /// A grid with cells of edge `cell` (> 0) holding the boxes `(min, max)`; item ids
    /// are the boxes' indices. Non-finite boxes are skipped.
    pub(crate) fn new(boxes: &[(V3, V3)], cell: f64) -> Self {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for (a, b) in boxes.iter().filter(|(a, b)| vec3::is_finite(*a) && vec3::is_finite(*b)) {
            for k in 0..3 {
                lo[k] = lo[k].min(a[k]);
                hi[k] = hi[k].max(b[k]);
            }
        }
        if lo[0] > hi[0] {
            return Self {
                origin: [0.0; 3],
                cell: 1.0,
                dims: [1; 3],
                entries: Vec::new(),
                large: Vec::new(),
            };
        }
        let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
        let mut cell = if cell > 0.0 && cell.is_finite() { cell } else { extent.max(1.0) };
        if extent / cell > MAX_CELLS_PER_AXIS - 2.0 {
            cell = extent / (MAX_CELLS_PER_AXIS - 2.0);
        }
        let dims = [0, 1, 2].map(|k| ((hi[k] - lo[k]) / cell).floor() as u64 + 1);
        let mut grid = Self { origin: lo, cell, dims, entries: Vec::new(), large: Vec::new() };
        let mut entries = Vec::with_capacity(boxes.len());
        for (i, (a, b)) in boxes.iter().enumerate() {
            if !(vec3::is_finite(*a) && vec3::is_finite(*b)) {
                continue;
            }
            let (c0, c1) = (grid.cell_of(*a), grid.cell_of(*b));
            let span: u64 = (0..3).map(|k| c1[k] - c0[k] + 1).product();
            if span > MAX_ITEM_CELLS {
                grid.large.push(i as u32);
                continue;
            }
            for x in c0[0]..=c1[0] {
                for y in c0[1]..=c1[1] {
                    for z in c0[2]..=c1[2] {
                        entries.push((grid.key([x, y, z]), i as u32));
                    }
                }
            }
        }
        entries.sort_unstable();
        grid.entries = entries;
        grid
    }

    #[inline]
    fn cell_of(&self, p: V3) -> [u64; 3] {
        [0, 1, 2].map(|k| {
            let c = ((p[k] - self.origin[k]) / self.cell).floor();
            if c.is_nan() || c < 0.0 { 0 } else { (c as u64).min(self.dims[k] - 1) }
        })
    }

    #[inline]
    fn key(&self, c: [u64; 3]) -> u64 {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    /// Calls `f` with every item whose cells overlap the box `(lo, hi)`; an item may be
    /// reported more than once (once per shared cell).
    pub(crate) fn for_each_candidate(&self, lo: V3, hi: V3, mut f: impl FnMut(u32)) {
        self.large.iter().for_each(|&i| f(i));
        if self.entries.is_empty() {
            return;
        }
        let (c0, c1) = (self.cell_of(lo), self.cell_of(hi));
        for z in c0[2]..=c1[2] {
            for y in c0[1]..=c1[1] {
                for x in c0[0]..=c1[0] {
                    let key = self.key([x, y, z]);
                    let start = self.entries.partition_point(|e| e.0 < key);
                    for e in self.entries[start..].iter().take_while(|e| e.0 == key) {
                        f(e.1);
                    }
                }
            }
        }
    }
}

/// Distance from `p` to the segment `[a, b]` (a point when `a == b`).
#[inline]
pub(crate) fn point_segment_distance(p: V3, a: V3, b: V3) -> f64 {
    let d = vec3::sub(b, a);
    let l2 = vec3::norm2(d);
    let t = if l2 > 0.0 { (vec3::dot(vec3::sub(p, a), d) / l2).clamp(0.0, 1.0) } else { 0.0 };
    vec3::norm(vec3::sub(p, vec3::add(a, vec3::scale(d, t))))
}

/// The bounding box of a segment.
#[inline]
pub(crate) fn segment_box(a: V3, b: V3) -> (V3, V3) {
    ([0, 1, 2].map(|k| a[k].min(b[k])), [0, 1, 2].map(|k| a[k].max(b[k])))
}

/// Splits `[a, b]` into pieces no longer than `max_len` (at least one piece).
pub(crate) fn split_segment(a: V3, b: V3, max_len: f64) -> impl Iterator<Item = (V3, V3)> {
    let len = vec3::norm(vec3::sub(b, a));
    let n = if max_len > 0.0 && len.is_finite() {
        ((len / max_len).ceil() as usize).clamp(1, 1 << 16)
    } else {
        1
    };
    (0..n).map(move |i| {
        (vec3::lerp(a, b, i as f64 / n as f64), vec3::lerp(a, b, (i + 1) as f64 / n as f64))
    })
}

/// Polylines as a grid of their (split) segments, answering "is any segment within
/// `r` of this point".
pub(crate) struct SegmentGrid {
    segments: Vec<(V3, V3)>,
    grid: BoxGrid,
}

impl SegmentGrid {
    /// Segments of all polylines, split to at most `cell` long, in a grid of cell `cell`.
    pub(crate) fn new<'a>(polylines: impl IntoIterator<Item = &'a [V3]>, cell: f64) -> Self {
        let mut segments = Vec::new();
        for pl in polylines {
            if pl.len() == 1 {
                segments.push((pl[0], pl[0]));
            }
            for w in pl.windows(2) {
                segments.extend(split_segment(w[0], w[1], cell));
            }
        }
        segments.retain(|(a, b)| vec3::is_finite(*a) && vec3::is_finite(*b));
        let boxes: Vec<(V3, V3)> = segments.iter().map(|&(a, b)| segment_box(a, b)).collect();
        Self { grid: BoxGrid::new(&boxes, cell), segments }
    }

    /// Distance from `p` to the nearest segment if it is at most `r`.
    pub(crate) fn nearest_within(&self, p: V3, r: f64) -> Option<f64> {
        let lo = vec3::sub(p, [r; 3]);
        let hi = vec3::add(p, [r; 3]);
        let mut best: Option<f64> = None;
        self.grid.for_each_candidate(lo, hi, |i| {
            let (a, b) = self.segments[i as usize];
            let d = point_segment_distance(p, a, b);
            if d <= r && best.is_none_or(|x| d < x) {
                best = Some(d);
            }
        });
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_finds_near_segments_only() {
        let lines: Vec<Vec<V3>> =
            vec![vec![[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]], vec![[0.0, 5.0, 0.0], [0.0, 6.0, 0.0]]];
        let g = SegmentGrid::new(lines.iter().map(|l| l.as_slice()), 0.5);
        assert!((g.nearest_within([3.0, 0.4, 0.0], 0.5).unwrap() - 0.4).abs() < 1e-12);
        assert!(g.nearest_within([3.0, 0.6, 0.0], 0.5).is_none());
        assert!((g.nearest_within([0.0, 6.2, 0.0], 0.5).unwrap() - 0.2).abs() < 1e-12);
        assert!(g.nearest_within([0.0, 3.0, 0.0], 1.0).is_none());
        // Queries outside the grid's box clamp to border cells and stay correct.
        assert!(g.nearest_within([-50.0, 0.0, 0.0], 0.5).is_none());
        assert!((g.nearest_within([10.3, 0.0, 0.0], 0.5).unwrap() - 0.3).abs() < 1e-12);
    }

    #[test]
    fn huge_items_are_found_without_filling_cells() {
        let boxes = vec![([0.0; 3], [0.01; 3]), ([-1e3; 3], [1e3; 3]), ([5.0; 3], [5.01; 3])];
        let g = BoxGrid::new(&boxes, 0.01);
        assert!(g.entries.len() <= 16, "{} entries", g.entries.len());
        let mut found = Vec::new();
        g.for_each_candidate([4.99; 3], [5.02; 3], |i| found.push(i));
        found.sort_unstable();
        found.dedup();
        assert_eq!(found, vec![1, 2]);
    }

    #[test]
    fn empty_grid_answers_none() {
        let g = SegmentGrid::new(std::iter::empty(), 1.0);
        assert!(g.nearest_within([0.0; 3], 10.0).is_none());
    }
}
