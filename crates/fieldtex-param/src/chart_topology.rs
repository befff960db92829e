//! Local connectivity of one chart: its own vertices, its Euler characteristic, and
//! splitting a chart in two.
//!
//! A chart's vertices are *corner fans*: the corners of the chart's triangles that meet
//! at one mesh vertex and are joined through chart-adjacent edges (see
//! [`crate::face_graph`]) form one chart vertex. A mesh vertex where a chart touches
//! itself only at that vertex (a "bow-tie") therefore becomes two chart vertices, which
//! is what flattening needs. With `V'` chart vertices, `F` triangles and `I` interior
//! (chart-adjacent) edges the chart has `E = 3F − I` edges and Euler characteristic
//! `χ = V' − E + F = V' − 2F + I`. Charts are connected orientable surfaces with
//! boundary, so `χ = 2 − 2g − b`, and a chart is a topological disk exactly when
//! `χ = 1`.

use crate::face_graph::{FaceGraph, NONE};
use fieldtex_core::vec3;
use fieldtex_mesh::UnionFind;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// One chart with local vertex numbering.
#[derive(Debug, Clone)]
pub struct ChartMesh {
    /// Global triangle ids, sorted ascending.
    pub faces: Vec<u32>,
    /// `#faces × 3` local vertex of each corner.
    pub corners: Vec<[u32; 3]>,
    /// Number of local vertices.
    pub n_vertices: usize,
    /// Mesh vertex of each local vertex.
    pub vertex_global: Vec<u32>,
    /// Number of chart-interior edges.
    pub n_interior_edges: usize,
}

impl ChartMesh {
    /// Builds the local numbering of the chart made of `faces` (any order, no
    /// duplicates); `triangles` are the mesh's triangles.
    pub fn build(mut faces: Vec<u32>, graph: &FaceGraph, triangles: &[[u32; 3]]) -> Self {
        faces.sort_unstable();
        let n = faces.len();
        let local = |g: u32| faces.binary_search(&g).ok();
        let mut uf = UnionFind::new(3 * n);
        let mut interior = 0usize;
        for (lf, &f) in faces.iter().enumerate() {
            for i in 0..3 {
                let g = graph.adj[f as usize][i];
                if g == NONE {
                    continue;
                }
                let Some(lg) = local(g) else { continue };
                if lg < lf {
                    continue; // each interior edge once
                }
                interior += 1;
                let j = graph.adj_edge[f as usize][i] as usize;
                uf.union(3 * lf + i, 3 * lg + (j + 1) % 3);
                uf.union(3 * lf + (i + 1) % 3, 3 * lg + j);
            }
        }
        let mut id = vec![u32::MAX; 3 * n];
        let mut vertex_global = Vec::new();
        let mut corners = vec![[0u32; 3]; n];
        for lf in 0..n {
            for i in 0..3 {
                let r = uf.find(3 * lf + i);
                if id[r] == u32::MAX {
                    id[r] = vertex_global.len() as u32;
                    vertex_global.push(triangles[faces[lf] as usize][i]);
                }
                corners[lf][i] = id[r];
            }
        }
        Self {
            faces,
            corners,
            n_vertices: vertex_global.len(),
            vertex_global,
            n_interior_edges: interior,
        }
    }

    /// Euler characteristic `V' − 2F + I`.
    pub fn euler_characteristic(&self) -> i64 {
        self.n_vertices as i64 - 2 * self.faces.len() as i64 + self.n_interior_edges as i64
    }

    /// `true` when the chart is a topological disk (connected charts only).
    pub fn is_disk(&self) -> bool {
        self.euler_characteristic() == 1
    }

    /// Per-local-vertex flag: lies on the chart boundary.
    pub fn boundary_vertices(&self, graph: &FaceGraph) -> Vec<bool> {
        let mut b = vec![false; self.n_vertices];
        for (lf, &f) in self.faces.iter().enumerate() {
            for i in 0..3 {
                let g = graph.adj[f as usize][i];
                if g == NONE || self.faces.binary_search(&g).is_err() {
                    b[self.corners[lf][i] as usize] = true;
                    b[self.corners[lf][(i + 1) % 3] as usize] = true;
                }
            }
        }
        b
    }
}

/// Splits a set of faces into at least two connected parts: the two faces farthest
/// apart (two Dijkstra sweeps over centroid-to-centroid distances) grow at once and
/// each face joins the nearer one, so a connected input gives two connected parts; a
/// disconnected input is also cut into its components. Returns `None` for a single face.
pub fn split_in_two(faces: &[u32], graph: &FaceGraph) -> Option<Vec<Vec<u32>>> {
    let parts = split_raw(faces, graph)?;
    Some(parts.iter().flat_map(|p| connected_parts(p, graph)).collect())
}

