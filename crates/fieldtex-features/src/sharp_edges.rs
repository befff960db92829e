//! Sharp creases: mesh edges whose dihedral angle passes a threshold, chained into
//! polylines.
//!
//! Curvature-based crest detection (see [`crate::crest_lines`]) assumes a smooth
//! surface sampled finely enough to differentiate curvature twice. On CAD parts
//! (fandisk, rocker-arm) the ridges are creases of the piecewise-smooth surface: the
//! curvature there is a Dirac along an edge chain, the per-vertex estimate saturates
//! and its derivative is meaningless, which is why curvature-only detectors miss them
//! (CGAL's ridge detector, for one, gives up on such meshes). The crease detector
//! finds them directly: the crest lines of this crate are *curvature extrema ∪ sharp
//! creases*, the usual construction for piecewise-smooth models (e.g. Hildebrandt,
//! Polthier & Wardetzky 2005, "Smooth feature lines on surface meshes", who treat
//! creases and smooth crest lines separately for the same reason).
//!
//! Definitions:
//! - the *dihedral angle* of an interior manifold edge is the angle between the unit
//!   normals of its two triangles, in `[0, π]` (0 where the surface is flat). When the
//!   two triangles traverse the edge in the same direction (inconsistent orientation,
//!   e.g. a Möbius strip) one normal is flipped first;
//! - a sharp edge is *convex* (a ridge crease) when the far corner of the second
//!   triangle lies below the plane of the first (`n₁ · (q − p) < 0`), *concave* (a
//!   valley crease) otherwise.
//!
//! Boundary edges, non-manifold edges (more than two triangles) and edges of
//! degenerate triangles are never sharp. Chains follow sharp edges of one convexity
//! through vertices with exactly two such edges and stop at corners, junctions and
//! convexity changes; closed chains repeat their first vertex at the end.

use fieldtex_core::vec3::{self, V3};
use fieldtex_mesh::{Topology, TriMesh};

/// One sharp edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SharpEdge {
    /// Index into [`Topology::edges`].
    pub edge: u32,
    /// Dihedral angle in radians, in `(threshold, π]`.
    pub angle: f64,
    /// `true` for a convex crease (ridge), `false` for a concave one (valley).
    pub convex: bool,
    /// One triangle of the edge (the first in [`Topology::edge_faces`]).
    pub face: u32,
}

/// Dihedral angle and convexity of interior manifold edge `e`, or `None` for boundary,
/// non-manifold and degenerate edges. `face_normals` as from
/// [`fieldtex_mesh::face_normals`] (zero vector for degenerate triangles).
pub fn edge_dihedral(
    mesh: &TriMesh,
    topo: &Topology,
    face_normals: &[V3],
    e: usize,
) -> Option<(f64, bool)> {
    let faces = topo.edge_faces(e);
    if faces.len() != 2 {
        return None;
    }
    let (f1, f2) = (faces[0] as usize, faces[1] as usize);
    let (n1, mut n2) = (face_normals[f1], face_normals[f2]);
    if n1 == [0.0; 3] || n2 == [0.0; 3] {
        return None;
    }
    let sign = |f: usize| {
        let i = (0..3).find(|&i| topo.face_edges[f][i] as usize == e).unwrap_or(0);
        topo.face_edge_signs[f][i]
    };
    if sign(f1) == sign(f2) {
        n2 = vec3::scale(n2, -1.0);
    }
    let angle = vec3::dot(n1, n2).clamp(-1.0, 1.0).acos();
    let [a, b] = topo.edges[e];
    let t2 = mesh.triangles[f2];
    let q = t2.iter().copied().find(|&v| v != a && v != b)?;
    let p = mesh.positions[a as usize];
    let convex = vec3::dot(n1, vec3::sub(mesh.positions[q as usize], p)) < 0.0;
    Some((angle, convex))
}

/// `#E` dihedral angle and convexity of every edge ([`edge_dihedral`]), in parallel.
pub fn edge_dihedrals(
    mesh: &TriMesh,
    topo: &Topology,
    face_normals: &[V3],
) -> Vec<Option<(f64, bool)>> {
    use rayon::prelude::*;
    (0..topo.n_edges())
        .into_par_iter()
        .with_min_len(4096)
        .map(|e| edge_dihedral(mesh, topo, face_normals, e))
        .collect()
}

