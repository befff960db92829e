//! Blocked triangular solves `L Lᵀ X = B` on the updatable factor while it keeps faer's
//! supernodal layout (`crate::cholesky_update::DynamicFactor`).
//!
//! Layout: supernode `s` owns the columns `b..e` (`e − b = ns`); its values are one
//! column-major `nrows × ns` block (`nrows = ns + #pattern`) whose column `c` holds rows
//! `b..e` then the pattern rows; entries above the diagonal are ignored. The factor of
//! a mesh has tens of thousands of supernodes, most of them a few columns wide, so the
//! per-call overhead of general dense kernels dominates a solve with few right-hand sides.
//! Here every supernode gathers the rows it touches of the right-hand-side block into a
//! small dense buffer (`nrows × W`, `W` = 4 or 8 interleaved right-hand sides, zero
//! padded), runs plain loops over the block, and scatters the result back: the factor is
//! streamed once per pass and the scattered accesses happen once per supernode row
//! instead of once per stored entry.
//!
//! Forward: `y_c ← y_c / L_cc`, then `y_r ← y_r − L_rc y_c` for the rows below, column
//! by column (two columns per sweep over the trailing rows, same operation order).
//! Backward: `x_c ← (y_c − Σ_r L_rc x_r) / L_cc` from the last column down, the sum
//! taken as four interleaved partial sums (fixed order) so it is not one long
//! dependency chain. Same arithmetic on every CPU (the AVX2 build uses the
//! same IEEE operations without FMA contraction), sequential, so results do not depend on
//! the thread count. They differ from faer's solve by rounding only.
//!
//! `DynamicFactor::solve_sparse_rhs_supernodal` is the one-right-hand-side form for
//! few nonzeros (`Cholesky::solve_sparse_with_residual`): the forward pass visits only
//! the supernodes on the elimination-tree reach of the nonzeros, each from the column
//! the reach enters it at; the backward pass every supernode, with plain (unpadded)
//! column dot products as eight interleaved partial sums.

use std::sync::Arc;

use crate::cholesky_update::DynamicFactor;
use crate::subtree_schedule::SubtreeSchedule;

impl DynamicFactor {
    /// Whether [`DynamicFactor::solve_supernodal_in_place`] can run (faer's supernodal
    /// layout intact).
    pub(crate) fn has_supernodal_layout(&self) -> bool {
        self.faer_layout && !self.supernodes.is_empty()
    }

