//! Blocked (matrix–matrix) multiple-rank *update* over one supernode of the factor:
//! `L̄ L̄ᵀ = L Lᵀ + W Wᵀ` for a supernode's columns, by structured Householder
//! reflections applied in panels with the compact WY form.
//!
//! Why: in a multiple-rank update of diagonal penalties (`crate::multiple_rank_update`,
//! Davis & Hager 2001) nearly all the work lies in the wide supernodes near the root of
//! the elimination tree, where every modification passes (measured on the refined horse,
//! 194K unknowns, greedy curve steps of 50–116 penalties: 96–99 % of the row operations).
//! The rank-1 sweeps of method C1 there are bandwidth-bound vector loops; the same update
//! written as reflections can be applied to the rows below a panel of `nb` columns by
//! two matrix products, which run at the speed of dense kernels.
//!
//! Formulation: with `L` the supernode's `m × b` column block (lower trapezoid, the
//! dense diagonal block then the rows of the supernode's pattern) and `W` the `m × k`
//! restriction of the `k` pending modification vectors to those rows, find an orthogonal
//! `Q` with `[L W] Q = [L̄ W̄]` where `W̄` vanishes on the supernode's own rows. Then
//! `L̄ L̄ᵀ + W̄ W̄ᵀ = L Lᵀ + W Wᵀ`: `L̄` is the updated block and `W̄` (nonzero only on the
//! pattern rows, all ancestors) is what the ancestors still have to absorb. `Q` is a
//! product of one reflection per column `c`, acting on column `c` of `L` and on `W`
//! only, that maps the row `(L[c][c], W[c][:])` onto `(β, 0, …, 0)` with
//! `β = √(L[c][c]² + ‖W[c][:]‖²) > 0` — the structured ("triangular-pentagonal") QR
//! step of LAPACK's `xTPQRT` (Elmroth & Gustavson 2000, "Applying recursion to serial and
//! parallel QR factorization leads to better performance", for the blocked form;
//! Schreiber & Van Loan 1989, "A storage-efficient WY representation for products of
//! Householder transformations", for the compact WY `I − V T Vᵀ`). The reflection's
//! vector is built without cancellation (`L[c][c] − β = −‖w‖² / (L[c][c] + β)`), so the
//! diagonal stays positive and the result is the unique Cholesky factor.
//!
//! The result equals the rank-1 sweeps' to rounding (not bit for bit: the operations
//! differ). Determinism: the rows below a panel are processed in fixed chunks of
//! [`CHUNK_ROWS`] in parallel, each with sequential dense products, so results do not
//! depend on the thread count.
//!
//! Not implemented: downdates (a hyperbolic variant is needed and is less stable; they
//! keep the rank-1 sweeps).

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par};
use rayon::prelude::*;

use crate::cholesky_update::DynamicFactor;

/// Columns per panel (reflections combined into one compact WY block).
const PANEL: usize = 32;
/// Rows per parallel chunk of the trailing update (fixed: thread-count independent).
const CHUNK_ROWS: usize = 128;
/// Scratch values per chunk: `S` and `S T`.
const SCRATCH: usize = 2 * CHUNK_ROWS * PANEL;
/// The blocked form is used for a supernode (suffix) of at least this many columns …
const MIN_WIDTH: usize = 8;
/// … with at least this many modifications passing through it …
const MIN_MODS: usize = 8;
/// … and at least this much work (rows × columns × modifications).
const MIN_WORK: usize = 1 << 16;

