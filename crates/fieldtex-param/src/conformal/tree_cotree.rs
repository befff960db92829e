//! Tree–cotree decomposition (Eppstein 2003; used for homology bases by Gu & Yau 2003):
//! a spanning tree `T` of the vertices, a spanning tree `C` of the faces over the edges
//! not in `T`, and the `2g` edges in neither, each of which closes one homology
//! generator. For each generator the *dual loop* (the edge plus the cotree path between
//! its two faces) gives a closed 1-form `η` (`d1 η = 0`) whose period on the primal loop
//! of another generator is their intersection number.
//!
//! Sign convention of a crossing: walking across edge `e` out of face `a` adds the sign
//! of `e` in `a`'s boundary (`Topology::face_edge_signs`) to `η[e]`; the face entered sees
//! the opposite sign, so every face of the loop has zero net circulation.

use fieldtex_mesh::Topology;
use std::collections::VecDeque;

/// See the module docs. Built over a closed (every edge has two faces), connected mesh.
#[derive(Debug, Clone)]
pub struct TreeCotree {
    /// Per edge: in the primal spanning tree.
    pub in_tree: Vec<bool>,
    /// Per face: `(parent face, edge crossed)` in the dual tree (`u32::MAX` at the root).
    pub cotree_parent: Vec<(u32, u32)>,
    /// Per face: depth in the dual tree.
    pub depth: Vec<u32>,
    /// The generator edges (in neither tree), in increasing edge order.
    pub generators: Vec<u32>,
}

/// Sign of edge `e` in the boundary of face `f` (`0` when `e` is not an edge of `f`).
pub fn edge_sign_in_face(topology: &Topology, f: usize, e: u32) -> f64 {
    (0..3)
        .find(|&k| topology.face_edges[f][k] == e)
        .map_or(0.0, |k| topology.face_edge_signs[f][k] as f64)
}

/// Per vertex: its incident edges, in increasing edge order.
pub fn vertex_edges(topology: &Topology) -> Vec<Vec<u32>> {
    let mut vertex_edges: Vec<Vec<u32>> = vec![Vec::new(); topology.n_vertices];
    for (e, ed) in topology.edges.iter().enumerate() {
        vertex_edges[ed[0] as usize].push(e as u32);
        vertex_edges[ed[1] as usize].push(e as u32);
    }
    vertex_edges
}

/// Builds the decomposition with breadth-first trees rooted at vertex 0 and face 0.
pub fn tree_cotree(topology: &Topology) -> TreeCotree {
    let nv = topology.n_vertices;
    let ne = topology.n_edges();
    let nf = topology.n_faces();
    let vertex_edges = vertex_edges(topology);
    let mut in_tree = vec![false; ne];
    let mut seen = vec![false; nv];
    let mut queue = VecDeque::new();
    if nv > 0 {
        seen[0] = true;
        queue.push_back(0usize);
    }
    while let Some(v) = queue.pop_front() {
        for &e in &vertex_edges[v] {
            let ed = topology.edges[e as usize];
            let w = if ed[0] as usize == v { ed[1] } else { ed[0] } as usize;
            if !seen[w] {
                seen[w] = true;
                in_tree[e as usize] = true;
                queue.push_back(w);
            }
        }
    }
    let mut cotree_parent = vec![(u32::MAX, u32::MAX); nf];
    let mut depth = vec![0u32; nf];
    let mut in_cotree = vec![false; ne];
    let mut fseen = vec![false; nf];
    if nf > 0 {
        fseen[0] = true;
        queue.push_back(0);
    }
    while let Some(f) = queue.pop_front() {
        for &e in &topology.face_edges[f] {
            if in_tree[e as usize] {
                continue;
            }
            for &g in topology.edge_faces(e as usize) {
                let g = g as usize;
                if !fseen[g] {
                    fseen[g] = true;
                    in_cotree[e as usize] = true;
                    cotree_parent[g] = (f as u32, e);
                    depth[g] = depth[f] + 1;
                    queue.push_back(g);
                }
            }
        }
    }
    let generators = (0..ne)
        .filter(|&e| !in_tree[e] && !in_cotree[e] && topology.edge_faces(e).len() == 2)
        .map(|e| e as u32)
        .collect();
    TreeCotree { in_tree, cotree_parent, depth, generators }
}

impl TreeCotree {
    /// The closed 1-form (`#E`) of the dual loop through generator edge `e`.
    pub fn dual_loop_form(&self, topology: &Topology, e: u32) -> Vec<f64> {
        let mut eta = vec![0.0; topology.n_edges()];
        let faces = topology.edge_faces(e as usize);
        let (fa, fb) = (faces[0] as usize, faces[1] as usize);
        eta[e as usize] += edge_sign_in_face(topology, fa, e);
        // From fb up to the common ancestor, then down to fa.
        let (mut x, mut y) = (fb, fa);
        let mut down: Vec<usize> = Vec::new(); // faces on fa's side, entered going down
        while x != y {
            if self.depth[x] >= self.depth[y] {
                let (p, pe) = self.cotree_parent[x];
                eta[pe as usize] += edge_sign_in_face(topology, x, pe);
                x = p as usize;
            } else {
                down.push(y);
                y = self.cotree_parent[y].0 as usize;
            }
        }
        for &c in down.iter().rev() {
            let (p, pe) = self.cotree_parent[c];
            eta[pe as usize] += edge_sign_in_face(topology, p as usize, pe);
        }
        eta
    }
}