    /// `X ← A⁻¹ X` for a column-major `n × k` block (`k ≤ 8`), module docs.
    pub(crate) fn solve_supernodal_in_place(&self, x: &mut [f64], k: usize) {
        debug_assert!(self.has_supernodal_layout() && k <= 8);
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked above).
            unsafe {
                if k <= 4 {
                    self.solve_avx2::<4>(x, k);
                } else {
                    self.solve_avx2::<8>(x, k);
                }
            }
            return;
        }
        if k <= 4 { self.solve_impl::<4>(x, k) } else { self.solve_impl::<8>(x, k) }
    }

    /// [`DynamicFactor::solve_impl`] compiled for AVX2 (bit-identical to the baseline).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn solve_avx2<const W: usize>(&self, x: &mut [f64], k: usize) {
        self.solve_impl::<W>(x, k);
    }

    #[inline(always)]
    fn solve_impl<const W: usize>(&self, x: &mut [f64], k: usize) {
        let n = self.n();
        let mut y = vec![[0.0f64; W]; n];
        for (i, &p) in self.perm.iter().enumerate() {
            for c in 0..k {
                y[i][c] = x[c * n + p];
            }
        }
        let mut buf: Vec<[f64; W]> = Vec::new();
        let sn = &self.supernodes;
        // forward: L Y = P B
        for s in 0..sn.len() - 1 {
            let (b, e) = (sn[s], sn[s + 1]);
            let (base, nrows) = (self.start[b], self.len[b]);
            let rows = &self.rows[base..base + nrows];
            buf.clear();
            buf.extend(rows.iter().map(|&r| y[r as usize]));
            let ns = e - b;
            let mut c = 0;
            // two columns at a time: each trailing row is loaded and stored once per pair
            // (the same operations in the same order as column by column)
            while c + 1 < ns {
                let col0 = &self.vals[base + c * nrows..base + (c + 1) * nrows];
                let col1 = &self.vals[base + (c + 1) * nrows..base + (c + 2) * nrows];
                let mut y0 = buf[c];
                for v in y0.iter_mut() {
                    *v /= col0[c];
                }
                let mut y1 = buf[c + 1];
                for w in 0..W {
                    y1[w] -= col0[c + 1] * y0[w];
                    y1[w] /= col1[c + 1];
                }
                buf[c] = y0;
                buf[c + 1] = y1;
                for ((bq, &l0), &l1) in
                    buf[c + 2..].iter_mut().zip(&col0[c + 2..]).zip(&col1[c + 2..])
                {
                    for w in 0..W {
                        bq[w] = (bq[w] - l0 * y0[w]) - l1 * y1[w];
                    }
                }
                c += 2;
            }
            if c < ns {
                let col = &self.vals[base + c * nrows..base + (c + 1) * nrows];
                let mut yc = buf[c];
                for v in yc.iter_mut() {
                    *v /= col[c];
                }
                buf[c] = yc;
                for (bq, &l) in buf[c + 1..].iter_mut().zip(&col[c + 1..]) {
                    for w in 0..W {
                        bq[w] -= l * yc[w];
                    }
                }
            }
            for (&r, v) in rows.iter().zip(&buf) {
                y[r as usize] = *v;
            }
        }
        // backward: Lᵀ Z = Y
        for s in (0..sn.len() - 1).rev() {
            let (b, e) = (sn[s], sn[s + 1]);
            let (base, nrows) = (self.start[b], self.len[b]);
            let rows = &self.rows[base..base + nrows];
            buf.clear();
            buf.extend(rows.iter().map(|&r| y[r as usize]));
            for c in (0..e - b).rev() {
                let col = &self.vals[base + c * nrows..base + (c + 1) * nrows];
                // four partial sums (rows q ≡ 0, 1, 2, 3 mod 4 past the diagonal) break
                // the dependency chain of one long sum
                let mut part = [[0.0f64; W]; 4];
                let (tail_b, tail_l) = (&buf[c + 1..], &col[c + 1..]);
                let full = tail_b.len() / 4 * 4;
                for (bq, lq) in tail_b[..full].chunks_exact(4).zip(tail_l[..full].chunks_exact(4)) {
                    for t in 0..4 {
                        for w in 0..W {
                            part[t][w] += lq[t] * bq[t][w];
                        }
                    }
                }
                for (bq, &l) in tail_b[full..].iter().zip(&tail_l[full..]) {
                    for w in 0..W {
                        part[0][w] += l * bq[w];
                    }
                }
                let mut acc = buf[c];
                for w in 0..W {
                    acc[w] -= (part[0][w] + part[1][w]) + (part[2][w] + part[3][w]);
                }
                let d = col[c];
                for v in acc.iter_mut() {
                    *v /= d;
                }
                buf[c] = acc;
            }
            for (&r, v) in rows[..e - b].iter().zip(&buf) {
                y[r as usize] = *v;
            }
        }
        for (i, &p) in self.perm.iter().enumerate() {
            for c in 0..k {
                x[c * n + p] = y[i][c];
            }
        }
    }
}

/// Sum of `a[i] · b[i]` as eight interleaved partial sums combined pairwise (a fixed
/// order: the same result on every CPU and thread count).
#[inline(always)]
fn dot8(a: &[f64], b: &[f64]) -> f64 {
    let mut part = [0.0f64; 8];
    let full = a.len().min(b.len()) / 8 * 8;
    for (ac, bc) in a[..full].chunks_exact(8).zip(b[..full].chunks_exact(8)) {
        for t in 0..8 {
            part[t] += ac[t] * bc[t];
        }
    }
    for (av, bv) in a[full..].iter().zip(&b[full..]) {
        part[0] += av * bv;
    }
    ((part[0] + part[1]) + (part[2] + part[3])) + ((part[4] + part[5]) + (part[6] + part[7]))
}

/// `y` shared by the workers of the backward pass: each writes only the columns of its
/// own supernodes and reads only columns already final (module docs of
/// `crate::subtree_schedule`).
#[derive(Clone, Copy)]
struct SharedColumns(*mut f64, usize);

// SAFETY: the schedule gives the workers disjoint columns to write and only finished
// columns to read (see `SharedColumns`).
unsafe impl Send for SharedColumns {}
// SAFETY: as above.
unsafe impl Sync for SharedColumns {}

