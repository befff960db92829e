//! Multiple-rank update and downdate by diagonal penalties: `L L̄ᵀ = L Lᵀ ± Σₜ αₜ eᵢₜ eᵢₜᵀ`
//! in one walk over the union of the elimination-tree paths.
//!
//! Algorithm: Davis & Hager 2001, "Multiple-rank modifications of a sparse Cholesky
//! factorization" (SIAM J. Matrix Anal. Appl. 22(4)): the `k` rank-1 modifications of
//! `crate::cholesky_update` (Davis & Hager 1999, method C1) are applied together, column
//! by column. A column `j` of `L` is changed by modification `t` only if `j` lies on the
//! path of `t` (from `iₜ` to the root of the elimination tree), and the change made by
//! `t` at `j` depends only on column `j` after modifications `1..t−1` and on `t`'s own
//! work vector after the columns below `j` on its path. So visiting the columns of the
//! union of the paths in increasing order (children before parents) and applying the
//! modifications `t = 1..k` in the given order at each column gives exactly the result of
//! `k` rank-1 modifications in turn, while every factor column is read and written
//! once instead of once per modification — the dominant cost when the paths share
//! their upper part (the separators near the root), as the vertices of one curve do.
//!
//! Work vectors live only on the union path (every row of a path column is an ancestor,
//! hence on the path): a compact `k × u` array (`u` the union size), one contiguous
//! vector per modification indexed by the column's slot in the sorted union. At column
//! `j` the modifications whose work entry there is nonzero are applied (a zero entry is
//! an identity step, exactly what the rank-1 code does for it), **modification by
//! modification, each sweeping the rows of the column**: a row sees the modifications in
//! the same order and with the same IEEE operations as the one-row recurrence, so the
//! result is bit-identical to it, but the rows of a sweep are independent. The rows of a
//! column are grouped into runs of consecutive slots (a supernode's dense block is one
//! run, its pattern a few), so a sweep is a contiguous loop that the AVX2 build (chosen
//! at run time, same operations, no FMA contraction) vectorises.
//!
//! A diagonal penalty never creates fill, so the pattern and the elimination tree stay.
//! Failure: a downdate that would make the matrix indefinite (same test as the rank-1
//! path: new pivot² ≤ 4 ε · old pivot²) is refused with [`LinalgError::UpdateFailed`] and
//! every factor column is restored — none of the `k` modifications is applied.
//!
//! Speed measurements of each form: `docs/perf/multiple-rank-update.md`.
//!
//! **Blocked supernodes (updates only).** Where many modifications pass through a wide
//! supernode of faer's layout (at least 8 columns and 8 modifications), an update
//! handles the whole supernode at once with structured Householder reflections in
//! panels (`crate::blocked_update`), whose trailing work is two dense matrix products.
//! There the result equals the sweeps' to rounding, no longer bit for bit (it is still
//! independent of the thread count).
//!
//! **Per-column modification lists.** A column is changed only by the modifications whose
//! path holds it, so a CSR list of those (ascending, from one walk up each path) replaces
//! the test of all `k` work vectors at every column — `k` loads `u` doubles apart, a cache
//! miss each; blocked supernodes take their candidates from the list of their last
//! column, and gather and scatter `W` by runs of consecutive slots; the work buffer is
//! kept zero between updates (every entry is consumed by its column) instead of being
//! refilled. Same operations, same bits.
//!
//! Not implemented: multiple-rank modifications by general (non-diagonal) vectors, which
//! can create fill (use [`Cholesky::update`] per vector); a blocked form of downdates
//! (hyperbolic reflections).

use crate::LinalgError;
use crate::blocked_update::Blocked;
use crate::cholesky::Cholesky;
use crate::cholesky_update::{DynamicFactor, NONE, check_alpha, pivot_failure_reason};

const NO_SLOT: u32 = u32::MAX;

