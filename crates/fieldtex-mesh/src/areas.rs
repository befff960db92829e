//! Triangle areas and per-vertex area shares.
//!
//! - [`face_areas`]: `#F` areas `|(b − a) × (c − a)| / 2`; 0 for degenerate or
//!   non-finite triangles (never NaN).
//! - [`barycentric_vertex_areas`]: `#V`, each vertex gets a third of every incident
//!   triangle's area.
//! - [`mixed_voronoi_vertex_areas`]: `#V`, the "mixed" Voronoi area of Meyer, Desbrun,
//!   Schröder & Barr 2003 ("Discrete differential-geometry operators for triangulated
//!   2-manifolds", §3.3 and Fig. 4): in a non-obtuse triangle each corner gets its
//!   Voronoi region `(|PR|² cot Q + |PQ|² cot R) / 8`; in an obtuse triangle the obtuse
//!   corner gets half the area and the two others a quarter each. Shares are clamped
//!   to `[0, area]`, so every share is finite and non-negative.
//!
//! Both vertex areas partition the surface: they sum to the total area up to rounding.
//! Unreferenced vertices get 0. Precondition: indices in range (see
//! [`TriMesh::validate`]).

use crate::TriMesh;
use fieldtex_core::vec3::{self, V3};
use rayon::prelude::*;

/// Which vertex area [`vertex_areas`] returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VertexAreaKind {
    /// A third of each incident triangle. Default: positive wherever a vertex touches a
    /// non-degenerate triangle, independent of angles.
    #[default]
    Barycentric,
    /// Mixed Voronoi area (Meyer et al. 2003).
    MixedVoronoi,
}

/// Area of triangle `(a, b, c)`; 0 when not finite.
#[inline]
pub fn triangle_area(a: V3, b: V3, c: V3) -> f64 {
    let s = 0.5 * vec3::norm(vec3::cross(vec3::sub(b, a), vec3::sub(c, a)));
    if s.is_finite() { s } else { 0.0 }
}

/// `#F` triangle areas.
pub fn face_areas(mesh: &TriMesh) -> Vec<f64> {
    crate::checks::map_triangles(mesh, "face_areas", triangle_area)
}

/// Sum of all triangle areas (sequential sum in triangle order: deterministic).
pub fn total_area(mesh: &TriMesh) -> f64 {
    face_areas(mesh).iter().sum()
}

/// Mixed Voronoi shares of corners `(a, b, c)` of one triangle (module docs); they sum
/// to the triangle's area. All zero for a degenerate or non-finite triangle.
pub fn mixed_voronoi_corner_areas(a: V3, b: V3, c: V3) -> [f64; 3] {
    let p = [a, b, c];
    let cr = vec3::norm(vec3::cross(vec3::sub(b, a), vec3::sub(c, a)));
    if !(cr > 0.0 && cr.is_finite()) {
        return [0.0; 3];
    }
    let area = 0.5 * cr;
    // dots[i]: dot product of the two edges leaving corner i; cot_i = dots[i] / cr.
    let mut dots = [0.0; 3];
    for i in 0..3 {
        let u = vec3::sub(p[(i + 1) % 3], p[i]);
        let v = vec3::sub(p[(i + 2) % 3], p[i]);
        dots[i] = vec3::dot(u, v);
    }
    if let Some(obtuse) = (0..3).find(|&i| dots[i] < 0.0) {
        let mut s = [0.25 * area; 3];
        s[obtuse] = 0.5 * area;
        return s;
    }
    // Squared length of the edge opposite corner i.
    let l2 = [0, 1, 2].map(|i| vec3::norm2(vec3::sub(p[(i + 2) % 3], p[(i + 1) % 3])));
    [0, 1, 2].map(|i| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        // Edge i–j is opposite k, edge i–k is opposite j.
        ((l2[k] * dots[k] + l2[j] * dots[j]) / (8.0 * cr)).clamp(0.0, area)
    })
}

/// `#V` barycentric vertex areas (a third of each incident triangle).
pub fn barycentric_vertex_areas(mesh: &TriMesh) -> Vec<f64> {
    let fa = face_areas(mesh);
    let mut va = vec![0.0; mesh.n_vertices()];
    for (t, a) in mesh.triangles.iter().zip(&fa) {
        let s = a / 3.0;
        for &v in t {
            va[v as usize] += s;
        }
    }
    va
}

/// `#V` mixed Voronoi vertex areas (Meyer et al. 2003).
pub fn mixed_voronoi_vertex_areas(mesh: &TriMesh) -> Vec<f64> {
    crate::checks::assert_indices(mesh, "mixed_voronoi_vertex_areas");
    let shares: Vec<[f64; 3]> = mesh
        .triangles
        .par_iter()
        .with_min_len(4096)
        .map(|t| {
            let p = |i: usize| mesh.positions[t[i] as usize];
            mixed_voronoi_corner_areas(p(0), p(1), p(2))
        })
        .collect();
    let mut va = vec![0.0; mesh.n_vertices()];
    for (t, s) in mesh.triangles.iter().zip(&shares) {
        for i in 0..3 {
            va[t[i] as usize] += s[i];
        }
    }
    va
}

/// `#V` vertex areas of the requested kind.
pub fn vertex_areas(mesh: &TriMesh, kind: VertexAreaKind) -> Vec<f64> {
    match kind {
        VertexAreaKind::Barycentric => barycentric_vertex_areas(mesh),
        VertexAreaKind::MixedVoronoi => mixed_voronoi_vertex_areas(mesh),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::{grid, icosphere, torus};

    #[test]
    fn grid_area_is_exact() {
        let m = grid(7, 5, 3.0, 2.0);
        assert!((total_area(&m) - 6.0).abs() < 1e-12);
        for kind in [VertexAreaKind::Barycentric, VertexAreaKind::MixedVoronoi] {
            let s: f64 = vertex_areas(&m, kind).iter().sum();
            assert!((s - 6.0).abs() < 1e-12, "{kind:?}: {s}");
        }
    }

    #[test]
    fn vertex_areas_partition_closed_surfaces() {
        for m in [icosphere(3), torus(2.0, 0.7, 40, 20)] {
            let total = total_area(&m);
            for kind in [VertexAreaKind::Barycentric, VertexAreaKind::MixedVoronoi] {
                let va = vertex_areas(&m, kind);
                assert!(va.iter().all(|&a| a > 0.0 && a.is_finite()));
                let s: f64 = va.iter().sum();
                assert!((s - total).abs() < 1e-10 * total);
            }
        }
        // The icosphere converges to 4π.
        let a = total_area(&icosphere(5));
        assert!((a - 4.0 * std::f64::consts::PI).abs() < 0.01 * a);
    }

    #[test]
    fn obtuse_and_degenerate_shares() {
        // Obtuse at corner 2.
        let s = mixed_voronoi_corner_areas([0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [2.0, 0.5, 0.0]);
        assert_eq!(s, [0.25, 0.25, 0.5]);
        // Right triangle: the right-angle corner is not obtuse; shares still sum to 0.5.
        let s = mixed_voronoi_corner_areas([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert!((s.iter().sum::<f64>() - 0.5).abs() < 1e-15);
        assert!((s[0] - 0.25).abs() < 1e-15);
        // Collinear and NaN corners give zeros, not NaN.
        let z = mixed_voronoi_corner_areas([0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]);
        assert_eq!(z, [0.0; 3]);
        let n = mixed_voronoi_corner_areas([f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert_eq!(n, [0.0; 3]);
        assert_eq!(triangle_area([f64::INFINITY, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), 0.0);
    }
}
