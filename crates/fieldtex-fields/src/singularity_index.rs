//! Singularity indices of N-RoSy fields (N = 1: vector fields, N = 2: orientation
//! fields), on triangle meshes and on pixel grids.
//!
//! Mesh: the field is one tangent vector per triangle (the N-RoSy representative). Around
//! each interior vertex `v` the triangles are walked counter-clockwise (about their
//! normals); between consecutive triangles `f → g` across the edge `d` the angle change
//! relative to the Levi-Civita transport is `Δ = (φ_g − ψ_g) − (φ_f − ψ_f)`, where `φ` is
//! the vector's and `ψ` the shared edge's angle in each triangle's own frame. With the
//! N-fold symmetry each change is taken as `wrap(N·Δ)` (wrapped to `(−π, π]`), and
//!
//! `index(v) = (Σ wrap(N·Δ) + N·K_v) / (2π N)`,
//!
//! where `K_v = 2π − Σ angles` is the angle defect (0 on a flat patch), so that the
//! indices of a field on a closed surface sum to its Euler characteristic (Poincaré–Hopf;
//! see Ray et al. 2008 "N-symmetry direction field design" for the discrete index).
//! Boundary vertices have no closed loop and get no index.
//!
//! Pixel grid: the same sum over the four pixels around each 2×2 block (pixel centres
//! `(x+½, y+½)`; the block's centre is the grid point `(x+1, y+1)`), traversed from `+x`
//! towards `+y`.
//!
//! The primitives ([`wrap_angle`], [`turns`], [`loop_turns`]) are the workspace's one
//! index computation: the per-vertex surface field metrics (`surface_field_metrics.rs`)
//! and `fieldtex-eval`'s image singularities and phase defects count turns with them.
//!
//! Detections closer than a radius are merged ([`cluster_singularities`]): indices are
//! summed and zero-sum clusters dropped, so a sub-cell dipole does not count, while
//! separated singularities stay separate.

use fieldtex_core::vec3::{dot, norm, normalize, sub};
use rayon::prelude::*;

use crate::dec::Dec;

/// A detected singularity: position (mesh or pixel coordinates), index (multiples of
/// `1/N`) and the element it was found at (vertex or pixel block `y·(W−1) + x`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectedSingularity {
    pub position: [f64; 3],
    pub index: f64,
    pub element: usize,
}

/// `a` wrapped to `(−π, π]` (the one angle wrap of the index computations).
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let mut a = a % TAU;
    if a > PI {
        a -= TAU;
    } else if a <= -PI {
        a += TAU;
    }
    a
}

/// Whole turns in a sum of wrapped angle changes around a closed loop (plus, on a
/// surface, `N` times the enclosed curvature): `round(total / 2π)`. With the changes
/// taken on `N`-fold angles this is `N · index`.
#[inline]
pub fn turns(total: f64) -> i32 {
    (total / std::f64::consts::TAU).round() as i32
}

/// Turns of the angles `angles` (already multiplied by `N`) around a closed loop,
/// visited in order and back to the first: `turns(Σ wrap(aₖ₊₁ − aₖ))` — the index of
/// an N-RoSy field around a loop of samples in a flat domain is this over `N`.
#[inline]
pub fn loop_turns(angles: &[f64]) -> i32 {
    let n = angles.len();
    let total: f64 = (0..n).map(|k| wrap_angle(angles[(k + 1) % n] - angles[k])).sum();
    turns(total)
}

/// Triangles around interior vertex `v` in counter-clockwise order, or `None` for
/// boundary or non-manifold vertices.
pub fn one_ring_faces(dec: &Dec, v: usize) -> Option<Vec<usize>> {
    let faces = dec.topology.vertex_faces(v);
    let &f0 = faces.first()?;
    let mut ring = Vec::with_capacity(faces.len());
    let mut f = f0 as usize;
    loop {
        ring.push(f);
        let t = dec.triangles[f];
        let i = (0..3).find(|&i| t[i] as usize == v)?;
        let b = t[(i + 2) % 3];
        let e = crate::natural_boundary::find_edge(dec, v as u32, b)?;
        let ef = dec.topology.edge_faces(e);
        if ef.len() != 2 {
            return None;
        }
        f = if ef[0] as usize == f { ef[1] as usize } else { ef[0] as usize };
        if f == f0 as usize {
            break;
        }
        if ring.len() > faces.len() {
            return None;
        }
    }
    (ring.len() == faces.len()).then_some(ring)
}

