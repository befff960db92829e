//! Where to put the period seams of a torus image: the fundamental domain of a lattice
//! can start at any level, and the seams of the texture are the level curves `v = c`
//! (and `u = c'`) where it starts. We pick the levels whose curves are shortest on the
//! surface — on a torus of revolution the inner equator instead of an arbitrary
//! longitude — which shortens the total seam length without changing the map
//! (Wang et al. 2005 do not discuss the choice; this is our own).

use fieldtex_core::vec3;

/// Surface length of the level set `{x_axis ≡ c (mod period)}` of the per-face charts
/// `corner` (one chart per face; the level is crossed where corner values straddle it).
pub fn level_length(
    corner: &[[[f64; 2]; 3]],
    triangles: &[[u32; 3]],
    positions: &[[f64; 3]],
    axis: usize,
    period: f64,
    c: f64,
) -> f64 {
    let mut total = 0.0;
    for (f, cu) in corner.iter().enumerate() {
        let x = [cu[0][axis], cu[1][axis], cu[2][axis]];
        if x.iter().any(|v| !v.is_finite()) {
            continue;
        }
        let (lo, hi) = (x[0].min(x[1]).min(x[2]), x[0].max(x[1]).max(x[2]));
        let mut k = ((lo - c) / period).ceil();
        while c + k * period <= hi {
            let level = c + k * period;
            let mut pts = Vec::with_capacity(2);
            for i in 0..3 {
                let j = (i + 1) % 3;
                let (a, b) = (x[i] - level, x[j] - level);
                if (a < 0.0) != (b < 0.0) {
                    let t = a / (a - b);
                    let (p, q) =
                        (positions[triangles[f][i] as usize], positions[triangles[f][j] as usize]);
                    pts.push(vec3::add(p, vec3::scale(vec3::sub(q, p), t)));
                }
            }
            if pts.len() == 2 {
                total += vec3::norm(vec3::sub(pts[1], pts[0]));
            }
            k += 1.0;
        }
    }
    total
}

/// The level `c ∈ [0, period)` (among `candidates` evenly spaced) with the shortest
/// [`level_length`]; the lowest on ties.
pub fn shortest_level(
    corner: &[[[f64; 2]; 3]],
    triangles: &[[u32; 3]],
    positions: &[[f64; 3]],
    axis: usize,
    period: f64,
    candidates: usize,
) -> f64 {
    let mut best = (f64::INFINITY, 0.0);
    for j in 0..candidates.max(1) {
        // Offset by half a step so that levels avoid the vertex at the origin.
        let c = period * (j as f64 + 0.5) / candidates.max(1) as f64;
        let l = level_length(corner, triangles, positions, axis, period, c);
        if l < best.0 {
            best = (l, c);
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shorter_level_wins() {
        // Two faces forming a trapezoid in 3-D (width 1 at y = 0, width 3 at y = 1)
        // charted as the unit square: the level y = c has length 1 + 2c.
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 1.0, 0.0], [-1.0, 1.0, 0.0]];
        let triangles = [[0, 1, 2], [0, 2, 3]];
        let corner = [[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]], [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0]]];
        let l = level_length(&corner, &triangles, &positions, 1, 10.0, 0.5);
        assert!((l - 2.0).abs() < 1e-12, "{l}");
        let c = shortest_level(&corner, &triangles, &positions, 1, 1.0, 10);
        assert!((c - 0.05).abs() < 1e-12, "{c}");
    }
}
