//! Per-vertex principal curvatures and directions from per-face curvature tensors.
//!
//! Method: Rusinkiewicz 2004, "Estimating Curvatures and Their Derivatives on Triangle
//! Meshes" (3DPVT), §3: per triangle, the second fundamental form `II` (a symmetric
//! 2×2 tensor in an orthonormal frame of the triangle's plane) is the least-squares
//! solution of `II · e = Δn` over its three edges `e` with `Δn` the difference of the
//! vertex normals at the edge's ends (6 equations, 3 unknowns); each vertex then
//! averages the tensors of its triangles, rotated into its own tangent frame, weighted
//! by the triangle's mixed Voronoi share of the vertex (Meyer et al. 2003). The
//! eigen-decomposition of the averaged tensor gives `k_max ≥ k_min` and their unit
//! directions.
//!
//! Sign convention: curvature is positive where the surface bends away from its normal
//! (`II = dn/dx`): a sphere with outward normals has `k = +1/r`, a cylinder `(1/r, 0)`
//! with the `k_max` direction around the axis. Normals are angle-weighted vertex normals
//! ([`crate::vertex_normals`]).
//!
//! Robustness: there is no per-vertex fit that can run short of neighbours: a vertex
//! with a single valid triangle still gets an estimate. Triangles with zero area or a
//! singular least-squares system are skipped; a vertex left with no valid triangle
//! (unreferenced, or only degenerate triangles) takes the average tensor of its
//! neighbours, growing the ring up to [`CurvatureOptions::fallback_rings`] times, and is
//! otherwise set to zero curvature; these vertices are counted in a warning. Boundary
//! vertices use the triangles they have. On planar regions (`II = 0`) and at umbilics the
//! directions are arbitrary but always finite, unit and orthonormal to the normal.
//! Optional smoothing averages each vertex's tensor with its 1-ring
//! ([`CurvatureOptions::smoothing_iterations`]).
//!
//! Not implemented: the curvature-derivative tensor of the same paper (§4).

use crate::areas::mixed_voronoi_corner_areas;
use crate::normals::{NormalWeighting, vertex_normals};
use crate::{MeshError, TriMesh};
use fieldtex_core::Warning;
use fieldtex_core::vec3::{self, V3};
use rayon::prelude::*;

/// Options of [`principal_curvatures`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvatureOptions {
    /// Passes of 1-ring tensor averaging after the per-vertex estimate (area weighted).
    /// Default 0 (the plain Rusinkiewicz estimate); 1–3 reduce noise on scans.
    pub smoothing_iterations: usize,
    /// How many times a vertex without a valid triangle may widen its neighbourhood to
    /// borrow a tensor before it is set to zero curvature. Default 3.
    pub fallback_rings: usize,
}

impl Default for CurvatureOptions {
    fn default() -> Self {
        Self { smoothing_iterations: 0, fallback_rings: 3 }
    }
}

/// Per-vertex principal curvatures (`#V` each) and frames (`#V × 3` each).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PrincipalCurvatures {
    /// Larger principal curvature.
    pub k_max: Vec<f64>,
    /// Smaller principal curvature (`k_min ≤ k_max`).
    pub k_min: Vec<f64>,
    /// Unit direction of `k_max`, orthogonal to `normals`.
    pub dir_max: Vec<V3>,
    /// Unit direction of `k_min`: `normal × dir_max`.
    pub dir_min: Vec<V3>,
    /// The unit vertex normals used.
    pub normals: Vec<V3>,
}

impl PrincipalCurvatures {
    /// `#V` mean curvature `(k_max + k_min) / 2`.
    pub fn mean(&self) -> Vec<f64> {
        self.k_max.iter().zip(&self.k_min).map(|(a, b)| 0.5 * (a + b)).collect()
    }
    /// `#V` Gaussian curvature `k_max · k_min`.
    pub fn gaussian(&self) -> Vec<f64> {
        self.k_max.iter().zip(&self.k_min).map(|(a, b)| a * b).collect()
    }
}

/// A symmetric 2×2 tensor `[[a, b], [b, c]]` in some orthonormal frame.
type Tensor = [f64; 3];

/// A face's tensor, its frame `(u, v)`, its normal and its corners' Voronoi shares.
type FaceTensor = (Tensor, (V3, V3), V3, [f64; 3]);

/// Rotates the tangent vector `x` (orthogonal to unit `from`) by the smallest rotation
/// taking `from` to unit `to`; `None` when the normals are (nearly) opposite.
#[inline]
fn rotate_tangent(x: V3, from: V3, to: V3) -> Option<V3> {
    let c = vec3::dot(from, to);
    if c <= -1.0 + 1e-12 {
        return None;
    }
    let s = vec3::dot(x, to) / (1.0 + c);
    Some(vec3::sub(x, vec3::scale(vec3::add(from, to), s)))
}

