//! Zero crossings of an extremality coefficient on mesh edges, joined inside triangles
//! and linked into polylines: the curvature half of the crest-line detector.
//!
//! Yoshizawa, Belyaev & Seidel 2005, §3, and Ohtake, Belyaev & Seidel 2004, §2:
//!
//! 1. **Edge test.** On edge `(a, b)` the principal direction `t_b` is flipped (with
//!    `e_b`) when `t_a · t_b < 0`, since both are only defined up to sign. The edge
//!    carries a crossing when `e_a` and `e_b` then have opposite signs; it lies at
//!    `λ = e_a / (e_a − e_b)` along the edge (linear interpolation).
//! 2. **Extremum type.** A ridge is a *maximum* of `k_max` along `t_max`: walking
//!    from `a` towards the crossing, `k` must increase, so `e_a · ((b − a) · t_a) > 0`,
//!    and symmetrically at `b`. The detector requires the sum
//!    `e_a ((b−a)·t_a) − e_b ((b−a)·t_b)` to be positive for a ridge (a discrete
//!    `∂e_max/∂t_max < 0`) and negative for a valley (a minimum of `k_min`,
//!    `∂e_min/∂t_min > 0`).
//! 3. **Curvature dominance, flatness, umbilics.** At the crossing (values
//!    interpolated with `λ`) a ridge needs `k_max > |k_min|` and `k_max ≥ flat`, a
//!    valley `k_min < −|k_max|` and `−k_min ≥ flat`; both need the anisotropy
//!    `|k_max − k_min| / |k|` to reach a minimum. These remove the noisy zero sets of
//!    `e` on planes and near umbilics (spheres), where `t` is arbitrary.
//! 4. **Triangles.** A triangle whose three directions cannot be oriented
//!    consistently (the product of the signs of `t_a·t_b`, `t_b·t_c`, `t_c·t_a` is
//!    negative: it contains a singularity of the direction field) is skipped, as are
//!    triangles the caller masks out (near creases and boundaries). Two crossings in a
//!    triangle give a segment; three are joined to the triangle's centroid
//!    (Ohtake et al. 2004), a junction where polylines stop.
//! 5. **Linking.** Crossings are shared by the two triangles of their edge, so
//!    segments form a graph whose nodes have degree ≤ 2 except at junctions; maximal
//!    paths through degree-2 nodes become polylines, closed cycles closed polylines.
//! 6. **Sharpness.** A line is kept when the length-weighted mean of the
//!    dimensionless sharpness `|∂e/∂t| / |k|³` of its triangles reaches a minimum.
//!    This is a scale-free form of the sharpness Yoshizawa et al. integrate along
//!    crest lines; it removes the zero sets of `e` where `k` barely varies across the
//!    line (cylinders, tori, tube-like limbs), which are discretisation noise.

use fieldtex_core::vec3::{self, V3};
use fieldtex_mesh::{Csr, Topology, TriMesh};

/// One principal-curvature family to trace (ridges use `k_max`, valleys `k_min`).
pub(crate) struct Family<'a> {
    /// `#V` curvature whose extrema are traced.
    pub k: &'a [f64],
    /// `#V` the other principal curvature.
    pub k_other: &'a [f64],
    /// `#V × 3` unit direction of `k`.
    pub t: &'a [V3],
    /// `#V` extremality coefficient `∇k · t`.
    pub e: &'a [f64],
    /// `true` for ridges (maxima of `k_max`), `false` for valleys.
    pub ridge: bool,
    /// Minimum `|k|` at a crossing.
    pub flat: f64,
    /// Minimum `|k − k_other| / max(|k|, |k_other|)` at a crossing.
    pub anisotropy: f64,
    /// Minimum length-weighted mean sharpness of a traced line.
    pub sharpness: f64,
}

/// A polyline on the mesh with the triangle of every point.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RawLine {
    pub points: Vec<V3>,
    pub faces: Vec<u32>,
    pub closed: bool,
}

/// Counters of one traced family.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct CrossingCounts {
    pub crossings: usize,
    pub segments: usize,
    pub junctions: usize,
    pub inconsistent_triangles: usize,
    /// Linked lines dropped for a mean sharpness below the minimum.
    pub blunt_lines: usize,
}

