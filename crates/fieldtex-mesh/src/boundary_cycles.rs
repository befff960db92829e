//! Boundary loops found without trusting triangle orientation.
//!
//! [`crate::Topology::boundary_loops`] follows the triangles' direction, which breaks
//! into open pieces where neighbouring triangles disagree. Inspection must count loops
//! on such meshes too, so here the boundary edges (edges with exactly one triangle) are
//! walked as an undirected graph: from an unused edge, repeatedly take the first unused
//! boundary edge (lowest edge index) at the current vertex until back at the start.
//!
//! Where every boundary vertex has exactly two boundary edges (any edge-manifold,
//! vertex-manifold mesh) the result is exactly the boundary cycles. At a vertex where
//! two loops touch the split between them is one of several valid choices; a walk that
//! gets stuck (odd degree, only next to non-manifold edges) is extended backwards from
//! its start and ends as an open chain; where boundary vertices have at most two
//! boundary edges, loops and chains are exactly the components of the boundary graph.
//! Linear time.

use crate::{Csr, Topology};

/// One boundary loop (or open chain) as a vertex sequence, plus the edge it started at.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryCycle {
    /// Vertices in walk order; the closing edge back to the first is implied when
    /// `closed`. An open chain of `n` vertices has `n − 1` edges.
    pub vertices: Vec<u32>,
    /// First edge of the walk (its smallest-index edge among unused ones).
    pub first_edge: u32,
    /// `false` when the walk got stuck before returning to its start.
    pub closed: bool,
}

/// First unused boundary edge at `v` and the vertex at its other end.
fn next_edge(
    topo: &Topology,
    adj: &Csr,
    used: &[bool],
    cursor: &mut [u32],
    v: u32,
) -> Option<(u32, u32)> {
    let end = adj.offsets[v as usize + 1];
    let mut c = cursor[v as usize];
    while c < end && used[adj.items[c as usize] as usize] {
        c += 1;
    }
    cursor[v as usize] = c;
    if c == end {
        return None;
    }
    let e = adj.items[c as usize];
    let [a, b] = topo.edges[e as usize];
    Some((e, if a == v { b } else { a }))
}

/// All boundary loops of `topo`, in order of their first edge.
pub fn boundary_cycles(topo: &Topology) -> Vec<BoundaryCycle> {
    let boundary: Vec<u32> =
        (0..topo.n_edges() as u32).filter(|&e| topo.is_boundary_edge(e as usize)).collect();
    if boundary.is_empty() {
        return Vec::new();
    }
    let adj = Csr::from_pairs(
        topo.n_vertices,
        boundary.iter().flat_map(|&e| {
            let [a, b] = topo.edges[e as usize];
            [(a, e), (b, e)]
        }),
    );
    let mut used = vec![false; topo.n_edges()];
    // Per-vertex cursor into its adjacency row, past used edges (amortised linear).
    let mut cursor: Vec<u32> = adj.offsets[..topo.n_vertices].to_vec();
    let mut out = Vec::new();
    for &e0 in &boundary {
        if used[e0 as usize] {
            continue;
        }
        used[e0 as usize] = true;
        let [start, second] = topo.edges[e0 as usize];
        let mut vertices = vec![start];
        let mut closed = true;
        let mut cur = second;
        while cur != start {
            vertices.push(cur);
            match next_edge(topo, &adj, &used, &mut cursor, cur) {
                Some((e, next)) => {
                    used[e as usize] = true;
                    cur = next;
                }
                None => {
                    closed = false;
                    break;
                }
            }
        }
        if !closed {
            // Extend the open chain backwards from its start, so that a path is found
            // whole wherever its walk began.
            let mut back = Vec::new();
            let mut cur = start;
            while let Some((e, next)) = next_edge(topo, &adj, &used, &mut cursor, cur) {
                used[e as usize] = true;
                back.push(next);
                cur = next;
            }
            back.reverse();
            back.extend(vertices);
            vertices = back;
        }
        out.push(BoundaryCycle { vertices, first_edge: e0, closed });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_and_flipped_square() {
        let tris = [[0, 1, 2], [0, 2, 3]];
        let c = boundary_cycles(&Topology::build(4, &tris));
        assert_eq!(c.len(), 1);
        assert!(c[0].closed);
        assert_eq!(c[0].vertices.len(), 4);
        // Inconsistent orientation: still one loop of 4.
        let tris = [[0, 1, 2], [0, 3, 2]];
        let c = boundary_cycles(&Topology::build(4, &tris));
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].vertices.len(), 4);
    }
}
