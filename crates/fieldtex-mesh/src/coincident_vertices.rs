//! Coincident-vertex classes: which vertices share a position, exactly or within a
//! distance `ε`, found with a hash of positions (exact) and a uniform hash grid of cell
//! size `16ε` (near; a point looks across a cell face only when it is within `ε` of
//! it), both expected `O(#V)`.
//!
//! A class is named by its smallest vertex index (its representative), so results do
//! not depend on hash order. Near classes are the transitive closure of "closer than
//! or at `ε`" (single linkage): a chain of points each within `ε` of the next forms one
//! class even when its ends are farther apart. Vertices with a NaN or infinite
//! coordinate are never merged (each is its own class).
//!
//! Not implemented: a bound on the chain diameter, and protection against many
//! distinct points packed into one cell (that case is quadratic in the points of
//! the cell; real meshes never pack more than a handful).

use crate::UnionFind;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A small multiplicative hasher for integer keys (deterministic, fast; not DoS-safe,
/// which does not matter for mesh data).
#[derive(Default, Clone, Copy)]
pub(crate) struct IntHasher(u64);

impl Hasher for IntHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            self.write_u64(u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]));
        }
        for &b in chunks.remainder() {
            self.write_u64(b as u64);
        }
    }
    #[inline]
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    #[inline]
    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }
    #[inline]
    fn write_i64(&mut self, x: i64) {
        self.write_u64(x as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

/// `HashMap` with [`IntHasher`].
pub(crate) type IntMap<K, V> = HashMap<K, V, BuildHasherDefault<IntHasher>>;

/// The bits of a position with `-0.0` read as `0.0`, so that equal coordinates hash
/// equal.
#[inline]
fn position_key(p: &[f64; 3]) -> [u64; 3] {
    p.map(|c| if c == 0.0 { 0u64 } else { c.to_bits() })
}

#[inline]
fn finite(p: &[f64; 3]) -> bool {
    p[0].is_finite() && p[1].is_finite() && p[2].is_finite()
}

/// Representative (smallest index) of each vertex's class of exactly equal positions.
/// `result[v] == v` for the first vertex at a position and for non-finite vertices.
pub fn exact_coincident_classes(positions: &[[f64; 3]]) -> Vec<u32> {
    let mut first: IntMap<[u64; 3], u32> = IntMap::default();
    first.reserve(positions.len());
    positions
        .iter()
        .enumerate()
        .map(|(v, p)| {
            if !finite(p) {
                return v as u32;
            }
            *first.entry(position_key(p)).or_insert(v as u32)
        })
        .collect()
}

/// Representative (smallest index) of each vertex's class of positions linked by
/// distances `≤ epsilon` (absolute units). With `epsilon <= 0` (or not finite) this is
/// [`exact_coincident_classes`].
pub fn near_coincident_classes(positions: &[[f64; 3]], epsilon: f64) -> Vec<u32> {
    near_coincident_classes_from(positions, exact_coincident_classes(positions), epsilon)
}

/// [`near_coincident_classes`] when the exact classes are already known.
pub fn near_coincident_classes_from(
    positions: &[[f64; 3]],
    exact: Vec<u32>,
    epsilon: f64,
) -> Vec<u32> {
    if !(epsilon > 0.0 && epsilon.is_finite()) {
        return exact;
    }
    // Work on the distinct finite positions only.
    let uniq: Vec<u32> = (0..positions.len() as u32)
        .filter(|&v| exact[v as usize] == v && finite(&positions[v as usize]))
        .collect();
    // Cells of side 16ε: a point closer than ε to a cell face (with a margin of 2×
    // for rounding) also looks in the cell across that face, so each pair within ε is
    // seen from both sides while a typical point looks at one or two cells only.
    let h = 16.0 * epsilon;
    let inv = 1.0 / h;
    let near_face = 2.0 / 16.0;
    let cell_of = |p: &[f64; 3]| -> [i64; 3] { p.map(|c| (c * inv).floor() as i64) };
    // Cells as a CSR table: cell id by first appearance, then the points of each cell.
    let mut cell_id: IntMap<[i64; 3], u32> = IntMap::default();
    cell_id.reserve(uniq.len());
    let point_cell: Vec<u32> = uniq
        .iter()
        .map(|&v| {
            let next = cell_id.len() as u32;
            *cell_id.entry(cell_of(&positions[v as usize])).or_insert(next)
        })
        .collect();
    let cells = crate::Csr::from_pairs(
        cell_id.len(),
        point_cell.iter().enumerate().map(|(k, &c)| (c, k as u32)),
    );
    let eps2 = epsilon * epsilon;
    let mut uf = UnionFind::new(uniq.len());
    for (k, &v) in uniq.iter().enumerate() {
        let p = positions[v as usize];
        let c = cell_of(&p);
        // Per axis, the neighbour cell offsets to visit: 0 and maybe -1 or +1.
        let offsets = [0, 1, 2].map(|a| {
            let frac = p[a] * inv - c[a] as f64;
            if frac < near_face {
                [0i64, -1]
            } else if frac > 1.0 - near_face {
                [0, 1]
            } else {
                [0, 0]
            }
        });
        let span = offsets.map(|o| if o[1] == 0 { 1 } else { 2 });
        for ix in 0..span[0] {
            for iy in 0..span[1] {
                for iz in 0..span[2] {
                    let key = [
                        c[0].saturating_add(offsets[0][ix]),
                        c[1].saturating_add(offsets[1][iy]),
                        c[2].saturating_add(offsets[2][iz]),
                    ];
                    let cid = if ix + iy + iz == 0 {
                        point_cell[k]
                    } else {
                        match cell_id.get(&key) {
                            Some(&cid) => cid,
                            None => continue,
                        }
                    };
                    for &k2 in cells.row(cid as usize) {
                        if (k2 as usize) <= k {
                            continue;
                        }
                        let q = positions[uniq[k2 as usize] as usize];
                        let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
                        if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= eps2 {
                            uf.union(k, k2 as usize);
                        }
                    }
                }
            }
        }
    }
    // Smallest vertex index per union-find root (uniq is ascending, so the first seen).
    let mut root_rep = vec![u32::MAX; uniq.len()];
    let mut uniq_rep = vec![0u32; uniq.len()];
    for (k, &v) in uniq.iter().enumerate() {
        let r = uf.find(k);
        if root_rep[r] == u32::MAX {
            root_rep[r] = v;
        }
        uniq_rep[k] = root_rep[r];
    }
    let mut rep_of_uniq = vec![u32::MAX; positions.len()];
    for (k, &v) in uniq.iter().enumerate() {
        rep_of_uniq[v as usize] = uniq_rep[k];
    }
    exact
        .iter()
        .enumerate()
        .map(|(v, &e)| {
            let r = rep_of_uniq[e as usize];
            if r == u32::MAX { v as u32 } else { r }
        })
        .collect()
}

/// Number of vertices that are not the representative of their class
/// (how many vertices a weld by `classes` would remove).
pub fn count_merged(classes: &[u32]) -> usize {
    classes.iter().enumerate().filter(|&(v, &r)| r as usize != v).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_and_near_classes() {
        let p = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [-0.0, 0.0, 0.0],
            [1.0 + 1e-9, 0.0, 0.0],
            [f64::NAN, 0.0, 0.0],
            [f64::NAN, 0.0, 0.0],
            [5.0, 5.0, 5.0],
            [1.0 + 2e-9, 0.0, 0.0],
        ];
        let ex = exact_coincident_classes(&p);
        assert_eq!(ex, vec![0, 1, 0, 3, 4, 5, 6, 7]);
        assert_eq!(count_merged(&ex), 1);
        let near = near_coincident_classes(&p, 1.5e-9);
        // 1, 3 and 7 chain together (1e-9 steps).
        assert_eq!(near, vec![0, 1, 0, 1, 4, 5, 6, 1]);
        assert_eq!(count_merged(&near), 3);
        assert_eq!(near_coincident_classes(&p, 0.0), ex);
    }

    /// Points on both sides of a cell boundary are still found.
    #[test]
    fn near_across_cells() {
        let p = vec![[0.999, 0.0, 0.0], [1.0005, 0.0, 0.0], [3.0, 0.0, 0.0]];
        let near = near_coincident_classes(&p, 0.01);
        assert_eq!(near, vec![0, 0, 2]);
    }

    /// Same classes as a brute-force pairwise search on clustered random points.
    #[test]
    fn matches_brute_force() {
        let mut state = 3u64;
        let mut unit = || {
            state = fieldtex_core::rng::mix64(state.wrapping_add(0x9e37_79b9_7f4a_7c15));
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let eps = 0.01;
        let p: Vec<[f64; 3]> = (0..600)
            .map(|_| {
                // Centres on a coarse lattice, jitter around ε so chains and misses occur.
                let c = [(unit() * 4.0).floor(), (unit() * 4.0).floor(), 0.5];
                [c[0] + unit() * 0.02, c[1] + unit() * 0.02, c[2] - unit() * 0.02]
            })
            .collect();
        let mut uf = UnionFind::new(p.len());
        for i in 0..p.len() {
            for j in i + 1..p.len() {
                let d = [p[i][0] - p[j][0], p[i][1] - p[j][1], p[i][2] - p[j][2]];
                if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= eps * eps {
                    uf.union(i, j);
                }
            }
        }
        let mut min_of_root = vec![u32::MAX; p.len()];
        let brute: Vec<u32> = (0..p.len())
            .map(|v| {
                let r = uf.find(v);
                if min_of_root[r] == u32::MAX {
                    min_of_root[r] = v as u32;
                }
                min_of_root[r]
            })
            .collect();
        let fast = near_coincident_classes(&p, eps);
        assert_eq!(fast, brute);
        let merged = count_merged(&fast);
        assert!(merged > 100 && merged < 590, "{merged}");
    }
}