impl DynamicFactor {
    /// Multiple-rank modification by `w_t = v_t e_{f_t}` (`f_t` permuted column, `v_t ≠ 0`)
    /// in the given order. On failure returns the permuted column where it failed; all
    /// values are restored for downdates.
    pub(crate) fn update_diagonal_multi(
        &mut self,
        cols: &[(usize, f64)],
        up: bool,
    ) -> Result<(), (usize, String)> {
        let n = self.n();
        let k = cols.len();
        if k == 0 {
            return Ok(());
        }
        if self.slot.len() != n {
            self.slot = vec![NO_SLOT; n];
        }
        // union of the paths, in increasing column order (topological: parent > child)
        let mut union: Vec<usize> = Vec::new();
        for &(f, _) in cols {
            let mut j = f;
            while j != NONE && self.slot[j] == NO_SLOT {
                self.slot[j] = 0;
                union.push(j);
                j = self.parent[j];
            }
        }
        union.sort_unstable();
        for (s, &j) in union.iter().enumerate() {
            self.slot[j] = s as u32;
        }
        // work vectors column-major by modification: `work[t · u + slot]`
        let u = union.len();
        let mut buf = std::mem::take(&mut self.multi_buf.0);
        // The buffer holds zeros between updates: every work entry is consumed (set to
        // zero) by the column it belongs to, so after a completed update all are zero
        // again, and only a failed one (or growth) needs a fill. This saves zeroing the
        // `u · k` entries (4.8 MB for a 250-edge stroke on the 128² field grid) each time.
        if buf.len() < u * k {
            buf.clear();
            buf.resize(u * k, 0.0);
        }
        debug_assert!(buf[..u * k].iter().all(|&w| w == 0.0));
        for (t, &(f, v)) in cols.iter().enumerate() {
            buf[t * u + self.slot[f] as usize] = v;
        }
        let mut work: Vec<&mut [f64]> = buf[..u * k].chunks_mut(u).collect();
        // the modifications whose path holds each union column, ascending (a CSR list):
        // only those can have a nonzero work entry there, so a column visits them instead
        // of testing all `k` work vectors (one cache miss each, `u` doubles apart)
        let mut through_ptr = vec![0u32; u + 1];
        for &(f, _) in cols {
            let mut j = f;
            while j != NONE {
                through_ptr[self.slot[j] as usize + 1] += 1;
                j = self.parent[j];
            }
        }
        for q in 0..u {
            through_ptr[q + 1] += through_ptr[q];
        }
        let mut fill: Vec<u32> = through_ptr[..u].to_vec();
        let mut through = vec![0u32; through_ptr[u] as usize];
        for (t, &(f, _)) in cols.iter().enumerate() {
            let mut j = f;
            while j != NONE {
                let q = self.slot[j] as usize;
                through[fill[q] as usize] = t as u32;
                fill[q] += 1;
                j = self.parent[j];
            }
        }
        drop(fill);
        let mut beta = vec![1.0f64; k];
        let sigma = if up { 1.0 } else { -1.0 };
        // per column: the modifications that change it, with their `(t, α, δ, γ)`
        let mut steps: Vec<(usize, f64, f64, f64)> = Vec::with_capacity(k);
        let mut runs: Vec<(usize, u32, u32)> = Vec::new();
        #[cfg(target_arch = "x86_64")]
        let avx2 = std::arch::is_x86_feature_detected!("avx2");
        #[cfg(not(target_arch = "x86_64"))]
        let avx2 = false;
        self.backup.clear();
        let mut failure = None;
        // columns before this one are not tried for the blocked form again
        let mut no_block_before = 0usize;
        let mut pos = 0usize;
        'columns: while pos < union.len() {
            let (step, j) = (pos, union[pos]);
            pos += 1;
            if up && j >= no_block_before {
                let through_of =
                    |q: usize| &through[through_ptr[q] as usize..through_ptr[q + 1] as usize];
                match self.blocked_supernode_update(&union, step, &mut work, &mut beta, through_of)
                {
                    Ok(Blocked::Done(next)) => {
                        pos = next;
                        continue;
                    }
                    Ok(Blocked::No(until)) => no_block_before = until,
                    Err(c) => {
                        failure = Some((step, c, f64::NAN));
                        break 'columns;
                    }
                }
            }
            let (s, l) = (self.start[j], self.len[j]);
            if !up {
                self.backup.extend_from_slice(&self.vals[s..s + l]);
            }
            let row_j = self.slot[j] as usize;
            let mut d = self.vals[s];
            steps.clear();
            let (t0, t1) = (through_ptr[row_j] as usize, through_ptr[row_j + 1] as usize);
            for &t in &through[t0..t1] {
                let t = t as usize;
                let w = work[t][row_j];
                if w == 0.0 {
                    continue;
                }
                work[t][row_j] = 0.0;
                let b = beta[t];
                let alpha = w / d;
                let beta2_sq = b * b + sigma * alpha * alpha;
                if beta2_sq.is_nan()
                    || beta2_sq <= 4.0 * f64::EPSILON * b * b
                    || !beta2_sq.is_finite()
                {
                    failure = Some((step, j, beta2_sq / (b * b)));
                    break 'columns;
                }
                let beta2 = beta2_sq.sqrt();
                let (delta, gamma) =
                    (if up { b / beta2 } else { beta2 / b }, sigma * alpha / (beta2 * b));
                let new_d = delta * d + if up { gamma * w } else { 0.0 };
                if !new_d.is_finite() || new_d <= 0.0 {
                    failure = Some((step, j, f64::NAN));
                    break 'columns;
                }
                d = new_d;
                beta[t] = beta2;
                if alpha == 0.0 && delta == 1.0 {
                    continue;
                }
                steps.push((t, alpha, delta, gamma));
            }
            self.vals[s] = d;
            if steps.is_empty() {
                continue;
            }
            // the column's rows as runs of consecutive slots (module docs)
            runs.clear();
            let (r0, rn) = self.run_ptr[j];
            runs.extend(
                self.runs[r0 as usize..(r0 + rn) as usize]
                    .iter()
                    .map(|&(q, r, m)| (q as usize, self.slot[r as usize], m)),
            );
            let vals = &mut self.vals[s + 1..s + l];
            let total = (l - 1) * steps.len();
            let split = if total >= PARALLEL_WORK && rayon::current_num_threads() > 1 {
                split_point(&runs)
            } else {
                None
            };
            match split {
                None => apply_steps(&steps, &runs, vals, &mut work, up, avx2),
                Some((p, q_p, o_p)) => {
                    // two halves with disjoint rows (values) and slots (work entries):
                    // every entry sees the same operations, so the result is the same
                    let (v_lo, v_hi) = vals.split_at_mut(q_p);
                    let mut lo: Vec<&mut [f64]> = Vec::with_capacity(k);
                    let mut hi: Vec<&mut [f64]> = Vec::with_capacity(k);
                    for w in work.iter_mut() {
                        let (a, b) = w.split_at_mut(o_p);
                        lo.push(a);
                        hi.push(b);
                    }
                    let runs_hi: Vec<(usize, u32, u32)> =
                        runs[p..].iter().map(|&(q, o, m)| (q - q_p, o - o_p as u32, m)).collect();
                    let steps = &steps;
                    let runs_lo = &runs[..p];
                    rayon::join(
                        || apply_steps(steps, runs_lo, v_lo, &mut lo, up, avx2),
                        || apply_steps(steps, &runs_hi, v_hi, &mut hi, up, avx2),
                    );
                }
            }
        }
        drop(work);
        if failure.is_some() {
            buf.fill(0.0);
        }
        debug_assert!(buf.iter().all(|&w| w == 0.0));
        self.multi_buf.0 = buf;
        for &j in &union {
            self.slot[j] = NO_SLOT;
        }
        if let Some((step, j, ratio)) = failure {
            if !up {
                let mut off = 0;
                for &c in &union[..=step] {
                    let (s, l) = (self.start[c], self.len[c]);
                    if off + l <= self.backup.len() {
                        self.vals[s..s + l].copy_from_slice(&self.backup[off..off + l]);
                    }
                    off += l;
                }
            }
            return Err((j, pivot_failure_reason(ratio)));
        }
        Ok(())
    }
}

