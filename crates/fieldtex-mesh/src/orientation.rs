//! Orientation analysis: which triangles must be flipped so that neighbours agree.
//!
//! Two triangles sharing an edge are consistently oriented when they traverse the edge
//! in opposite directions (`face_edge_signs` differ). A breadth-first search over
//! edges with exactly two triangles assigns each triangle a parity (flip or not,
//! relative to the first triangle of its patch); a *patch* is a set of triangles
//! connected through such edges. A patch where the parities contradict each other
//! (a Möbius strip, a Klein bottle) is non-orientable.
//!
//! Edges with more than two triangles are ignored: whether a non-manifold surface is
//! orientable has no single answer. Linear time.

use crate::Topology;
use crate::vertex_fans::edge_slot;

/// Result of [`orientation_patches`].
#[derive(Debug, Clone)]
pub struct OrientationPatches {
    /// `#F`: patch of each triangle; patches are numbered by their first triangle.
    pub patch: Vec<u32>,
    /// `#F`: `true` when the triangle disagrees with its patch's first triangle.
    /// Meaningless inside non-orientable patches.
    pub parity: Vec<bool>,
    /// Per patch: no contradiction was found.
    pub orientable: Vec<bool>,
    /// Edges with two triangles traversing them in the same direction, ascending.
    pub inconsistent_edges: Vec<u32>,
}

impl OrientationPatches {
    pub fn n_patches(&self) -> usize {
        self.orientable.len()
    }
}

/// Patches, parities and inconsistent edges of a mesh whose topology is `topo`.
pub fn orientation_patches(topo: &Topology) -> OrientationPatches {
    let nf = topo.n_faces();
    let mut patch = vec![u32::MAX; nf];
    let mut parity = vec![false; nf];
    let mut orientable = Vec::new();
    let mut queue: Vec<u32> = Vec::new();
    for seed in 0..nf {
        if patch[seed] != u32::MAX {
            continue;
        }
        let id = orientable.len() as u32;
        let mut ok = true;
        patch[seed] = id;
        queue.clear();
        queue.push(seed as u32);
        let mut head = 0;
        while head < queue.len() {
            let f = queue[head] as usize;
            head += 1;
            for i in 0..3 {
                let e = topo.face_edges[f][i];
                let faces = topo.edge_faces(e as usize);
                if faces.len() != 2 {
                    continue;
                }
                let g = if faces[0] as usize == f { faces[1] } else { faces[0] } as usize;
                if g == f {
                    continue;
                }
                let sf = topo.face_edge_signs[f][i];
                let sg = topo.face_edge_signs[g][edge_slot(topo, g, e)];
                let want = parity[f] ^ (sf == sg);
                if patch[g] == u32::MAX {
                    patch[g] = id;
                    parity[g] = want;
                    queue.push(g as u32);
                } else if parity[g] != want {
                    ok = false;
                }
            }
        }
        orientable.push(ok);
    }
    let inconsistent_edges = (0..topo.n_edges() as u32)
        .filter(|&e| {
            let faces = topo.edge_faces(e as usize);
            faces.len() == 2 && {
                let (f, g) = (faces[0] as usize, faces[1] as usize);
                topo.face_edge_signs[f][edge_slot(topo, f, e)]
                    == topo.face_edge_signs[g][edge_slot(topo, g, e)]
            }
        })
        .collect();
    OrientationPatches { patch, parity, orientable, inconsistent_edges }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flipped_square_half() {
        // Square split along 0-2, second triangle flipped.
        let tris = [[0, 1, 2], [0, 3, 2]];
        let topo = Topology::build(4, &tris);
        let o = orientation_patches(&topo);
        assert_eq!(o.n_patches(), 1);
        assert!(o.orientable[0]);
        assert_eq!(o.parity, vec![false, true]);
        assert_eq!(o.inconsistent_edges.len(), 1);
    }
}