impl DynamicFactor {
    /// Tries the blocked update for the supernode that holds `union[pos]`: the columns
    /// `union[pos] ..` up to the supernode's end must all be on the union (they are:
    /// within a supernode each column's parent is the next) and stored in faer's
    /// column-major block. `work[t]` is modification `t`'s work vector over the union's
    /// slots and `beta[t]` its C1 scale (the pending vector is `work[t] / beta[t]`).
    /// `through(q)` lists, ascending, the modifications whose path holds the union column
    /// in slot `q` (the only ones that can have nonzero work entries there).
    /// Returns [`Blocked::Done`] with the union position after the supernode,
    /// [`Blocked::No`] with the first column past it if it does not qualify (the caller
    /// sweeps its columns), `Err(column)` if a pivot became non-finite (overflow).
    pub(crate) fn blocked_supernode_update<'a>(
        &mut self,
        union: &[usize],
        pos: usize,
        work: &mut [&mut [f64]],
        beta: &mut [f64],
        through: impl Fn(usize) -> &'a [u32],
    ) -> Result<Blocked, usize> {
        let j = union[pos];
        if !self.faer_layout || self.supernodes.len() < 2 {
            return Ok(Blocked::No(usize::MAX));
        }
        let sn = self.supernodes.partition_point(|&c| c <= j) - 1;
        let end = self.supernodes[sn + 1];
        let b = end - j;
        if b < MIN_WIDTH || union.len() < pos + b || union[pos + b - 1] != end - 1 {
            return Ok(Blocked::No(end));
        }
        let (s0, m) = (self.start[j], self.len[j]);
        let stride = self.start[j + 1] - self.start[j];
        let ld = stride - 1;
        if ld < m
            || (0..b).any(|i| self.start[j + i] != s0 + i * stride || self.len[j + i] != m - i)
        {
            return Ok(Blocked::No(end));
        }
        let slot0 = self.slot[j] as usize;
        // every path that meets the supernode leaves it through its last column
        // (the supernode's columns are consecutive on the union: so are their slots)
        let active: Vec<usize> = through(slot0 + b - 1)
            .iter()
            .map(|&t| t as usize)
            .filter(|&t| work[t][slot0..slot0 + b].iter().any(|&w| w != 0.0))
            .collect();
        let k = active.len();
        if k < MIN_MODS || m * b * k < MIN_WORK {
            return Ok(Blocked::No(end));
        }
        // the block's rows as segments `(first block row, first slot, length)` of
        // consecutive slots: the diagonal row, then the column's runs of consecutive rows
        // (consecutive slots on any union of paths, `DynamicFactor::runs`)
        let mut segments: Vec<(usize, usize, usize)> = vec![(0, slot0, 1)];
        let (r0, rn) = self.run_ptr[j];
        for &(q, r, len) in &self.runs[r0 as usize..(r0 + rn) as usize] {
            let (row, sl, len) = (1 + q as usize, self.slot[r as usize] as usize, len as usize);
            match segments.last_mut() {
                Some(last) if last.0 + last.2 == row && last.1 + last.2 == sl => last.2 += len,
                _ => segments.push((row, sl, len)),
            }
        }
        debug_assert_eq!(segments.iter().map(|g| g.2).sum::<usize>(), m);
        // reused buffers (no fresh pages per supernode): `W`, then the chunks' scratch
        let mut buf = std::mem::take(&mut self.blocked_buf.0);
        let n_chunks = (m - b.min(PANEL)).div_ceil(CHUNK_ROWS);
        // grown only (no zero fill): `W` is written whole by the gather below and the
        // scratch by `apply_block` before it is read
        let need = m * k + n_chunks * SCRATCH;
        if buf.len() < need {
            buf.resize(need, 0.0);
        }
        let (wbuf, scratch) = buf[..need].split_at_mut(m * k);
        for (a, &t) in active.iter().enumerate() {
            let inv = 1.0 / beta[t];
            let (src, col) = (&work[t], &mut wbuf[a * m..(a + 1) * m]);
            for &(row, sl, len) in &segments {
                for (x, &w) in col[row..row + len].iter_mut().zip(&src[sl..sl + len]) {
                    *x = w * inv;
                }
            }
        }
        let len = (b - 1) * ld + m;
        let l =
            MatMut::from_column_major_slice_with_stride_mut(&mut self.vals[s0..s0 + len], m, b, ld);
        let result =
            householder_update(l, MatMut::from_column_major_slice_mut(wbuf, m, k), scratch);
        if result.is_ok() {
            for (a, &t) in active.iter().enumerate() {
                let (dst, col) = (&mut work[t], &wbuf[a * m..(a + 1) * m]);
                for &(row, sl, len) in &segments {
                    dst[sl..sl + len].copy_from_slice(&col[row..row + len]);
                }
                beta[t] = 1.0;
            }
        }
        self.blocked_buf.0 = buf;
        result?;
        self.blocked_count += 1;
        Ok(Blocked::Done(pos + b))
    }
}