/// Re-expresses tensor `t` given in frame `(fu, fv)` in frame `(u, v)` lying in the
/// same plane.
#[inline]
fn change_frame(t: Tensor, (fu, fv): (V3, V3), (u, v): (V3, V3)) -> Tensor {
    let (u1, v1) = (vec3::dot(u, fu), vec3::dot(u, fv));
    let (u2, v2) = (vec3::dot(v, fu), vec3::dot(v, fv));
    [
        t[0] * u1 * u1 + 2.0 * t[1] * u1 * v1 + t[2] * v1 * v1,
        t[0] * u1 * u2 + t[1] * (u1 * v2 + u2 * v1) + t[2] * v1 * v2,
        t[0] * u2 * u2 + 2.0 * t[1] * u2 * v2 + t[2] * v2 * v2,
    ]
}

/// Transfers tensor `t` from frame `src` (normal `src_n`) into vertex frame `dst`
/// (normal `dst_n`): the vertex frame is rotated into the source plane first.
#[inline]
fn transfer(t: Tensor, src: (V3, V3), src_n: V3, dst: (V3, V3), dst_n: V3) -> Option<Tensor> {
    let u = rotate_tangent(dst.0, dst_n, src_n)?;
    let v = rotate_tangent(dst.1, dst_n, src_n)?;
    Some(change_frame(t, src, (u, v)))
}

/// Per-face tensor in the face frame `(u_f, v_f)` with normal `n_f`, or `None` for a
/// degenerate triangle or a singular system.
fn face_tensor(p: [V3; 3], n: [V3; 3]) -> Option<(Tensor, (V3, V3), V3)> {
    let e0 = vec3::sub(p[1], p[0]);
    let mut nf = vec3::normalize(vec3::cross(e0, vec3::sub(p[2], p[0])))?;
    // Orient the face frame like its vertex normals (tolerates flipped triangles).
    if vec3::dot(nf, vec3::add(vec3::add(n[0], n[1]), n[2])) < 0.0 {
        nf = vec3::scale(nf, -1.0);
    }
    let uf = vec3::normalize(e0)?;
    let vf = vec3::cross(nf, uf);
    let mut m = [[0.0; 3]; 3];
    let mut r = [0.0; 3];
    let mut scale = 0.0;
    for i in 0..3 {
        let (a, b) = ((i + 1) % 3, (i + 2) % 3);
        let e = vec3::sub(p[b], p[a]);
        let dn = vec3::sub(n[b], n[a]);
        let (eu, ev) = (vec3::dot(e, uf), vec3::dot(e, vf));
        let (nu, nv) = (vec3::dot(dn, uf), vec3::dot(dn, vf));
        m[0][0] += eu * eu;
        m[0][1] += eu * ev;
        m[1][1] += eu * eu + ev * ev;
        m[1][2] += eu * ev;
        m[2][2] += ev * ev;
        r[0] += nu * eu;
        r[1] += nu * ev + nv * eu;
        r[2] += nv * ev;
        scale += eu * eu + ev * ev;
    }
    m[1][0] = m[0][1];
    m[2][1] = m[1][2];
    let t = solve3(m, r, scale)?;
    if t.iter().all(|x| x.is_finite()) { Some((t, (uf, vf), nf)) } else { None }
}

