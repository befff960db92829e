//! The smoothest line field of a mesh, aligned to principal curvature only where the
//! surface is clearly anisotropic: the fallback field of `fieldtex align` where no
//! feature curve constrains the field (Knöppel, Crane, Pinkall & Schröder 2013,
//! "Globally optimal direction fields", §4–6).
//!
//! # Method
//! - Per vertex a tangent frame `(e₁, e₂)` (vertex normal, [`vec3::any_orthonormal`]);
//!   a line field (`n = 2`) is one complex number `u_i` per vertex, direction
//!   `arg(u_i)/2` in that frame.
//! - Connection Laplacian `A` (Knöppel et al. eq. 5): for each edge `ij` with cotan
//!   weight `w_ij` (negative weights clamped to 0 so that `A` stays positive
//!   semi-definite), the energy `w_ij |u_j − r_ij u_i|²` with the discrete Levi-Civita
//!   transport `r_ij = exp(i·n·(β_ij − α_ij))`, `α_ij`/`β_ij` the angles of the edge
//!   vector `p_j − p_i` in the frames of `i` and `j`. `M` is the lumped (barycentric)
//!   mass. The Hermitian `A` is solved in its real `2#V × 2#V` form
//!   `[[Re A, −Im A], [Im A, Re A]]` with the workspace's sparse Cholesky.
//! - Smoothest field: the eigenvector of the smallest eigenvalue of `A u = λ M u`, by
//!   inverse iteration with the shift `ε·tr A / tr M` (`ε = 10⁻⁸`), 24 iterations,
//!   normalised per connected component (so every component gets its own field),
//!   started from the longest bounding-box axis projected onto the tangent planes
//!   (deterministic; on a flat patch the field is that axis).
//! - Curvature alignment where clearly anisotropic: the target `q_i = a_i·e^{2iφ_i}`
//!   (`φ_i` the angle of the principal direction of smaller `|k|`, along which a ridge
//!   runs, as the curve-constrained field runs along crest lines; `a_i = ρ_i·s(c_i)` with the
//!   anisotropy `ρ_i = |k₁ − k₂| / (|k₁| + |k₂|)`, `c_i = |k₁ − k₂|·D` (`D` the
//!   bounding-box diagonal) and `s` a smooth step from [`ANISOTROPY_LOW`] to
//!   [`ANISOTROPY_HIGH`]: flat and umbilic regions get 0). *Substitute:* Knöppel et al.
//!   solve `(A − λ_t M) u = M q` with `λ_t` just below `λ_min`; here
//!   `u = (A + δM)⁻¹ M (q + γ u₀)` with `u₀` the smoothest field (unit RMS), `δ =
//!   1/(0.05 D)²` (alignment spreads about 5 % of the model size) and
//!   `γ = δ/2`: where curvature is anisotropic the field follows it, elsewhere it is
//!   the smoothest field; one extra factorisation.
//! - The line field becomes a vector field by choosing signs along a breadth-first
//!   tree of each component (a vector agrees with its parent's): sign jumps are left
//!   only along cuts through the ±½ singularities a line field can have.

use crate::FieldsError;
use fieldtex_core::vec3::{self, V3};
use fieldtex_linalg::{Cholesky, SparseMatrix};
use fieldtex_mesh::{
    CurvatureOptions, NormalWeighting, TriMesh, VertexAreaKind, cotan_laplacian, lumped_mass,
    principal_curvatures, vertex_normals,
};

/// Below this `|k₁ − k₂|·D` curvature counts as isotropic noise.
pub const ANISOTROPY_LOW: f64 = 4.0;
/// Above this `|k₁ − k₂|·D` (and with `ρ` near 1) curvature fully steers the field.
pub const ANISOTROPY_HIGH: f64 = 12.0;
const ITERATIONS: usize = 24;

/// A unit tangent vector per vertex (zero for isolated vertices), and the share of
/// surface area where curvature steered it.
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothestField {
    pub vectors: Vec<V3>,
    pub aligned_area_fraction: f64,
}

