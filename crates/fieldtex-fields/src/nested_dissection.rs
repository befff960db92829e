//! Geometric nested-dissection ordering of a mesh's unknowns for sparse Cholesky
//! (George 1973, "Nested dissection of a regular finite element mesh"; the geometric
//! splitting of Miller, Teng, Thurston & Vavasis 1998, here simply by coordinate).
//!
//! A vertex set larger than [`LEAF`] is split at the median of its longest bounding-box
//! axis; the vertices of the lower half that have a neighbour in the upper half form the
//! separator. The order is: the lower half (recursively), the upper half (recursively),
//! the separator last. Leaves keep their input order (mesh order, usually spatially
//! coherent). The elimination tree is then balanced and the paths from a vertex to the
//! root cross one separator per level, which keeps rank-1 update paths and partial solves
//! short. Deterministic (ties broken by index).

use fieldtex_core::vec3::V3;

/// Sets at most this large are not split.
pub const LEAF: usize = 64;

/// Ordering of the `n` unknowns of a mesh block: `perm[k]` = the local index eliminated
/// `k`-th. `positions[i]` is unknown `i`'s position; the adjacency is a symmetric CSC
/// pattern (`col_ptr`, `row_idx`; the diagonal may be present).
pub fn nested_dissection_order(
    positions: &[V3],
    col_ptr: &[usize],
    row_idx: &[usize],
) -> Vec<usize> {
    let n = positions.len();
    let mut side = vec![0u8; n];
    let mut out = Vec::with_capacity(n);
    let all: Vec<u32> = (0..n as u32).collect();
    dissect(all, positions, col_ptr, row_idx, &mut side, &mut out);
    out
}

fn dissect(
    mut set: Vec<u32>,
    positions: &[V3],
    col_ptr: &[usize],
    row_idx: &[usize],
    side: &mut [u8],
    out: &mut Vec<usize>,
) {
    if set.len() <= LEAF {
        out.extend(set.iter().map(|&v| v as usize));
        return;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for &v in &set {
        let p = positions[v as usize];
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let axis = (0..3).max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b]))).unwrap_or(0);
    let mid = set.len() / 2;
    set.select_nth_unstable_by(mid, |&a, &b| {
        positions[a as usize][axis].total_cmp(&positions[b as usize][axis]).then(a.cmp(&b))
    });
    let upper = set.split_off(mid);
    for &v in &set {
        side[v as usize] = 1;
    }
    for &v in &upper {
        side[v as usize] = 2;
    }
    let mut lower = Vec::with_capacity(set.len());
    let mut separator = Vec::new();
    for &v in &set {
        let touches_upper =
            row_idx[col_ptr[v as usize]..col_ptr[v as usize + 1]].iter().any(|&r| side[r] == 2);
        if touches_upper { separator.push(v) } else { lower.push(v) }
    }
    for &v in set.iter().chain(&upper) {
        side[v as usize] = 0;
    }
    lower.sort_unstable();
    let mut upper = upper;
    upper.sort_unstable();
    separator.sort_unstable();
    dissect(lower, positions, col_ptr, row_idx, side, out);
    dissect(upper, positions, col_ptr, row_idx, side, out);
    out.extend(separator.iter().map(|&v| v as usize));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ordering_is_a_permutation_with_separators_last() {
        // 30 × 30 grid graph
        let side = 30;
        let n = side * side;
        let positions: Vec<V3> =
            (0..n).map(|i| [(i % side) as f64, (i / side) as f64, 0.0]).collect();
        let mut col_ptr = vec![0];
        let mut row_idx = Vec::new();
        for i in 0..n {
            let (x, y) = (i % side, i / side);
            if x > 0 {
                row_idx.push(i - 1)
            }
            if x + 1 < side {
                row_idx.push(i + 1)
            }
            if y > 0 {
                row_idx.push(i - side)
            }
            if y + 1 < side {
                row_idx.push(i + side)
            }
            col_ptr.push(row_idx.len());
        }
        let perm = nested_dissection_order(&positions, &col_ptr, &row_idx);
        let mut seen = vec![false; n];
        for &v in &perm {
            assert!(!seen[v]);
            seen[v] = true;
        }
        assert!(seen.iter().all(|&s| s));
        // the last vertices form the top separator: one grid line (30 vertices)
        let top = &perm[n - side..];
        let column = top.iter().all(|&v| v % side == top[0] % side);
        let row = top.iter().all(|&v| v / side == top[0] / side);
        assert!(column || row, "a grid line: {top:?}");
    }
}
