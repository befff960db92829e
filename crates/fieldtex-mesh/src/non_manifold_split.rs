//! Making a mesh edge- and vertex-manifold by splitting vertices per fan.
//!
//! Strategy (the usual "cut along the pinch" repair):
//! 1. Fans are computed with [`FanRule::PairNonManifold`]: every edge with exactly two
//!    triangles connects them; an edge with more (a non-manifold edge) keeps one pair
//!    connected — the first two of its triangles, in triangle order, that traverse it in
//!    opposite directions (so they agree in orientation), else its first two.
//! 2. Every vertex with more than one fan is split: the fan holding its first corner (in
//!    triangle order) keeps the vertex, each other fan gets a new vertex at the same
//!    position (appended after the existing ones, in order of first corner). The
//!    triangles beyond the kept pair of a non-manifold edge are thereby detached along
//!    it: they get their own copy of the edge.
//! 3. In rare configurations a detached triangle is still connected to the pair around
//!    both ends of the edge (through other triangles), so the edge stays non-manifold.
//!    Those extra triangles (all but the edge's chosen pair) are removed and the split
//!    starts again from the input minus them, until no edge is left with more than two
//!    triangles (each round removes at least one). Nothing else is ever removed.
//!
//! Afterwards every edge has at most two triangles and every vertex a single fan.
//! Positions are not moved, so split copies coincide; [`crate::vertex_welding`] does
//! not weld them back. Linear time; an edge table is built only in step 3.

use crate::Topology;
use crate::vertex_fans::{FanRule, chosen_pair, corner_fans, edge_slot, vertex_face_table};

/// What [`split_non_manifold`] did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NonManifoldSplit {
    /// For each new vertex (appended after the input's), the vertex it copies.
    pub copies_of: Vec<u32>,
    /// Vertices (input indices) that were split, ascending.
    pub split_vertices: Vec<u32>,
    /// Edges that had more than two triangles, as vertex pairs (input indices).
    pub non_manifold_edges: Vec<[u32; 2]>,
    /// Triangles (indices into the input list) that had to be removed in step 3,
    /// ascending; the returned triangle list no longer has them.
    pub removed_triangles: Vec<u32>,
}

impl NonManifoldSplit {
    pub fn is_noop(&self) -> bool {
        self.copies_of.is_empty() && self.removed_triangles.is_empty()
    }
}

/// Splits non-manifold vertices and edges of `triangles` (distinct indices `<
/// n_vertices` in each). Returns the new triangle list (input order, minus
/// `removed_triangles`) and what was done.
pub fn split_non_manifold(
    n_vertices: usize,
    triangles: &[[u32; 3]],
) -> (Vec<[u32; 3]>, NonManifoldSplit) {
    let mut removed = vec![false; triangles.len()];
    let mut input_nm: Option<Vec<[u32; 2]>> = None;
    loop {
        // Input triangles still in play, and their indices.
        let kept: Vec<u32> =
            (0..triangles.len() as u32).filter(|&f| !removed[f as usize]).collect();
        let mut tris: Vec<[u32; 3]> = kept.iter().map(|&f| triangles[f as usize]).collect();
        let mut report = NonManifoldSplit::default();
        let fans =
            corner_fans(&tris, &vertex_face_table(n_vertices, &tris), FanRule::PairNonManifold);
        report.non_manifold_edges =
            input_nm.get_or_insert_with(|| fans.non_manifold_edges.clone()).clone();
        assign_fan_vertices(&mut tris, &fans.corner_fan, fans.n_fans, n_vertices, &mut report);
        if fans.non_manifold_edges.is_empty() {
            report.removed_triangles = removed_list(&removed);
            return (tris, report);
        }
        // Step 3: edges still non-manifold after the split.
        let n_total = n_vertices + report.copies_of.len();
        let topo = Topology::build(n_total, &tris);
        let mut outgoing: Vec<bool> = Vec::new();
        let mut any = false;
        for e in 0..topo.n_edges() {
            let faces = topo.edge_faces(e);
            if faces.len() > 2 {
                outgoing.clear();
                outgoing.extend(faces.iter().map(|&f| {
                    topo.face_edge_signs[f as usize][edge_slot(&topo, f as usize, e as u32)] > 0
                }));
                let (i, j) = chosen_pair(&outgoing);
                for (k, &f) in faces.iter().enumerate() {
                    if k != i && k != j {
                        removed[kept[f as usize] as usize] = true;
                        any = true;
                    }
                }
            }
        }
        if !any {
            // Non-manifold only in the input: the first split resolved everything.
            report.removed_triangles = removed_list(&removed);
            return (tris, report);
        }
    }
}

fn removed_list(removed: &[bool]) -> Vec<u32> {
    (0..removed.len() as u32).filter(|&f| removed[f as usize]).collect()
}

/// Step 2: the fan holding a vertex's first corner keeps it, other fans get copies.
fn assign_fan_vertices(
    tris: &mut [[u32; 3]],
    corner_fan: &[[u32; 3]],
    n_fans: usize,
    n_vertices: usize,
    report: &mut NonManifoldSplit,
) {
    let mut fan_vertex = vec![u32::MAX; n_fans];
    let mut taken = vec![false; n_vertices];
    for (t, cf) in tris.iter_mut().zip(corner_fan) {
        for i in 0..3 {
            let fan = cf[i] as usize;
            let v = t[i];
            if fan_vertex[fan] == u32::MAX {
                if !taken[v as usize] {
                    taken[v as usize] = true;
                    fan_vertex[fan] = v;
                } else {
                    report.copies_of.push(v);
                    report.split_vertices.push(v);
                    fan_vertex[fan] = (n_vertices + report.copies_of.len() - 1) as u32;
                }
            }
            t[i] = fan_vertex[fan];
        }
    }
    report.split_vertices.sort_unstable();
    report.split_vertices.dedup();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bowtie_splits() {
        let (t, r) = split_non_manifold(5, &[[0, 1, 2], [0, 3, 4]]);
        assert_eq!(t, vec![[0, 1, 2], [5, 3, 4]]);
        assert_eq!(r.copies_of, vec![0]);
        assert_eq!(r.split_vertices, vec![0]);
        assert!(r.non_manifold_edges.is_empty());
    }

    #[test]
    fn three_triangles_on_an_edge() {
        let tris = [[0, 1, 2], [0, 1, 3], [1, 0, 4]];
        let (t, r) = split_non_manifold(5, &tris);
        // Pair (0, 2) traverses 0-1 in opposite directions and stays attached.
        assert_eq!(t[0], [0, 1, 2]);
        assert_eq!(t[2], [1, 0, 4]);
        assert_eq!(t[1], [5, 6, 3]);
        assert_eq!(r.non_manifold_edges, vec![[0, 1]]);
        let topo = Topology::build(7, &t);
        assert!((0..topo.n_edges()).all(|e| topo.edge_faces(e).len() <= 2));
        // Idempotent.
        let (t2, r2) = split_non_manifold(7, &t);
        assert_eq!(t2, t);
        assert!(r2.is_noop());
    }
}