/// The fallback field of `mesh` (module docs).
pub fn smoothest_field(mesh: &TriMesh) -> Result<SmoothestField, FieldsError> {
    let nv = mesh.n_vertices();
    let (normals, _) = vertex_normals(mesh, NormalWeighting::Angle);
    let e1: Vec<V3> = normals.iter().map(|&n| vec3::any_orthonormal(n)).collect();
    let e2: Vec<V3> = normals.iter().zip(&e1).map(|(&n, &a)| vec3::cross(n, a)).collect();
    let angle_in = |i: usize, v: V3| vec3::dot(v, e2[i]).atan2(vec3::dot(v, e1[i]));
    let (l, _) = cotan_laplacian(mesh)?;
    let mass = lumped_mass(mesh, VertexAreaKind::Barycentric)?;
    let mut trip: Vec<(usize, usize, f64)> = Vec::new();
    let mut diag = vec![0.0f64; nv];
    let (cp, ri, va) = (l.col_ptr(), l.row_idx(), l.values());
    let mut adjacency: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for j in 0..nv {
        for k in cp[j]..cp[j + 1] {
            let i = ri[k];
            if i >= j {
                continue;
            }
            adjacency[i].push(j as u32);
            adjacency[j].push(i as u32);
            let w = (-va[k]).max(0.0);
            if w == 0.0 {
                continue;
            }
            let e = vec3::sub(mesh.positions[j], mesh.positions[i]);
            let rho = 2.0 * (angle_in(j, e) - angle_in(i, e));
            let (c, s) = (rho.cos(), rho.sin());
            diag[i] += w;
            diag[j] += w;
            // A_ji = −w r, A_ij = −w conj(r); real form [[Re, −Im], [Im, Re]].
            for (r, col, re, im) in [(j, i, -w * c, -w * s), (i, j, -w * c, w * s)] {
                trip.push((r, col, re));
                trip.push((nv + r, nv + col, re));
                trip.push((r, nv + col, -im));
                trip.push((nv + r, col, im));
            }
        }
    }
    let tr_a: f64 = diag.iter().sum();
    let tr_m: f64 = mass.iter().sum();
    if !(tr_m > 0.0 && tr_m.is_finite()) {
        return Err(FieldsError::InvalidOption {
            name: "mesh area (smoothest field)",
            value: tr_m,
            expected: "a mesh with positive, finite area",
        });
    }
    let system = |shift: f64| -> Result<Cholesky, FieldsError> {
        let mut t = trip.clone();
        for i in 0..nv {
            // A vertex without edges or area (isolated) is decoupled: 1 on the diagonal,
            // and its right-hand side is 0.
            let d = diag[i] + shift * mass[i];
            let d = if d > 0.0 && d.is_finite() { d } else { 1.0 };
            t.push((i, i, d));
            t.push((nv + i, nv + i, d));
        }
        Ok(Cholesky::factor(&SparseMatrix::from_triplets(2 * nv, 2 * nv, &t)?)?)
    };
    let components = vertex_components(&adjacency);
    // Start: the longest bounding-box axis, projected.
    let ext = mesh.bounding_box().map_or([0.0; 3], |bb| vec3::sub(bb.max, bb.min));
    let diagonal = vec3::norm(ext).max(1e-300);
    let axis = (0..3).fold(0, |a, k| if ext[k] > ext[a] { k } else { a });
    let mut dir = [0.0; 3];
    dir[axis] = 1.0;
    let mut u = vec![0.0f64; 2 * nv];
    for i in 0..nv {
        let t = vec3::sub(dir, vec3::scale(normals[i], vec3::dot(dir, normals[i])));
        let phi = 2.0 * angle_in(i, t);
        (u[i], u[nv + i]) = (phi.cos(), phi.sin());
    }
    let chol = system(1e-8 * tr_a / tr_m)?;
    for _ in 0..ITERATIONS {
        let rhs: Vec<f64> = (0..2 * nv).map(|k| mass[k % nv] * u[k]).collect();
        u = chol.solve(&rhs)?;
        normalise_per_component(&mut u, &mass, &components);
    }
    // Curvature target where clearly anisotropic.
    let (pc, _) = principal_curvatures(mesh, &CurvatureOptions::default())?;
    let mut q = vec![0.0f64; 2 * nv];
    let mut aligned_area = 0.0;
    for i in 0..nv {
        let (k1, k2) = (pc.k_max[i], pc.k_min[i]);
        let diff = (k1 - k2).abs();
        let rho = diff / (k1.abs() + k2.abs()).max(1e-300);
        let c = diff * diagonal;
        let t = ((c - ANISOTROPY_LOW) / (ANISOTROPY_HIGH - ANISOTROPY_LOW)).clamp(0.0, 1.0);
        let a = rho * t * t * (3.0 - 2.0 * t);
        if !(a > 0.0 && a.is_finite()) {
            continue;
        }
        aligned_area += a * mass[i];
        // Along the less curved principal direction (the way a ridge runs, as the
        // curve-constrained field does along crest lines).
        let along = if k1.abs() >= k2.abs() { pc.dir_min[i] } else { pc.dir_max[i] };
        let phi = 2.0 * angle_in(i, along);
        (q[i], q[nv + i]) = (a * phi.cos(), a * phi.sin());
    }
    if aligned_area > 0.0 {
        // Smoothest field at unit RMS magnitude, then (A + δM)⁻¹ M (q + γ u₀).
        let rms = (u.iter().map(|v| v * v).sum::<f64>() / nv.max(1) as f64).sqrt();
        let delta = 1.0 / (0.05 * diagonal).powi(2);
        let gamma = 0.5 * delta / rms.max(1e-300);
        let rhs: Vec<f64> = (0..2 * nv).map(|k| mass[k % nv] * (q[k] + gamma * u[k])).collect();
        let aligned = system(delta)?.solve(&rhs)?;
        // Keep the smoothest field where the aligned solution cancels out.
        for i in 0..nv {
            let m = aligned[i].hypot(aligned[nv + i]);
            if m > 1e-12 * delta.recip() {
                (u[i], u[nv + i]) = (aligned[i], aligned[nv + i]);
            }
        }
    }
    // Line field → vectors, signs along a breadth-first tree.
    let mut vectors = vec![[0.0; 3]; nv];
    for i in 0..nv {
        if u[i] == 0.0 && u[nv + i] == 0.0 {
            continue;
        }
        let theta = 0.5 * u[nv + i].atan2(u[i]);
        vectors[i] = vec3::add(vec3::scale(e1[i], theta.cos()), vec3::scale(e2[i], theta.sin()));
    }
    let mut seen = vec![false; nv];
    let mut queue = std::collections::VecDeque::new();
    for root in 0..nv {
        if seen[root] {
            continue;
        }
        seen[root] = true;
        queue.push_back(root);
        while let Some(i) = queue.pop_front() {
            for &j in &adjacency[i] {
                let j = j as usize;
                if !seen[j] {
                    seen[j] = true;
                    if vec3::dot(vectors[i], vectors[j]) < 0.0 {
                        vectors[j] = vec3::scale(vectors[j], -1.0);
                    }
                    queue.push_back(j);
                }
            }
        }
    }
    Ok(SmoothestField { vectors, aligned_area_fraction: aligned_area / tr_m })
}