/// The crossing on edge `e`, as `λ` from `edges[e][0]`, or `None` (module docs).
fn edge_crossing(mesh: &TriMesh, topo: &Topology, fam: &Family, e: usize) -> Option<f64> {
    let [a, b] = topo.edges[e].map(|v| v as usize);
    if a == b {
        return None;
    }
    let (ta, mut tb) = (fam.t[a], fam.t[b]);
    let (ea, mut eb) = (fam.e[a], fam.e[b]);
    if vec3::dot(ta, tb) < 0.0 {
        tb = vec3::scale(tb, -1.0);
        eb = -eb;
    }
    if (ea >= 0.0) == (eb >= 0.0) {
        return None;
    }
    let d = vec3::sub(mesh.positions[b], mesh.positions[a]);
    let test = ea * vec3::dot(d, ta) - eb * vec3::dot(d, tb);
    if (fam.ridge && test <= 0.0) || (!fam.ridge && test >= 0.0) {
        return None;
    }
    let lambda = ea / (ea - eb);
    if !lambda.is_finite() {
        return None;
    }
    let lambda = lambda.clamp(0.0, 1.0);
    let k = fam.k[a] + lambda * (fam.k[b] - fam.k[a]);
    let ko = fam.k_other[a] + lambda * (fam.k_other[b] - fam.k_other[a]);
    let dominant = if fam.ridge { k > ko.abs() } else { -k > ko.abs() };
    let ok = dominant && k.abs() >= fam.flat && (k - ko).abs() >= fam.anisotropy * k.abs();
    ok.then_some(lambda)
}

/// Traces one family (module docs). `face_allowed[f]` masks triangles out.
pub(crate) fn trace_family(
    mesh: &TriMesh,
    topo: &Topology,
    fam: &Family,
    face_allowed: &[bool],
) -> (Vec<RawLine>, CrossingCounts) {
    use rayon::prelude::*;
    let mut counts = CrossingCounts::default();
    let lambdas: Vec<Option<f64>> = (0..topo.n_edges())
        .into_par_iter()
        .with_min_len(4096)
        .map(|e| edge_crossing(mesh, topo, fam, e))
        .collect();
    // Nodes: crossings first (in edge order), then junction centroids.
    let mut node_of_edge = vec![u32::MAX; topo.n_edges()];
    let mut nodes: Vec<V3> = Vec::new();
    for (e, l) in lambdas.iter().enumerate() {
        if let Some(l) = *l {
            let [a, b] = topo.edges[e];
            node_of_edge[e] = nodes.len() as u32;
            nodes.push(vec3::lerp(mesh.positions[a as usize], mesh.positions[b as usize], l));
        }
    }
    counts.crossings = nodes.len();
    // Segments (node, node, face).
    let mut segments: Vec<(u32, u32, u32)> = Vec::new();
    for (f, fe) in topo.face_edges.iter().enumerate() {
        if !face_allowed[f] {
            continue;
        }
        let hits: Vec<u32> =
            fe.iter().map(|&e| node_of_edge[e as usize]).filter(|&n| n != u32::MAX).collect();
        if hits.len() < 2 {
            continue;
        }
        let t = mesh.triangles[f].map(|v| fam.t[v as usize]);
        let negative =
            [(0, 1), (1, 2), (2, 0)].iter().filter(|&&(i, j)| vec3::dot(t[i], t[j]) < 0.0).count();
        if negative % 2 == 1 {
            counts.inconsistent_triangles += 1;
            continue;
        }
        if hits.len() == 2 {
            segments.push((hits[0], hits[1], f as u32));
        } else {
            let c = nodes.len() as u32;
            let p = mesh.triangle_positions(f);
            nodes.push(vec3::scale(vec3::add(vec3::add(p[0], p[1]), p[2]), 1.0 / 3.0));
            counts.junctions += 1;
            for h in hits {
                segments.push((h, c, f as u32));
            }
        }
    }
    counts.segments = segments.len();
    let mut lines = link_segments(&nodes, &segments);
    let before = lines.len();
    lines.retain(|l| line_sharpness(mesh, fam, l) >= fam.sharpness);
    counts.blunt_lines = before - lines.len();
    (lines, counts)
}

