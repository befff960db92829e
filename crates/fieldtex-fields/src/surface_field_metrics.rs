//! Quality measures of a per-vertex tangent vector field on a triangle mesh: singularity
//! indices per face, Dirichlet energy, alignment with constraints (DESIGN.md §6, "field
//! quality").
//!
//! **Transport** (intrinsic, exact Gauss–Bonnet). Every vertex gets polar coordinates:
//! its corner angles, walked counter-clockwise from a reference edge and scaled by
//! `2π / Σ angles` at interior vertices (unscaled at boundary vertices), give each
//! outgoing edge `ij` an angle `θ_ij`. A tangent vector `uᵢ` (3-D, in the plane of the
//! vertex normal `nᵢ`) gets the angle `φᵢ` by interpolating between the projected edge
//! directions of the wedge it lies in. Transport along edge `ij` adds
//! `ρ_ij = θ_ji − θ_ij + π` (the angle to the edge is kept: the Levi-Civita connection
//! of Knöppel, Crane, Pinkall & Schröder 2013, "Globally optimal direction fields"), and
//! the field turns by `δ_ij = wrap(φⱼ − φᵢ − ρ_ij) ∈ (−π, π]`, computed once per edge
//! (low → high index) so that `δ_ji = −δ_ij` exactly.
//!
//! **Index** of face `f = (i, j, k)` (counter-clockwise):
//! `index_f = (δ_ij + δ_jk + δ_ki + K_f) / 2π` with `K_f = Σ` scaled corner angles `− π`,
//! the face's share of Gaussian curvature (the holonomy of its loop); the numerator is a
//! multiple of `2π` up to rounding. The `δ` cancel between the two faces of an edge and
//! `Σ_f K_f = 2π (V − F/2) = 2πχ` on a closed mesh, so the indices of a closed,
//! consistently oriented manifold sum to `χ` exactly (Poincaré–Hopf), whatever the
//! field. Faces touching a zero vector or a vertex whose one-ring is not a single fan
//! (non-manifold, inconsistently oriented) are *undetermined* and get no index.
//!
//! **Dirichlet energy** `Σ_edges w_ij |T_ij uᵢ − uⱼ|² = Σ w_ij (2 − 2 cos δ_ij)` with the
//! cotan weights `w_ij` (transported: a parallel field costs 0), and the ambient variant
//! `Σ w_ij |uᵢ − uⱼ|²` (what paper A's per-component diffusion minimises). Edges with an
//! undefined end are left out.
//!
//! The field is projected to the tangent planes and normalised first; vectors shorter
//! than `1e-12` count as undefined.

use fieldtex_core::vec3::{self, V3};
use fieldtex_mesh::{MeshGeometry, NormalWeighting, Topology, TriMesh};
use rayon::prelude::*;
use serde::Serialize;

use crate::FieldsError;
use crate::singularity_index::{turns as index_turns, wrap_angle};

/// A face whose field index is not zero.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FieldSingularity {
    pub face: usize,
    pub index: i32,
    /// Centroid of the face.
    pub position: V3,
}

/// Mean and largest angle between the field and constraint tangents.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct AlignmentError {
    pub mean_deg: f64,
    pub max_deg: f64,
    /// Constraints measured (those where the field is defined).
    pub n: usize,
}

/// All field quality measures of [`surface_field_metrics`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SurfaceFieldMetrics {
    pub singularities: Vec<FieldSingularity>,
    /// Sum of all face indices (`χ` for a closed surface when no face is undetermined).
    pub index_sum: i32,
    /// `χ = V − E + F` of the mesh (used vertices only), to compare with `index_sum`.
    pub euler_characteristic: i64,
    /// Faces without an index (a zero vector at a corner, opposite normals).
    pub undetermined_faces: usize,
    /// Transported Dirichlet energy (module docs).
    pub dirichlet_energy: f64,
    /// Ambient Dirichlet energy `Σ w |uᵢ − uⱼ|²`.
    pub dirichlet_energy_ambient: f64,
    pub alignment: AlignmentError,
}

