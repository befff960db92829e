//! Closest points on a triangle mesh, for snapping user curves onto the surface.
//!
//! Triangles are binned in a uniform grid (module `spatial_grid`) with cells of two
//! mean edge lengths; a query searches a box that doubles until it holds a triangle
//! no farther than the box's half-size, which makes the answer exact. The closest
//! point on one triangle follows Ericson 2005 ("Real-Time Collision Detection",
//! §5.1.5: Voronoi regions of the vertices, edges and face).

use crate::spatial_grid::BoxGrid;
use fieldtex_core::vec3::{self, V3};
use fieldtex_mesh::TriMesh;

/// A grid over a mesh's triangles answering closest-point queries.
pub struct SurfaceLocator<'a> {
    mesh: &'a TriMesh,
    grid: BoxGrid,
    cell: f64,
    extent: f64,
}

impl<'a> SurfaceLocator<'a> {
    /// Bins the triangles of `mesh` (valid indices required) in cells of `cell`.
    pub fn new(mesh: &'a TriMesh, cell: f64) -> Self {
        let boxes: Vec<(V3, V3)> = (0..mesh.n_triangles())
            .map(|f| {
                let p = mesh.triangle_positions(f);
                let lo = [0, 1, 2].map(|k| p[0][k].min(p[1][k]).min(p[2][k]));
                let hi = [0, 1, 2].map(|k| p[0][k].max(p[1][k]).max(p[2][k]));
                (lo, hi)
            })
            .collect();
        let extent = mesh.bounding_box().map_or(1.0, |b| b.diagonal()).max(cell);
        Self { mesh, grid: BoxGrid::new(&boxes, cell), cell, extent }
    }

    /// The closest surface point to `p` and its triangle, or `None` for an empty mesh
    /// or a non-finite `p`. Ties go to the lowest triangle index.
    pub fn closest_point(&self, p: V3) -> Option<(V3, u32)> {
        if !vec3::is_finite(p) || self.mesh.triangles.is_empty() {
            return None;
        }
        let mut r = self.cell;
        loop {
            let mut best: Option<(f64, V3, u32)> = None;
            self.grid.for_each_candidate(vec3::sub(p, [r; 3]), vec3::add(p, [r; 3]), |f| {
                let q = closest_point_on_triangle(p, self.mesh.triangle_positions(f as usize));
                let d = vec3::norm2(vec3::sub(q, p));
                if best.is_none_or(|(bd, _, bf)| d < bd || (d == bd && f < bf)) {
                    best = Some((d, q, f));
                }
            });
            if let Some((d, q, f)) = best
                && (d.sqrt() <= r || r > 4.0 * self.extent)
            {
                return Some((q, f));
            }
            if r > 4.0 * self.extent {
                return None;
            }
            r *= 2.0;
        }
    }
}

/// Closest point to `p` on triangle `t` (Ericson 2005, §5.1.5).
pub fn closest_point_on_triangle(p: V3, t: [V3; 3]) -> V3 {
    let [a, b, c] = t;
    let (ab, ac, ap) = (vec3::sub(b, a), vec3::sub(c, a), vec3::sub(p, a));
    let (d1, d2) = (vec3::dot(ab, ap), vec3::dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = vec3::sub(p, b);
    let (d3, d4) = (vec3::dot(ab, bp), vec3::dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return vec3::add(a, vec3::scale(ab, v));
    }
    let cp = vec3::sub(p, c);
    let (d5, d6) = (vec3::dot(ab, cp), vec3::dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return vec3::add(a, vec3::scale(ac, w));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return vec3::add(b, vec3::scale(vec3::sub(c, b), w));
    }
    let denom = va + vb + vc;
    if denom == 0.0 || !denom.is_finite() {
        // Degenerate triangle: the nearest of its corners.
        return *t
            .iter()
            .min_by(|x, y| {
                vec3::norm2(vec3::sub(**x, p)).total_cmp(&vec3::norm2(vec3::sub(**y, p)))
            })
            .expect("three corners");
    }
    let (v, w) = (vb / denom, vc / denom);
    vec3::add(a, vec3::add(vec3::scale(ab, v), vec3::scale(ac, w)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_mesh::primitives::icosphere;

    #[test]
    fn triangle_regions() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let near = |p: V3, q: V3| vec3::norm(vec3::sub(closest_point_on_triangle(p, t), q)) < 1e-12;
        assert!(near([0.2, 0.2, 3.0], [0.2, 0.2, 0.0]));
        assert!(near([-1.0, -1.0, 0.0], [0.0, 0.0, 0.0]));
        assert!(near([0.5, -2.0, 1.0], [0.5, 0.0, 0.0]));
        assert!(near([1.0, 1.0, 0.0], [0.5, 0.5, 0.0]));
        assert!(near([3.0, -1.0, 0.0], [1.0, 0.0, 0.0]));
        assert!(near([-0.5, 0.4, 2.0], [0.0, 0.4, 0.0]));
    }

    #[test]
    fn sphere_projection_matches_brute_force() {
        let m = icosphere(3);
        let loc = SurfaceLocator::new(&m, 0.1);
        for i in 0..50 {
            let a = i as f64 * 0.7;
            let p = [1.7 * a.cos(), 1.3 * a.sin(), 0.4 * (a * 0.3).sin() - 0.1];
            let (q, _) = loc.closest_point(p).unwrap();
            let brute = (0..m.n_triangles())
                .map(|f| {
                    vec3::norm(vec3::sub(closest_point_on_triangle(p, m.triangle_positions(f)), p))
                })
                .fold(f64::INFINITY, f64::min);
            assert!((vec3::norm(vec3::sub(q, p)) - brute).abs() < 1e-12);
        }
    }
}