/// Outcome of [`DynamicFactor::blocked_supernode_update`].
pub(crate) enum Blocked {
    /// Done; the union position after the supernode.
    Done(usize),
    /// Not blocked; do not try again before this column.
    No(usize),
}

/// `[L W] Q = [L̄ W̄]` (module docs) for a dense `m × b` lower-trapezoidal `l` (only
/// entries on and below the diagonal are read or written) and `m × k` `w`; `w`'s rows
/// `0..b` end up zero. `Err(c)`: the new pivot of column `c` is not finite.
pub(crate) fn householder_update(
    mut l: MatMut<'_, f64>,
    mut w: MatMut<'_, f64>,
    scratch: &mut [f64],
) -> Result<(), usize> {
    let (m, b, k) = (l.nrows(), l.ncols(), w.ncols());
    debug_assert!(w.nrows() == m && b <= m);
    let mut u = Mat::<f64>::zeros(k, PANEL);
    let mut t = Mat::<f64>::zeros(PANEL, PANEL);
    let mut gram = Mat::<f64>::zeros(PANEL, PANEL);
    let mut tau = [0.0f64; PANEL];
    // the panel's rows of `w`, row-major (`wp[i·k + a]`), for the unblocked part
    let mut wp = vec![0.0f64; PANEL * k];
    // per-chunk scratch `(S, S T)`, reused by every panel
    debug_assert!(scratch.len() >= (m - b.min(PANEL)).div_ceil(CHUNK_ROWS) * SCRATCH);
    for p0 in (0..b).step_by(PANEL) {
        let pb = PANEL.min(b - p0);
        // column by column: each reads a few contiguous entries of `w`
        for a in 0..k {
            for i in 0..pb {
                wp[i * k + a] = w[(p0 + i, a)];
            }
        }
        // reflections of the panel's columns, applied at once to the panel's own rows
        reflect_panel_dispatch(l.as_mut(), &mut wp, &mut u, &mut tau, p0, pb, k)?;
        for a in 0..k {
            w.as_mut().col_mut(a).subrows_mut(p0, pb).fill(0.0);
        }
        let rest = m - p0 - pb;
        if rest == 0 {
            continue;
        }
        // compact WY: H₀ ⋯ H_{pb−1} = I − V T Vᵀ, V = [I; U] (forward accumulation):
        // T[r][i] = −τᵢ Σ_{r≤q<i} T[r][q] (UᵀU)[q][i], from the Gram matrix of U
        let ur = u.as_ref().subcols(0, pb);
        matmul(
            gram.as_mut().submatrix_mut(0, 0, pb, pb),
            Accum::Replace,
            ur.transpose(),
            ur,
            1.0,
            Par::Seq,
        );
        for i in 0..pb {
            for r in 0..pb {
                t[(r, i)] = 0.0;
            }
            t[(i, i)] = tau[i];
            if tau[i] == 0.0 {
                continue;
            }
            for r in 0..i {
                let s: f64 = (r..i).map(|q| t[(r, q)] * gram[(q, i)]).sum();
                t[(r, i)] = -tau[i] * s;
            }
        }
        let (ur, tr) = (u.as_ref().subcols(0, pb), t.as_ref().submatrix(0, 0, pb, pb));
        // rows below the panel, in fixed chunks: S = L_p + W U, S ← S T, L_p −= S,
        // W −= S Uᵀ
        let lp = l.as_mut().submatrix_mut(p0 + pb, p0, rest, pb);
        let wr = w.as_mut().subrows_mut(p0 + pb, rest);
        let mut chunks = Vec::with_capacity(rest.div_ceil(CHUNK_ROWS));
        let (mut lrest, mut wrest) = (lp, wr);
        while lrest.nrows() > 0 {
            let h = CHUNK_ROWS.min(lrest.nrows());
            let (la, lb) = lrest.split_at_row_mut(h);
            let (wa, wb) = wrest.split_at_row_mut(h);
            chunks.push((la, wa));
            (lrest, wrest) = (lb, wb);
        }
        chunks
            .into_par_iter()
            .zip(scratch.par_chunks_mut(SCRATCH))
            .for_each(|((lc, wc), sc)| apply_block(lc, wc, ur, tr, sc));
    }
    Ok(())
}

