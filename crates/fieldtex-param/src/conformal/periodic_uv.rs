//! Integrating a closed ℝ²-valued 1-form into per-corner UVs on a periodic domain.
//!
//! The 1-form `d` (one 2-vector per edge, low → high) is integrated along a
//! breadth-first spanning tree into a base position per vertex; each triangle then gets
//! its own local chart (its first corner's base position plus the form along its two
//! edges), and is moved by a lattice translation so that its centroid lies in the
//! fundamental domain. Because the form is closed, neighbouring triangles in the same
//! cell agree, and triangles on the two sides of a period seam differ by exactly one
//! lattice vector: the seams of the texture are where that translation changes.

use fieldtex_mesh::Topology;
use std::collections::VecDeque;

/// The translations that identify the fundamental domain's opposite sides.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lattice {
    /// Horizontal period `(a, 0)`, `a > 0`; `None` when x is not periodic.
    pub a: Option<f64>,
    /// Second period `(b.x, b.y)`, `b.y > 0`, `0 ≤ b.x < a`; `None` when y is not periodic.
    pub b: Option<[f64; 2]>,
}

impl Lattice {
    /// The lattice translation that moves `c` into the fundamental domain
    /// `[0, a) × [0, b.y)` (only the periodic directions are reduced).
    pub fn reduction(&self, c: [f64; 2]) -> [f64; 2] {
        let mut s = [0.0, 0.0];
        let mut c = c;
        if let Some(b) = self.b {
            let n = (c[1] / b[1]).floor();
            s = [-n * b[0], -n * b[1]];
            c = [c[0] + s[0], c[1] + s[1]];
        }
        if let Some(a) = self.a {
            let m = (c[0] / a).floor();
            s[0] -= m * a;
        }
        s
    }
}

/// Base UV per vertex (NaN where not reached) and per-face corner UVs (NaN for faces
/// without `keep`).
#[derive(Debug, Clone)]
pub struct PeriodicUv {
    pub base: Vec<[f64; 2]>,
    pub corner: Vec<[[f64; 2]; 3]>,
}

/// The value of the 2-vector form along corner edge `i → j` of face `f`.
pub fn along2(topology: &Topology, d: &[[f64; 2]], f: usize, i: usize, j: usize) -> [f64; 2] {
    let fe = topology.face_edges[f];
    let (k, s) = if (i + 1) % 3 == j {
        (i, topology.face_edge_signs[f][i] as f64)
    } else {
        (j, -(topology.face_edge_signs[f][j] as f64))
    };
    let v = d[fe[k] as usize];
    [s * v[0], s * v[1]]
}

/// Integrates `d` over the faces with `keep` (see the module docs).
pub fn integrate(
    topology: &Topology,
    triangles: &[[u32; 3]],
    keep: &[bool],
    d: &[[f64; 2]],
) -> PeriodicUv {
    let nv = topology.n_vertices;
    let mut edge_kept = vec![false; topology.n_edges()];
    for (f, fe) in topology.face_edges.iter().enumerate() {
        if keep[f] {
            for &e in fe {
                edge_kept[e as usize] = true;
            }
        }
    }
    let mut vertex_edges: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for (e, ed) in topology.edges.iter().enumerate() {
        if edge_kept[e] {
            vertex_edges[ed[0] as usize].push(e as u32);
            vertex_edges[ed[1] as usize].push(e as u32);
        }
    }
    let mut base = vec![[f64::NAN; 2]; nv];
    let mut queue = VecDeque::new();
    for root in 0..nv {
        if !base[root][0].is_nan() || vertex_edges[root].is_empty() {
            continue;
        }
        base[root] = [0.0, 0.0];
        queue.push_back(root);
        while let Some(v) = queue.pop_front() {
            for &e in &vertex_edges[v] {
                let ed = topology.edges[e as usize];
                let de = d[e as usize];
                let (w, s) = if ed[0] as usize == v {
                    (ed[1] as usize, 1.0)
                } else {
                    (ed[0] as usize, -1.0)
                };
                if base[w][0].is_nan() {
                    base[w] = [base[v][0] + s * de[0], base[v][1] + s * de[1]];
                    queue.push_back(w);
                }
            }
        }
    }
    let corner = (0..triangles.len())
        .map(|f| {
            if !keep[f] {
                return [[f64::NAN; 2]; 3];
            }
            let c0 = base[triangles[f][0] as usize];
            let d1 = along2(topology, d, f, 0, 1);
            let d2 = along2(topology, d, f, 0, 2);
            [c0, [c0[0] + d1[0], c0[1] + d1[1]], [c0[0] + d2[0], c0[1] + d2[1]]]
        })
        .collect();
    PeriodicUv { base, corner }
}

/// Moves every face (non-NaN corners) by the lattice translation of its centroid.
pub fn reduce_faces(corner: &mut [[[f64; 2]; 3]], lattice: &Lattice) {
    for c in corner.iter_mut() {
        if c[0][0].is_nan() {
            continue;
        }
        let g = [(c[0][0] + c[1][0] + c[2][0]) / 3.0, (c[0][1] + c[1][1] + c[2][1]) / 3.0];
        let s = lattice.reduction(g);
        for p in c.iter_mut() {
            p[0] += s[0];
            p[1] += s[1];
        }
    }
}

/// Lagrange–Gauss reduction of a 2-D lattice basis: returns a basis of the same lattice
/// whose first vector is a shortest non-zero lattice vector and whose second is the
/// shortest independent one (`|⟨z1, z2⟩| ≤ |z1|²/2`). A torus image cut along the
/// shortest period has the shortest seams (e.g. meridians rather than helices).
pub fn reduce_basis(mut z1: [f64; 2], mut z2: [f64; 2]) -> ([f64; 2], [f64; 2]) {
    let n2 = |z: [f64; 2]| z[0] * z[0] + z[1] * z[1];
    for _ in 0..64 {
        if n2(z2) < n2(z1) {
            std::mem::swap(&mut z1, &mut z2);
        }
        let d = n2(z1);
        if d <= 0.0 || !d.is_finite() {
            break;
        }
        let m = ((z1[0] * z2[0] + z1[1] * z2[1]) / d).round();
        if m == 0.0 {
            break;
        }
        z2 = [z2[0] - m * z1[0], z2[1] - m * z1[1]];
    }
    (z1, z2)
}

/// Signed UV area of a face.
pub fn signed_area(c: &[[f64; 2]; 3]) -> f64 {
    0.5 * ((c[1][0] - c[0][0]) * (c[2][1] - c[0][1]) - (c[1][1] - c[0][1]) * (c[2][0] - c[0][0]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_reduction_finds_the_short_basis() {
        // The rectangular lattice (1, 0), (0, 4) given by a sheared basis.
        let (z1, z2) = reduce_basis([3.0, 4.0], [5.0, 8.0]);
        assert_eq!(z1.map(f64::abs), [1.0, 0.0]);
        assert_eq!(z2.map(f64::abs), [0.0, 4.0]);
    }
}
