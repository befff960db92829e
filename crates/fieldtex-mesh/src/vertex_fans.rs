//! Fans: the triangles around a vertex that are connected to each other through edges
//! at that vertex.
//!
//! A vertex is manifold when its triangles form exactly one fan (a disk inside, a
//! half-disk on the boundary). Two cones touching at their tips give a vertex with two
//! fans; a vertex on an edge shared by three or more triangles usually has several.
//!
//! Everything about the edges at `v` is visible from `v`'s own triangles (every
//! triangle on edge `v–x` contains `v`), so fans are found vertex by vertex: each
//! triangle at `v` contributes its two edges at `v`; sorted by the other end, equal
//! ends pair the triangles up; a tiny union-find over `v`'s triangles gives the fans.
//! Linear, parallel over fixed blocks of vertices (deterministic), no edge table.
//!
//! Edges with more than two triangles connect nothing, unless [`FanRule::PairNonManifold`]
//! is asked for: then each such edge joins one chosen pair, the first two of its
//! triangles (in triangle order) that traverse it in opposite directions, or its first
//! two triangles when no such pair exists. Repair uses that to keep two triangles
//! attached along a non-manifold edge and detach the others.

use crate::Csr;
use crate::Topology;
use rayon::prelude::*;

/// How edges used by more than two triangles take part in fans.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FanRule {
    /// Non-manifold edges connect nothing.
    ManifoldEdgesOnly,
    /// Each non-manifold edge connects one chosen pair of its triangles.
    PairNonManifold,
}

/// Fans of every corner.
#[derive(Debug, Clone)]
pub struct CornerFans {
    /// `#F × 3` fan id per corner, unique over the mesh (`< n_fans`); the fans of
    /// vertex `v` are numbered consecutively in order of their first triangle.
    pub corner_fan: Vec<[u32; 3]>,
    /// Number of distinct fans over the whole mesh.
    pub n_fans: usize,
    /// `#V`: number of fans at each vertex (0 for vertices no triangle uses).
    pub fans_at_vertex: Vec<u32>,
    /// Edges with more than two triangles, `[low, high]`, ascending.
    pub non_manifold_edges: Vec<[u32; 2]>,
}

/// The pair a non-manifold edge keeps attached: `outgoing[k]` tells the direction in
/// which its `k`-th triangle (in triangle order) traverses it.
pub fn chosen_pair(outgoing: &[bool]) -> (usize, usize) {
    for i in 0..outgoing.len() {
        for j in i + 1..outgoing.len() {
            if outgoing[i] != outgoing[j] {
                return (i, j);
            }
        }
    }
    (0, 1)
}

/// Corner of triangle `t` at vertex `v` (the first one if repeated).
#[inline]
pub(crate) fn corner_at(t: &[u32; 3], v: u32) -> usize {
    if t[0] == v {
        0
    } else if t[1] == v {
        1
    } else {
        2
    }
}

/// Slot `i` of triangle `f` with `face_edges[f][i] == e`.
#[inline]
pub(crate) fn edge_slot(topo: &Topology, f: usize, e: u32) -> usize {
    let fe = topo.face_edges[f];
    if fe[0] == e {
        0
    } else if fe[1] == e {
        1
    } else {
        2
    }
}

/// Vertex → triangles table, triangles ascending in each row.
pub fn vertex_face_table(n_vertices: usize, triangles: &[[u32; 3]]) -> Csr {
    Csr::from_pairs(
        n_vertices,
        triangles.iter().enumerate().flat_map(|(f, t)| t.iter().map(move |&v| (v, f as u32))),
    )
}

/// Buffers reused from vertex to vertex.
#[derive(Default)]
struct Scratch {
    /// (other end, local triangle, triangle leaves v along this edge)
    ends: Vec<(u32, u32, bool)>,
    parent: Vec<u32>,
    label_of_root: Vec<u32>,
    outgoing: Vec<bool>,
}

