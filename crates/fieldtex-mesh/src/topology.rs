//! Edge and adjacency tables of a triangle mesh.
//!
//! Conventions (shared with DEC code, which needs stable edge signs):
//! - `edges` are sorted, unique, oriented from the lower to the higher vertex index;
//!   this is the reference orientation of each edge (a 1-form value on edge `e` is its
//!   integral from `edges[e][0]` to `edges[e][1]`).
//! - `face_edges[f][i]` is the edge between corners `i` and `(i + 1) % 3` of triangle
//!   `f`; it is opposite corner `(i + 2) % 3`. `face_edge_signs[f][i]` is `+1` when the
//!   triangle traverses that edge from low to high index, `-1` otherwise.
//! - `edge_faces(e)` lists every triangle using edge `e` (1 on a boundary, 2 inside a
//!   manifold, more on a non-manifold edge); `vertex_faces(v)` every triangle at `v`.
//!
//! Built in `O(F log F)`; works on any input, manifold or not. Degenerate triangles
//! with a repeated vertex produce an edge `[a, a]`; run repair to drop them first.

/// Compressed row storage of a ragged `u32` table.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Csr {
    pub offsets: Vec<u32>,
    pub items: Vec<u32>,
}

impl Csr {
    /// Row `i` of the table.
    #[inline]
    pub fn row(&self, i: usize) -> &[u32] {
        &self.items[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }
    pub fn n_rows(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }
    /// Builds the table from `(row, item)` pairs; items in a row keep input order.
    pub fn from_pairs(n_rows: usize, pairs: impl Iterator<Item = (u32, u32)> + Clone) -> Self {
        let mut counts = vec![0u32; n_rows + 1];
        for (r, _) in pairs.clone() {
            counts[r as usize + 1] += 1;
        }
        for i in 0..n_rows {
            counts[i + 1] += counts[i];
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; counts[n_rows] as usize];
        for (r, it) in pairs {
            let slot = &mut fill[r as usize];
            items[*slot as usize] = it;
            *slot += 1;
        }
        Self { offsets: counts, items }
    }
}

/// Edge and adjacency tables; see the module docs for conventions.
#[derive(Debug, Clone, PartialEq)]
pub struct Topology {
    pub n_vertices: usize,
    /// `#E × 2` edges, `edges[e][0] <= edges[e][1]`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// `#F × 3` edge of corner pair `(i, i+1)`.
    pub face_edges: Vec<[u32; 3]>,
    /// `#F × 3` orientation of `face_edges` relative to the edge's reference direction.
    pub face_edge_signs: Vec<[i8; 3]>,
    edge_faces: Csr,
    vertex_faces: Csr,
}

impl Topology {
    /// Builds the tables for `n_vertices` vertices and the given triangles.
    /// Indices must be `< n_vertices` (see [`crate::TriMesh::validate`]).
    pub fn build(n_vertices: usize, triangles: &[[u32; 3]]) -> Self {
        let nf = triangles.len();
        // (low, high, face, corner) for every half-edge.
        let mut half: Vec<(u32, u32, u32, u8)> = Vec::with_capacity(3 * nf);
        for (f, t) in triangles.iter().enumerate() {
            for i in 0..3 {
                let a = t[i];
                let b = t[(i + 1) % 3];
                half.push((a.min(b), a.max(b), f as u32, i as u8));
            }
        }
        half.sort_unstable();
        let mut edges: Vec<[u32; 2]> = Vec::with_capacity(3 * nf / 2 + 1);
        let mut face_edges = vec![[0u32; 3]; nf];
        let mut face_edge_signs = vec![[0i8; 3]; nf];
        let mut ef_pairs: Vec<(u32, u32)> = Vec::with_capacity(3 * nf);
        for &(lo, hi, f, i) in &half {
            if edges.last() != Some(&[lo, hi]) {
                edges.push([lo, hi]);
            }
            let e = (edges.len() - 1) as u32;
            face_edges[f as usize][i as usize] = e;
            let a = triangles[f as usize][i as usize];
            face_edge_signs[f as usize][i as usize] = if a == lo { 1 } else { -1 };
            ef_pairs.push((e, f));
        }
        let edge_faces = Csr::from_pairs(edges.len(), ef_pairs.iter().copied());
        let vertex_faces = Csr::from_pairs(
            n_vertices,
            triangles.iter().enumerate().flat_map(|(f, t)| t.iter().map(move |&v| (v, f as u32))),
        );
        Self { n_vertices, edges, face_edges, face_edge_signs, edge_faces, vertex_faces }
    }

