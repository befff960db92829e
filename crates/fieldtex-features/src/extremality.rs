//! Extremality coefficients of principal curvatures: `e_max = ∇k_max · t_max` and
//! `e_min = ∇k_min · t_min` per vertex.
//!
//! Yoshizawa, Belyaev & Seidel 2005 ("Fast and robust detection of crest lines on
//! meshes", SPM, §3) and Ohtake, Belyaev & Seidel 2004 ("Ridge-valley lines on meshes
//! via implicit surface fitting", SIGGRAPH, §2) define crest lines as the zero sets of
//! these coefficients: the derivative of a principal curvature along its own curvature
//! line. Following Yoshizawa et al. the gradient of the scalar `k` is taken from the
//! mesh itself rather than from a fitted surface:
//!
//! - per triangle `(a, b, c)` with unit normal `n` and area `A`, the gradient of the
//!   linear interpolant is `∇k = [k_a n×(c−b) + k_b n×(a−c) + k_c n×(b−a)] / (2A)`;
//! - per vertex, `∇k(v)` is the average of its triangles' gradients weighted by the
//!   corner angle at `v` (so the result does not depend on how a flat fan is split),
//!   projected onto the tangent plane of the vertex normal;
//! - `e(v) = ∇k(v) · t(v)`.
//!
//! `t` is only defined up to sign and so is `e`; consumers compare neighbouring values
//! only after orienting `t` consistently (see [`crate::crest_lines`]). Degenerate
//! triangles contribute nothing; a vertex without a valid triangle gets `e = 0`.
//! Units: `e` has the units of `1 / length²`.

use fieldtex_core::vec3::{self, V3};
use fieldtex_mesh::TriMesh;
use fieldtex_mesh::normals::corner_angle;
use rayon::prelude::*;

/// `#F × 3` gradients of the piecewise-linear interpolant of the `#V` values `k`
/// (zero for degenerate triangles).
pub fn face_gradients(mesh: &TriMesh, k: &[f64]) -> Vec<V3> {
    mesh.triangles
        .par_iter()
        .with_min_len(2048)
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let cr = vec3::cross(vec3::sub(b, a), vec3::sub(c, a));
            let dbl_area = vec3::norm(cr);
            if !(dbl_area > 0.0 && dbl_area.is_finite()) {
                return [0.0; 3];
            }
            let n = vec3::scale(cr, 1.0 / dbl_area);
            let [ka, kb, kc] = t.map(|i| k[i as usize]);
            let g = vec3::add(
                vec3::add(
                    vec3::scale(vec3::cross(n, vec3::sub(c, b)), ka),
                    vec3::scale(vec3::cross(n, vec3::sub(a, c)), kb),
                ),
                vec3::scale(vec3::cross(n, vec3::sub(b, a)), kc),
            );
            let g = vec3::scale(g, 1.0 / dbl_area);
            if vec3::is_finite(g) { g } else { [0.0; 3] }
        })
        .collect()
}

/// `#V × 3` per-vertex gradients: angle-weighted averages of the incident triangles'
/// gradients, projected onto the tangent planes of `normals`. `vertex_corners[v]` lists
/// the corners `3f + i` at vertex `v` (CSR `offsets`, `corners`).
pub fn vertex_gradients(
    mesh: &TriMesh,
    face_grad: &[V3],
    normals: &[V3],
    offsets: &[u32],
    corners: &[u32],
) -> Vec<V3> {
    (0..mesh.n_vertices())
        .into_par_iter()
        .with_min_len(2048)
        .map(|v| {
            let mut acc = [0.0; 3];
            let mut wsum = 0.0;
            for &c in &corners[offsets[v] as usize..offsets[v + 1] as usize] {
                let (f, i) = ((c / 3) as usize, (c % 3) as usize);
                let t = mesh.triangles[f];
                let p = |j: usize| mesh.positions[t[(i + j) % 3] as usize];
                let w = corner_angle(p(0), p(1), p(2));
                if w > 0.0 && w.is_finite() {
                    acc = vec3::add(acc, vec3::scale(face_grad[f], w));
                    wsum += w;
                }
            }
            if wsum <= 0.0 {
                return [0.0; 3];
            }
            let g = vec3::scale(acc, 1.0 / wsum);
            let n = normals[v];
            vec3::sub(g, vec3::scale(n, vec3::dot(g, n)))
        })
        .collect()
}

/// Corners of every vertex as CSR (`offsets` of length `#V + 1`, corner ids `3f + i`).
pub fn vertex_corners(n_vertices: usize, triangles: &[[u32; 3]]) -> (Vec<u32>, Vec<u32>) {
    let csr = fieldtex_mesh::Csr::from_pairs(
        n_vertices,
        triangles
            .iter()
            .enumerate()
            .flat_map(|(f, t)| (0..3).map(move |i| (t[i], (3 * f + i) as u32))),
    );
    (csr.offsets, csr.items)
}

/// Extremality coefficients `e(v) = ∇k(v) · t(v)` (module docs), `#V`.
pub fn extremality(
    mesh: &TriMesh,
    k: &[f64],
    t: &[V3],
    normals: &[V3],
    corners: (&[u32], &[u32]),
) -> Vec<f64> {
    let fg = face_gradients(mesh, k);
    let vg = vertex_gradients(mesh, &fg, normals, corners.0, corners.1);
    vg.iter().zip(t).map(|(g, d)| vec3::dot(*g, *d)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_mesh::primitives::grid;

    #[test]
    fn gradient_of_a_linear_function_is_exact() {
        let m = grid(6, 5, 2.0, 1.0);
        let k: Vec<f64> = m.positions.iter().map(|p| 3.0 * p[0] - 2.0 * p[1] + 1.0).collect();
        let fg = face_gradients(&m, &k);
        for g in &fg {
            assert!((g[0] - 3.0).abs() < 1e-12 && (g[1] + 2.0).abs() < 1e-12 && g[2].abs() < 1e-12);
        }
        let normals = vec![[0.0, 0.0, 1.0]; m.n_vertices()];
        let (o, c) = vertex_corners(m.n_vertices(), &m.triangles);
        let t = vec![[0.6, 0.8, 0.0]; m.n_vertices()];
        let e = extremality(&m, &k, &t, &normals, (&o, &c));
        for x in e {
            assert!((x - (3.0 * 0.6 - 2.0 * 0.8)).abs() < 1e-12);
        }
    }
}