/// Dimensionless sharpness of the extremum inside triangle `f`:
/// `max(0, ∓∂e/∂t) / |k|³` (`−` for ridges, `+` for valleys), with `e` and `t`
/// oriented like the triangle's first corner, `∂e/∂t` the derivative of the linear
/// interpolant of `e` along the mean direction and `k` the mean curvature of the
/// corners. For a ridge whose cross-section is an ellipse with semi-axes `a ≥ b`
/// (the ridge at the end of `a`) it equals `3 (1 − b²/a²)`: 0 on a circle or cylinder,
/// where `e ≡ 0` and its zero set is noise, and up to 3 on knife edges.
fn face_sharpness(mesh: &TriMesh, fam: &Family, f: usize) -> f64 {
    let tri = mesh.triangles[f].map(|v| v as usize);
    let [pa, pb, pc] = tri.map(|v| mesh.positions[v]);
    let cr = vec3::cross(vec3::sub(pb, pa), vec3::sub(pc, pa));
    let dbl_area = vec3::norm(cr);
    if !(dbl_area > 0.0 && dbl_area.is_finite()) {
        return 0.0;
    }
    let n = vec3::scale(cr, 1.0 / dbl_area);
    let t0 = fam.t[tri[0]];
    let mut t_sum = [0.0; 3];
    let mut e = [0.0; 3];
    for (i, &v) in tri.iter().enumerate() {
        let s = if vec3::dot(fam.t[v], t0) < 0.0 { -1.0 } else { 1.0 };
        t_sum = vec3::add(t_sum, vec3::scale(fam.t[v], s));
        e[i] = s * fam.e[v];
    }
    let Some(t) = vec3::normalize(t_sum) else { return 0.0 };
    let grad = vec3::add(
        vec3::add(
            vec3::scale(vec3::cross(n, vec3::sub(pc, pb)), e[0]),
            vec3::scale(vec3::cross(n, vec3::sub(pa, pc)), e[1]),
        ),
        vec3::scale(vec3::cross(n, vec3::sub(pb, pa)), e[2]),
    );
    let de_dt = vec3::dot(grad, t) / dbl_area;
    let k = (fam.k[tri[0]] + fam.k[tri[1]] + fam.k[tri[2]]) / 3.0;
    let s = if fam.ridge { -de_dt } else { de_dt };
    let value = s.max(0.0) / k.abs().powi(3);
    if value.is_finite() { value } else { 0.0 }
}

/// Length-weighted mean of [`face_sharpness`] over a line's segments.
fn line_sharpness(mesh: &TriMesh, fam: &Family, line: &RawLine) -> f64 {
    let (mut acc, mut len) = (0.0, 0.0);
    for (i, w) in line.points.windows(2).enumerate() {
        let l = vec3::norm(vec3::sub(w[1], w[0]));
        acc += l * face_sharpness(mesh, fam, line.faces[i] as usize);
        len += l;
    }
    if len > 0.0 { acc / len } else { 0.0 }
}

/// Maximal paths of the segment graph through degree-2 nodes, then cycles (module
/// docs, step 5). Deterministic: paths start at the lowest chain-end node.
pub(crate) fn link_segments(nodes: &[V3], segments: &[(u32, u32, u32)]) -> Vec<RawLine> {
    let inc = Csr::from_pairs(
        nodes.len(),
        segments.iter().enumerate().flat_map(|(s, &(a, b, _))| [(a, s as u32), (b, s as u32)]),
    );
    let mut used = vec![false; segments.len()];
    let walk = |start: u32, first: u32, used: &mut Vec<bool>| {
        let mut points = vec![nodes[start as usize]];
        let mut faces = Vec::new();
        let (mut v, mut s) = (start, first);
        loop {
            used[s as usize] = true;
            let (a, b, f) = segments[s as usize];
            v = if a == v { b } else { a };
            points.push(nodes[v as usize]);
            faces.push(f);
            let row = inc.row(v as usize);
            if row.len() != 2 {
                break;
            }
            let next = if row[0] == s { row[1] } else { row[0] };
            if used[next as usize] {
                break;
            }
            s = next;
        }
        faces.push(*faces.last().unwrap_or(&0));
        let closed = is_closed(&points);
        RawLine { points, faces, closed }
    };
    let mut lines = Vec::new();
    for v in 0..nodes.len() {
        let row = inc.row(v);
        if row.len() == 2 {
            continue;
        }
        for &s in row {
            if !used[s as usize] {
                lines.push(walk(v as u32, s, &mut used));
            }
        }
    }
    for s in 0..segments.len() {
        if !used[s] {
            lines.push(walk(segments[s].0, s as u32, &mut used));
        }
    }
    lines
}

/// A polyline of ≥ 3 points whose last point repeats its first.
fn is_closed(points: &[V3]) -> bool {
    points.len() > 3 && points.first() == points.last()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linking_paths_cycles_and_junctions() {
        let nodes: Vec<V3> = (0..8).map(|i| [i as f64, 0.0, 0.0]).collect();
        // Path 0-1-2-7-6 (all inner nodes of degree 2) and the cycle 3-4-5-3.
        let segs =
            vec![(0, 1, 0), (1, 2, 1), (3, 4, 2), (4, 5, 3), (5, 3, 4), (2, 7, 5), (6, 7, 6)];
        let lines = link_segments(&nodes, &segs);
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[0].points.len(), 5);
        assert!(!lines[0].closed);
        assert_eq!(lines[0].faces, vec![0, 1, 5, 6, 6]);
        assert!(lines[1].closed);
        assert_eq!(lines[1].points.len(), 4);
    }
}
