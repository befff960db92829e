//! A short cut graph for a patch layout (our construction, issue 13).
//!
//! Every cut layout of a surface with `k` openings (slit openings of the kept copy of a
//! double cover, or holes) must join the openings (the patches are disks) and must
//! reach every zero point of the form (a 4π cone cannot be developed into the plane
//! without a cut through it). This joins the openings and the negative-index zero
//! points by a minimum spanning tree of shortest edge paths (Prim over the terminals'
//! edge-path distances, each a multi-source Dijkstra from one terminal), cut besides
//! the critical trajectories; the patches then grow over both as before
//! ([`super::translation_patches`]), whose overlap guard still cuts where the
//! development would overlap itself. Without it a growing patch closes each opening
//! wherever its own fronts meet, which made most of the seam length on the shared
//! meshes; the trajectories stay besides the tree (docs/conformal.md, session 16).

use super::homology_loops::{edge_lengths, shortest_path_forest};
use super::tree_cotree::vertex_edges;
use fieldtex_mesh::{Topology, UnionFind};

/// Per edge of `topology`: on the spanning cut of the faces with `kept[f]`, joining
/// the openings of the kept region and the vertices `zeros`.
pub fn spanning_cut(
    positions: &[[f64; 3]],
    topology: &Topology,
    kept: &[bool],
    zeros: &[u32],
) -> Vec<bool> {
    let ne = topology.n_edges();
    let nv = topology.n_vertices;
    let kept_faces =
        |e: usize| topology.edge_faces(e).iter().filter(|&&f| kept[f as usize]).count();
    let mut length = edge_lengths(positions, topology);
    for (e, l) in length.iter_mut().enumerate() {
        if kept_faces(e) == 0 {
            *l = f64::INFINITY;
        }
    }
    // Openings: boundary loops of the kept region.
    let mut uf = UnionFind::new(nv);
    let mut on_boundary = vec![false; nv];
    for e in 0..ne {
        if kept_faces(e) == 1 {
            let [a, b] = topology.edges[e];
            uf.union(a as usize, b as usize);
            on_boundary[a as usize] = true;
            on_boundary[b as usize] = true;
        }
    }
    let mut terminals: Vec<Vec<usize>> = Vec::new();
    let mut slot = vec![usize::MAX; nv];
    for (v, &b) in on_boundary.iter().enumerate() {
        if b {
            let r = uf.find(v);
            if slot[r] == usize::MAX {
                slot[r] = terminals.len();
                terminals.push(Vec::new());
            }
            terminals[slot[r]].push(v);
        }
    }
    let vedges = vertex_edges(topology);
    for &z in zeros {
        if !on_boundary[z as usize] {
            terminals.push(vec![z as usize]);
        }
    }
    let mut cut = vec![false; ne];
    let m = terminals.len();
    if m < 2 {
        return cut;
    }
    let forests: Vec<(Vec<f64>, Vec<u32>)> = terminals
        .iter()
        .map(|t| shortest_path_forest(topology, &vedges, &length, t, f64::INFINITY))
        .collect();
    // Nearest vertex of terminal j from terminal i, and its distance.
    let nearest = |i: usize, j: usize| -> (f64, usize) {
        terminals[j]
            .iter()
            .map(|&v| (forests[i].0[v], v))
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
            .unwrap_or((f64::INFINITY, usize::MAX))
    };
    // Prim from terminal 0.
    let mut in_tree = vec![false; m];
    let mut best: Vec<(f64, usize)> = vec![(f64::INFINITY, usize::MAX); m];
    best[0] = (0.0, usize::MAX);
    for _ in 0..m {
        let Some(u) = (0..m)
            .filter(|&i| !in_tree[i] && best[i].0.is_finite())
            .min_by(|&a, &b| best[a].0.total_cmp(&best[b].0).then(a.cmp(&b)))
        else {
            break;
        };
        in_tree[u] = true;
        if best[u].1 != usize::MAX {
            // Trace the path from terminal `from` to terminal `u`.
            let from = best[u].1;
            let (_, mut v) = nearest(from, u);
            let parent = &forests[from].1;
            while parent[v] != u32::MAX {
                let e = parent[v] as usize;
                cut[e] = true;
                let [a, b] = topology.edges[e];
                v = if a as usize == v { b as usize } else { a as usize };
            }
        }
        for j in 0..m {
            if !in_tree[j] {
                let (d, _) = nearest(u, j);
                if d < best[j].0 {
                    best[j] = (d, u);
                }
            }
        }
    }
    cut
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 12 × 12 grid of unit cells (so 13 × 13 vertices) without the faces of the
    /// cells `[3, 5) × [3, 5)` and `[8, 10) × [7, 9)`: an outer boundary and two holes.
    fn holed_grid() -> (fieldtex_mesh::TriMesh, Vec<bool>) {
        let mesh = fieldtex_mesh::primitives::grid(12, 12, 12.0, 12.0);
        let kept = (0..mesh.n_triangles())
            .map(|f| {
                let (i, j) = ((f / 2) % 12, (f / 2) / 12);
                !((3..5).contains(&i) && (3..5).contains(&j)
                    || (8..10).contains(&i) && (7..9).contains(&j))
            })
            .collect();
        (mesh, kept)
    }

    #[test]
    fn the_cut_joins_every_opening_and_zero_by_short_paths() {
        let (mesh, kept) = holed_grid();
        let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
        let zero = 10 * 13 + 2; // vertex (2, 10)
        let cut = spanning_cut(&mesh.positions, &topo, &kept, &[zero]);
        // Connected through cut edges: the two holes, the outer boundary and the zero.
        let mut uf = UnionFind::new(mesh.n_vertices());
        for (e, _) in cut.iter().enumerate().filter(|(_, c)| **c) {
            let [a, b] = topo.edges[e];
            uf.union(a as usize, b as usize);
        }
        let id = |i: usize, j: usize| j * 13 + i;
        // Hole corners (3, 3) … (5, 5) and (8, 7) … (10, 9): join each hole's rim first.
        for (i0, j0) in [(3, 3), (8, 7)] {
            for k in 0..2 {
                uf.union(id(i0 + k, j0), id(i0 + k + 1, j0));
                uf.union(id(i0 + 2, j0 + k), id(i0 + 2, j0 + k + 1));
                uf.union(id(i0 + k + 1, j0 + 2), id(i0 + k, j0 + 2));
                uf.union(id(i0, j0 + k + 1), id(i0, j0 + k));
            }
        }
        for k in 0..12 {
            uf.union(id(k, 0), id(k + 1, 0));
            uf.union(id(12, k), id(12, k + 1));
            uf.union(id(k + 1, 12), id(k, 12));
            uf.union(id(0, k + 1), id(0, k));
        }
        let root = uf.find(id(0, 0));
        for v in [id(3, 3), id(8, 7), zero as usize] {
            assert_eq!(uf.find(v), root, "vertex {v} not joined");
        }
        // Short: the three links are at most 3 (hole to border), 2 (zero to border) and
        // about 4 (hole to hole) units, with diagonal steps of √2.
        let length: f64 = cut
            .iter()
            .enumerate()
            .filter(|(_, c)| **c)
            .map(|(e, _)| {
                let [a, b] = topo.edges[e];
                fieldtex_core::vec3::norm(fieldtex_core::vec3::sub(
                    mesh.positions[a as usize],
                    mesh.positions[b as usize],
                ))
            })
            .sum();
        assert!(length > 4.0 && length < 12.0, "cut length {length}");
        // Only edges of kept faces are cut, and the result does not depend on the run.
        for (e, _) in cut.iter().enumerate().filter(|(_, c)| **c) {
            assert!(topo.edge_faces(e).iter().any(|&f| kept[f as usize]));
        }
        assert_eq!(cut, spanning_cut(&mesh.positions, &topo, &kept, &[zero]));
    }

    #[test]
    fn one_opening_and_no_zero_needs_no_cut() {
        let mesh = fieldtex_mesh::primitives::grid(4, 4, 1.0, 1.0);
        let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
        let kept = vec![true; mesh.n_triangles()];
        assert!(spanning_cut(&mesh.positions, &topo, &kept, &[]).iter().all(|&c| !c));
    }
}