/// Work (rows × modifications) of one column above which its rows are split in two
/// halves that run in parallel.
const PARALLEL_WORK: usize = 1 << 15;

/// Where to split a column's runs into two halves of about equal rows, as
/// `(first run of the upper half, its row offset, its slot)`: only if the runs increase in
/// both row offset and slot (always, unless fill appended rows out of order) and both
/// halves are non-empty.
fn split_point(runs: &[(usize, u32, u32)]) -> Option<(usize, usize, usize)> {
    let monotone = runs.windows(2).all(|p| p[0].0 < p[1].0 && p[0].1 + p[0].2 <= p[1].1);
    if !monotone || runs.len() < 2 {
        return None;
    }
    let total: usize = runs.iter().map(|r| r.2 as usize).sum();
    let mut acc = 0;
    for (p, r) in runs.iter().enumerate() {
        if p > 0 && 2 * acc >= total {
            return Some((p, r.0, r.1 as usize));
        }
        acc += r.2 as usize;
    }
    let p = runs.len() - 1;
    Some((p, runs[p].0, runs[p].1 as usize))
}

/// The modifications `steps` in order over the rows `runs` of a column, four at a time:
/// a row's value stays in a register through the four (one load and store of it instead
/// of four), each row still sees the modifications in the same order with the same
/// operations. `work[t]`: modification `t`'s work vector.
#[inline(always)]
fn sweep_steps(
    steps: &[(usize, f64, f64, f64)],
    runs: &[(usize, u32, u32)],
    vals: &mut [f64],
    work: &mut [&mut [f64]],
    up: bool,
) {
    let mut chunks = steps.chunks_exact(4);
    for c in &mut chunks {
        let [w0, w1, w2, w3] = work
            .get_disjoint_mut([c[0].0, c[1].0, c[2].0, c[3].0])
            .expect("distinct modifications");
        let p = [c[0], c[1], c[2], c[3]].map(|(_, a, dl, g)| (a, dl, g));
        for &(q0, o0, m) in runs {
            let (o0, m) = (o0 as usize, m as usize);
            let ws = [
                &mut w0[o0..o0 + m],
                &mut w1[o0..o0 + m],
                &mut w2[o0..o0 + m],
                &mut w3[o0..o0 + m],
            ];
            sweep4(ws, &mut vals[q0..q0 + m], p, up);
        }
    }
    for &(t, a, dl, g) in chunks.remainder() {
        sweep(&mut work[t][..], runs, vals, a, dl, g, up);
    }
}

