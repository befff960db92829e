//! Fan-aware vertex welding: merge coincident vertices only where merging stitches the
//! surface together, never where it would pinch it.
//!
//! A plain weld (merge every class of [`crate::coincident_vertices`]) turns a triangle
//! soup into a closed surface, but it also glues back together vertices that were
//! deliberately kept apart — two cones that touch at their tips, or the copies that
//! [`crate::non_manifold_split`] creates — producing non-manifold vertices again, so a
//! repair would never settle. Here the plain weld is only used to look at the result:
//!
//! 1. merge every coincidence class tentatively;
//! 2. triangles that collapse (two corners in one class) have those corners merged for
//!    real: the short edge is contracted;
//! 3. in the tentative mesh, find the fans around each merged vertex
//!    ([`crate::vertex_fans`], only edges with exactly two triangles connect);
//! 4. merge for real the original vertices that meet in one fan.
//!
//! Vertices that only share a position, like the tips of the two cones, are in
//! different fans and stay apart. Along a seam where three or more sheets would meet
//! nothing is welded (the tentative edge is non-manifold). The kept vertex is the
//! smallest index of its merged set, so its position and attributes win. Linear time.

use crate::UnionFind;
use crate::coincident_vertices::near_coincident_classes;
use crate::vertex_fans::{FanRule, corner_fans, vertex_face_table};

/// For every vertex, the vertex it is welded into (itself when kept). `triangles` must
/// index `positions`; `epsilon` is an absolute distance (`0` = exactly equal
/// positions only). Non-finite positions are never welded.
pub fn fan_aware_weld(positions: &[[f64; 3]], triangles: &[[u32; 3]], epsilon: f64) -> Vec<u32> {
    let nv = positions.len();
    let classes = near_coincident_classes(positions, epsilon);
    let identity: Vec<u32> = (0..nv as u32).collect();
    if classes == identity {
        return identity;
    }
    let mut uf = UnionFind::new(nv);
    // Tentative triangles; collapsed ones contract their short edges.
    let mut kept_orig: Vec<[u32; 3]> = Vec::with_capacity(triangles.len());
    let mut tentative: Vec<[u32; 3]> = Vec::with_capacity(triangles.len());
    for t in triangles {
        let m = t.map(|v| classes[v as usize]);
        if m[0] == m[1] || m[1] == m[2] || m[0] == m[2] {
            for (i, j) in [(0, 1), (1, 2), (0, 2)] {
                if m[i] == m[j] {
                    uf.union(t[i] as usize, t[j] as usize);
                }
            }
        } else {
            kept_orig.push(*t);
            tentative.push(m);
        }
    }
    let fans =
        corner_fans(&tentative, &vertex_face_table(nv, &tentative), FanRule::ManifoldEdgesOnly);
    let mut fan_first = vec![u32::MAX; fans.n_fans];
    for (t, cf) in kept_orig.iter().zip(&fans.corner_fan) {
        for i in 0..3 {
            let slot = &mut fan_first[cf[i] as usize];
            if *slot == u32::MAX {
                *slot = t[i];
            } else {
                uf.union(*slot as usize, t[i] as usize);
            }
        }
    }
    // Smallest index of each set (vertices are visited in ascending order).
    let mut root_min = vec![u32::MAX; nv];
    (0..nv)
        .map(|v| {
            let r = uf.find(v);
            if root_min[r] == u32::MAX {
                root_min[r] = v as u32;
            }
            root_min[r]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles of a square stored as a soup weld along the diagonal.
    #[test]
    fn soup_square_welds() {
        let p = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let w = fan_aware_weld(&p, &[[0, 1, 2], [3, 4, 5]], 0.0);
        assert_eq!(w, vec![0, 1, 2, 0, 2, 5]);
    }

    /// A bowtie with the shared corner stored twice stays apart.
    #[test]
    fn bowtie_copies_stay_apart() {
        let p = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [-1.0, -1.0, 0.0],
        ];
        let w = fan_aware_weld(&p, &[[0, 1, 2], [3, 4, 5]], 0.0);
        assert_eq!(w, (0..6).collect::<Vec<u32>>());
    }

    /// A needle whose short edge is below epsilon is contracted.
    #[test]
    fn short_edge_contracts() {
        let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1e-9, 0.0]];
        let w = fan_aware_weld(&p, &[[0, 1, 2]], 1e-6);
        assert_eq!(w, vec![0, 1, 1]);
    }
}
