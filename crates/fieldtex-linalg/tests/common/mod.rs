//! Shared test fixtures: 2-D grid Laplacians with penalty diagonals, a tiny LCG.
#![allow(dead_code)]

use fieldtex_linalg::SparseMatrix;

/// Graph Laplacian (positive semi-definite, 4-neighbour) of a `w × h` grid, full symmetric.
pub fn grid_laplacian(w: usize, h: usize) -> SparseMatrix {
    let id = |x: usize, y: usize| y * w + x;
    let mut t = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let mut edge = |a: usize, b: usize| {
                t.push((a, a, 1.0));
                t.push((b, b, 1.0));
                t.push((a, b, -1.0));
                t.push((b, a, -1.0));
            };
            if x + 1 < w {
                edge(id(x, y), id(x + 1, y));
            }
            if y + 1 < h {
                edge(id(x, y), id(x, y + 1));
            }
        }
    }
    SparseMatrix::from_triplets(w * h, w * h, &t).unwrap()
}

/// Indices of every `step`-th unknown (a deterministic constraint set).
pub fn every(n: usize, step: usize) -> Vec<usize> {
    (0..n).step_by(step).collect()
}

/// Laplacian + α on the diagonal at `constrained`.
pub fn penalty_system(w: usize, h: usize, constrained: &[usize], alpha: f64) -> SparseMatrix {
    let l = grid_laplacian(w, h);
    let mut d = vec![0.0; w * h];
    for &i in constrained {
        d[i] += alpha;
    }
    l.add_diagonal(&d)
}

/// Small deterministic generator (tests only).
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64) / ((1u64 << 53) as f64)
    }
    pub fn below(&mut self, n: usize) -> usize {
        ((self.next_f64() * n as f64) as usize).min(n - 1)
    }
    pub fn vec(&mut self, n: usize) -> Vec<f64> {
        (0..n).map(|_| self.next_f64() * 2.0 - 1.0).collect()
    }
}

pub fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

pub fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |m, x| m.max(x.abs()))
}