/// Every edge whose dihedral angle exceeds `threshold_rad`, in edge order.
pub fn sharp_edges(
    mesh: &TriMesh,
    topo: &Topology,
    face_normals: &[V3],
    threshold_rad: f64,
) -> Vec<SharpEdge> {
    sharp_from(topo, &edge_dihedrals(mesh, topo, face_normals), threshold_rad)
}

fn sharp_from(
    topo: &Topology,
    dihedrals: &[Option<(f64, bool)>],
    threshold_rad: f64,
) -> Vec<SharpEdge> {
    dihedrals
        .iter()
        .enumerate()
        .filter_map(|(e, d)| {
            let (angle, convex) = (*d)?;
            (angle > threshold_rad).then(|| SharpEdge {
                edge: e as u32,
                angle,
                convex,
                face: topo.edge_faces(e)[0],
            })
        })
        .collect()
}

/// Sharp edges that stand out from their surroundings: dihedral angle above
/// `threshold_rad` *and* at least `contrast` times the median dihedral angle of the
/// edges around each of its two vertices (boundary and non-manifold edges count as
/// 0°). On a CAD part a crease vertex has a few crease edges among flat ones, so the
/// median is small; on a rough scan every edge bends and no single one stands out, so
/// noise does not become a crease. `contrast = 0` keeps every sharp edge.
pub fn salient_creases(
    mesh: &TriMesh,
    topo: &Topology,
    face_normals: &[V3],
    threshold_rad: f64,
    contrast: f64,
) -> Vec<SharpEdge> {
    let dihedrals = edge_dihedrals(mesh, topo, face_normals);
    let sharp = sharp_from(topo, &dihedrals, threshold_rad);
    if contrast <= 0.0 || sharp.is_empty() {
        return sharp;
    }
    // Median over the edges of the triangles around `v` that touch `v`.
    let mut buf: Vec<(u32, f64)> = Vec::new();
    let mut median_at = |v: u32| {
        buf.clear();
        for &f in topo.vertex_faces(v as usize) {
            for &e in &topo.face_edges[f as usize] {
                let [a, b] = topo.edges[e as usize];
                if a == v || b == v {
                    buf.push((e, dihedrals[e as usize].map_or(0.0, |d| d.0)));
                }
            }
        }
        buf.sort_by_key(|x| x.0);
        buf.dedup_by_key(|x| x.0);
        buf.sort_by(|x, y| x.1.total_cmp(&y.1));
        let n = buf.len();
        if n == 0 {
            0.0
        } else if n % 2 == 1 {
            buf[n / 2].1
        } else {
            0.5 * (buf[n / 2 - 1].1 + buf[n / 2].1)
        }
    };
    sharp
        .into_iter()
        .filter(|s| {
            let [a, b] = topo.edges[s.edge as usize];
            s.angle >= contrast * median_at(a).max(median_at(b))
        })
        .collect()
}

/// A chain of sharp edges of one convexity.
#[derive(Debug, Clone, PartialEq)]
pub struct SharpChain {
    /// Vertex sequence; a closed chain repeats its first vertex at the end.
    pub vertices: Vec<u32>,
    /// Indices into the `sharp` slice given to [`sharp_edge_chains`], one per step.
    pub edges: Vec<u32>,
    pub convex: bool,
    pub closed: bool,
}

