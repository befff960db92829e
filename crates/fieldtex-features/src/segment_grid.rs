//! Polylines as boxes of their (split) segments in the workspace's one spatial grid
//! (`fieldtex_mesh::SpatialGrid`), for "what lies near this point" queries in the
//! curve-matching code (coverage metric), so none of them is `O(n²)`. Long segments are
//! split first ([`split_segment`]) so that few boxes span many cells.

use fieldtex_core::vec3::{self, V3};
use fieldtex_mesh::SpatialGrid;

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
    grid: SpatialGrid,
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
        Self { grid: SpatialGrid::from_boxes(&boxes, cell), segments }
    }

    /// Distance from `p` to the nearest segment if it is at most `r`.
    pub(crate) fn nearest_within(&self, p: V3, r: f64) -> Option<f64> {
        let lo = vec3::sub(p, [r; 3]);
        let hi = vec3::add(p, [r; 3]);
        let mut best: Option<f64> = None;
        self.grid.for_each_in_box(lo, hi, |i| {
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
        // Queries outside the grid's box stay correct.
        assert!(g.nearest_within([-50.0, 0.0, 0.0], 0.5).is_none());
        assert!((g.nearest_within([10.3, 0.0, 0.0], 0.5).unwrap() - 0.3).abs() < 1e-12);
    }

    #[test]
    fn empty_grid_answers_none() {
        let g = SegmentGrid::new(std::iter::empty(), 1.0);
        assert!(g.nearest_within([0.0; 3], 10.0).is_none());
    }
}
