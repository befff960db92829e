//! Sparse right-hand side, partial solution: entries `needed` of `x = A⁻¹ r` where `r`
//! has few nonzeros, without touching the rest of the factor.
//!
//! With `A = Pᵀ L Lᵀ P` (`P` the fill-reducing permutation): the forward solve `L y = P r`
//! only fills the rows on the elimination-tree paths from the nonzeros of `P r` to the
//! root (Gilbert & Peierls 1988; Davis 2006, "Direct Methods for Sparse Linear Systems",
//! §3.2 — the reach of `r`), so it visits those columns only, in increasing order. In the
//! backward solve `Lᵀ z = y`, entry `z_j` needs `z` at the rows of column `j`, which are
//! ancestors of `j`; the entries `needed` therefore only need the columns on the paths
//! from `needed` to the root, visited in decreasing order. Cost: the stored entries on
//! the two unions of paths (for a mesh of 194K vertices and a curve of 50 vertices about
//! a tenth of the factor), against the whole factor twice for a full solve.
//!
//! Used to update a solution after new penalties: if `A x = b` and the system becomes
//! `A' x' = b'`, then `x' = x + A'⁻¹ (b' − A' x)` and the correction's right-hand side
//! lives on the changed rows only.
//!
//! No residual check (the full solution is never formed): callers check with a full
//! [`Cholesky::solve_many`] when they need the whole vector.
//!
//! [`Cholesky::solve_sparse_with_residual`] is the full-vector form: sparse forward pass,
//! backward pass over every column, the ordinary residual check (the interactive field
//! design's right-hand side lives on the stroke edges). While the factor keeps faer's
//! supernodal layout both passes run per supernode on dense column blocks
//! (`crate::supernodal_solve`); otherwise per column over the row runs. On the 128²
//! field-design grid (49K unknowns, 2.3M factor entries) the supernodal form took the
//! re-solve after a singularity move from 19 to 11 ms (medians, 2 cores under a load
//! average of 4.4–5.0, `fieldtex-fields/examples/bench_fields.rs`,
//! `field_move_singularity_solve_only`, which includes the model field and residual);
//! its backward pass streams the whole factor (18.7 MB) and is memory-latency bound on
//! one core (4.5–4.8 ms of a ~6 ms solve; a version without the per-column dependency
//! chain and one with software prefetching were no faster). With two threads it runs on
//! two workers over disjoint subtrees (`crate::subtree_schedule`, same bits): the
//! re-solve after a singularity move 8.8–13.0 → 6.1–6.3 ms, a long-stroke frame
//! 24.5–32.2 → 21.2–22.4 ms (same binary, the schedule switched off and on, other
//! processes paused, load ≈ 1). An earlier tree-parallel attempt that built its split
//! per solve was slower under load. The residual of one right-hand side has its own
//! loop (same sums): 1.45 → 0.9 ms. No refinement solve runs unless the residual exceeds
//! `refine_above` (the field design's residuals are ~1e-15).

use crate::LinalgError;
use crate::cholesky::Cholesky;
use crate::cholesky_update::{DynamicFactor, NONE};

impl DynamicFactor {
    /// Columns on the paths from `cols` (permuted) to the root, increasing, and the slot
    /// of each (`slot[j]` = position, `u32::MAX` elsewhere; the caller resets it).
    fn reach(&self, cols: impl Iterator<Item = usize>, slot: &mut [u32]) -> Vec<usize> {
        let mut out = Vec::new();
        for f in cols {
            let mut j = f;
            while j != NONE && slot[j] == u32::MAX {
                slot[j] = 0;
                out.push(j);
                j = self.parent[j];
            }
        }
        out.sort_unstable();
        for (s, &j) in out.iter().enumerate() {
            slot[j] = s as u32;
        }
        out
    }

    /// Forward solve `L y = b` for `b` given by `(permuted row, W values)`: only the
    /// columns on the reach of the rows (module docs), in increasing order. Returns `y`
    /// on the reach, indexed by `slot` (filled here; `u32::MAX` off the reach).
    #[inline(always)]
    fn forward_sparse<const W: usize>(
        &self,
        rhs: &[(usize, [f64; W])],
        slot: &mut [u32],
    ) -> Vec<[f64; W]> {
        let forward = self.reach(rhs.iter().map(|&(i, _)| i), slot);
        let mut y = vec![[0.0f64; W]; forward.len()];
        for &(i, v) in rhs {
            let s = slot[i] as usize;
            for w in 0..W {
                y[s][w] += v[w];
            }
        }
        for (s, &j) in forward.iter().enumerate() {
            let st = self.start[j];
            let mut yj = y[s];
            let d = self.vals[st];
            for v in yj.iter_mut() {
                *v /= d;
            }
            y[s] = yj;
            let vals = &self.vals[st + 1..];
            let (r0, rn) = self.run_ptr[j];
            for &(q, r, m) in &self.runs[r0 as usize..(r0 + rn) as usize] {
                let (q, m) = (q as usize, m as usize);
                let base = slot[r as usize] as usize;
                for (t, &lv) in y[base..base + m].iter_mut().zip(&vals[q..q + m]) {
                    for w in 0..W {
                        t[w] -= lv * yj[w];
                    }
                }
            }
        }
        y
    }