fn split_raw(faces: &[u32], graph: &FaceGraph) -> Option<Vec<Vec<u32>>> {
    if faces.len() < 2 {
        return None;
    }
    let mut sorted = faces.to_vec();
    sorted.sort_unstable();
    let n = sorted.len();
    let local = |g: u32| sorted.binary_search(&g).ok();
    // Local adjacency with centroid distances.
    let mut nbrs: Vec<[(u32, f64); 3]> = vec![[(u32::MAX, 0.0); 3]; n];
    for (lf, &f) in sorted.iter().enumerate() {
        for (slot, &g) in nbrs[lf].iter_mut().zip(&graph.adj[f as usize]) {
            if g == NONE {
                continue;
            }
            if let Some(lg) = local(g) {
                let d =
                    vec3::norm(vec3::sub(graph.centroids[f as usize], graph.centroids[g as usize]));
                *slot = (lg as u32, d);
            }
        }
    }
    let dijkstra = |sources: &[usize], label: &mut Vec<u32>| -> Vec<f64> {
        let mut dist = vec![f64::INFINITY; n];
        let mut heap = BinaryHeap::new();
        for (k, &s) in sources.iter().enumerate() {
            dist[s] = 0.0;
            label[s] = k as u32;
            heap.push(Reverse((0u64, s as u32, k as u32)));
        }
        while let Some(Reverse((dbits, v, k))) = heap.pop() {
            let d = f64::from_bits(dbits);
            if d > dist[v as usize] || label[v as usize] != k {
                continue;
            }
            for &(w, len) in &nbrs[v as usize] {
                if w == u32::MAX {
                    continue;
                }
                let nd = d + len;
                let w = w as usize;
                if nd < dist[w] || (nd == dist[w] && k < label[w]) {
                    dist[w] = nd;
                    label[w] = k;
                    heap.push(Reverse((nd.to_bits(), w as u32, k)));
                }
            }
        }
        dist
    };
    let far = |dist: &[f64]| -> usize {
        let mut best = 0;
        for i in 0..n {
            if dist[i].is_finite() && dist[i] > dist[best] {
                best = i;
            }
        }
        best
    };
    let mut label = vec![u32::MAX; n];
    let d0 = dijkstra(&[0], &mut label);
    let a = far(&d0);
    label.fill(u32::MAX);
    let da = dijkstra(&[a], &mut label);
    let b = far(&da);
    if a == b {
        // Every reached face coincides with `a`: the set is disconnected or one face.
        let reached: Vec<u32> = (0..n).filter(|&i| da[i].is_finite()).map(|i| sorted[i]).collect();
        let rest: Vec<u32> = (0..n).filter(|&i| !da[i].is_finite()).map(|i| sorted[i]).collect();
        return if rest.is_empty() { split_by_index(&sorted) } else { Some(vec![reached, rest]) };
    }
    label.fill(u32::MAX);
    dijkstra(&[a, b], &mut label);
    let mut parts = vec![Vec::new(), Vec::new(), Vec::new()];
    for i in 0..n {
        let k = if label[i] == u32::MAX { 2 } else { label[i] as usize };
        parts[k].push(sorted[i]);
    }
    parts.retain(|p| !p.is_empty());
    Some(parts)
}

/// Fallback for sets whose faces are all at zero distance: split the list in half.
fn split_by_index(sorted: &[u32]) -> Option<Vec<Vec<u32>>> {
    if sorted.len() < 2 {
        return None;
    }
    let h = sorted.len() / 2;
    Some(vec![sorted[..h].to_vec(), sorted[h..].to_vec()])
}

/// Splits a face set into its connected components (through chart adjacency).
pub fn connected_parts(faces: &[u32], graph: &FaceGraph) -> Vec<Vec<u32>> {
    let mut sorted = faces.to_vec();
    sorted.sort_unstable();
    let n = sorted.len();
    let mut seen = vec![false; n];
    let mut parts = Vec::new();
    let mut stack = Vec::new();
    for s in 0..n {
        if seen[s] {
            continue;
        }
        seen[s] = true;
        stack.push(s);
        let mut part = Vec::new();
        while let Some(v) = stack.pop() {
            part.push(sorted[v]);
            for &g in &graph.adj[sorted[v] as usize] {
                if g == NONE {
                    continue;
                }
                if let Ok(w) = sorted.binary_search(&g)
                    && !seen[w]
                {
                    seen[w] = true;
                    stack.push(w);
                }
            }
        }
        part.sort_unstable();
        parts.push(part);
    }
    parts
}