/// Four modifications over one run (equal lengths).
#[inline(always)]
fn sweep4(ws: [&mut [f64]; 4], vs: &mut [f64], p: [(f64, f64, f64); 4], up: bool) {
    let [w0, w1, w2, w3] = ws;
    let it =
        vs.iter_mut().zip(w0.iter_mut()).zip(w1.iter_mut()).zip(w2.iter_mut()).zip(w3.iter_mut());
    if up {
        for ((((v, w0), w1), w2), w3) in it {
            let mut x = *v;
            for (w, &(a, dl, g)) in [w0, w1, w2, w3].into_iter().zip(&p) {
                let w1 = *w;
                *w = w1 - a * x;
                x = dl * x + g * w1;
            }
            *v = x;
        }
    } else {
        for ((((v, w0), w1), w2), w3) in it {
            let mut x = *v;
            for (w, &(a, dl, g)) in [w0, w1, w2, w3].into_iter().zip(&p) {
                let w2 = *w - a * x;
                *w = w2;
                x = dl * x + g * w2;
            }
            *v = x;
        }
    }
}

/// One modification `(α, δ, γ)` over the rows `runs` of a column: the recurrence of
/// Davis & Hager's method C1 on each row.
#[inline(always)]
fn sweep(
    w: &mut [f64],
    runs: &[(usize, u32, u32)],
    vals: &mut [f64],
    a: f64,
    dl: f64,
    g: f64,
    up: bool,
) {
    for &(q0, o0, m) in runs {
        let (o0, m) = (o0 as usize, m as usize);
        let ws = &mut w[o0..o0 + m];
        let vs = &mut vals[q0..q0 + m];
        if up {
            for (wv, v) in ws.iter_mut().zip(vs.iter_mut()) {
                let w1 = *wv;
                *wv = w1 - a * *v;
                *v = dl * *v + g * w1;
            }
        } else {
            for (wv, v) in ws.iter_mut().zip(vs.iter_mut()) {
                let w2 = *wv - a * *v;
                *wv = w2;
                *v = dl * *v + g * w2;
            }
        }
    }
}

/// Applies the modifications `steps` (`(t, α, δ, γ)` in order) of one column to its
/// off-diagonal values `vals` and the work vectors (`work[t][slot]`, restricted to the
/// slots of `runs` — the whole union, or one half of a split column), the rows given as
/// `runs` of consecutive slots. Modifications outer, rows inner: each row sees the
/// modifications in the same order and with the same IEEE operations as the one-row
/// recurrence (bit-identical results), but the rows of a sweep are independent and
/// contiguous within a run, so the sweep vectorises instead of waiting on the
/// recurrence's latency.
fn apply_steps(
    steps: &[(usize, f64, f64, f64)],
    runs: &[(usize, u32, u32)],
    vals: &mut [f64],
    work: &mut [&mut [f64]],
    up: bool,
    avx2: bool,
) {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: the caller checked that the CPU supports AVX2.
        unsafe { apply_steps_avx2(steps, runs, vals, work, up) };
        return;
    }
    let _ = avx2;
    sweep_steps(steps, runs, vals, work, up);
}