    /// Module docs; `rhs` as `(permuted row, k values)`, result row-major
    /// `needed.len() × k` for permuted `needed`.
    fn partial_solve(&self, rhs: &[(usize, [f64; 4])], needed: &[usize], k: usize) -> Vec<f64> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked above).
            return unsafe { self.partial_solve_avx2(rhs, needed, k) };
        }
        self.partial_solve_impl(rhs, needed, k)
    }

    /// [`DynamicFactor::partial_solve_impl`] compiled for AVX2 (same IEEE operations, no
    /// FMA contraction: bit-identical to the baseline build).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn partial_solve_avx2(
        &self,
        rhs: &[(usize, [f64; 4])],
        needed: &[usize],
        k: usize,
    ) -> Vec<f64> {
        self.partial_solve_impl(rhs, needed, k)
    }

    #[inline(always)]
    fn partial_solve_impl(
        &self,
        rhs: &[(usize, [f64; 4])],
        needed: &[usize],
        k: usize,
    ) -> Vec<f64> {
        const W: usize = 4;
        let n = self.n();
        let mut slot_f = vec![u32::MAX; n];
        let y = self.forward_sparse(rhs, &mut slot_f);
        let mut slot_b = vec![u32::MAX; n];
        let backward = self.reach(needed.iter().copied(), &mut slot_b);
        let mut z = vec![[0.0f64; W]; backward.len()];
        for (s, &j) in backward.iter().enumerate().rev() {
            let st = self.start[j];
            let vals = &self.vals[st + 1..];
            let mut part = [[0.0f64; W]; 2];
            let (r0, rn) = self.run_ptr[j];
            for &(q, r, m) in &self.runs[r0 as usize..(r0 + rn) as usize] {
                let (q, m) = (q as usize, m as usize);
                let base = slot_b[r as usize] as usize;
                let (zs, ls) = (&z[base..base + m], &vals[q..q + m]);
                let pairs = m / 2 * 2;
                for (zp, lp) in zs[..pairs].chunks_exact(2).zip(ls[..pairs].chunks_exact(2)) {
                    for t in 0..2 {
                        for w in 0..W {
                            part[t][w] += lp[t] * zp[t][w];
                        }
                    }
                }
                if pairs < m {
                    for w in 0..W {
                        part[0][w] += ls[pairs] * zs[pairs][w];
                    }
                }
            }
            let mut acc = if slot_f[j] == u32::MAX { [0.0; W] } else { y[slot_f[j] as usize] };
            let d = self.vals[st];
            for w in 0..W {
                acc[w] = (acc[w] - (part[0][w] + part[1][w])) / d;
            }
            z[s] = acc;
        }
        let mut out = Vec::with_capacity(needed.len() * k);
        for &i in needed {
            out.extend_from_slice(&z[slot_b[i] as usize][..k]);
        }
        out
    }
}