/// Signed angle from `a` to `b` about `n`.
fn signed_angle(a: V3, b: V3, n: V3) -> f64 {
    vec3::dot(n, vec3::cross(a, b)).atan2(vec3::dot(a, b))
}

/// Per-vertex unit tangent vectors (projected onto the normals), `None` where undefined.
fn unit_tangents(field: &[V3], normals: &[V3]) -> Vec<Option<V3>> {
    field
        .par_iter()
        .zip(normals.par_iter())
        .map(|(&u, &n)| {
            let t = vec3::sub(u, vec3::scale(n, vec3::dot(u, n)));
            let len = vec3::norm(t);
            (len > 1e-12 && len.is_finite()).then(|| vec3::scale(t, 1.0 / len))
        })
        .collect()
}

/// Polar coordinates of one vertex: per incident corner `(face, corner, θ of the edge to
/// the next corner, scaled corner angle)`, and the field angle `φ`. `None` when the
/// one-ring is not a single consistently oriented fan.
type VertexPolar = (Vec<(u32, u8, f64, f64)>, Option<f64>);

fn vertex_polar(
    mesh: &TriMesh,
    topology: &Topology,
    normal: V3,
    u: Option<V3>,
    v: usize,
) -> Option<VertexPolar> {
    use std::f64::consts::TAU;
    let p = &mesh.positions;
    // (a, b, face, corner, angle) for every corner (v, a, b) in counter-clockwise order.
    let mut fan = Vec::new();
    for &f in topology.vertex_faces(v) {
        let t = mesh.triangles[f as usize];
        let c = (0..3).find(|&c| t[c] as usize == v)?;
        let (a, b) = (t[(c + 1) % 3], t[(c + 2) % 3]);
        if a as usize == v || b as usize == v || a == b {
            return None;
        }
        let ang = fieldtex_mesh::normals::corner_angle(p[v], p[a as usize], p[b as usize]);
        fan.push((a, b, f, c as u8, ang));
    }
    let starts: Vec<usize> =
        (0..fan.len()).filter(|&k| !fan.iter().any(|e| e.1 == fan[k].0)).collect();
    let interior = starts.is_empty();
    if starts.len() > 1 || fan.is_empty() {
        return None;
    }
    let mut order = vec![starts.first().copied().unwrap_or(0)];
    while order.len() < fan.len() {
        let b = fan[*order.last().expect("non-empty")].1;
        let mut next = (0..fan.len()).filter(|&k| fan[k].0 == b);
        let k = next.next()?;
        if next.next().is_some() || order.contains(&k) {
            return None;
        }
        order.push(k);
    }
    if interior && fan[order[fan.len() - 1]].1 != fan[order[0]].0 {
        return None;
    }
    let total: f64 = fan.iter().map(|e| e.4).sum();
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    let scale = if interior { TAU / total } else { 1.0 };
    let mut corners = Vec::with_capacity(fan.len());
    let mut theta = 0.0;
    for &k in &order {
        let (_, _, f, c, ang) = fan[k];
        corners.push((f, c, theta, ang * scale));
        theta += ang * scale;
    }
    // Field angle: interpolate between the projected edge directions of its wedge.
    let phi = u.and_then(|u| {
        let proj = |w: u32| {
            let d = vec3::sub(p[w as usize], p[v]);
            vec3::normalize(vec3::sub(d, vec3::scale(normal, vec3::dot(d, normal))))
        };
        let reference = proj(fan[order[0]].0)?;
        let psi = |d: V3| signed_angle(reference, d, normal).rem_euclid(TAU);
        let pu = psi(u);
        let mut lo = 0.0;
        for (i, &k) in order.iter().enumerate() {
            let hi = if interior && i + 1 == order.len() { TAU } else { psi(proj(fan[k].1)?) };
            if hi.is_nan() || hi <= lo {
                return Some(pu); // folded projection: plain extrinsic angle
            }
            if pu < hi {
                return Some(corners[i].2 + corners[i].3 * (pu - lo) / (hi - lo));
            }
            lo = hi;
        }
        Some(theta + (pu - lo)) // outside a boundary fan
    });
    Some((corners, phi))
}

