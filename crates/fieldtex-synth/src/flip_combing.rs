//! Combed flip indicators for 2-RoSy synthesis (paper D §4).
//!
//! An orientation field is given by one representative vector per sample, and the
//! representatives may turn by 180° between neighbours anywhere (e.g. along the branch
//! cut of a complex square root), not only where a singularity forces it. The synthesis
//! works with the effective frame `(−1)^I J`; paper D starts from `I = 0`, so every
//! representative jump is a seam that the flip indicator must then repair. Combing
//! chooses the initial `I` so that the effective frames of grid neighbours agree
//! wherever possible: a breadth-first sweep over the 4-neighbours gives each sample its
//! discoverer's flip xor the consistency bit `⟨J(p), J(q)⟩ < 0` of the pair. What is
//! left are seams between samples reached along different paths around a singularity
//! (the index ±½ makes some seam unavoidable). Deterministic: a fixed sweep order.

use std::collections::VecDeque;

use crate::lattice_domain::{Jacobian, frobenius};

/// Combed flips of one level: `nbr[p]` holds the neighbours of `p` (`u32::MAX`: none)
/// in the engine's slot order, `jac[p]` its representative Jacobian, `axes` the slots of
/// the `2D` axis neighbours the sweep follows (for a 2-D grid `(1,0), (0,1), (−1,0),
/// (0,−1)`).
pub(crate) fn comb_flips<const D: usize, const S: usize>(
    nbr: &[[u32; S]],
    jac: &[Jacobian<D>],
    axes: &[usize],
) -> Vec<bool> {
    let n = jac.len();
    let mut fl = vec![false; n];
    let mut seen = vec![false; n];
    let mut queue = VecDeque::new();
    for start in 0..n {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        queue.push_back(start);
        while let Some(p) = queue.pop_front() {
            for &k in axes {
                let q = nbr[p][k];
                if q == u32::MAX || seen[q as usize] {
                    continue;
                }
                let q = q as usize;
                seen[q] = true;
                let opposite = frobenius(&jac[p], &jac[q]) < 0.0;
                fl[q] = fl[p] ^ opposite;
                queue.push_back(q);
            }
        }
    }
    fl
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 8-neighbour table of a `w × h` grid.
    fn grid(w: usize, h: usize) -> Vec<[u32; 8]> {
        const OFFS: [[i64; 2]; 8] =
            [[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1]];
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as i64, (i / w) as i64);
                OFFS.map(|o| {
                    let (a, b) = (x + o[0], y + o[1]);
                    if a < 0 || b < 0 || a >= w as i64 || b >= h as i64 {
                        u32::MAX
                    } else {
                        (b as usize * w + a as usize) as u32
                    }
                })
            })
            .collect()
    }

    /// Axis slots of the 8-neighbour order above.
    const AXIS_SLOTS: [usize; 4] = [0, 2, 4, 6];

    fn rot(a: f32) -> [f32; 4] {
        let (s, c) = a.sin_cos();
        [c, s, -s, c]
    }

    fn rows(jac: &[[f32; 4]]) -> Vec<Jacobian<2>> {
        jac.iter().map(|j| [[j[0], j[1]], [j[2], j[3]]]).collect()
    }

    #[test]
    fn a_jump_without_singularity_is_combed_away() {
        let (w, h) = (8, 5);
        // Representatives at 10° on the left half, 190° on the right: one orientation.
        let jac: Vec<[f32; 4]> = (0..w * h)
            .map(|i| rot(if i % w < 4 { 0.17 } else { 0.17 + std::f32::consts::PI }))
            .collect();
        let fl = comb_flips(&grid(w, h), &rows(&jac), &AXIS_SLOTS);
        for (i, &f) in fl.iter().enumerate() {
            assert_eq!(f, i % w >= 4, "sample {i}");
        }
    }

    #[test]
    fn a_wedge_keeps_one_short_seam() {
        // +1/2 wedge at the centre: the angle turns by π around it, so some seam is
        // forced; combing leaves seams only next to the centre row.
        let n = 16;
        let c = n as f32 / 2.0 - 0.5;
        let jac: Vec<[f32; 4]> =
            (0..n * n).map(|i| rot(0.5 * ((i / n) as f32 - c).atan2((i % n) as f32 - c))).collect();
        let nbr = grid(n, n);
        let fl = comb_flips(&nbr, &rows(&jac), &AXIS_SLOTS);
        let eff = |p: usize| jac[p].map(|v| if fl[p] { -v } else { v });
        let mut seams = 0;
        for (p, nb) in nbr.iter().enumerate() {
            for k in [0, 2] {
                let q = nb[k];
                if q != u32::MAX {
                    let (a, b) = (eff(p), eff(q as usize));
                    seams += (a[0] * b[0] + a[1] * b[1] < 0.0) as usize;
                }
            }
        }
        let raw = (0..n * n)
            .flat_map(|p| [0, 2].map(|k| (p, nbr[p][k])))
            .filter(|&(p, q)| {
                q != u32::MAX && {
                    let (a, b) = (jac[p], jac[q as usize]);
                    a[0] * b[0] + a[1] * b[1] < 0.0
                }
            })
            .count();
        assert!(seams >= 1, "a wedge needs a seam");
        assert!(seams <= n / 2 + 1, "{seams} seam pairs (representatives: {raw})");
    }
}