/// The reflections of the panel `p0 .. p0 + pb` from its own rows (`wp`: those rows of
/// `W`, row-major `pb × k`), applied to those rows; fills `u`'s first `pb` columns and
/// `tau`. Runs the AVX2 build when the CPU has it (the same IEEE operations, no FMA:
/// bit-identical).
fn reflect_panel_dispatch(
    l: MatMut<'_, f64>,
    wp: &mut [f64],
    u: &mut Mat<f64>,
    tau: &mut [f64],
    p0: usize,
    pb: usize,
    k: usize,
) -> Result<(), usize> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 support was just checked.
        return unsafe { reflect_panel_avx2(l, wp, u, tau, p0, pb, k) };
    }
    reflect_panel(l, wp, u, tau, p0, pb, k)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn reflect_panel_avx2(
    l: MatMut<'_, f64>,
    wp: &mut [f64],
    u: &mut Mat<f64>,
    tau: &mut [f64],
    p0: usize,
    pb: usize,
    k: usize,
) -> Result<(), usize> {
    reflect_panel(l, wp, u, tau, p0, pb, k)
}

#[inline(always)]
fn reflect_panel(
    mut l: MatMut<'_, f64>,
    wp: &mut [f64],
    u: &mut Mat<f64>,
    tau: &mut [f64],
    p0: usize,
    pb: usize,
    k: usize,
) -> Result<(), usize> {
    for i in 0..pb {
        let c = p0 + i;
        let alpha = l[(c, c)];
        let (row, below) = wp[i * k..pb * k].split_at_mut(k);
        let sigma = dot(row, row);
        if sigma == 0.0 {
            tau[i] = 0.0;
            u.col_mut(i).fill(0.0);
            continue;
        }
        let beta = (alpha * alpha + sigma).sqrt();
        let v0 = -sigma / (alpha + beta);
        if !(beta.is_finite() && v0 != 0.0 && v0.is_finite()) {
            return Err(c);
        }
        let ui = u.col_mut(i).try_as_col_major_mut().expect("contiguous column").as_slice_mut();
        for (ua, wa) in ui.iter_mut().zip(row.iter_mut()) {
            *ua = *wa / v0;
            *wa = 0.0;
        }
        let ti = -v0 / beta;
        tau[i] = ti;
        l[(c, c)] = beta;
        // two rows at a time: `ui` is loaded once per pair (each row's dot and update are
        // the same operations in the same order as row by row: same bits)
        let mut rows = below.chunks_exact_mut(k);
        let mut r = c + 1;
        loop {
            match (rows.next(), rows.next()) {
                (Some(w0), Some(w1)) => {
                    let (d0, d1) = dot2(w0, w1, ui);
                    let t0 = ti * (l[(r, c)] + d0);
                    let t1 = ti * (l[(r + 1, c)] + d1);
                    l[(r, c)] -= t0;
                    l[(r + 1, c)] -= t1;
                    for ((x0, x1), y) in w0.iter_mut().zip(w1.iter_mut()).zip(ui.iter()) {
                        *x0 -= t0 * y;
                        *x1 -= t1 * y;
                    }
                    r += 2;
                }
                (Some(w0), None) => {
                    let t0 = ti * (l[(r, c)] + dot(w0, ui));
                    l[(r, c)] -= t0;
                    for (x, y) in w0.iter_mut().zip(ui.iter()) {
                        *x -= t0 * y;
                    }
                    break;
                }
                _ => break,
            }
        }
    }
    Ok(())
}