impl DynamicFactor {
    /// `Lᵀ z = y` in place (permuted order) over every supernode: sequentially, or the
    /// schedule's top then its two bins on two workers (`crate::subtree_schedule`: the
    /// same bits either way).
    fn backward_all(&self, y: &mut [f64], buf: &mut Vec<f64>) {
        let nsn = self.supernodes.len() - 1;
        let shared = SharedColumns(y.as_mut_ptr(), y.len());
        match &self.backward_schedule {
            Some(plan) if rayon::current_num_threads() > 1 => {
                // SAFETY: `y` is borrowed mutably for the whole call; the top runs alone,
                // then the bins write disjoint columns and read only columns of their own
                // subtrees or of the (finished) top.
                let bin = |list: &[u32]| unsafe {
                    self.backward_list(list.iter().map(|&s| s as usize), shared, &mut Vec::new())
                };
                // SAFETY: as above; the top runs before either bin starts.
                unsafe { self.backward_list(plan.top.iter().map(|&s| s as usize), shared, buf) };
                rayon::join(|| bin(&plan.bins[0]), || bin(&plan.bins[1]));
            }
            // SAFETY: one worker, `y` borrowed mutably.
            _ => unsafe { self.backward_list((0..nsn).rev(), shared, buf) },
        }
    }

    /// The backward step of each supernode of `list` in turn (module docs), AVX2 build
    /// when the CPU has it (the same IEEE operations: bit-identical).
    ///
    /// # Safety
    /// `y` points to `n` live values; no other thread writes the columns read here or
    /// touches the columns written here (the list's own supernodes) meanwhile.
    unsafe fn backward_list(
        &self,
        list: impl Iterator<Item = usize>,
        y: SharedColumns,
        buf: &mut Vec<f64>,
    ) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: AVX2 checked; the caller's contract.
            return unsafe { self.backward_list_avx2(list, y, buf) };
        }
        // SAFETY: the caller's contract.
        unsafe { self.backward_list_impl(list, y, buf) }
    }

    /// # Safety
    /// As [`DynamicFactor::backward_list`], on a CPU with AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn backward_list_avx2(
        &self,
        list: impl Iterator<Item = usize>,
        y: SharedColumns,
        buf: &mut Vec<f64>,
    ) {
        // SAFETY: the caller's contract.
        unsafe { self.backward_list_impl(list, y, buf) }
    }

    /// # Safety
    /// As [`DynamicFactor::backward_list`].
    #[inline(always)]
    unsafe fn backward_list_impl(
        &self,
        list: impl Iterator<Item = usize>,
        y: SharedColumns,
        buf: &mut Vec<f64>,
    ) {
        let sn = &self.supernodes;
        debug_assert_eq!(y.1, self.n());
        for s in list {
            let (b, e) = (sn[s], sn[s + 1]);
            let (base, nrows) = (self.start[b], self.len[b]);
            let rows = &self.rows[base..base + nrows];
            let ns = e - b;
            buf.clear();
            // SAFETY: columns `b..e` are this worker's; the pattern rows are ancestors,
            // final before this supernode runs (caller's contract), all `< n`.
            unsafe {
                buf.extend_from_slice(std::slice::from_raw_parts(y.0.add(b), ns));
                buf.extend(rows[ns..].iter().map(|&r| *y.0.add(r as usize)));
            }
            for c in (0..ns).rev() {
                let col = &self.vals[base + c * nrows..base + (c + 1) * nrows];
                let acc = buf[c] - dot8(&col[c + 1..], &buf[c + 1..]);
                buf[c] = acc / col[c];
            }
            // SAFETY: this worker's own columns.
            unsafe { std::slice::from_raw_parts_mut(y.0.add(b), ns).copy_from_slice(&buf[..ns]) };
        }
    }
}

impl DynamicFactor {
    /// The two-worker backward schedule of this factor's supernodal layout (`None`:
    /// simplicial, or too small to gain): per supernode its stored entries and parent.
    pub(crate) fn build_backward_schedule(&self) -> Option<Arc<SubtreeSchedule>> {
        if !self.has_supernodal_layout() {
            return None;
        }
        let sn = &self.supernodes;
        let nsn = sn.len() - 1;
        let cost: Vec<usize> = (0..nsn).map(|s| (sn[s + 1] - sn[s]) * self.len[sn[s]]).collect();
        let parent: Vec<u32> = (0..nsn)
            .map(|s| match self.parent[sn[s + 1] - 1] {
                crate::cholesky_update::NONE => u32::MAX,
                p => self.supernode_of(p) as u32,
            })
            .collect();
        SubtreeSchedule::build(&cost, &parent).map(Arc::new)
    }

