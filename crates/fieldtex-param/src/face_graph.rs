//! Face adjacency used by chart segmentation and flattening.
//!
//! Two triangles are *chart-adjacent* across an edge only when that edge is manifold
//! (exactly two triangles), both triangles traverse it in opposite directions
//! (consistent orientation) and neither triangle repeats a vertex. Every other edge is
//! a forced cut: charts therefore never contain non-manifold edges, never flip
//! orientation inside, and never cross from one connected component to another, so a
//! chart is always an orientable surface with boundary.

use fieldtex_core::vec3::{self, V3};
use fieldtex_mesh::{Topology, TriMesh};

/// `u32::MAX` marks "no chart-adjacent neighbour across this edge".
pub const NONE: u32 = u32::MAX;

/// Per-triangle geometry and chart adjacency of a mesh.
#[derive(Debug, Clone)]
pub struct FaceGraph {
    /// `#F` unit normals (`[0; 3]` for zero-area triangles).
    pub normals: Vec<V3>,
    /// `#F` areas.
    pub areas: Vec<f64>,
    /// `#F` centroids.
    pub centroids: Vec<V3>,
    /// `#F × 3` neighbour across the edge from corner `i` to corner `i + 1`, or [`NONE`].
    pub adj: Vec<[u32; 3]>,
    /// `#F × 3` for each neighbour, the index `j` of the same edge in the neighbour
    /// (the edge from its corner `j` to corner `j + 1`).
    pub adj_edge: Vec<[u8; 3]>,
    /// `#F × 3` lengths of the edges from corner `i` to corner `i + 1`.
    pub edge_len: Vec<[f64; 3]>,
    /// `#F` flag: zero area or a repeated vertex index; excluded from flip checks.
    pub degenerate: Vec<bool>,
}

impl FaceGraph {
    /// Builds the tables. `mesh` must have passed [`TriMesh::validate`].
    pub fn build(mesh: &TriMesh) -> Self {
        let nf = mesh.n_triangles();
        let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
        let mut normals = Vec::with_capacity(nf);
        let mut areas = Vec::with_capacity(nf);
        let mut centroids = Vec::with_capacity(nf);
        let mut edge_len = Vec::with_capacity(nf);
        let mut max_len = 0.0f64;
        for f in 0..nf {
            let [a, b, c] = mesh.triangle_positions(f);
            let n = vec3::cross(vec3::sub(b, a), vec3::sub(c, a));
            let dbl = vec3::norm(n);
            areas.push(0.5 * dbl);
            normals.push(if dbl > 0.0 { vec3::scale(n, 1.0 / dbl) } else { [0.0; 3] });
            centroids.push(vec3::scale(vec3::add(vec3::add(a, b), c), 1.0 / 3.0));
            let l = [
                vec3::norm(vec3::sub(b, a)),
                vec3::norm(vec3::sub(c, b)),
                vec3::norm(vec3::sub(a, c)),
            ];
            max_len = max_len.max(l[0]).max(l[1]).max(l[2]);
            edge_len.push(l);
        }
        // A triangle is degenerate when its area is negligible against the squared
        // scale of the mesh (or it repeats a vertex index).
        let tiny = 1e-14 * max_len * max_len;
        let degenerate: Vec<bool> = (0..nf)
            .map(|f| {
                let t = mesh.triangles[f];
                t[0] == t[1]
                    || t[1] == t[2]
                    || t[0] == t[2]
                    || areas[f].is_nan()
                    || areas[f] <= tiny
            })
            .collect();
        let mut adj = vec![[NONE; 3]; nf];
        let mut adj_edge = vec![[0u8; 3]; nf];
        for f in 0..nf {
            let t = mesh.triangles[f];
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                continue;
            }
            for i in 0..3 {
                let e = topo.face_edges[f][i] as usize;
                let faces = topo.edge_faces(e);
                if faces.len() != 2 {
                    continue;
                }
                let g = if faces[0] as usize == f { faces[1] } else { faces[0] } as usize;
                if g == f {
                    continue;
                }
                let tg = mesh.triangles[g];
                if tg[0] == tg[1] || tg[1] == tg[2] || tg[0] == tg[2] {
                    continue;
                }
                let Some(j) = (0..3).find(|&j| topo.face_edges[g][j] as usize == e) else {
                    continue;
                };
                // Opposite traversal = consistent orientation.
                if topo.face_edge_signs[g][j] == topo.face_edge_signs[f][i] {
                    continue;
                }
                adj[f][i] = g as u32;
                adj_edge[f][i] = j as u8;
            }
        }
        Self { normals, areas, centroids, adj, adj_edge, edge_len, degenerate }
    }

    pub fn n_faces(&self) -> usize {
        self.areas.len()
    }
}
