//! Shortest system of homology loops through a base point (Erickson & Whittlesey 2005,
//! *Greedy optimal homotopy and homology generators*, SODA, §3: the greedy tree–cotree
//! construction), used as a cut graph that opens a closed surface of genus `g ≥ 1` into
//! one disk.
//!
//! For a base vertex `x`: `T` is the shortest-path tree from `x` (Dijkstra over 3-D
//! edge lengths); every edge `e = (a, b)` not in `T` closes the loop
//! `σ(e) = T[x → a] · e · T[b → x]` of length `d(a) + |e| + d(b)`. The cotree `C` is a
//! *maximum* spanning tree of the dual graph over the non-tree edges weighted by that
//! length (Kruskal, longest first); the `2g` edges in neither tree close the loops of
//! the system. Erickson & Whittlesey prove this system is the shortest system of loops
//! based at `x` (their Theorem 3.1); the shortest homology basis takes the best `x` over
//! all vertices, which here is approximated by trying a few candidate base points
//! (the caller's choice, e.g. the zero points of the holomorphic form) and keeping the
//! cut graph with the least total edge length (shared tree paths counted once, since
//! that is the seam they make).
//!
//! Each loop is kept as a simple cycle (the stem its two tree paths share up to the base
//! cancels). The union of the `2g` cycles cuts every period: a closed curve that
//! crosses none of them has zero intersection with a homology basis, so it is
//! null-homologous and a closed 1-form integrates to a single-valued function on the
//! cut-open surface (with the stems added the union would be the system's cut graph,
//! whose complement is one disk).

use super::tree_cotree::vertex_edges;
use fieldtex_core::vec3;
use fieldtex_mesh::{Topology, UnionFind};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// A system of loops through one base vertex and the cut graph they make.
#[derive(Debug, Clone)]
pub struct LoopSystem {
    pub root: u32,
    /// Per loop: its closing edge (in neither tree).
    pub closing_edges: Vec<u32>,
    /// Per loop: its edges (tree paths and closing edge; a stem the two paths share
    /// cancels), and its length.
    pub loops: Vec<(Vec<u32>, f64)>,
    /// Per edge: on some loop (stems excluded).
    pub cut: Vec<bool>,
    /// Total 3-D length of the cut edges.
    pub length: f64,
}

/// Edge lengths in 3-D.
pub(super) fn edge_lengths(positions: &[[f64; 3]], topology: &Topology) -> Vec<f64> {
    topology
        .edges
        .iter()
        .map(|e| vec3::norm(vec3::sub(positions[e[1] as usize], positions[e[0] as usize])))
        .collect()
}

/// Shortest-path tree from `root`: per vertex its distance and the tree edge to its
/// parent (`u32::MAX` at the root and at unreachable vertices). Ties break by vertex id,
/// so the tree is deterministic. With `radius` finite the search stops there: every
/// vertex within it has its exact distance, farther ones an upper bound above `radius`
/// or infinity.
pub(super) fn shortest_path_tree(
    topology: &Topology,
    vertex_edges: &[Vec<u32>],
    length: &[f64],
    root: usize,
    radius: f64,
) -> (Vec<f64>, Vec<u32>) {
    shortest_path_forest(topology, vertex_edges, length, &[root], radius)
}

/// [`shortest_path_tree`] grown from all of `roots` at once (distance to the nearest
/// root); an infinite edge length closes that edge.
pub(super) fn shortest_path_forest(
    topology: &Topology,
    vertex_edges: &[Vec<u32>],
    length: &[f64],
    roots: &[usize],
    radius: f64,
) -> (Vec<f64>, Vec<u32>) {
    let nv = topology.n_vertices;
    let mut dist = vec![f64::INFINITY; nv];
    let mut parent = vec![u32::MAX; nv];
    let mut done = vec![false; nv];
    let mut heap = BinaryHeap::new();
    for &root in roots {
        dist[root] = 0.0;
        heap.push(Reverse((0u64, root as u32)));
    }
    while let Some(Reverse((_, v))) = heap.pop() {
        let v = v as usize;
        if done[v] {
            continue;
        }
        if dist[v] > radius {
            break;
        }
        done[v] = true;
        for &e in &vertex_edges[v] {
            let ed = topology.edges[e as usize];
            let w = if ed[0] as usize == v { ed[1] } else { ed[0] } as usize;
            let nd = dist[v] + length[e as usize];
            if !done[w] && nd < dist[w] {
                dist[w] = nd;
                parent[w] = e;
                // Non-negative f64 bits order like the values.
                heap.push(Reverse((nd.to_bits(), w as u32)));
            }
        }
    }
    (dist, parent)
}