/// Index of the per-triangle field `face_vectors` (3-D tangent vectors) around each
/// vertex, in units of `1/n` (`index_times_n[v] = n · index`); `None` at boundary and
/// non-manifold vertices.
pub fn vertex_indices(dec: &Dec, face_vectors: &[[f64; 3]], n: u32) -> Vec<Option<i32>> {
    use std::f64::consts::TAU;
    let nf = n as f64;
    // Own frame per triangle: first edge direction.
    let frame = |f: usize| {
        let t = dec.triangles[f];
        let e1 = normalize(sub(dec.positions[t[1] as usize], dec.positions[t[0] as usize]))
            .unwrap_or([1.0, 0.0, 0.0]);
        let e2 = fieldtex_core::vec3::cross(dec.face_normals[f], e1);
        (e1, e2)
    };
    (0..dec.n_vertices())
        .into_par_iter()
        .map(|v| {
            let ring = one_ring_faces(dec, v)?;
            let mut total = 0.0;
            let mut angle_sum = 0.0;
            for (k, &f) in ring.iter().enumerate() {
                let g = ring[(k + 1) % ring.len()];
                let t = dec.triangles[f];
                let i = (0..3).find(|&i| t[i] as usize == v)?;
                let (pa, pb) = (
                    dec.positions[t[(i + 1) % 3] as usize],
                    dec.positions[t[(i + 2) % 3] as usize],
                );
                let (da, db) = (sub(pa, dec.positions[v]), sub(pb, dec.positions[v]));
                let c =
                    (dot(da, db) / (norm(da) * norm(db)).max(f64::MIN_POSITIVE)).clamp(-1.0, 1.0);
                angle_sum += c.acos();
                let d = db; // shared edge v → b between f and g
                let (f1, f2) = frame(f);
                let (g1, g2) = frame(g);
                let (uf, ug) = (face_vectors[f], face_vectors[g]);
                let phi_f = dot(uf, f2).atan2(dot(uf, f1));
                let phi_g = dot(ug, g2).atan2(dot(ug, g1));
                let psi_f = dot(d, f2).atan2(dot(d, f1));
                let psi_g = dot(d, g2).atan2(dot(d, g1));
                total += wrap_angle(nf * ((phi_g - psi_g) - (phi_f - psi_f)));
            }
            let defect = TAU - angle_sum;
            Some(turns(total + nf * defect))
        })
        .collect()
}

/// Singular vertices of a per-triangle N-RoSy field (index ≠ 0), unclustered.
pub fn mesh_singularities(
    dec: &Dec,
    face_vectors: &[[f64; 3]],
    n: u32,
) -> Vec<DetectedSingularity> {
    vertex_indices(dec, face_vectors, n)
        .into_iter()
        .enumerate()
        .filter_map(|(v, i)| match i {
            Some(k) if k != 0 => Some(DetectedSingularity {
                position: dec.positions[v],
                index: k as f64 / n as f64,
                element: v,
            }),
            _ => None,
        })
        .collect()
}

/// Singular 2×2 pixel blocks of a `width × height` field of (representative) vectors
/// `(dx, dy)`, row-major, x right, y down; unclustered. Position = block centre.
pub fn pixel_singularities(
    field: &[[f32; 2]],
    width: usize,
    height: usize,
    n: u32,
) -> Vec<DetectedSingularity> {
    if width < 2 || height < 2 || field.len() < width * height {
        return Vec::new();
    }
    let nf = n as f64;
    let angle = |x: usize, y: usize| {
        let v = field[y * width + x];
        (v[1] as f64).atan2(v[0] as f64) * nf
    };
    let rows: Vec<Vec<DetectedSingularity>> = (0..height - 1)
        .into_par_iter()
        .map(|y| {
            let mut out = Vec::new();
            for x in 0..width - 1 {
                let a = [angle(x, y), angle(x + 1, y), angle(x + 1, y + 1), angle(x, y + 1)];
                let k = loop_turns(&a);
                if k != 0 {
                    out.push(DetectedSingularity {
                        position: [x as f64 + 1.0, y as f64 + 1.0, 0.0],
                        index: k as f64 / nf,
                        element: y * (width - 1) + x,
                    });
                }
            }
            out
        })
        .collect();
    rows.into_iter().flatten().collect()
}

/// Merges detections closer than `radius` (transitively): the cluster's index is the
/// sum, its position the mean of its members; clusters with index 0 are dropped.
/// Output order follows the first member's input order (deterministic).
pub fn cluster_singularities(
    found: &[DetectedSingularity],
    radius: f64,
) -> Vec<DetectedSingularity> {
    let n = found.len();
    let mut uf = fieldtex_mesh::UnionFind::new(n);
    let r2 = radius * radius;
    for i in 0..n {
        for j in i + 1..n {
            let d = sub(found[i].position, found[j].position);
            if dot(d, d) <= r2 {
                uf.union(i, j);
            }
        }
    }
    let mut order: Vec<usize> = Vec::new();
    let mut acc: Vec<([f64; 3], f64, usize, usize)> = Vec::new(); // pos sum, index, count, first
    let mut slot = vec![usize::MAX; n];
    for i in 0..n {
        let r = uf.find(i);
        if slot[r] == usize::MAX {
            slot[r] = acc.len();
            acc.push(([0.0; 3], 0.0, 0, i));
            order.push(r);
        }
        let a = &mut acc[slot[r]];
        a.0 = fieldtex_core::vec3::add(a.0, found[i].position);
        a.1 += found[i].index;
        a.2 += 1;
    }
    acc.into_iter()
        .filter(|a| a.1.abs() > 1e-9)
        .map(|(p, index, count, first)| DetectedSingularity {
            position: fieldtex_core::vec3::scale(p, 1.0 / count as f64),
            index,
            element: found[first].element,
        })
        .collect()
}