/// `Σ aᵢ bᵢ` with eight independent partial sums (fixed order: vectorisable and
/// deterministic).
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for q in 0..8 {
            acc[q] += x[q] * y[q];
        }
    }
    for (q, (x, y)) in ra.iter().zip(rb).enumerate() {
        acc[q] += x * y;
    }
    ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]))
}

/// [`dot`] of `a` and of `b` with `u`, in one pass over `u` (each sum in `dot`'s order).
#[inline(always)]
fn dot2(a: &[f64], b: &[f64], u: &[f64]) -> (f64, f64) {
    let (mut p, mut q) = ([0.0f64; 8], [0.0f64; 8]);
    let (ca, cb, cu) = (a.chunks_exact(8), b.chunks_exact(8), u.chunks_exact(8));
    let (ra, rb, ru) = (ca.remainder(), cb.remainder(), cu.remainder());
    for ((x, y), z) in ca.zip(cb).zip(cu) {
        for t in 0..8 {
            p[t] += x[t] * z[t];
            q[t] += y[t] * z[t];
        }
    }
    for (t, ((x, y), z)) in ra.iter().zip(rb).zip(ru).enumerate() {
        p[t] += x * z;
        q[t] += y * z;
    }
    let sum = |a: [f64; 8]| ((a[0] + a[4]) + (a[1] + a[5])) + ((a[2] + a[6]) + (a[3] + a[7]));
    (sum(p), sum(q))
}