    /// Supernode holding permuted column `j`.
    #[inline]
    fn supernode_of(&self, j: usize) -> usize {
        self.supernodes.partition_point(|&b| b <= j) - 1
    }

    /// `z = L⁻ᵀ L⁻¹ y` (permuted order) for a right-hand side with few nonzeros
    /// `(permuted row, value)`, one right-hand side, on faer's supernodal layout: the
    /// forward pass visits only the supernodes on the elimination-tree reach of the
    /// nonzeros, each from the first column the reach enters it at (the columns before
    /// hold zeros); the backward pass visits every supernode. Per supernode the rows it
    /// touches are gathered into a dense buffer; forward: `y_c ← y_c / L_cc`, then
    /// `y_r ← y_r − L_rc y_c` (contiguous column tails); backward:
    /// `x_c ← (y_c − Σ_r L_rc x_r) / L_cc`, the sum as eight interleaved partial sums.
    /// Sequential with a fixed operation order (no FMA contraction in the AVX2 build),
    /// so bit-identical across CPUs with AVX2 and the baseline and across thread counts.
    pub(crate) fn solve_sparse_rhs_supernodal(&self, nz: &[(usize, f64)]) -> Vec<f64> {
        debug_assert!(self.has_supernodal_layout());
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked above).
            return unsafe { self.sparse_rhs_supernodal_avx2(nz) };
        }
        self.sparse_rhs_supernodal_impl(nz)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn sparse_rhs_supernodal_avx2(&self, nz: &[(usize, f64)]) -> Vec<f64> {
        self.sparse_rhs_supernodal_impl(nz)
    }

    #[inline(always)]
    fn sparse_rhs_supernodal_impl(&self, nz: &[(usize, f64)]) -> Vec<f64> {
        let n = self.n();
        let sn = &self.supernodes;
        let nsn = sn.len() - 1;
        let mut y = vec![0.0f64; n];
        // reach: first reached column per supernode (`usize::MAX`: not reached)
        let mut first = vec![usize::MAX; nsn];
        let mut reached = Vec::new();
        for &(i, v) in nz {
            y[i] += v;
            let mut j = i;
            loop {
                let s = self.supernode_of(j);
                let seen = first[s] != usize::MAX;
                if seen && first[s] <= j {
                    break;
                }
                if !seen {
                    reached.push(s);
                }
                first[s] = j;
                if seen {
                    // the ancestors of `s` do not depend on where the reach enters it
                    break;
                }
                let up = self.parent[sn[s + 1] - 1];
                if up == crate::cholesky_update::NONE {
                    break;
                }
                j = up;
            }
        }
        reached.sort_unstable();
        let mut buf: Vec<f64> = Vec::new();
        // forward: L y = b on the reach
        for &s in &reached {
            let (b, e) = (sn[s], sn[s + 1]);
            let (base, nrows) = (self.start[b], self.len[b]);
            let rows = &self.rows[base..base + nrows];
            let c0 = first[s] - b;
            buf.clear();
            buf.extend(rows.iter().map(|&r| y[r as usize]));
            for c in c0..e - b {
                let col = &self.vals[base + c * nrows..base + (c + 1) * nrows];
                let yc = buf[c] / col[c];
                buf[c] = yc;
                if yc != 0.0 {
                    for (bq, &l) in buf[c + 1..].iter_mut().zip(&col[c + 1..]) {
                        *bq -= l * yc;
                    }
                }
            }
            for (&r, &v) in rows[c0..].iter().zip(&buf[c0..]) {
                y[r as usize] = v;
            }
        }
        // backward: Lᵀ z = y over every supernode
        self.backward_all(&mut y, &mut buf);
        let mut x = vec![0.0f64; n];
        for (i, &p) in self.perm.iter().enumerate() {
            x[p] = y[i];
        }
        x
    }
}

#[cfg(test)]
mod tests {
    use crate::test_support::penalised_grid;
    use crate::{Cholesky, FactorLayout, SparseMatrix, SymbolicCholesky};

    /// Penalised 5-point Laplacian of a `side × side` grid, supernodal factor taken over
    /// for updates (one penalty added).
    fn updated_factor(side: usize) -> (Cholesky, SparseMatrix) {
        let n = side * side;
        let a = penalised_grid(side, 37);
        let sym = SymbolicCholesky::analyze_with(&a, FactorLayout::Supernodal).unwrap();
        let mut f = Cholesky::factor_with(&sym, &a).unwrap();
        f.add_diagonal_penalty(5, 1e8).unwrap();
        let mut d = vec![0.0; n];
        d[5] = 1e8;
        (f, a.add_diagonal(&d))
    }

