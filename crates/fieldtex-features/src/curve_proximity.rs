//! Salient curves seen from the surface: points on the surface along the curves, and
//! the distance from surface points to the curves within a band (paper A §5.2's
//! constrained samples and feature-coverage metric).
//!
//! [`distance_to_curves`] measures the 3-D distance to the curves, resampled every
//! `step`, through the one spatial grid (`fieldtex_mesh::SpatialGrid`); it is within
//! `step / 2` of the distance to the polylines. Paper A uses the geodesic distance: in a
//! band a few times the feature size wide the two agree up to `O(κ d²)`, and unlike the
//! heat method (whose distances are smoothed over a few edges near the source) the 3-D
//! distance is exact at the curve, where the constraint matters most.

use fieldtex_core::vec3::{V3, lerp, norm, sub};
use fieldtex_mesh::{Bvh, SpatialGrid};
use rayon::prelude::*;

/// Surface points `(triangle, barycentric)` along `curves` (the closest surface point of
/// segment samples about `spacing` apart), each with the curve length it stands for
/// (for length-weighted measures).
pub fn curve_surface_points(
    bvh: &Bvh,
    curves: &[Vec<V3>],
    spacing: f64,
) -> Vec<((u32, [f64; 3]), f64)> {
    let mut pts = Vec::new();
    for_each_segment(curves, spacing, 10_000, |a, b, len, n| {
        for k in 0..n {
            let t = (k as f64 + 0.5) / n as f64;
            if let Some(cp) = bvh.closest_point(lerp(a, b, t)) {
                pts.push(((cp.triangle, cp.barycentric), len / n as f64));
            }
        }
    });
    pts
}

/// Calls `f(a, b, length, pieces)` for every segment of finite length of `curves`, with
/// the number of pieces of at most `step` it splits into (`1..=max_pieces`).
fn for_each_segment(
    curves: &[Vec<V3>],
    step: f64,
    max_pieces: usize,
    mut f: impl FnMut(V3, V3, f64, usize),
) {
    for c in curves {
        for s in c.windows(2) {
            let len = norm(sub(s[1], s[0]));
            if len.is_finite() {
                f(s[0], s[1], len, ((len / step).ceil() as usize).clamp(1, max_pieces));
            }
        }
    }
}

/// Distance from each of `positions` to the nearest of `curves` (resampled every
/// `step`) when it is at most `band`, `+∞` beyond (module docs).
pub fn distance_to_curves(positions: &[V3], curves: &[Vec<V3>], step: f64, band: f64) -> Vec<f64> {
    let mut pts = Vec::new();
    for_each_segment(curves, step, 100_000, |a, b, _, n| {
        pts.extend((0..=n).map(|k| lerp(a, b, k as f64 / n as f64)));
    });
    if pts.is_empty() {
        return vec![f64::INFINITY; positions.len()];
    }
    let grid = SpatialGrid::new(&pts, band);
    positions
        .par_iter()
        .map(|&p| {
            let mut best = f64::INFINITY;
            grid.for_each_within(&pts, p, band, |_, d2| best = best.min(d2));
            let d = best.sqrt();
            if d <= band { d } else { f64::INFINITY }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn band_distances_match_the_polyline_distance() {
        let curves = vec![vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0]], vec![[0.0, 3.0, 0.0]]];
        let pos = [[1.3, 0.2, 0.0], [2.0, 0.0, 0.45], [2.0, 1.5, 0.0], [-0.3, 0.0, 0.0]];
        let d = distance_to_curves(&pos, &curves, 0.01, 0.5);
        assert!((d[0] - 0.2).abs() < 0.005, "{d:?}");
        assert!((d[1] - 0.45).abs() < 0.005, "{d:?}");
        assert_eq!(d[2], f64::INFINITY);
        assert!((d[3] - 0.3).abs() < 1e-12, "{d:?}");
        // A lone point is no segment: no curve samples at all.
        assert!(distance_to_curves(&pos, &curves[1..], 0.01, 10.0).iter().all(|x| x.is_infinite()));
    }

    #[test]
    fn curve_points_lie_on_the_surface_and_carry_the_length() {
        let mesh = fieldtex_mesh::primitives::grid(4, 4, 1.0, 1.0);
        let bvh = Bvh::build(&mesh).unwrap();
        let curves = vec![vec![[0.1, 0.5, 0.3], [0.9, 0.5, 0.3]]];
        let pts = curve_surface_points(&bvh, &curves, 0.1);
        assert_eq!(pts.len(), 8);
        let total: f64 = pts.iter().map(|p| p.1).sum();
        assert!((total - 0.8).abs() < 1e-12);
        for ((t, b), _) in pts {
            assert!((t as usize) < mesh.n_triangles());
            assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-9);
        }
    }
}
