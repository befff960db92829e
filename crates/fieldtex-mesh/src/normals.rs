//! Face and vertex normals.
//!
//! - [`face_normals`]: `#F × 3` unit normals following the triangle's corner order
//!   (counter-clockwise seen from the side the normal points to). A triangle whose
//!   cross product is zero or not finite (zero area, repeated vertex, NaN corner) gets
//!   the **zero vector**: callers can test `n == [0.0; 3]` to skip it.
//! - [`vertex_normals`]: `#V × 3` unit normals, by default weighted by the corner angle
//!   of every incident triangle (Thürmer & Wüthrich 1998, "Computing vertex normals from
//!   polygonal meshes"), which does not depend on how a flat region is triangulated;
//!   area weighting (sum of unnormalised cross products) is the alternative.
//!
//! Fallbacks, never NaN: a vertex whose weighted sum vanishes (all incident triangles
//! degenerate, or opposite triangles cancelling) first retries with area weights, then
//! with unit weights of its non-degenerate incident face normals; a vertex that still
//! has no direction (unreferenced, or only degenerate triangles) gets `[0, 0, 1]` and is
//! counted in a `vertex-normal-fallback` warning.
//!
//! Precondition: triangle indices are in range ([`TriMesh::validate`]); out-of-range
//! indices are a programming error and panic with a message saying so.

use crate::TriMesh;
use fieldtex_core::Warning;
use fieldtex_core::vec3::{self, V3};
use rayon::prelude::*;

/// How incident triangles are weighted in [`vertex_normals`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NormalWeighting {
    /// Corner angle at the vertex (Thürmer & Wüthrich 1998). Default.
    #[default]
    Angle,
    /// Triangle area.
    Area,
    /// Every non-degenerate incident triangle counts the same.
    Uniform,
}

/// The unit normal of triangle `(a, b, c)`, or the zero vector when it has no
/// well-defined normal (zero area or non-finite corners).
#[inline]
pub fn triangle_normal(a: V3, b: V3, c: V3) -> V3 {
    let n = vec3::cross(vec3::sub(b, a), vec3::sub(c, a));
    vec3::normalize(n).unwrap_or([0.0; 3])
}

/// `#F × 3` unit face normals; zero vector for degenerate triangles (module docs).
pub fn face_normals(mesh: &TriMesh) -> Vec<V3> {
    crate::checks::map_triangles(mesh, "face_normals", triangle_normal)
}

/// Interior angle at corner `a` of triangle `(a, b, c)` in `[0, π]`; 0 when an
/// adjacent edge has zero length or a corner is not finite.
#[inline]
pub fn corner_angle(a: V3, b: V3, c: V3) -> f64 {
    let u = vec3::sub(b, a);
    let v = vec3::sub(c, a);
    // atan2(|u×v|, u·v) is accurate for angles near 0 and π, unlike acos.
    let s = vec3::norm(vec3::cross(u, v));
    let d = vec3::dot(u, v);
    let ang = s.atan2(d);
    if ang.is_finite() { ang } else { 0.0 }
}