/// Component label per vertex over `adjacency` (vertices without edges: own label).
fn vertex_components(adjacency: &[Vec<u32>]) -> Vec<u32> {
    let n = adjacency.len();
    let mut label = vec![u32::MAX; n];
    let mut next = 0u32;
    let mut stack = Vec::new();
    for s in 0..n {
        if label[s] != u32::MAX {
            continue;
        }
        label[s] = next;
        stack.push(s);
        while let Some(i) = stack.pop() {
            for &j in &adjacency[i] {
                if label[j as usize] == u32::MAX {
                    label[j as usize] = next;
                    stack.push(j as usize);
                }
            }
        }
        next += 1;
    }
    label
}

/// Scales `u` (`2#V`, real then imaginary parts) to unit M-norm on each component.
fn normalise_per_component(u: &mut [f64], mass: &[f64], comp: &[u32]) {
    let nv = mass.len();
    let nc = comp.iter().map(|&c| c as usize + 1).max().unwrap_or(0);
    let mut norm2 = vec![0.0f64; nc];
    for i in 0..nv {
        norm2[comp[i] as usize] += mass[i] * (u[i] * u[i] + u[nv + i] * u[nv + i]);
    }
    for i in 0..nv {
        let n = norm2[comp[i] as usize].sqrt();
        if n > 0.0 && n.is_finite() {
            u[i] /= n;
            u[nv + i] /= n;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_mesh::primitives;

    #[test]
    fn a_flat_mesh_gets_one_constant_direction() {
        // A 3 × 1 rectangle: the field is its long axis everywhere.
        let m = primitives::grid(24, 8, 3.0, 1.0);
        let f = smoothest_field(&m).unwrap();
        assert_eq!(f.aligned_area_fraction, 0.0);
        for v in &f.vectors {
            assert!((v[0].abs() - 1.0).abs() < 1e-3 && v[2].abs() < 1e-9, "{v:?}");
        }
        // Signs agree across the whole patch.
        assert!(f.vectors.iter().all(|v| v[0] * f.vectors[0][0] > 0.0));
    }

    #[test]
    fn a_torus_follows_its_curvature() {
        let m = primitives::torus(3.0, 1.0, 64, 24);
        let f = smoothest_field(&m).unwrap();
        assert!(f.aligned_area_fraction > 0.5, "{}", f.aligned_area_fraction);
        // The less curved principal direction runs around the main axis (toroidal).
        let mut along = 0.0;
        for (p, v) in m.positions.iter().zip(&f.vectors) {
            let r = p[0].hypot(p[1]);
            let toroidal = [-p[1] / r, p[0] / r, 0.0];
            along += vec3::dot(*v, toroidal).abs();
        }
        let mean = along / m.positions.len() as f64;
        assert!(mean > 0.9, "mean |cos| to the toroidal direction {mean:.3}");
    }
}