    pub fn n_edges(&self) -> usize {
        self.edges.len()
    }

    pub fn n_faces(&self) -> usize {
        self.face_edges.len()
    }

    /// Euler characteristic `V − E + F` of the whole mesh, counting only vertices used
    /// by a triangle (an unreferenced vertex is not a component). Per-component values
    /// are in [`crate::inspect`].
    pub fn euler_characteristic(&self) -> i64 {
        let used = (0..self.n_vertices).filter(|&v| !self.vertex_faces(v).is_empty()).count();
        used as i64 - self.n_edges() as i64 + self.n_faces() as i64
    }

    /// Triangles using edge `e`.
    #[inline]
    pub fn edge_faces(&self, e: usize) -> &[u32] {
        self.edge_faces.row(e)
    }

    /// Triangles using vertex `v`.
    #[inline]
    pub fn vertex_faces(&self, v: usize) -> &[u32] {
        self.vertex_faces.row(v)
    }

    /// `true` when exactly one triangle uses edge `e`.
    #[inline]
    pub fn is_boundary_edge(&self, e: usize) -> bool {
        self.edge_faces(e).len() == 1
    }

    /// `true` when more than two triangles use edge `e`.
    #[inline]
    pub fn is_nonmanifold_edge(&self, e: usize) -> bool {
        self.edge_faces(e).len() > 2
    }

    /// Per-vertex flag: lies on a boundary edge.
    pub fn boundary_vertices(&self) -> Vec<bool> {
        let mut b = vec![false; self.n_vertices];
        for (e, ed) in self.edges.iter().enumerate() {
            if self.is_boundary_edge(e) {
                b[ed[0] as usize] = true;
                b[ed[1] as usize] = true;
            }
        }
        b
    }

    /// Vertex-to-vertex adjacency (sorted neighbours of each vertex).
    pub fn vertex_neighbors(&self) -> Csr {
        let pairs =
            self.edges.iter().filter(|e| e[0] != e[1]).flat_map(|e| [(e[0], e[1]), (e[1], e[0])]);
        let mut csr = Csr::from_pairs(self.n_vertices, pairs);
        for v in 0..self.n_vertices {
            let (s, t) = (csr.offsets[v] as usize, csr.offsets[v + 1] as usize);
            csr.items[s..t].sort_unstable();
        }
        csr
    }

    /// Boundary loops as vertex sequences, each traversed in the direction of its
    /// triangles' orientation (so the surface lies to the left for a CCW mesh).
    /// Around a non-manifold boundary vertex the walk takes the first unused edge.
    pub fn boundary_loops(&self, triangles: &[[u32; 3]]) -> Vec<Vec<u32>> {
        // Outgoing boundary half-edges per vertex: (from, to).
        let mut out: Vec<(u32, u32)> = Vec::new();
        for (e, _) in self.edges.iter().enumerate() {
            if self.is_boundary_edge(e) {
                let f = self.edge_faces(e)[0] as usize;
                let i = (0..3).find(|&i| self.face_edges[f][i] as usize == e).unwrap_or(0);
                let a = triangles[f][i];
                let b = triangles[f][(i + 1) % 3];
                if a != b {
                    out.push((a, b));
                }
            }
        }
        out.sort_unstable();
        let mut used = vec![false; out.len()];
        let first_out = |v: u32, out: &Vec<(u32, u32)>, used: &Vec<bool>| -> Option<usize> {
            let start = out.partition_point(|&(a, _)| a < v);
            (start..out.len()).take_while(|&k| out[k].0 == v).find(|&k| !used[k])
        };
        let mut loops = Vec::new();
        for k0 in 0..out.len() {
            if used[k0] {
                continue;
            }
            let mut lp = vec![out[k0].0];
            used[k0] = true;
            let start = out[k0].0;
            let mut cur = out[k0].1;
            let mut guard = 0usize;
            while cur != start && guard <= out.len() {
                lp.push(cur);
                match first_out(cur, &out, &used) {
                    Some(k) => {
                        used[k] = true;
                        cur = out[k].1;
                    }
                    None => break, // open chain (inconsistent orientation)
                }
                guard += 1;
            }
            loops.push(lp);
        }
        loops
    }