/// Field turn `δ_e` of every edge (low → high) and curvature `K_f` of every face
/// (module docs); `None` where undefined.
fn field_turns(
    mesh: &TriMesh,
    topology: &Topology,
    normals: &[V3],
    field: &[V3],
) -> (Vec<Option<f64>>, Vec<Option<f64>>) {
    let u = unit_tangents(field, normals);
    let polar: Vec<Option<VertexPolar>> = (0..mesh.n_vertices())
        .into_par_iter()
        .map(|v| vertex_polar(mesh, topology, normals[v], u[v], v))
        .collect();
    let nf = mesh.n_triangles();
    // Per corner: θ of the edge to the next corner and the scaled angle.
    let mut corner: Vec<[Option<(f64, f64)>; 3]> = vec![[None; 3]; nf];
    let mut phi = vec![None; mesh.n_vertices()];
    for (v, pv) in polar.iter().enumerate() {
        if let Some((corners, ph)) = pv {
            phi[v] = *ph;
            for &(f, c, theta, scaled) in corners {
                corner[f as usize][c as usize] = Some((theta, scaled));
            }
        }
    }
    let turns: Vec<Option<f64>> = (0..topology.n_edges())
        .into_par_iter()
        .map(|e| {
            let [a, b] = topology.edges[e];
            let &f = topology.edge_faces(e).first()?;
            let t = mesh.triangles[f as usize];
            let ca = (0..3).find(|&c| t[c] == a)?;
            let cb = (0..3).find(|&c| t[c] == b)?;
            let (na, sa) = corner[f as usize][ca]?;
            let (nb, sb) = corner[f as usize][cb]?;
            // θ_ab and θ_ba: `b` follows `a` in the face, or precedes it.
            let (tab, tba) = if t[(ca + 1) % 3] == b { (na, nb + sb) } else { (na + sa, nb) };
            let rho = tba - tab + std::f64::consts::PI;
            Some(wrap_angle(phi[b as usize]? - phi[a as usize]? - rho))
        })
        .collect();
    let curvature: Vec<Option<f64>> = corner
        .par_iter()
        .map(|c| Some(c[0]?.1 + c[1]?.1 + c[2]?.1 - std::f64::consts::PI))
        .collect();
    (turns, curvature)
}

/// Singularities of `field` (`#V × 3`) with vertex `normals`: the faces of non-zero
/// index, and the number of undetermined faces (module docs).
pub fn field_singularities(
    mesh: &TriMesh,
    topology: &Topology,
    normals: &[V3],
    field: &[V3],
) -> (Vec<FieldSingularity>, usize) {
    let (turns, curvature) = field_turns(mesh, topology, normals, field);
    let per_face: Vec<Option<i32>> = (0..mesh.n_triangles())
        .into_par_iter()
        .map(|f| {
            let mut sum = curvature[f]?;
            for c in 0..3 {
                let e = topology.face_edges[f][c] as usize;
                sum += f64::from(topology.face_edge_signs[f][c]) * turns[e]?;
            }
            Some(index_turns(sum))
        })
        .collect();
    let mut singularities = Vec::new();
    let mut undetermined = 0;
    for (f, idx) in per_face.iter().enumerate() {
        match idx {
            None => undetermined += 1,
            Some(0) => {}
            Some(index) => {
                let p = mesh.triangle_positions(f);
                let position = vec3::scale(vec3::add(vec3::add(p[0], p[1]), p[2]), 1.0 / 3.0);
                singularities.push(FieldSingularity { face: f, index: *index, position });
            }
        }
    }
    (singularities, undetermined)
}

