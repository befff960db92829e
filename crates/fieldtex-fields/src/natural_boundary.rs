//! The natural boundary term of Liu et al. (paper D, §2.2).
//!
//! On a flat patch `M` with a trivial connection, the Dirichlet energy of a tangent
//! field `u` splits as
//!
//! `∫_M |∇u|² = ∫_M (∇·u)² + (∇×u)² − ∮_∂M (u × du)·n`,
//!
//! because `2 det ∇u` is the exterior derivative of `u₁ du₂ − u₂ du₁` (Stokes), with
//! `∂M` traversed positively (surface on the left). Fisher et al. (2007) minimise only
//! the divergence and curl terms; every harmonic field (div = curl = 0) is then free,
//! which shows up as spurious singularities near the boundary (paper D, Fig. 2).
//! Subtracting the boundary term makes the energy the Dirichlet energy, whose only
//! free directions are the constant fields.
//!
//! Discretisation (paper D, Fig. 1): along each boundary loop with consecutive edges
//! `e_i`, `e_{i+1}` meeting at vertex `v`, `∮ u × du ≈ Σ_i (u_i × u_{i+1})·n_v`, where
//! `u_i` is the Whitney vector of the triangle owning `e_i` at its barycentre (linear in
//! the 1-form, three edges per triangle) and `n_v` the vertex normal. Hence the term is
//! a quadratic form `ωᵀ B ω`; [`boundary_term_triplets`] returns the symmetric `B`
//! (`#E × #E`, 9 edge pairs per boundary vertex, each entry split evenly between
//! `(j, l)` and `(l, j)`). Consecutive edges of one triangle contribute `u × u = 0`.
//!
//! The sign convention is pinned by tests: for the linear fields `(x, y)`, `(x, −y)` and
//! `(−y, x)` on a disk, `div² + curl² − B` reproduces `∫|∇u|² = 2·area`.
//! Not implemented: the curvature term of the Weitzenböck formula on curved patches
//! (ignored, as in the paper).

use fieldtex_core::vec3::{cross, dot};

use crate::dec::Dec;

/// Index of the edge between vertices `a` and `b` (sorted edge table lookup).
pub(crate) fn find_edge(dec: &Dec, a: u32, b: u32) -> Option<usize> {
    let key = [a.min(b), a.max(b)];
    dec.topology.edges.binary_search(&key).ok()
}

/// Triplets `(row, col, value)` of the symmetric boundary matrix `B` with
/// `ωᵀ B ω = Σ_i (u_i × u_{i+1})·n_i` over all boundary loops (empty for closed meshes).
pub fn boundary_term_triplets(dec: &Dec) -> Vec<(usize, usize, f64)> {
    let loops = dec.topology.boundary_loops(&dec.triangles);
    let mut t = Vec::new();
    for lp in &loops {
        let m = lp.len();
        if m < 3 {
            continue;
        }
        // Boundary edge i goes from lp[i] to lp[i+1]; its triangle is the only one.
        let faces: Vec<Option<usize>> = (0..m)
            .map(|i| {
                find_edge(dec, lp[i], lp[(i + 1) % m])
                    .filter(|&e| dec.topology.is_boundary_edge(e))
                    .map(|e| dec.topology.edge_faces(e)[0] as usize)
            })
            .collect();
        for i in 0..m {
            let (Some(fa), Some(fb)) = (faces[i], faces[(i + 1) % m]) else {
                continue;
            };
            if fa == fb {
                continue;
            }
            let n = dec.vertex_normals[lp[(i + 1) % m] as usize];
            let wa = dec.whitney_at_barycenter(fa);
            let wb = dec.whitney_at_barycenter(fb);
            for j in 0..3 {
                let ej = dec.topology.face_edges[fa][j] as usize;
                for l in 0..3 {
                    let el = dec.topology.face_edges[fb][l] as usize;
                    let c = 0.5 * dot(cross(wa[j], wb[l]), n);
                    t.push((ej, el, c));
                    t.push((el, ej, c));
                }
            }
        }
    }
    t
}

/// Evaluates `ωᵀ B ω = Σ_i (u_i × u_{i+1})·n_i` directly (for tests and reports).
pub fn boundary_term_value(dec: &Dec, omega: &[f64]) -> f64 {
    boundary_term_triplets(dec).iter().map(|&(i, j, v)| omega[i] * v * omega[j]).sum()
}