/// Local fans of one vertex: pushes a label per row entry and the non-manifold edges
/// `v–x` with `x > v`; returns the fan count.
fn vertex_local(
    v: u32,
    faces: &[u32],
    triangles: &[[u32; 3]],
    rule: FanRule,
    labels: &mut Vec<u32>,
    nm: &mut Vec<[u32; 2]>,
    scratch: &mut Scratch,
) -> u32 {
    let n = faces.len();
    let Scratch { ends, parent, label_of_root, outgoing } = scratch;
    ends.clear();
    for (k, &f) in faces.iter().enumerate() {
        let t = &triangles[f as usize];
        let i = corner_at(t, v);
        ends.push((t[(i + 1) % 3], k as u32, true));
        ends.push((t[(i + 2) % 3], k as u32, false));
    }
    ends.sort_unstable();
    parent.clear();
    parent.extend(0..n as u32);
    fn find(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    let mut s = 0;
    while s < ends.len() {
        let mut e = s + 1;
        while e < ends.len() && ends[e].0 == ends[s].0 {
            e += 1;
        }
        let group = &ends[s..e];
        let pair = match group.len() {
            2 => Some((0, 1)),
            m if m > 2 => {
                if ends[s].0 > v {
                    nm.push([v, ends[s].0]);
                }
                if rule == FanRule::PairNonManifold {
                    outgoing.clear();
                    outgoing.extend(group.iter().map(|g| g.2));
                    Some(chosen_pair(outgoing))
                } else {
                    None
                }
            }
            _ => None,
        };
        if let Some((a, b)) = pair {
            let (ra, rb) = (find(parent, group[a].1), find(parent, group[b].1));
            if ra != rb {
                parent[ra.max(rb) as usize] = ra.min(rb);
            }
        }
        s = e;
    }
    // Labels in order of first triangle.
    label_of_root.clear();
    label_of_root.resize(n, u32::MAX);
    let mut count = 0u32;
    for k in 0..n as u32 {
        let r = find(parent, k) as usize;
        if label_of_root[r] == u32::MAX {
            label_of_root[r] = count;
            count += 1;
        }
        labels.push(label_of_root[r]);
    }
    count
}

/// Fans of all corners. `triangles` must have distinct indices in each triangle (a
/// repeated one is treated as its first corner only); `vertex_faces` is
/// [`vertex_face_table`] of them (or the same rows from a [`Topology`]).
pub fn corner_fans(triangles: &[[u32; 3]], vertex_faces: &Csr, rule: FanRule) -> CornerFans {
    const BLOCK: usize = 2048;
    let nv = vertex_faces.n_rows();
    // Per block of vertices: (labels of its rows' entries, fans per vertex, nm edges).
    type Block = (Vec<u32>, Vec<u32>, Vec<[u32; 2]>);
    let blocks: Vec<Block> = (0..nv.div_ceil(BLOCK))
        .into_par_iter()
        .map(|b| {
            let (mut labels, mut counts, mut nm) = (Vec::new(), Vec::new(), Vec::new());
            let mut scratch = Scratch::default();
            for v in b * BLOCK..((b + 1) * BLOCK).min(nv) {
                let row = vertex_faces.row(v);
                let c = vertex_local(
                    v as u32,
                    row,
                    triangles,
                    rule,
                    &mut labels,
                    &mut nm,
                    &mut scratch,
                );
                counts.push(c);
            }
            (labels, counts, nm)
        })
        .collect();
    let mut fans_at_vertex = Vec::with_capacity(nv);
    let mut non_manifold_edges = Vec::new();
    let mut corner_fan = vec![[u32::MAX; 3]; triangles.len()];
    let mut base = 0u32;
    let mut v = 0usize;
    for (labels, counts, nm) in blocks {
        let mut k = 0;
        for c in counts {
            for &f in vertex_faces.row(v) {
                let t = &triangles[f as usize];
                corner_fan[f as usize][corner_at(t, v as u32)] = base + labels[k];
                k += 1;
            }
            base += c;
            fans_at_vertex.push(c);
            v += 1;
        }
        non_manifold_edges.extend(nm);
    }
    // Corners a repeated index hid get a fan of their own.
    for cf in &mut corner_fan {
        for slot in cf.iter_mut() {
            if *slot == u32::MAX {
                *slot = base;
                base += 1;
            }
        }
    }
    CornerFans { corner_fan, n_fans: base as usize, fans_at_vertex, non_manifold_edges }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fans(tris: &[[u32; 3]], nv: usize, rule: FanRule) -> CornerFans {
        corner_fans(tris, &vertex_face_table(nv, tris), rule)
    }

    /// Two triangles touching at vertex 0 only: two fans there.
    #[test]
    fn bowtie_has_two_fans() {
        let f = fans(&[[0, 1, 2], [0, 3, 4]], 5, FanRule::ManifoldEdgesOnly);
        assert_eq!(f.fans_at_vertex, vec![2, 1, 1, 1, 1]);
        assert_eq!(f.n_fans, 6);
        assert!(f.non_manifold_edges.is_empty());
    }

    /// Three triangles on edge 0-1: separate fans, or one pair joined.
    #[test]
    fn nonmanifold_edge_pairing() {
        let tris = [[0, 1, 2], [1, 0, 3], [0, 1, 4]];
        let f = fans(&tris, 5, FanRule::ManifoldEdgesOnly);
        assert_eq!(f.fans_at_vertex[..2], [3, 3]);
        assert_eq!(f.non_manifold_edges, vec![[0, 1]]);
        let f = fans(&tris, 5, FanRule::PairNonManifold);
        assert_eq!(f.fans_at_vertex[..2], [2, 2]);
        // Triangles 0 and 1 traverse 0-1 in opposite directions: they are the pair.
        assert_eq!(f.corner_fan[0][0], f.corner_fan[1][1]);
        assert_ne!(f.corner_fan[0][0], f.corner_fan[2][0]);
    }

    /// A closed fan (icosphere vertex) and an open one (grid corner) are single fans.
    #[test]
    fn manifold_meshes_have_one_fan_per_vertex() {
        for m in [crate::primitives::icosphere(2), crate::primitives::grid(5, 3, 1.0, 1.0)] {
            let f = fans(&m.triangles, m.n_vertices(), FanRule::ManifoldEdgesOnly);
            assert!(f.fans_at_vertex.iter().all(|&c| c == 1));
            assert_eq!(f.n_fans, m.n_vertices());
        }
    }
}
