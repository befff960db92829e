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

use crate::cholesky_update::DynamicFactor;

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