/// The greedy shortest system of loops through `root` (see the module docs) on a closed,
/// connected mesh.
pub fn loop_system(positions: &[[f64; 3]], topology: &Topology, root: u32) -> LoopSystem {
    let ne = topology.n_edges();
    let length = edge_lengths(positions, topology);
    let vertex_edges = vertex_edges(topology);
    let (dist, parent) =
        shortest_path_tree(topology, &vertex_edges, &length, root as usize, f64::INFINITY);
    let mut in_tree = vec![false; ne];
    for &e in &parent {
        if e != u32::MAX {
            in_tree[e as usize] = true;
        }
    }
    // Maximum spanning tree of the dual over the non-tree edges, by loop length.
    let loop_len = |e: usize| {
        let ed = topology.edges[e];
        dist[ed[0] as usize] + length[e] + dist[ed[1] as usize]
    };
    let mut order: Vec<usize> =
        (0..ne).filter(|&e| !in_tree[e] && topology.edge_faces(e).len() == 2).collect();
    order.sort_by(|&a, &b| loop_len(b).total_cmp(&loop_len(a)).then(a.cmp(&b)));
    let mut faces = UnionFind::new(topology.n_faces());
    let mut closing_edges = Vec::new();
    for e in order {
        let f = topology.edge_faces(e);
        if !faces.union(f[0] as usize, f[1] as usize) {
            closing_edges.push(e as u32);
        }
    }
    closing_edges.sort_unstable();
    let mut cut = vec![false; ne];
    let mut loops = Vec::with_capacity(closing_edges.len());
    for &e in &closing_edges {
        // Edges of the loop mod 2: the shared stem of the two tree paths cancels.
        let mut odd: Vec<u32> = vec![e];
        for mut v in topology.edges[e as usize].map(|v| v as usize) {
            while parent[v] != u32::MAX {
                let pe = parent[v];
                odd.push(pe);
                let ed = topology.edges[pe as usize];
                v = if ed[0] as usize == v { ed[1] } else { ed[0] } as usize;
            }
        }
        odd.sort_unstable();
        let mut edges: Vec<u32> = Vec::with_capacity(odd.len());
        let mut k = 0;
        while k < odd.len() {
            let run = odd[k..].iter().take_while(|&&x| x == odd[k]).count();
            if run % 2 == 1 {
                edges.push(odd[k]);
            }
            k += run;
        }
        for &x in &edges {
            cut[x as usize] = true;
        }
        let len = edges.iter().map(|&x| length[x as usize]).sum();
        loops.push((edges, len));
    }
    let total = cut_length(&cut, &length);
    LoopSystem { root, closing_edges, loops, cut, length: total }
}

fn cut_length(cut: &[bool], length: &[f64]) -> f64 {
    (0..cut.len()).filter(|&e| cut[e]).map(|e| length[e]).sum()
}

/// A short homology basis (Erickson & Whittlesey 2005 §4, the greedy basis over
/// candidate loops): the loops of the greedy systems through every candidate base in
/// `roots` are pooled, sorted by length, and taken greedily while their classes stay
/// independent over `Z₂` — the class of a loop is its pairing with the closed `cocycles`
/// (the `2g` dual-loop forms of a tree–cotree, integer-valued), mod 2. Unlike a system
/// of loops the basis loops need not share a base point, so no stems join them; the
/// surface cut along `2g` independent loops is connected up to pieces cut off where
/// loops cross, and every closed curve that crosses no loop is null-homologous, so a
/// closed 1-form integrates to a single-valued function on it. Their edges make `cut`;
/// `root` and `closing_edges` are those of the shortest system (for reference).
/// `None` when `roots` is empty or the pooled loops span fewer than `2g` classes.
pub fn shortest_homology_basis(
    positions: &[[f64; 3]],
    topology: &Topology,
    cocycles: &[Vec<f64>],
    roots: &[u32],
) -> Option<LoopSystem> {
    let n = cocycles.len();
    if n == 0 || n > 64 {
        return None;
    }
    let mut systems: Vec<LoopSystem> =
        roots.iter().map(|&r| loop_system(positions, topology, r)).collect();
    let class = |edges: &[u32]| -> u64 {
        let mut bits = 0u64;
        for (k, eta) in cocycles.iter().enumerate() {
            let s: f64 = edges.iter().map(|&e| eta[e as usize]).sum();
            if (s.round() as i64).rem_euclid(2) == 1 {
                bits |= 1 << k;
            }
        }
        bits
    };
    let mut pool: Vec<(f64, usize, usize)> = Vec::new();
    for (i, s) in systems.iter().enumerate() {
        for (j, l) in s.loops.iter().enumerate() {
            pool.push((l.1, i, j));
        }
    }
    pool.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    // Gaussian elimination over Z₂, one pivot bit per kept class.
    let mut pivots: Vec<u64> = Vec::new();
    let mut chosen: Vec<(usize, usize)> = Vec::new();
    for &(_, i, j) in &pool {
        let mut c = class(&systems[i].loops[j].0);
        for &p in &pivots {
            c = c.min(c ^ p);
        }
        if c != 0 {
            pivots.push(c);
            pivots.sort_unstable_by(|a, b| b.cmp(a));
            chosen.push((i, j));
            if chosen.len() == n {
                break;
            }
        }
    }
    if chosen.len() < n {
        return None;
    }
    let length = edge_lengths(positions, topology);
    let mut cut = vec![false; topology.n_edges()];
    let mut loops = Vec::with_capacity(n);
    for &(i, j) in &chosen {
        for &e in &systems[i].loops[j].0 {
            cut[e as usize] = true;
        }
        loops.push(systems[i].loops[j].clone());
    }
    let best = (0..systems.len())
        .min_by(|&a, &b| systems[a].length.total_cmp(&systems[b].length).then(a.cmp(&b)))?;
    let s = systems.swap_remove(best);
    let total = cut_length(&cut, &length);
    Some(LoopSystem { root: s.root, closing_edges: s.closing_edges, loops, cut, length: total })
}

/// The shortest cut graph (least total length) among the loop systems through the
/// candidate `roots` (the first wins a tie); `None` when `roots` is empty.
pub fn shortest_loop_system(
    positions: &[[f64; 3]],
    topology: &Topology,
    roots: &[u32],
) -> Option<LoopSystem> {
    let mut best: Option<LoopSystem> = None;
    for &r in roots {
        let s = loop_system(positions, topology, r);
        if best.as_ref().is_none_or(|b| s.length < b.length) {
            best = Some(s);
        }
    }
    best
}