/// [`sweep_steps`] compiled for AVX2 (the same IEEE operations, no FMA contraction:
/// bit-identical to the baseline build).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn apply_steps_avx2(
    steps: &[(usize, f64, f64, f64)],
    runs: &[(usize, u32, u32)],
    vals: &mut [f64],
    work: &mut [&mut [f64]],
    up: bool,
) {
    sweep_steps(steps, runs, vals, work, up);
}

impl Cholesky {
    /// Adds the penalties `Σₜ αₜ eᵢₜ eᵢₜᵀ` (`(iₜ, αₜ)`, `αₜ` finite and > 0; an index may
    /// repeat) by one multiple-rank update (Davis & Hager 2001, module docs): the same
    /// factor as [`Cholesky::add_diagonal_penalty`] for each pair in turn, with every
    /// factor column on the union of their elimination-tree paths read once.
    ///
    /// Errors (nothing is changed): index out of range, invalid `α`.
    pub fn add_diagonal_penalties(
        &mut self,
        penalties: &[(usize, f64)],
    ) -> Result<(), LinalgError> {
        self.modify_diagonal(penalties, true)
    }

    /// Removes penalties added by [`Cholesky::add_diagonal_penalties`] (or one at a time)
    /// by one multiple-rank downdate. A downdate that would leave the matrix indefinite is
    /// refused with [`LinalgError::UpdateFailed`]; then none of the penalties is removed.
    pub fn remove_diagonal_penalties(
        &mut self,
        penalties: &[(usize, f64)],
    ) -> Result<(), LinalgError> {
        self.modify_diagonal(penalties, false)
    }

    fn modify_diagonal(&mut self, penalties: &[(usize, f64)], up: bool) -> Result<(), LinalgError> {
        let n = self.size();
        let mut w = Vec::with_capacity(penalties.len());
        for &(i, alpha) in penalties {
            if i >= n {
                return Err(LinalgError::IndexOutOfRange { row: i, col: i, nrows: n, ncols: n });
            }
            check_alpha(alpha)?;
            let v = alpha.sqrt();
            if !(v * v).is_finite() {
                return Err(LinalgError::InvalidArgument {
                    what: "penalty weight alpha",
                    value: alpha,
                    reason: "its square root squared overflows",
                });
            }
            w.push((i, v));
        }
        if w.is_empty() {
            return Ok(());
        }
        let dynamic = self.ensure_dynamic()?;
        let permuted: Vec<(usize, f64)> = w.iter().map(|&(i, v)| (dynamic.inv[i], v)).collect();
        dynamic.update_diagonal_multi(&permuted, up).map_err(|(j, reason)| {
            LinalgError::UpdateFailed {
                kind: if up { "multiple-rank update" } else { "multiple-rank downdate" },
                column: dynamic.perm[j],
                reason,
            }
        })?;
        self.downdated |= !up;
        // keep the matrix used by residual checks current (as the rank-1 path does)
        let s = if up { 1.0 } else { -1.0 };
        for &(i, v) in &w {
            match self.matrix.find(i, i) {
                Some(p) => self.matrix.values_mut()[p] += s * v * v,
                None => self.extra_terms.push((vec![(i, v)], s)),
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx2_sweep_is_bit_identical_to_baseline() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let u = 50;
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let steps: Vec<(usize, f64, f64, f64)> =
            (0..5).map(|t| (t, next(), 1.0 + 0.1 * next(), next())).collect();
        // rows: a run of 13 consecutive slots, two short runs, single rows
        let runs = vec![(0, 2, 13), (13, 20, 3), (16, 30, 1), (17, 40, 7)];
        let vals: Vec<f64> = (0..24).map(|_| next()).collect();
        let work: Vec<f64> = (0..5 * u).map(|_| next()).collect();
        for up in [true, false] {
            let (mut v1, mut w1) = (vals.clone(), work.clone());
            let (mut v2, mut w2) = (vals.clone(), work.clone());
            sweep_steps(&steps, &runs, &mut v1, &mut w1.chunks_mut(u).collect::<Vec<_>>(), up);
            // SAFETY: AVX2 checked above.
            unsafe {
                apply_steps_avx2(
                    &steps,
                    &runs,
                    &mut v2,
                    &mut w2.chunks_mut(u).collect::<Vec<_>>(),
                    up,
                )
            };
            let same =
                |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(p, q)| p.to_bits() == q.to_bits());
            assert!(same(&v1, &v2) && same(&w1, &w2));
            assert!(v1 != vals, "the sweep changed the values");
        }
    }
}
