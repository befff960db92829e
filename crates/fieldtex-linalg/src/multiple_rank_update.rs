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
//! hence on the path): a compact `u × k` row-major array, `u` the union size. The
//! modifications are processed in chunks of [`CHUNK`] (a fixed-width inner loop); a
//! chunk whose work entries at column `j` are all zero is skipped there, a zero entry of
//! an active chunk is an identity step (exactly what the rank-1 code does for it).
//!
//! A diagonal penalty never creates fill, so the pattern and the elimination tree stay.
//! Failure: a downdate that would make the matrix indefinite (same test as the rank-1
//! path: new pivot² ≤ 4 ε · old pivot²) is refused with [`LinalgError::UpdateFailed`] and
//! every factor column is restored — none of the `k` modifications is applied.
//!
//! Speed (measured, `examples/bench_linalg.rs`, 200K-unknown grid, 61 penalties along a
//! curve; and the refined horse of `fieldtex-fields/examples/bench_orientation.rs`): about
//! the time of the 61 rank-1 updates in turn (100–112 ms vs 98–101 ms on the grid), not
//! faster. The path of one penalty (~0.5 M entries, ~6 MB) stays in cache, so sequential
//! rank-1 updates are bound by arithmetic (~5 flops per entry and modification), not by
//! memory traffic, and reading each column once saves little; the serial recurrence of
//! each row over the `k` modifications costs latency. Versions tried and dropped: rows
//! gathered into 4-row interleaved groups (with and without AVX2, with rayon over the
//! rows of long columns), and four rows interleaved in place (89 ms vs 80 ms for the
//! rank-1 updates in turn) — no faster under a shared 2-core load.
//!
//! Not implemented: multiple-rank modifications by general (non-diagonal) vectors, which
//! can create fill (use [`Cholesky::update`] per vector); a SIMD form (e.g. the
//! recurrence over a chunk of modifications written as a small triangular matrix–vector
//! product per row, vectorised across modifications).

use crate::LinalgError;
use crate::cholesky::Cholesky;
use crate::cholesky_update::{DynamicFactor, NONE, check_alpha};

/// Modifications processed together in the inner loop.
pub const CHUNK: usize = 8;

const NO_SLOT: u32 = u32::MAX;

/// Per-modification scalars of one column: `(α, δ, γ)` with identity `(0, 1, 0)`.
type Params = ([f64; CHUNK], [f64; CHUNK], [f64; CHUNK]);

const IDENTITY: Params = ([0.0; CHUNK], [1.0; CHUNK], [0.0; CHUNK]);

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
        let n_chunks = k.div_ceil(CHUNK);
        let kp = n_chunks * CHUNK;
        let mut work = vec![0.0f64; union.len() * kp];
        for (t, &(f, v)) in cols.iter().enumerate() {
            work[self.slot[f] as usize * kp + t] = v;
        }
        let mut beta = vec![1.0f64; kp];
        let sigma = if up { 1.0 } else { -1.0 };
        let mut params: Vec<Params> = vec![IDENTITY; n_chunks];
        let mut active: Vec<usize> = Vec::with_capacity(n_chunks);
        self.backup.clear();
        let mut failure = None;
        'columns: for (step, &j) in union.iter().enumerate() {
            let (s, l) = (self.start[j], self.len[j]);
            if !up {
                self.backup.extend_from_slice(&self.vals[s..s + l]);
            }
            let row_j = self.slot[j] as usize * kp;
            let mut d = self.vals[s];
            active.clear();
            for c in 0..n_chunks {
                let wj = &mut work[row_j + c * CHUNK..row_j + (c + 1) * CHUNK];
                if wj.iter().all(|&x| x == 0.0) {
                    continue;
                }
                let p = &mut params[c];
                *p = IDENTITY;
                let mut changes = false;
                for t in 0..CHUNK {
                    let w = wj[t];
                    if w == 0.0 {
                        continue;
                    }
                    wj[t] = 0.0;
                    let b = beta[c * CHUNK + t];
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
                    beta[c * CHUNK + t] = beta2;
                    if alpha == 0.0 && delta == 1.0 {
                        continue;
                    }
                    (p.0[t], p.1[t], p.2[t]) = (alpha, delta, gamma);
                    changes = true;
                }
                if changes {
                    active.push(c);
                }
            }
            self.vals[s] = d;
            if active.is_empty() {
                continue;
            }
            let rows = &self.rows[s + 1..s + l];
            let vals = &mut self.vals[s + 1..s + l];
            for (&i, v) in rows.iter().zip(vals.iter_mut()) {
                let row = self.slot[i as usize] as usize * kp;
                let mut x = *v;
                for &c in &active {
                    let (a, dl, g) = &params[c];
                    let w: &mut [f64; CHUNK] = (&mut work[row + c * CHUNK..row + (c + 1) * CHUNK])
                        .try_into()
                        .expect("chunk width");
                    if up {
                        for t in 0..CHUNK {
                            let w1 = w[t];
                            w[t] = w1 - a[t] * x;
                            x = dl[t] * x + g[t] * w1;
                        }
                    } else {
                        for t in 0..CHUNK {
                            let w2 = w[t] - a[t] * x;
                            w[t] = w2;
                            x = dl[t] * x + g[t] * w2;
                        }
                    }
                }
                *v = x;
            }
        }
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
            let reason = if ratio.is_nan() {
                "the updated pivot is not a positive finite number (overflow?)".to_string()
            } else {
                format!(
                    "the pivot would change by a factor of {ratio:e} in its square: the downdated matrix is not (numerically) positive definite"
                )
            };
            return Err((j, reason));
        }
        Ok(())
    }
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