/// `[L_p W] ← [L_p W] (I − V T Vᵀ)` with `V = [I; U]` for one chunk of rows (`scratch`:
/// [`SCRATCH`] values).
fn apply_block(
    mut lc: MatMut<'_, f64>,
    mut wc: MatMut<'_, f64>,
    u: MatRef<'_, f64>,
    t: MatRef<'_, f64>,
    scratch: &mut [f64],
) {
    let (h, pb) = (lc.nrows(), lc.ncols());
    let (s, st) = scratch.split_at_mut(CHUNK_ROWS * PANEL);
    let mut s = MatMut::from_column_major_slice_mut(&mut s[..h * pb], h, pb);
    s.copy_from(lc.as_ref());
    matmul(s.as_mut(), Accum::Add, wc.as_ref(), u, 1.0, Par::Seq);
    let mut st = MatMut::from_column_major_slice_mut(&mut st[..h * pb], h, pb);
    matmul(st.as_mut(), Accum::Replace, s.as_ref(), t, 1.0, Par::Seq);
    for c in 0..pb {
        for r in 0..h {
            lc[(r, c)] -= st[(r, c)];
        }
    }
    matmul(wc.as_mut(), Accum::Add, st.as_ref(), u.transpose(), -1.0, Par::Seq);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::penalised_grid;
    use crate::{Cholesky, FactorLayout, SymbolicCholesky};

    /// Curve-like penalties on a grid large enough for wide root supernodes: the blocked
    /// form is used, and the result matches the rank-1 updates in turn and a
    /// refactorisation; 1 and 2 threads give the same bits.
    #[test]
    fn blocked_supernodes_match_rank1_updates_and_refactorisation() {
        let side = 70;
        let n = side * side;
        let a = penalised_grid(side, 113);
        let sym = SymbolicCholesky::analyze_with(&a, FactorLayout::Supernodal).unwrap();
        // a staircase "curve" of 90 nodes plus 30 scattered ones, α from 1 to 1e8
        let mut pens = Vec::new();
        let (mut x, mut y) = (3usize, 2usize);
        while pens.len() < 90 {
            pens.push((y * side + x, 10f64.powi(pens.len() as i32 % 9)));
            if pens.len() % 3 == 0 { y += 1 } else { x += 1 }
        }
        pens.extend((0..30).map(|q| ((q * 977 + 31) % n, 1e4)));
        let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 101) as f64 - 50.0).collect();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut chol = Cholesky::factor_with(&sym, &a).unwrap();
                chol.add_diagonal_penalties(&pens).unwrap();
                let blocked = chol.dynamic.as_ref().unwrap().blocked_count;
                (chol.solve(&b).unwrap(), blocked)
            })
        };
        let ((x1, blocked), (x2, _)) = (run(1), run(2));
        assert!(blocked >= 1, "the blocked form was not used");
        assert!(x1.iter().zip(&x2).all(|(p, q)| p.to_bits() == q.to_bits()));
        let mut seq = Cholesky::factor_with(&sym, &a).unwrap();
        for &(i, alpha) in &pens {
            seq.add_diagonal_penalty(i, alpha).unwrap();
        }
        let mut d = vec![0.0; n];
        for &(i, alpha) in &pens {
            d[i] += alpha;
        }
        let fresh = Cholesky::factor(&a.add_diagonal(&d)).unwrap().solve(&b).unwrap();
        let scale = fresh.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = |x: &[f64], y: &[f64]| {
            x.iter().zip(y).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max) / scale
        };
        let xs = seq.solve(&b).unwrap();
        assert!(diff(&x1, &xs) < 1e-10, "blocked vs rank-1 in turn: {:e}", diff(&x1, &xs));
        assert!(diff(&x1, &fresh) < 1e-10, "blocked vs refactorisation: {:e}", diff(&x1, &fresh));
    }

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    /// `L̄ L̄ᵀ + W̄ W̄ᵀ = L Lᵀ + W Wᵀ` on the trapezoid, `W̄` zero on the block's rows, and
    /// a positive diagonal, for sizes around the panel width.
    #[test]
    fn reflections_preserve_the_sum_and_clear_the_block_rows() {
        for (m, b, k) in [(5, 5, 1), (40, 33, 9), (100, 64, 20), (300, 70, 3), (70, 70, 40)] {
            let mut seed = (m * 1000 + b * 10 + k) as u64;
            let mut l = Mat::<f64>::zeros(m, b);
            for c in 0..b {
                l[(c, c)] = 1.0 + lcg(&mut seed).abs();
                for r in c + 1..m {
                    l[(r, c)] = lcg(&mut seed);
                }
            }
            let mut w = Mat::<f64>::from_fn(m, k, |_, _| 2.0 * lcg(&mut seed));
            // some modifications enter below the block's first column
            for a in 0..k / 2 {
                for r in 0..(a * 3).min(b) {
                    w[(r, a)] = 0.0;
                }
            }
            let before = &l * l.transpose() + &w * w.transpose();
            let (mut l2, mut w2) = (l.clone(), w.clone());
            let mut scratch = vec![0.0; m.div_ceil(CHUNK_ROWS) * SCRATCH];
            householder_update(l2.as_mut(), w2.as_mut(), &mut scratch).expect("finite");
            let after = &l2 * l2.transpose() + &w2 * w2.transpose();
            let scale = before.norm_max();
            // only the rows/cols ≥ 0 within the trapezoid's reach are comparable: all of
            // them are (L is m × b lower trapezoidal, the rest of LLᵀ is its product)
            assert!((&after - &before).norm_max() <= 1e-12 * scale, "m={m} b={b} k={k}");
            for c in 0..b {
                assert!(l2[(c, c)] > 0.0);
                for a in 0..k {
                    assert_eq!(w2[(c, a)], 0.0);
                }
                for r in 0..c {
                    assert_eq!(l2[(r, c)], 0.0, "upper part untouched");
                }
            }
        }
    }
}