/// Links sharp edges into chains (module docs). Deterministic: chains start at the
/// lowest-indexed chain end, then closed loops follow in edge order.
pub fn sharp_edge_chains(topo: &Topology, sharp: &[SharpEdge]) -> Vec<SharpChain> {
    let mut out = Vec::new();
    for convex in [true, false] {
        let ids: Vec<u32> =
            (0..sharp.len() as u32).filter(|&i| sharp[i as usize].convex == convex).collect();
        // vertex → incident sharp edges of this convexity.
        let pairs = ids.iter().flat_map(|&i| {
            let [a, b] = topo.edges[sharp[i as usize].edge as usize];
            [(a, i), (b, i)]
        });
        let inc = fieldtex_mesh::Csr::from_pairs(topo.n_vertices, pairs);
        let mut used = vec![false; sharp.len()];
        let other = |i: u32, v: u32| {
            let [a, b] = topo.edges[sharp[i as usize].edge as usize];
            if a == v { b } else { a }
        };
        let walk = |start: u32, first: u32, used: &mut Vec<bool>| {
            let mut vertices = vec![start];
            let mut edges = Vec::new();
            let (mut v, mut e) = (start, first);
            loop {
                used[e as usize] = true;
                edges.push(e);
                v = other(e, v);
                vertices.push(v);
                let row = inc.row(v as usize);
                if row.len() != 2 {
                    break;
                }
                let next = if row[0] == e { row[1] } else { row[0] };
                if used[next as usize] {
                    break;
                }
                e = next;
            }
            (vertices, edges)
        };
        for v in 0..topo.n_vertices {
            let row = inc.row(v);
            if row.len() == 2 {
                continue;
            }
            for &e in row {
                if !used[e as usize] {
                    let (vertices, edges) = walk(v as u32, e, &mut used);
                    out.push(SharpChain { vertices, edges, convex, closed: false });
                }
            }
        }
        for &e in &ids {
            if !used[e as usize] {
                let start = topo.edges[sharp[e as usize].edge as usize][0];
                let (vertices, edges) = walk(start, e, &mut used);
                let closed = vertices.first() == vertices.last();
                out.push(SharpChain { vertices, edges, convex, closed });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_shapes::cube;
    use fieldtex_mesh::face_normals;

    #[test]
    fn cube_has_twelve_convex_sharp_edges_in_twelve_chains() {
        let m = cube();
        let topo = Topology::build(8, &m.triangles);
        let s = sharp_edges(&m, &topo, &face_normals(&m), 30f64.to_radians());
        assert_eq!(s.len(), 12);
        assert!(
            s.iter().all(|e| e.convex && (e.angle - std::f64::consts::FRAC_PI_2).abs() < 1e-12)
        );
        // Every cube corner joins three sharp edges: each edge is its own chain.
        let chains = sharp_edge_chains(&topo, &s);
        assert_eq!(chains.len(), 12);
        assert!(chains.iter().all(|c| c.vertices.len() == 2 && !c.closed));
    }

    #[test]
    fn inverted_cube_is_concave() {
        let mut m = cube();
        for t in &mut m.triangles {
            t.swap(1, 2);
        }
        let topo = Topology::build(8, &m.triangles);
        let s = sharp_edges(&m, &topo, &face_normals(&m), 30f64.to_radians());
        assert_eq!(s.len(), 12);
        assert!(s.iter().all(|e| !e.convex));
    }

    #[test]
    fn prism_rim_is_a_closed_chain() {
        // A 48-gon prism: its side edges (7.5° apart) are smooth, its two rims sharp,
        // so every rim vertex has exactly two sharp edges and each rim is one loop.
        let n = 48;
        let mut p = Vec::new();
        for z in [0.0, 1.0] {
            for i in 0..n {
                let a = 2.0 * std::f64::consts::PI * i as f64 / n as f64;
                p.push([a.cos(), a.sin(), z]);
            }
        }
        p.push([0.0, 0.0, 0.0]);
        p.push([0.0, 0.0, 1.0]);
        let (c0, c1) = (2 * n as u32, 2 * n as u32 + 1);
        let mut t = Vec::new();
        for i in 0..n as u32 {
            let j = (i + 1) % n as u32;
            t.push([i, j, j + n as u32]);
            t.push([i, j + n as u32, i + n as u32]);
            t.push([c0, j, i]);
            t.push([c1, i + n as u32, j + n as u32]);
        }
        let m = TriMesh::new(p, t);
        let topo = Topology::build(m.n_vertices(), &m.triangles);
        let s = sharp_edges(&m, &topo, &face_normals(&m), 30f64.to_radians());
        assert_eq!(s.len(), 2 * n);
        let chains = sharp_edge_chains(&topo, &s);
        assert_eq!(chains.len(), 2);
        for c in &chains {
            assert!(c.closed && c.convex);
            assert_eq!(c.vertices.len(), n + 1);
            assert_eq!(c.vertices.first(), c.vertices.last());
        }
    }
}