impl Cholesky {
    /// Entries `needed` of `A⁻¹ r` for a sparse `r` with `k ≤ 4` columns given as
    /// `(row, values)` pairs (rows may repeat: summed), module docs. Returns `needed.len()
    /// × k` values, row-major. The first call on a factor never updated takes it over
    /// for updates (as [`Cholesky::update`] does).
    ///
    /// Errors: `k` not in `1..=4`, a value slice of another length, an index out of
    /// range, a non-finite value.
    pub fn solve_sparse_at(
        &mut self,
        rhs: &[(usize, &[f64])],
        needed: &[usize],
        k: usize,
    ) -> Result<Vec<f64>, LinalgError> {
        let n = self.size();
        if !(1..=4).contains(&k) {
            return Err(LinalgError::Dimension {
                what: "right-hand sides of a sparse solve (1 to 4)",
                expected: 4,
                found: k,
            });
        }
        for &(i, v) in rhs {
            if i >= n {
                return Err(LinalgError::IndexOutOfRange { row: i, col: 0, nrows: n, ncols: k });
            }
            LinalgError::check_len("values per right-hand-side row", k, v.len())?;
            if v.iter().any(|x| !x.is_finite()) {
                return Err(LinalgError::NonFinite { what: "right-hand side", index: i });
            }
        }
        if let Some(&i) = needed.iter().find(|&&i| i >= n) {
            return Err(LinalgError::IndexOutOfRange { row: i, col: 0, nrows: n, ncols: k });
        }
        let d = self.ensure_dynamic()?;
        let rows: Vec<(usize, [f64; 4])> = rhs
            .iter()
            .map(|&(i, v)| {
                let mut a = [0.0; 4];
                a[..k].copy_from_slice(v);
                (d.inv[i], a)
            })
            .collect();
        let needed_p: Vec<usize> = needed.iter().map(|&i| d.inv[i]).collect();
        let out = d.partial_solve(&rows, &needed_p, k);
        if out.iter().any(|v| !v.is_finite()) {
            return Err(LinalgError::SolveFailed {
                size: n,
                residual: f64::NAN,
                tolerance: self.options().residual_tolerance,
            });
        }
        Ok(out)
    }
}

/// Right-hand sides with at most this fraction of nonzeros take the sparse forward pass
/// in [`Cholesky::solve_sparse_with_residual`].
const SPARSE_FRACTION: usize = 8;

impl DynamicFactor {
    /// `x = A⁻¹ b` (original order) for `b` given by its nonzeros `(permuted row, value)`:
    /// forward solve on the reach of the nonzeros only, backward solve over every column.
    fn solve_sparse_rhs(&self, nz: &[(usize, f64)]) -> Vec<f64> {
        if self.has_supernodal_layout() {
            return self.solve_sparse_rhs_supernodal(nz);
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked above).
            return unsafe { self.solve_sparse_rhs_avx2(nz) };
        }
        self.solve_sparse_rhs_impl(nz)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn solve_sparse_rhs_avx2(&self, nz: &[(usize, f64)]) -> Vec<f64> {
        self.solve_sparse_rhs_impl(nz)
    }

    #[inline(always)]
    fn solve_sparse_rhs_impl(&self, nz: &[(usize, f64)]) -> Vec<f64> {
        let n = self.n();
        let mut slot_f = vec![u32::MAX; n];
        let rhs: Vec<(usize, [f64; 1])> = nz.iter().map(|&(i, v)| (i, [v])).collect();
        let y = self.forward_sparse(&rhs, &mut slot_f);
        let mut z = vec![0.0f64; n];
        for j in (0..n).rev() {
            let st = self.start[j];
            let vals = &self.vals[st + 1..];
            let mut part = [0.0f64; 4];
            let (r0, rn) = self.run_ptr[j];
            for &(q, r, m) in &self.runs[r0 as usize..(r0 + rn) as usize] {
                let (q, r, m) = (q as usize, r as usize, m as usize);
                let (zs, ls) = (&z[r..r + m], &vals[q..q + m]);
                let full = m / 4 * 4;
                for (zc, lc) in zs[..full].chunks_exact(4).zip(ls[..full].chunks_exact(4)) {
                    for t in 0..4 {
                        part[t] += lc[t] * zc[t];
                    }
                }
                for (zv, lv) in zs[full..].iter().zip(&ls[full..]) {
                    part[0] += lv * zv;
                }
            }
            let yj = if slot_f[j] == u32::MAX { 0.0 } else { y[slot_f[j] as usize][0] };
            z[j] = (yj - ((part[0] + part[1]) + (part[2] + part[3]))) / self.vals[st];
        }
        let mut x = vec![0.0f64; n];
        for (i, &p) in self.perm.iter().enumerate() {
            x[p] = z[i];
        }
        x
    }
}