    fn block(n: usize, k: usize) -> Vec<f64> {
        (0..n * k).map(|i| ((i * 7919) % 1000) as f64 / 1000.0 - 0.3).collect()
    }

    #[test]
    fn supernodal_solve_matches_a_fresh_factor() {
        let (f, a) = updated_factor(40);
        let n = a.nrows();
        let d = f.dynamic.as_ref().unwrap();
        assert!(d.has_supernodal_layout());
        let fresh = Cholesky::factor(&a).unwrap();
        for k in [1, 3, 4, 5, 8] {
            let b = block(n, k);
            let mut x = b.clone();
            d.solve_supernodal_in_place(&mut x, k);
            let bs: Vec<Vec<f64>> = (0..k).map(|c| b[c * n..(c + 1) * n].to_vec()).collect();
            let reference = fresh.solve_many(&bs).unwrap();
            for c in 0..k {
                let scale = reference[c].iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let diff = x[c * n..(c + 1) * n]
                    .iter()
                    .zip(&reference[c])
                    .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
                assert!(diff <= 1e-9 * scale, "k = {k}, column {c}: {diff:e} vs {scale:e}");
            }
        }
    }

    #[test]
    fn sparse_rhs_supernodal_matches_column_loops() {
        let (f, a) = updated_factor(36);
        let n = a.nrows();
        let d = f.dynamic.as_ref().unwrap();
        // nonzeros at a leaf cluster, mid-tree and at the last (root) columns, permuted
        let nz: Vec<(usize, f64)> = [3usize, 4, 5, 400, 401, 650, n - 2, n - 1]
            .iter()
            .map(|&i| (i, 0.5 + i as f64))
            .collect();
        let x = d.solve_sparse_rhs_supernodal(&nz);
        let mut dense = vec![0.0; n];
        for &(i, v) in &nz {
            dense[d.perm[i]] += v;
        }
        d.solve_supernodal_in_place(&mut dense, 1);
        let scale = dense.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = x.iter().zip(&dense).fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        assert!(diff <= 1e-12 * scale, "{diff:e} vs {scale:e}");
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let base = d.sparse_rhs_supernodal_impl(&nz);
            // SAFETY: AVX2 checked above.
            let wide = unsafe { d.sparse_rhs_supernodal_avx2(&nz) };
            assert!(base.iter().zip(&wide).all(|(p, q)| p.to_bits() == q.to_bits()));
        }
    }

    /// A factor large enough for the two-worker backward schedule: the sparse solve on
    /// two threads gives the bits of one thread (the sequential pass), and matches the
    /// blocked dense solve.
    #[test]
    fn two_worker_backward_pass_is_bit_identical_to_one() {
        let (f, a) = updated_factor(150);
        let n = a.nrows();
        let d = f.dynamic.as_ref().unwrap();
        assert!(d.backward_schedule.is_some(), "a schedule for {n} unknowns");
        let nz: Vec<(usize, f64)> =
            [7usize, 900, 901, 5000, n / 2, n - 3].iter().map(|&i| (i, 1.0 + i as f64)).collect();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| d.solve_sparse_rhs_supernodal(&nz))
        };
        let (one, two) = (run(1), run(2));
        assert!(one.iter().zip(&two).all(|(p, q)| p.to_bits() == q.to_bits()));
        let mut dense = vec![0.0; n];
        for &(i, v) in &nz {
            dense[d.perm[i]] += v;
        }
        d.solve_supernodal_in_place(&mut dense, 1);
        let scale = dense.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = two.iter().zip(&dense).fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        assert!(diff <= 1e-12 * scale, "{diff:e} vs {scale:e}");
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx2_build_is_bit_identical_to_baseline() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let (f, a) = updated_factor(30);
        let n = a.nrows();
        let d = f.dynamic.as_ref().unwrap();
        for k in [3, 6] {
            let b = block(n, k);
            let (mut x1, mut x2) = (b.clone(), b);
            if k <= 4 {
                d.solve_impl::<4>(&mut x1, k);
                // SAFETY: AVX2 checked above.
                unsafe { d.solve_avx2::<4>(&mut x2, k) };
            } else {
                d.solve_impl::<8>(&mut x1, k);
                // SAFETY: AVX2 checked above.
                unsafe { d.solve_avx2::<8>(&mut x2, k) };
            }
            assert!(x1.iter().zip(&x2).all(|(p, q)| p.to_bits() == q.to_bits()));
        }
    }
}
