//! Maximum flow / minimum s–t cut by the Boykov–Kolmogorov algorithm ("An experimental
//! comparison of min-cut/max-flow algorithms for energy minimization in vision", Boykov
//! & Kolmogorov 2004): two search trees grown from the source and the sink, augmentation
//! along the path where they meet, and adoption of the orphans the augmentation cut off.
//! Used for the graph-cut seams of image quilting (Kwatra et al. 2003).
//!
//! Capacities are integers (`i64`), so augmentation is exact and the search terminates;
//! callers scale real costs. Terminal links are stored as one signed residual per node
//! (`> 0`: residual from the source, `< 0`: to the sink). Every arc is stored with its
//! reverse (`arc ^ 1`). Deterministic: nodes and arcs are visited in insertion order.

use std::collections::VecDeque;

const NONE: usize = usize::MAX;
const TERMINAL: usize = usize::MAX - 1;

/// A flow network for [`MaxFlow::solve`]. Nodes are `0..n`.
#[derive(Debug, Clone)]
pub struct MaxFlow {
    terminal: Vec<i64>,
    first: Vec<usize>,
    next: Vec<usize>,
    head: Vec<u32>,
    cap: Vec<i64>,
    flow: i64,
    label: Vec<u8>,
    parent: Vec<usize>,
}

impl MaxFlow {
    /// An empty network with `n` nodes.
    pub fn new(n: usize) -> Self {
        Self {
            terminal: vec![0; n],
            first: vec![NONE; n],
            next: Vec::new(),
            head: Vec::new(),
            cap: Vec::new(),
            flow: 0,
            label: vec![0; n],
            parent: vec![NONE; n],
        }
    }

    /// Adds capacity `source` from the source to `v` and `sink` from `v` to the sink.
    pub fn add_terminal(&mut self, v: usize, source: i64, sink: i64) {
        let m = source.min(sink);
        self.flow += m;
        self.terminal[v] += source - sink;
    }

    /// Adds the arc pair `u → v` (capacity `cap_uv`) and `v → u` (`cap_vu`).
    pub fn add_edge(&mut self, u: usize, v: usize, cap_uv: i64, cap_vu: i64) {
        for (from, to, c) in [(u, v, cap_uv), (v, u, cap_vu)] {
            self.head.push(to as u32);
            self.cap.push(c.max(0));
            self.next.push(self.first[from]);
            self.first[from] = self.head.len() - 1;
        }
    }

    fn tail(&self, a: usize) -> usize {
        self.head[a ^ 1] as usize
    }

    /// Runs the algorithm; returns the maximum flow value (= the minimum cut cost).
    pub fn solve(&mut self) -> i64 {
        let n = self.terminal.len();
        let mut active: VecDeque<usize> = VecDeque::new();
        for v in 0..n {
            if self.terminal[v] != 0 {
                self.label[v] = if self.terminal[v] > 0 { 1 } else { 2 };
                self.parent[v] = TERMINAL;
                active.push_back(v);
            }
        }
        let mut orphans: VecDeque<usize> = VecDeque::new();
        while let Some(&p) = active.front() {
            if self.label[p] == 0 {
                active.pop_front();
                continue;
            }
            // Growth: find an arc from the source tree to the sink tree.
            let mut meet = NONE;
            let mut a = self.first[p];
            while a != NONE {
                let q = self.head[a] as usize;
                if self.label[p] == 1 && self.cap[a] > 0 {
                    if self.label[q] == 0 {
                        self.label[q] = 1;
                        self.parent[q] = a;
                        active.push_back(q);
                    } else if self.label[q] == 2 {
                        meet = a;
                        break;
                    }
                } else if self.label[p] == 2 && self.cap[a ^ 1] > 0 {
                    if self.label[q] == 0 {
                        self.label[q] = 2;
                        self.parent[q] = a ^ 1;
                        active.push_back(q);
                    } else if self.label[q] == 1 {
                        meet = a ^ 1;
                        break;
                    }
                }
                a = self.next[a];
            }
            if meet == NONE {
                active.pop_front();
                continue;
            }
            // Augmentation along source root → … → tail(meet) → head(meet) → … → sink.
            let mut bottleneck = self.cap[meet];
            let mut x = self.tail(meet);
            while self.parent[x] != TERMINAL {
                let pa = self.parent[x];
                bottleneck = bottleneck.min(self.cap[pa]);
                x = self.tail(pa);
            }
            bottleneck = bottleneck.min(self.terminal[x]);
            let mut y = self.head[meet] as usize;
            while self.parent[y] != TERMINAL {
                let pa = self.parent[y];
                bottleneck = bottleneck.min(self.cap[pa]);
                y = self.head[pa] as usize;
            }
            bottleneck = bottleneck.min(-self.terminal[y]);
            self.cap[meet] -= bottleneck;
            self.cap[meet ^ 1] += bottleneck;
            let mut x = self.tail(meet);
            while self.parent[x] != TERMINAL {
                let pa = self.parent[x];
                self.cap[pa] -= bottleneck;
                self.cap[pa ^ 1] += bottleneck;
                if self.cap[pa] == 0 {
                    self.parent[x] = NONE;
                    orphans.push_back(x);
                }
                x = self.tail(pa);
            }
            self.terminal[x] -= bottleneck;
            if self.terminal[x] == 0 {
                self.parent[x] = NONE;
                orphans.push_back(x);
            }
            let mut y = self.head[meet] as usize;
            while self.parent[y] != TERMINAL {
                let pa = self.parent[y];
                self.cap[pa] -= bottleneck;
                self.cap[pa ^ 1] += bottleneck;
                if self.cap[pa] == 0 {
                    self.parent[y] = NONE;
                    orphans.push_back(y);
                }
                y = self.head[pa] as usize;
            }
            self.terminal[y] += bottleneck;
            if self.terminal[y] == 0 {
                self.parent[y] = NONE;
                orphans.push_back(y);
            }
            self.flow += bottleneck;
            // Adoption.
            while let Some(o) = orphans.pop_front() {
                self.adopt(o, &mut active, &mut orphans);
            }
        }
        self.flow
    }