    /// Connected components of triangles (triangles sharing a vertex are connected).
    /// Returns `(component of each triangle, number of components)`; components are
    /// numbered in order of their first triangle.
    pub fn face_components(&self, triangles: &[[u32; 3]]) -> (Vec<u32>, usize) {
        let mut uf = UnionFind::new(self.n_vertices);
        for t in triangles {
            uf.union(t[0] as usize, t[1] as usize);
            uf.union(t[0] as usize, t[2] as usize);
        }
        let mut label = vec![u32::MAX; self.n_vertices];
        let mut n = 0u32;
        let comp = triangles
            .iter()
            .map(|t| {
                let r = uf.find(t[0] as usize);
                if label[r] == u32::MAX {
                    label[r] = n;
                    n += 1;
                }
                label[r]
            })
            .collect();
        (comp, n as usize)
    }
}

/// Disjoint-set forest with path halving and union by size.
#[derive(Debug, Clone)]
pub struct UnionFind {
    parent: Vec<u32>,
    size: Vec<u32>,
}

impl UnionFind {
    pub fn new(n: usize) -> Self {
        Self { parent: (0..n as u32).collect(), size: vec![1; n] }
    }
    pub fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] as usize != x {
            let p = self.parent[x] as usize;
            self.parent[x] = self.parent[p];
            x = self.parent[x] as usize;
        }
        x
    }
    /// Merges the sets of `a` and `b`; returns `false` if they were already one.
    pub fn union(&mut self, a: usize, b: usize) -> bool {
        let (mut ra, mut rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        if self.size[ra] < self.size[rb] {
            std::mem::swap(&mut ra, &mut rb);
        }
        self.parent[rb] = ra as u32;
        self.size[ra] += self.size[rb];
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles forming a square: 5 edges, 4 boundary, one loop.
    #[test]
    fn square_tables() {
        let tris = [[0, 1, 2], [0, 2, 3]];
        let t = Topology::build(4, &tris);
        assert_eq!(t.n_edges(), 5);
        let nb = (0..5).filter(|&e| t.is_boundary_edge(e)).count();
        assert_eq!(nb, 4);
        let loops = t.boundary_loops(&tris);
        assert_eq!(loops.len(), 1);
        assert_eq!(loops[0], vec![0, 1, 2, 3]);
        // The diagonal 0-2 is used by both faces with opposite signs.
        let e02 = t.edges.iter().position(|e| *e == [0, 2]).unwrap();
        let mut signs = vec![];
        for f in 0..2 {
            for i in 0..3 {
                if t.face_edges[f][i] as usize == e02 {
                    signs.push(t.face_edge_signs[f][i]);
                }
            }
        }
        signs.sort();
        assert_eq!(signs, vec![-1, 1]);
        let (comp, n) = t.face_components(&tris);
        assert_eq!(n, 1);
        assert_eq!(comp, vec![0, 0]);
    }

    #[test]
    fn tetrahedron_is_closed() {
        let tris = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
        let t = Topology::build(4, &tris);
        assert_eq!(t.n_edges(), 6);
        assert!(t.boundary_loops(&tris).is_empty());
        assert!((0..6).all(|e| t.edge_faces(e).len() == 2));
        let nb = t.vertex_neighbors();
        assert!((0..4).all(|v| nb.row(v).len() == 3));
    }
}