/// Solves the symmetric 3×3 system `m x = r` by Cramer's rule; `None` when the
/// determinant is negligible relative to `scale³`.
fn solve3(m: [[f64; 3]; 3], r: [f64; 3], scale: f64) -> Option<[f64; 3]> {
    let det3 = |a: [[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let d = det3(m);
    if d.is_nan() || d.abs() <= 1e-12 * scale * scale * scale {
        return None;
    }
    let mut x = [0.0; 3];
    for (k, xk) in x.iter_mut().enumerate() {
        let mut a = m;
        for row in 0..3 {
            a[row][k] = r[row];
        }
        *xk = det3(a) / d;
    }
    Some(x)
}

/// Eigen-decomposition of a tensor in frame `(u, v)`: `(k_max, k_min, dir_max)`.
fn eigen(t: Tensor, (u, v): (V3, V3)) -> (f64, f64, V3) {
    let h = 0.5 * (t[0] - t[2]);
    let rad = h.hypot(t[1]);
    let mid = 0.5 * (t[0] + t[2]);
    let theta = 0.5 * t[1].atan2(h);
    let (s, c) = if theta.is_finite() { theta.sin_cos() } else { (0.0, 1.0) };
    let d = vec3::normalize(vec3::add(vec3::scale(u, c), vec3::scale(v, s))).unwrap_or(u);
    (mid + rad, mid - rad, d)
}

/// Principal curvatures and directions of every vertex (module docs), with a warning
/// counting the vertices that needed a fallback.
pub fn principal_curvatures(
    mesh: &TriMesh,
    options: &CurvatureOptions,
) -> Result<(PrincipalCurvatures, Vec<Warning>), MeshError> {
    crate::checks::check_indices(mesh)?;
    let nv = mesh.n_vertices();
    let (normals, _) = vertex_normals(mesh, NormalWeighting::Angle);
    let frames: Vec<(V3, V3)> = normals
        .iter()
        .map(|&n| {
            let u = vec3::any_orthonormal(n);
            (u, vec3::cross(n, u))
        })
        .collect();
    let faces: Vec<Option<FaceTensor>> = mesh
        .triangles
        .par_iter()
        .with_min_len(1024)
        .map(|t| {
            let p = t.map(|i| mesh.positions[i as usize]);
            let n = t.map(|i| normals[i as usize]);
            let (ten, frame, nf) = face_tensor(p, n)?;
            Some((ten, frame, nf, mixed_voronoi_corner_areas(p[0], p[1], p[2])))
        })
        .collect();
    let (offsets, corners) = crate::cotan_laplacian::vertex_corners(nv, &mesh.triangles);
    let corner_range = |v: usize| offsets[v] as usize..offsets[v + 1] as usize;
    let mut tensors: Vec<Option<Tensor>> = (0..nv)
        .into_par_iter()
        .with_min_len(1024)
        .map(|v| {
            let mut acc = [0.0; 3];
            let mut wsum = 0.0;
            for &c in &corners[corner_range(v)] {
                let (f, i) = ((c / 3) as usize, (c % 3) as usize);
                let Some((t, frame, nf, shares)) = faces[f] else { continue };
                let w = shares[i];
                if w <= 0.0 {
                    continue;
                }
                if let Some(tv) = transfer(t, frame, nf, frames[v], normals[v]) {
                    for k in 0..3 {
                        acc[k] += w * tv[k];
                    }
                    wsum += w;
                }
            }
            (wsum > 0.0).then(|| acc.map(|a| a / wsum))
        })
        .collect();
    // Neighbours through shared triangles, for the fallback and for smoothing.
    let ring = |v: usize| {
        corners[corner_range(v)].iter().flat_map(|&c| {
            let t = mesh.triangles[(c / 3) as usize];
            let i = (c % 3) as usize;
            [t[(i + 1) % 3] as usize, t[(i + 2) % 3] as usize]
        })
    };
    let average_ring = |v: usize, tensors: &[Option<Tensor>], weights: Option<&[f64]>| {
        let mut acc = [0.0; 3];
        let mut wsum = 0.0;
        for q in std::iter::once(v).chain(ring(v)) {
            let Some(t) = tensors[q] else { continue };
            let w = weights.map_or(1.0, |w| w[q]);
            if w <= 0.0 {
                continue;
            }
            let tv = if q == v {
                Some(t)
            } else {
                transfer(t, frames[q], normals[q], frames[v], normals[v])
            };
            if let Some(tv) = tv {
                for k in 0..3 {
                    acc[k] += w * tv[k];
                }
                wsum += w;
            }
        }
        (wsum > 0.0).then(|| acc.map(|a| a / wsum))
    };
    let missing_before = tensors.iter().filter(|t| t.is_none()).count();
    for _ in 0..options.fallback_rings {
        if tensors.iter().all(Option::is_some) {
            break;
        }
        let grown: Vec<Option<Tensor>> = (0..nv)
            .into_par_iter()
            .with_min_len(1024)
            .map(|v| tensors[v].or_else(|| average_ring(v, &tensors, None)))
            .collect();
        tensors = grown;
    }
    let n_zero = tensors.iter().filter(|t| t.is_none()).count();
    if options.smoothing_iterations > 0 {
        let areas = crate::areas::mixed_voronoi_vertex_areas(mesh);
        for _ in 0..options.smoothing_iterations {
            let smoothed: Vec<Option<Tensor>> = (0..nv)
                .into_par_iter()
                .with_min_len(1024)
                .map(|v| tensors[v].and(average_ring(v, &tensors, Some(&areas))).or(tensors[v]))
                .collect();
            tensors = smoothed;
        }
    }
    let mut out = PrincipalCurvatures {
        k_max: vec![0.0; nv],
        k_min: vec![0.0; nv],
        dir_max: vec![[0.0; 3]; nv],
        dir_min: vec![[0.0; 3]; nv],
        normals,
    };
    for v in 0..nv {
        let (k1, k2, d1) = eigen(tensors[v].unwrap_or([0.0; 3]), frames[v]);
        out.k_max[v] = k1;
        out.k_min[v] = k2;
        out.dir_max[v] = d1;
        out.dir_min[v] = vec3::cross(out.normals[v], d1);
    }
    let mut warnings = Vec::new();
    if missing_before > 0 {
        warnings.push(Warning::new(
            "curvature-fallback",
            format!(
                "{missing_before} vertices have no non-degenerate triangle to estimate \
                 curvature from; {} borrowed it from their neighbours and {n_zero} \
                 (e.g. unreferenced vertices) were set to zero curvature",
                missing_before - n_zero
            ),
        ));
    }
    Ok((out, warnings))
}

#[cfg(test)]
#[path = "principal_curvature_tests.rs"]
mod tests;