    /// `true` when the tree of `v` still reaches its terminal.
    fn rooted(&self, mut v: usize, source_tree: bool) -> bool {
        loop {
            match self.parent[v] {
                TERMINAL => return true,
                NONE => return false,
                a => v = if source_tree { self.tail(a) } else { self.head[a] as usize },
            }
        }
    }

    fn adopt(&mut self, o: usize, active: &mut VecDeque<usize>, orphans: &mut VecDeque<usize>) {
        let s = self.label[o] == 1;
        let mut a = self.first[o];
        while a != NONE {
            let q = self.head[a] as usize;
            // Source tree: parent q needs residual q → o (arc a ^ 1); sink tree: o → q (arc a).
            let residual = if s { self.cap[a ^ 1] } else { self.cap[a] };
            if self.label[q] == self.label[o] && residual > 0 && self.rooted(q, s) {
                self.parent[o] = if s { a ^ 1 } else { a };
                return;
            }
            a = self.next[a];
        }
        let mut a = self.first[o];
        while a != NONE {
            let q = self.head[a] as usize;
            if self.label[q] == self.label[o] {
                let residual = if s { self.cap[a ^ 1] } else { self.cap[a] };
                if residual > 0 {
                    active.push_back(q);
                }
                let pq = self.parent[q];
                if pq != NONE && pq != TERMINAL {
                    let through_o =
                        if s { self.tail(pq) == o } else { self.head[pq] as usize == o };
                    if through_o {
                        self.parent[q] = NONE;
                        orphans.push_back(q);
                    }
                }
            }
            a = self.next[a];
        }
        self.label[o] = 0;
    }

    /// After [`Self::solve`]: `true` when `v` is on the source side of the minimum cut.
    pub fn source_side(&self, v: usize) -> bool {
        self.label[v] == 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    /// Cost of the cut where `mask` bit `v` set = `v` on the source side.
    fn cut_cost(
        n: usize,
        term: &[(i64, i64)],
        edges: &[(usize, usize, i64, i64)],
        mask: u32,
    ) -> i64 {
        let side = |v: usize| mask >> v & 1 == 1;
        let mut c = 0;
        for (v, t) in term.iter().enumerate().take(n) {
            c += if side(v) { t.1 } else { t.0 };
        }
        for &(u, v, cuv, cvu) in edges {
            if side(u) && !side(v) {
                c += cuv;
            }
            if side(v) && !side(u) {
                c += cvu;
            }
        }
        c
    }

    #[test]
    fn matches_brute_force_on_random_small_graphs() {
        let mut rng = fieldtex_core::stream(7, "max-flow-test", 0);
        for case in 0..400 {
            let n = 2 + case % 9;
            let term: Vec<(i64, i64)> = (0..n)
                .map(|_| {
                    (
                        rng.random_range(0..6) * rng.random_range(0..2),
                        rng.random_range(0..6) * rng.random_range(0..2),
                    )
                })
                .collect();
            let mut edges = Vec::new();
            for _ in 0..rng.random_range(0..3 * n) {
                let (u, v) = (rng.random_range(0..n), rng.random_range(0..n));
                if u != v {
                    edges.push((u, v, rng.random_range(0..8), rng.random_range(0..8)));
                }
            }
            let mut g = MaxFlow::new(n);
            for (v, &(s, t)) in term.iter().enumerate() {
                g.add_terminal(v, s, t);
            }
            for &(u, v, a, b) in &edges {
                g.add_edge(u, v, a, b);
            }
            let flow = g.solve();
            let best = (0..1u32 << n).map(|m| cut_cost(n, &term, &edges, m)).min().unwrap();
            assert_eq!(flow, best, "case {case}");
            let mask = (0..n).fold(0u32, |m, v| m | (g.source_side(v) as u32) << v);
            assert_eq!(cut_cost(n, &term, &edges, mask), best, "case {case}: returned cut");
        }
    }
}