/// `#V × 3` unit vertex normals with the given weighting, plus warnings for vertices
/// that needed the last-resort fallback (module docs). Deterministic: contributions
/// are accumulated in triangle order.
pub fn vertex_normals(mesh: &TriMesh, weighting: NormalWeighting) -> (Vec<V3>, Vec<Warning>) {
    crate::checks::assert_indices(mesh, "vertex_normals");
    // Per face: unit normal, twice the area, and the three corner angles.
    let per_face: Vec<(V3, f64, [f64; 3])> = mesh
        .triangles
        .par_iter()
        .with_min_len(4096)
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|i| mesh.positions[t[i] as usize]);
            let cr = vec3::cross(vec3::sub(b, a), vec3::sub(c, a));
            let len = vec3::norm(cr);
            if !(len > 0.0 && len.is_finite()) {
                return ([0.0; 3], 0.0, [0.0; 3]);
            }
            let n = vec3::scale(cr, 1.0 / len);
            (n, len, [corner_angle(a, b, c), corner_angle(b, c, a), corner_angle(c, a, b)])
        })
        .collect();
    let weight = |w: NormalWeighting, f: usize, i: usize| -> f64 {
        let (_, dbl_area, ang) = per_face[f];
        match w {
            NormalWeighting::Angle => ang[i],
            NormalWeighting::Area => dbl_area,
            NormalWeighting::Uniform => {
                if dbl_area > 0.0 {
                    1.0
                } else {
                    0.0
                }
            }
        }
    };
    let accumulate = |w: NormalWeighting, only: Option<&[bool]>| -> Vec<V3> {
        let mut acc = vec![[0.0; 3]; mesh.n_vertices()];
        for (f, t) in mesh.triangles.iter().enumerate() {
            let n = per_face[f].0;
            for (i, &v) in t.iter().enumerate() {
                let v = v as usize;
                if only.is_some_and(|o| !o[v]) {
                    continue;
                }
                acc[v] = vec3::add(acc[v], vec3::scale(n, weight(w, f, i)));
            }
        }
        acc
    };
    let mut sums = accumulate(weighting, None);
    let mut normals = vec![[0.0; 3]; mesh.n_vertices()];
    let mut failed = vec![false; mesh.n_vertices()];
    let mut n_failed = 0usize;
    for (v, s) in sums.iter().enumerate() {
        match vec3::normalize(*s) {
            Some(n) => normals[v] = n,
            None => {
                failed[v] = true;
                n_failed += 1;
            }
        }
    }
    let mut warnings = Vec::new();
    if n_failed == 0 {
        return (normals, warnings);
    }
    for fallback in [NormalWeighting::Area, NormalWeighting::Uniform] {
        if fallback == weighting {
            continue;
        }
        sums = accumulate(fallback, Some(&failed));
        for (v, s) in sums.iter().enumerate() {
            if failed[v]
                && let Some(n) = vec3::normalize(*s)
            {
                normals[v] = n;
                failed[v] = false;
                n_failed -= 1;
            }
        }
    }
    if n_failed > 0 {
        let first = failed.iter().position(|&f| f).unwrap_or(0);
        for (v, f) in failed.iter().enumerate() {
            if *f {
                normals[v] = [0.0, 0.0, 1.0];
            }
        }
        warnings.push(Warning::new(
            "vertex-normal-fallback",
            format!(
                "{n_failed} vertices (first: {first}) have no incident triangle with a \
                 well-defined normal (unreferenced or only degenerate triangles); their \
                 normal was set to +z"
            ),
        ));
    }
    (normals, warnings)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::{grid, icosphere};

    #[test]
    fn sphere_normals_point_outward_and_are_unit() {
        let m = icosphere(3);
        let (vn, w) = vertex_normals(&m, NormalWeighting::Angle);
        assert!(w.is_empty());
        for (p, n) in m.positions.iter().zip(&vn) {
            assert!((vec3::norm(*n) - 1.0).abs() < 1e-12);
            assert!(vec3::dot(*p, *n) > 0.999, "vertex normal should match the radius");
        }
        let fnrm = face_normals(&m);
        for (f, n) in fnrm.iter().enumerate() {
            assert!((vec3::norm(*n) - 1.0).abs() < 1e-12);
            let c = m.triangle_positions(f);
            let centroid = vec3::scale(vec3::add(vec3::add(c[0], c[1]), c[2]), 1.0 / 3.0);
            assert!(vec3::dot(centroid, *n) > 0.0);
        }
    }

    #[test]
    fn grid_normals_are_plus_z_for_every_weighting() {
        let m = grid(4, 3, 2.0, 1.0);
        for w in [NormalWeighting::Angle, NormalWeighting::Area, NormalWeighting::Uniform] {
            let (vn, warn) = vertex_normals(&m, w);
            assert!(warn.is_empty());
            for n in vn {
                assert!((n[2] - 1.0).abs() < 1e-12, "{w:?}: {n:?}");
            }
        }
    }

    #[test]
    fn degenerate_and_unreferenced_vertices_fall_back() {
        // Triangle 0 is fine, triangle 1 has zero area (collinear), vertex 5 unused,
        // vertex 4 is only used by the degenerate triangle.
        let m = TriMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [2.0, 0.0, 0.0],
                [3.0, 0.0, 0.0],
                [9.0, 9.0, 9.0],
            ],
            vec![[0, 1, 2], [1, 3, 4]],
        );
        let fnrm = face_normals(&m);
        assert_eq!(fnrm[1], [0.0; 3]);
        assert!((fnrm[0][2] - 1.0).abs() < 1e-15);
        let (vn, w) = vertex_normals(&m, NormalWeighting::Angle);
        assert_eq!(w.len(), 1);
        assert!(w[0].message.starts_with("3 vertices"), "{}", w[0].message);
        for n in &vn {
            assert!((vec3::norm(*n) - 1.0).abs() < 1e-12);
        }
        assert_eq!(vn[1], [0.0, 0.0, 1.0]);
    }

    #[test]
    fn unit_and_finite_over_categories_and_fixtures() {
        let fixtures = ["fertility.obj", "stanford-bunny.obj", "defects/narrow_triangles.obj"];
        let all = crate::test_meshes::categories_and(&fixtures);
        for (name, m) in &all {
            for w in [NormalWeighting::Angle, NormalWeighting::Area, NormalWeighting::Uniform] {
                let (vn, _) = vertex_normals(m, w);
                assert!(vn.iter().all(|n| (vec3::norm(*n) - 1.0).abs() < 1e-12), "{name} {w:?}");
            }
            for n in face_normals(m) {
                let l = vec3::norm(n);
                assert!(l == 0.0 || (l - 1.0).abs() < 1e-12, "{name}");
            }
        }
    }

    #[test]
    fn corner_angles_sum_to_pi() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [3.0, 0.1, 0.0], [0.4, 2.0, 0.5]);
        let s = corner_angle(a, b, c) + corner_angle(b, c, a) + corner_angle(c, a, b);
        assert!((s - std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(corner_angle(a, a, c), 0.0);
    }
}