impl Cholesky {
    /// [`Cholesky::solve_with_residual`] for a right-hand side with few nonzeros (at most
    /// an eighth of the entries; denser ones take the ordinary solve): the forward
    /// triangular solve only visits the elimination-tree reach of the nonzeros (module
    /// docs), the backward one every column. The same residual check; a residual above
    /// the refinement threshold repeats the solve by the ordinary path (with its
    /// refinement). The first call on a factor never updated takes it over for updates.
    pub fn solve_sparse_with_residual(
        &mut self,
        b: &[f64],
    ) -> Result<(Vec<f64>, f64), LinalgError> {
        let n = self.size();
        LinalgError::check_len("right-hand side", n, b.len())?;
        if let Some(index) = b.iter().position(|v| !v.is_finite()) {
            return Err(LinalgError::NonFinite { what: "right-hand side", index });
        }
        let nonzeros = b.iter().filter(|&&v| v != 0.0).count();
        if nonzeros == 0 || nonzeros * SPARSE_FRACTION > n {
            return self.solve_with_residual(b);
        }
        let d = self.ensure_dynamic()?;
        let nz: Vec<(usize, f64)> =
            b.iter().enumerate().filter(|(_, v)| **v != 0.0).map(|(i, &v)| (d.inv[i], v)).collect();
        let x = d.solve_sparse_rhs(&nz);
        let r = self.residual_block(&x, b, 1);
        let rel = crate::cholesky::norm2(&r) / crate::cholesky::norm2(b);
        if rel.is_nan() || rel > self.options().refine_above || x.iter().any(|v| !v.is_finite()) {
            return self.solve_with_residual(b);
        }
        self.store_last_residual(rel);
        Ok((x, rel))
    }
}

#[cfg(test)]
mod tests {
    use crate::test_support::penalised_grid;
    use crate::{Cholesky, FactorLayout, SparseMatrix, SymbolicCholesky};

    fn grid(side: usize) -> SparseMatrix {
        penalised_grid(side, 53)
    }

    #[test]
    fn partial_sparse_solve_matches_full_solve() {
        for layout in [FactorLayout::Simplicial, FactorLayout::Supernodal] {
            let a = grid(35);
            let n = a.nrows();
            let sym = SymbolicCholesky::analyze_with(&a, layout).unwrap();
            let mut f = Cholesky::factor_with(&sym, &a).unwrap();
            let vals: Vec<[f64; 3]> = (0..6)
                .map(|i| [1.0 + i as f64, -2.0 * i as f64, 0.5 + 1e8 * (i % 2) as f64])
                .collect();
            let rows = [17usize, 400, 401, 402, 900, 17];
            let rhs: Vec<(usize, &[f64])> =
                rows.iter().zip(&vals).map(|(&i, v)| (i, v.as_slice())).collect();
            let needed: Vec<usize> = (0..n).step_by(7).chain([400, 1224]).collect();
            let got = f.solve_sparse_at(&rhs, &needed, 3).unwrap();
            let dense: Vec<Vec<f64>> = (0..3)
                .map(|c| {
                    let mut b = vec![0.0; n];
                    for (&i, v) in rows.iter().zip(&vals) {
                        b[i] += v[c];
                    }
                    b
                })
                .collect();
            let full = f.solve_many(&dense).unwrap();
            for (q, &i) in needed.iter().enumerate() {
                for c in 0..3 {
                    let (p, r) = (got[q * 3 + c], full[c][i]);
                    let scale = full[c].iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    assert!(
                        (p - r).abs() <= 1e-10 * scale,
                        "{layout:?} row {i} col {c}: {p} vs {r}"
                    );
                }
            }
            assert!(f.solve_sparse_at(&rhs, &[n], 3).is_err());
            assert!(f.solve_sparse_at(&rhs, &needed, 5).is_err());
            let nan = [f64::NAN, 0.0, 0.0];
            assert!(f.solve_sparse_at(&[(3, &nan[..])], &needed, 3).is_err());
        }
    }

    #[test]
    fn sparse_right_hand_side_solve_matches_full_solve() {
        for layout in [FactorLayout::Simplicial, FactorLayout::Supernodal] {
            let a = grid(40);
            let n = a.nrows();
            let sym = SymbolicCholesky::analyze_with(&a, layout).unwrap();
            let mut f = Cholesky::factor_with(&sym, &a).unwrap();
            let mut b = vec![0.0; n];
            for (k, i) in [3usize, 700, 701, 1599, 820].into_iter().enumerate() {
                b[i] = 1.0 + k as f64 - 1e8 * (k % 2) as f64;
            }
            let (x, r) = f.solve_sparse_with_residual(&b).unwrap();
            let (full, _) = f.solve_with_residual(&b).unwrap();
            let scale = full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = x.iter().zip(&full).fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
            assert!(diff <= 1e-10 * scale, "{layout:?}: {diff:e}");
            assert!(r < 1e-11, "residual {r:e}");
            // dense and empty right-hand sides take the ordinary path
            let dense: Vec<f64> = (0..n).map(|i| (i % 7) as f64).collect();
            assert!(f.solve_sparse_with_residual(&dense).is_ok());
            assert_eq!(f.solve_sparse_with_residual(&vec![0.0; n]).unwrap().0, vec![0.0; n]);
            assert!(f.solve_sparse_with_residual(&[1.0]).is_err());
        }
    }
}
