//! Harmonic 1-forms: the closed and co-closed representative `ω = η + d0 f` of the
//! cohomology class of a closed 1-form `η` (Gu & Yau 2003, §4), and the per-triangle
//! vector of a closed 1-form.
//!
//! `f` minimises `Σ_e w_e (η_e + f_hi − f_lo)²` with the cotan weights `w` (the
//! discrete `⋆1`), i.e. solves `L f = −d0ᵀ ⋆1 η`; then `δω = 0` at every free vertex.
//! 1-forms are `#E` values, the integral from `edges[e][0]` to `edges[e][1]`.

use super::cotan_system::FixedLaplacian;
use crate::ParamError;
use fieldtex_core::vec3;
use fieldtex_mesh::Topology;

/// The harmonic representative of the class of `eta` (see the module docs).
pub fn harmonic_projection(
    topology: &Topology,
    weights: &[f64],
    laplacian: &FixedLaplacian,
    eta: &[f64],
) -> Result<Vec<f64>, ParamError> {
    let mut rhs = vec![0.0; topology.n_vertices];
    for (e, ed) in topology.edges.iter().enumerate() {
        let we = weights[e] * eta[e];
        rhs[ed[1] as usize] -= we;
        rhs[ed[0] as usize] += we;
    }
    let f = laplacian.solve(&rhs)?;
    Ok(topology
        .edges
        .iter()
        .enumerate()
        .map(|(e, ed)| eta[e] + f[ed[1] as usize] - f[ed[0] as usize])
        .collect())
}

/// The value of 1-form `form` along corner edge `i → j` of face `f`.
pub fn along(
    topology: &Topology,
    triangles: &[[u32; 3]],
    form: &[f64],
    f: usize,
    i: usize,
    j: usize,
) -> f64 {
    let t = triangles[f];
    let fe = topology.face_edges[f];
    // Corner edge k joins corners k and k+1.
    if (i + 1) % 3 == j {
        topology.face_edge_signs[f][i] as f64 * form[fe[i] as usize]
    } else {
        debug_assert_eq!((j + 1) % 3, i);
        let _ = t;
        -(topology.face_edge_signs[f][j] as f64) * form[fe[j] as usize]
    }
}

/// The constant tangent vector `X` of a closed 1-form on triangle `p` (CCW corners):
/// `X · (p1 − p0) = w01`, `X · (p2 − p0) = w02`, `X` in the triangle's plane.
pub fn face_vector(p: [[f64; 3]; 3], w01: f64, w02: f64) -> [f64; 3] {
    let n2 = vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0]));
    let a2 = vec3::norm(n2);
    if a2 <= 0.0 || !a2.is_finite() {
        return [0.0; 3];
    }
    let n = vec3::scale(n2, 1.0 / a2);
    // ∇λ_i = n × (p_{i+2} − p_{i+1}) / (2A).
    let g1 = vec3::scale(vec3::cross(n, vec3::sub(p[0], p[2])), 1.0 / a2);
    let g2 = vec3::scale(vec3::cross(n, vec3::sub(p[1], p[0])), 1.0 / a2);
    vec3::add(vec3::scale(g1, w01), vec3::scale(g2, w02))
}

/// Face vectors (`#F`) of the 1-form `form` on the faces with `keep[f]` (zero elsewhere).
pub fn face_vectors(
    topology: &Topology,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    form: &[f64],
    keep: &[bool],
) -> Vec<[f64; 3]> {
    (0..triangles.len())
        .map(|f| {
            if !keep[f] {
                return [0.0; 3];
            }
            let t = triangles[f];
            let p = [positions[t[0] as usize], positions[t[1] as usize], positions[t[2] as usize]];
            face_vector(
                p,
                along(topology, triangles, form, f, 0, 1),
                along(topology, triangles, form, f, 0, 2),
            )
        })
        .collect()
}

/// Per triangle: area and unit normal (`[0, 0, 1]` for a degenerate triangle), the
/// frame in which a face vector is turned by the Hodge star (`n × X`).
pub fn face_areas_normals(mesh: &fieldtex_mesh::TriMesh) -> (Vec<f64>, Vec<[f64; 3]>) {
    (0..mesh.n_triangles())
        .map(|f| {
            let p = mesh.triangle_positions(f);
            let n2 = vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0]));
            (0.5 * vec3::norm(n2), vec3::normalize(n2).unwrap_or([0.0, 0.0, 1.0]))
        })
        .unzip()
}