/// `(transported, ambient)` Dirichlet energies with the `#E` edge weights (module docs).
pub fn field_dirichlet_energy(
    mesh: &TriMesh,
    topology: &Topology,
    normals: &[V3],
    field: &[V3],
    edge_weights: &[f64],
) -> (f64, f64) {
    let u = unit_tangents(field, normals);
    let (turns, _) = field_turns(mesh, topology, normals, field);
    let per_edge: Vec<(f64, f64)> = (0..topology.n_edges())
        .into_par_iter()
        .map(|e| {
            let [a, b] = topology.edges[e];
            let w = edge_weights[e];
            let ambient = match (u[a as usize], u[b as usize]) {
                (Some(ua), Some(ub)) => w * vec3::norm2(vec3::sub(ua, ub)),
                _ => 0.0,
            };
            (turns[e].map_or(0.0, |d| w * (2.0 - 2.0 * d.cos())), ambient)
        })
        .collect();
    // Sequential sum: the same for any thread count.
    per_edge.iter().fold((0.0, 0.0), |(s, t), &(a, b)| (s + a, t + b))
}

/// Angles between the field and `constraints` (`(vertex, tangent)`), where both are
/// defined after projection to the tangent plane.
pub fn constraint_alignment_error(
    normals: &[V3],
    field: &[V3],
    constraints: &[(u32, V3)],
) -> AlignmentError {
    let mut e = AlignmentError::default();
    let mut sum = 0.0;
    for &(v, t) in constraints {
        let v = v as usize;
        if v >= field.len() {
            continue;
        }
        let u = unit_tangents(&[field[v], t], &[normals[v], normals[v]]);
        if let [Some(a), Some(b)] = u[..] {
            let ang = vec3::norm(vec3::cross(a, b)).atan2(vec3::dot(a, b)).to_degrees();
            sum += ang;
            e.max_deg = e.max_deg.max(ang);
            e.n += 1;
        }
    }
    e.mean_deg = if e.n > 0 { sum / e.n as f64 } else { 0.0 };
    e
}

/// Every measure at once (builds the topology, angle-weighted vertex normals and cotan
/// edge weights). `constraints` may be empty.
pub fn surface_field_metrics(
    mesh: &TriMesh,
    field: &[V3],
    constraints: &[(u32, V3)],
) -> Result<SurfaceFieldMetrics, FieldsError> {
    surface_field_metrics_with(&MeshGeometry::new(mesh), field, constraints)
}

/// [`surface_field_metrics`] with the topology, angle-weighted normals and cotan edge
/// weights of a per-mesh [`MeshGeometry`] (computed there at most once per pipeline).
pub fn surface_field_metrics_with(
    geometry: &MeshGeometry<'_>,
    field: &[V3],
    constraints: &[(u32, V3)],
) -> Result<SurfaceFieldMetrics, FieldsError> {
    let mesh = geometry.mesh();
    mesh.validate()?;
    if field.len() != mesh.n_vertices() {
        return Err(FieldsError::InvalidOption {
            name: "field length",
            value: field.len() as f64,
            expected: "one vector per mesh vertex",
        });
    }
    let topology = geometry.require_topology();
    let (normals, _) = geometry.require_vertex_normals(NormalWeighting::Angle);
    let (weights, _) = geometry.require_cotan_edge_weights()?;
    let (singularities, undetermined_faces) = field_singularities(mesh, topology, normals, field);
    let (dirichlet_energy, dirichlet_energy_ambient) =
        field_dirichlet_energy(mesh, topology, normals, field, weights);
    Ok(SurfaceFieldMetrics {
        index_sum: singularities.iter().map(|s| s.index).sum(),
        euler_characteristic: topology.euler_characteristic(),
        singularities,
        undetermined_faces,
        dirichlet_energy,
        dirichlet_energy_ambient,
        alignment: constraint_alignment_error(normals, field, constraints),
    })
}
