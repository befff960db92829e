//! Sparse rank-1 update and downdate of a Cholesky factor: `L Lᵀ ± w wᵀ = L̄ L̄ᵀ`.
//!
//! Algorithm: Davis & Hager 1999, "Modifying a sparse Cholesky factorization" (SIAM J.
//! Matrix Anal. Appl. 20(3)), the sparse form of the Carlson/Gill–Golub–Murray–Saunders
//! rank-1 modification (method C1), as also used by CSparse's up/down-date (Davis 2006,
//! "Direct Methods for Sparse Linear Systems", §8.5). Only the columns of `L` on the
//! path from `f = min{i : wᵢ ≠ 0}` to the root of the elimination tree of the *modified*
//! factor change, so an update costs the sum of the column lengths along that path
//! (about 1 ms at 200K unknowns) instead of a refactorisation.
//!
//! Storage: the first update takes over faer's numeric factor *in place* (no copy of
//! the values): a row-index array parallel to faer's value array describes every column
//! from its diagonal down, which is contiguous in both of faer's layouts (supernodal
//! column-major blocks, simplicial CSC). Updates write into faer's values, so faer's
//! fast solve keeps working. Only when a `w` with several nonzeros creates fill does a
//! column that outgrows its slot move to the end of the arrays (with slack, as CHOLMOD
//! does); from then on the factor is a simplicial CSC `L` (diagonal first per column)
//! solved by own loops. Explicit zeros of faer's relaxed supernodes are kept (harmless).
//!
//! Pattern change (Davis & Hager 1999, §4): walking the new path, each column `j` takes
//! the pending indices from its child on the path; its new parent is the smallest
//! off-diagonal row. A single-entry `w = √α eᵢ` (a penalty) never creates fill.
//!
//! Failure: a downdate that would make the matrix indefinite (or cancel a pivot to
//! within rounding: new pivot² ≤ 4 ε · old pivot²) is refused with
//! [`LinalgError::UpdateFailed`] and the factor values are restored (structural zeros
//! inserted for fill stay; they do not change the factored matrix). An update (`+`)
//! cannot lose definiteness; it could only fail by floating-point overflow, which leaves
//! non-finite values that every later solve reports as [`LinalgError::SolveFailed`].
//!
//! Accuracy: removing a penalty `α` leaves an absolute error ~`ε α` in the factor, so
//! solves after a downdate take one step of iterative refinement against the exact
//! matrix (`CholeskyOptions::refine_after_downdate`).
//!
//! Multiple-rank updates of diagonal penalties (Davis & Hager 2001) are in
//! `crate::multiple_rank_update`. Not implemented: general (non-diagonal) multiple-rank
//! updates (apply rank-1 updates in turn), row/column addition and deletion, and pattern shrinking (entries cancelled by
//! a downdate stay as explicit zeros).

use faer::sparse::linalg::cholesky as fc;
use rayon::prelude::*;

use crate::LinalgError;
use crate::cholesky::Cholesky;

/// Direction of a rank-1 modification `A ± w wᵀ`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpdateSign {
    /// `A + w wᵀ`
    Up,
    /// `A − w wᵀ`
    Down,
}

pub(crate) const NONE: usize = usize::MAX;

/// Simplicial lower-triangular factor of `P A Pᵀ` (`perm[k]` = original index of the
/// `k`-th unknown), column `j` stored at `start[j]..start[j] + len[j]` with the diagonal
/// first; `parent` is the elimination tree (`NONE` for roots).
#[derive(Clone, Debug)]
pub(crate) struct DynamicFactor {
    /// `vals[..len_val]` is still a valid faer factor (no column has moved).
    pub(crate) faer_layout: bool,
    pub(crate) perm: Vec<usize>,
    pub(crate) inv: Vec<usize>,
    pub(crate) start: Vec<usize>,
    pub(crate) len: Vec<usize>,
    pub(crate) cap: Vec<usize>,
    pub(crate) rows: Vec<u32>,
    pub(crate) vals: Vec<f64>,
    pub(crate) parent: Vec<usize>,
    // scratch
    pub(crate) work: Vec<f64>,
    pub(crate) mark: Vec<u64>,
    pub(crate) stamp: u64,
    pub(crate) path: Vec<usize>,
    pub(crate) backup: Vec<f64>,
    /// Compact slot of each column on a multiple-rank path (`crate::multiple_rank_update`).
    pub(crate) slot: Vec<u32>,
    /// Off-diagonal rows of each column as runs of consecutive row indices
    /// `(offset past the diagonal, first row, length)`; column `j`'s runs are
    /// `runs[run_ptr[j].0 ..][.. run_ptr[j].1]`. Every row of a column is an ancestor of
    /// it, so on any union of elimination-tree paths that holds the column, a run's rows
    /// have consecutive positions (the update and the partial solve use this to loop over
    /// contiguous memory).
    pub(crate) runs: Vec<(u32, u32, u32)>,
    pub(crate) run_ptr: Vec<(u32, u32)>,
    /// First column of each of faer's supernodes, then `n` (empty for a simplicial
    /// factor); used by `crate::supernodal_solve` while [`DynamicFactor::faer_layout`]
    /// holds.
    pub(crate) supernodes: Vec<usize>,
    /// Two-worker schedule of the supernodal backward pass (`crate::subtree_schedule`;
    /// `None`: sequential), built from the structure, which updates keep.
    pub(crate) backward_schedule: Option<std::sync::Arc<crate::subtree_schedule::SubtreeSchedule>>,
    /// Supernodes updated by the blocked form (`crate::blocked_update`), for tests.
    pub(crate) blocked_count: usize,
    /// Reused buffers of the multiple-rank update (work vectors) and of the blocked form
    /// (a clone of the factor starts with empty ones).
    pub(crate) multi_buf: Scratch,
    pub(crate) blocked_buf: Scratch,
}

/// A reusable buffer that is not copied when its owner is cloned.
#[derive(Debug, Default)]
pub(crate) struct Scratch(pub(crate) Vec<f64>);

impl Clone for Scratch {
    fn clone(&self) -> Self {
        Self(Vec::new())
    }
}

impl DynamicFactor {
    /// Takes over faer's numeric factor *in place*: `values` keeps faer's layout
    /// (supernodal column-major blocks, or simplicial CSC) and a parallel row-index array
    /// describes each column from its diagonal down, so that faer's solve stays usable
    /// until fill forces a column to move. A simplicial factor whose columns do not start
    /// with the diagonal is copied into own CSC storage instead. Needs `n < 2³²`.
    pub(crate) fn from_faer(sym: &fc::SymbolicCholesky<usize>, values: Vec<f64>) -> Self {
        let n = sym.nrows();
        debug_assert!(n < u32::MAX as usize);
        let (perm, inv) = match sym.perm() {
            Some(p) => (p.arrays().0.to_vec(), p.arrays().1.to_vec()),
            None => ((0..n).collect(), (0..n).collect()),
        };
        let mut start = Vec::with_capacity(n);
        let mut len = Vec::with_capacity(n);
        let mut rows: Vec<u32>;
        let mut vals = values;
        let mut faer_layout = true;
        let mut supernodes = Vec::new();
        match sym.raw() {
            fc::SymbolicCholeskyRaw::Simplicial(s) => {
                let (cp, ri) = (s.col_ptr(), s.row_idx());
                if (0..n).all(|j| cp[j] < cp[j + 1] && ri[cp[j]] == j) {
                    rows = ri.iter().map(|&r| r as u32).collect();
                    start.extend_from_slice(&cp[..n]);
                    len.extend((0..n).map(|j| cp[j + 1] - cp[j]));
                } else {
                    // reorder: diagonal first (own storage, faer's layout is given up)
                    faer_layout = false;
                    let old = std::mem::take(&mut vals);
                    rows = Vec::with_capacity(old.len());
                    for j in 0..n {
                        start.push(rows.len());
                        let range = cp[j]..cp[j + 1];
                        let d = ri[range.clone()].iter().position(|&r| r == j);
                        rows.push(j as u32);
                        vals.push(d.map_or(0.0, |d| old[cp[j] + d]));
                        for p in range.filter(|&p| ri[p] != j) {
                            rows.push(ri[p] as u32);
                            vals.push(old[p]);
                        }
                        len.push(rows.len() - start[j]);
                    }
                }
            }
            fc::SymbolicCholeskyRaw::Supernodal(s) => {
                let (begin, end, vptr) =
                    (s.supernode_begin(), s.supernode_end(), s.col_ptr_for_val());
                let ns = s.n_supernodes();
                rows = vec![0u32; vals.len()];
                // one disjoint block of `rows` per supernode, filled in parallel
                let mut blocks = Vec::with_capacity(ns);
                let mut rest = &mut rows[..];
                for sn in 0..ns {
                    let (block, tail) = rest.split_at_mut(vptr[sn + 1] - vptr[sn]);
                    blocks.push(block);
                    rest = tail;
                }
                blocks.into_par_iter().enumerate().for_each(|(sn, block)| {
                    let (b, e) = (begin[sn], end[sn]);
                    let pattern = s.supernode(sn).pattern();
                    let nrows = (e - b) + pattern.len();
                    for k in 0..e - b {
                        // column b + k: rows b + k .. e (dense block), then the pattern
                        let col = &mut block[k * nrows..(k + 1) * nrows];
                        for (r, slot) in col.iter_mut().enumerate().take(e - b).skip(k) {
                            *slot = (b + r) as u32;
                        }
                        for (slot, &r) in col[e - b..].iter_mut().zip(pattern) {
                            *slot = r as u32;
                        }
                    }
                });
                if (0..ns).all(|sn| end[sn] == if sn + 1 < ns { begin[sn + 1] } else { n }) {
                    supernodes.extend_from_slice(&begin[..ns]);
                    supernodes.push(n);
                }
                for sn in 0..ns {
                    let (b, e) = (begin[sn], end[sn]);
                    let nrows = (e - b) + s.supernode(sn).pattern().len();
                    for k in 0..e - b {
                        start.push(vptr[sn] + k * nrows + k);
                        len.push(nrows - k);
                    }
                }
            }
        }
        let mut parent = vec![NONE; n];
        let mut runs = Vec::new();
        let mut run_ptr = Vec::with_capacity(n);
        for j in 0..n {
            let col = &rows[start[j] + 1..start[j] + len[j]];
            parent[j] = col.iter().map(|&r| r as usize).min().unwrap_or(NONE);
            run_ptr.push(push_runs(col, &mut runs));
        }
        let mut factor = Self {
            backward_schedule: None,
            faer_layout,
            perm,
            inv,
            cap: len.clone(),
            start,
            len,
            rows,
            vals,
            parent,
            work: vec![0.0; n],
            mark: vec![0; n],
            stamp: 0,
            path: Vec::new(),
            backup: Vec::new(),
            slot: Vec::new(),
            runs,
            run_ptr,
            supernodes,
            blocked_count: 0,
            multi_buf: Scratch::default(),
            blocked_buf: Scratch::default(),
        };
        factor.backward_schedule = factor.build_backward_schedule();
        factor
    }

    /// Makes `self` a copy of `s`, a factor of the same pattern and ordering. When both
    /// keep faer's layout with the same columns (rows, runs and tree are then those of
    /// the same analysis) only the values are copied, into the existing allocation;
    /// otherwise (fill has moved columns: rare) it is a clone. `self`'s update buffers
    /// are kept.
    pub(crate) fn copy_same_pattern_from(&mut self, s: &DynamicFactor) {
        let same_columns = self.faer_layout
            && s.faer_layout
            && self.supernodes == s.supernodes
            && self.start == s.start
            && self.len == s.len
            && self.vals.len() == s.vals.len();
        if same_columns {
            self.vals.copy_from_slice(&s.vals);
            self.blocked_count = s.blocked_count;
        } else {
            let buffers =
                (std::mem::take(&mut self.multi_buf), std::mem::take(&mut self.blocked_buf));
            *self = s.clone();
            (self.multi_buf, self.blocked_buf) = buffers;
        }
    }

    /// Copies from `s` the columns on the elimination-tree paths of the permuted columns
    /// `from` (each path from the column to its root), where the two factors may differ
    /// when they were equal before and only diagonal modifications at `from` happened
    /// since (a diagonal modification changes exactly the columns on its path). Returns
    /// the number of values copied, or `None` (nothing copied) when the column layouts
    /// differ.
    pub(crate) fn copy_paths_from(&mut self, s: &DynamicFactor, from: &[usize]) -> Option<usize> {
        let same_columns = self.faer_layout == s.faer_layout
            && self.start == s.start
            && self.len == s.len
            && self.parent == s.parent
            && self.vals.len() == s.vals.len();
        if !same_columns {
            return None;
        }
        let n = self.n();
        let mut seen = vec![false; n];
        let mut copied = 0;
        for &f in from {
            let mut j = f;
            while j != NONE && !seen[j] {
                seen[j] = true;
                let (st, l) = (self.start[j], self.len[j]);
                self.vals[st..st + l].copy_from_slice(&s.vals[st..st + l]);
                copied += l;
                j = self.parent[j];
            }
        }
        self.blocked_count = s.blocked_count;
        Some(copied)
    }

    pub(crate) fn n(&self) -> usize {
        self.perm.len()
    }

    /// Columns and entries an update starting at permuted column `f` would touch
    /// (current tree, no fill).
    fn path_cost(&self, f: usize) -> (usize, usize) {
        let (mut cols, mut entries, mut j) = (0, 0, f);
        while j != NONE {
            cols += 1;
            entries += self.len[j];
            j = self.parent[j];
        }
        (cols, entries)
    }

    /// Stored entries of `L` (explicit zeros included).
    pub(crate) fn nnz(&self) -> usize {
        self.len.iter().sum()
    }

    /// The values array (faer's layout while [`DynamicFactor::faer_layout`] holds).
    pub(crate) fn values(&self) -> &[f64] {
        &self.vals
    }

    /// `X ← A⁻¹ X` for a column-major `n × k` block: permute, `L Y = P X`, `Lᵀ Z = Y`,
    /// permute back, with the `k` columns interleaved so each factor entry is read once
    /// per pass (own simplicial loops; used once fill has moved columns out of faer's
    /// layout).
    pub(crate) fn solve_block_in_place(&self, x: &mut [f64], k: usize) {
        let n = self.n();
        let mut y = vec![0.0f64; n * k];
        for (i, &p) in self.perm.iter().enumerate() {
            for c in 0..k {
                y[i * k + c] = x[c * n + p];
            }
        }
        let mut t = vec![0.0f64; k];
        for j in 0..n {
            let s = self.start[j];
            let d = self.vals[s];
            t.copy_from_slice(&y[j * k..(j + 1) * k]);
            for tc in t.iter_mut() {
                *tc /= d;
            }
            y[j * k..(j + 1) * k].copy_from_slice(&t);
            for p in s + 1..s + self.len[j] {
                let (r, v) = (self.rows[p] as usize, self.vals[p]);
                for (yc, tc) in y[r * k..(r + 1) * k].iter_mut().zip(&t) {
                    *yc -= v * tc;
                }
            }
        }
        for j in (0..n).rev() {
            let s = self.start[j];
            t.copy_from_slice(&y[j * k..(j + 1) * k]);
            for p in s + 1..s + self.len[j] {
                let (r, v) = (self.rows[p] as usize, self.vals[p]);
                for (tc, yc) in t.iter_mut().zip(&y[r * k..(r + 1) * k]) {
                    *tc -= v * yc;
                }
            }
            let d = self.vals[s];
            for (yc, tc) in y[j * k..(j + 1) * k].iter_mut().zip(&t) {
                *yc = tc / d;
            }
        }
        for (i, &p) in self.perm.iter().enumerate() {
            for c in 0..k {
                x[c * n + p] = y[i * k + c];
            }
        }
    }

    /// Appends explicit-zero entries `new_rows` to column `j`, moving the column to the
    /// end of the arrays (with 50 % slack) when it outgrows its slot.
    fn grow_column(&mut self, j: usize, new_rows: &[usize]) {
        let need = self.len[j] + new_rows.len();
        if need > self.cap[j] {
            let cap = need + need / 2 + 4;
            let old = self.start[j];
            let new_start = self.rows.len();
            self.rows.extend_from_within(old..old + self.len[j]);
            self.vals.extend_from_within(old..old + self.len[j]);
            self.rows.resize(new_start + cap, 0);
            self.vals.resize(new_start + cap, 0.0);
            self.start[j] = new_start;
            self.cap[j] = cap;
            self.faer_layout = false;
        }
        let at = self.start[j] + self.len[j];
        for (t, &r) in new_rows.iter().enumerate() {
            self.rows[at + t] = r as u32;
            self.vals[at + t] = 0.0;
        }
        self.len[j] = need;
        let s = self.start[j];
        self.run_ptr[j] = push_runs(&self.rows[s + 1..s + need], &mut self.runs);
    }

    /// Symbolic phase: walks the path of the modified elimination tree from `f`,
    /// inserting the fill of `w` (pattern `pending`, all > `f`) and recording the path.
    fn symbolic_path(&mut self, f: usize, mut pending: Vec<usize>) {
        self.path.clear();
        let mut j = f;
        let mut added = Vec::new();
        loop {
            self.path.push(j);
            if !pending.is_empty() {
                self.stamp += 1;
                let st = self.stamp;
                let s = self.start[j];
                for p in s..s + self.len[j] {
                    self.mark[self.rows[p] as usize] = st;
                }
                added.clear();
                for &i in &pending {
                    if self.mark[i] != st {
                        self.mark[i] = st;
                        added.push(i);
                    }
                }
                if !added.is_empty() {
                    let add = std::mem::take(&mut added);
                    self.grow_column(j, &add);
                    added = add;
                }
                let old_parent = self.parent[j];
                let new_parent = added.iter().copied().fold(old_parent, usize::min);
                self.parent[j] = new_parent;
                pending.clear();
                if new_parent != old_parent {
                    // new parent: the whole column (but the parent itself) must reach it
                    let s = self.start[j];
                    pending.extend(self.rows[s + 1..s + self.len[j]].iter().map(|&r| r as usize));
                } else {
                    pending.extend_from_slice(&added);
                }
            }
            let p = self.parent[j];
            if p == NONE {
                break;
            }
            pending.retain(|&i| i != p);
            j = p;
        }
    }

    /// `L L̄ᵀ = L Lᵀ + sigma · w wᵀ` for `w` in *permuted* indices (unique, nonzero).
    /// On failure returns the permuted column where it failed; values are restored.
    pub(crate) fn update(&mut self, w: &[(usize, f64)], up: bool) -> Result<(), (usize, String)> {
        let Some(f) = w.iter().map(|&(i, _)| i).min() else {
            return Ok(());
        };
        let pending: Vec<usize> = w.iter().map(|&(i, _)| i).filter(|&i| i != f).collect();
        self.symbolic_path(f, pending);
        for &(i, v) in w {
            self.work[i] = v;
        }
        self.backup.clear();
        let sigma = if up { 1.0 } else { -1.0 };
        let mut beta = 1.0f64;
        let mut failure = None;
        for step in 0..self.path.len() {
            let j = self.path[step];
            let (s, l) = (self.start[j], self.len[j]);
            if !up {
                self.backup.extend_from_slice(&self.vals[s..s + l]);
            }
            let d = self.vals[s];
            let wj = self.work[j];
            self.work[j] = 0.0;
            let alpha = wj / d;
            let beta2_sq = beta * beta + sigma * alpha * alpha;
            if beta2_sq.is_nan()
                || beta2_sq <= 4.0 * f64::EPSILON * beta * beta
                || !beta2_sq.is_finite()
            {
                failure = Some((step, j, beta2_sq / (beta * beta)));
                break;
            }
            let beta2 = beta2_sq.sqrt();
            let (delta, gamma) =
                (if up { beta / beta2 } else { beta2 / beta }, sigma * alpha / (beta2 * beta));
            let new_d = delta * d + if up { gamma * wj } else { 0.0 };
            if !new_d.is_finite() || new_d <= 0.0 {
                failure = Some((step, j, f64::NAN));
                break;
            }
            self.vals[s] = new_d;
            beta = beta2;
            if alpha == 0.0 && delta == 1.0 {
                // no change in this column; entries of w below stay as they are
                continue;
            }
            let rows = &self.rows[s + 1..s + l];
            let vals = &mut self.vals[s + 1..s + l];
            let work = &mut self.work[..];
            if up {
                for (&i, v) in rows.iter().zip(vals.iter_mut()) {
                    let w1 = work[i as usize];
                    work[i as usize] = w1 - alpha * *v;
                    *v = delta * *v + gamma * w1;
                }
            } else {
                for (&i, v) in rows.iter().zip(vals.iter_mut()) {
                    let w2 = work[i as usize] - alpha * *v;
                    work[i as usize] = w2;
                    *v = delta * *v + gamma * w2;
                }
            }
        }
        if let Some((step, j, ratio)) = failure {
            // restore processed columns (downdates keep a backup; an update can only fail
            // by overflow, which leaves non-finite values that every later solve reports)
            // and clear the work vector on the rest of the path
            let mut off = 0;
            let restored = if up { 0 } else { step + 1 };
            for &c in &self.path[..restored] {
                let (s, l) = (self.start[c], self.len[c]);
                if off + l <= self.backup.len() {
                    self.vals[s..s + l].copy_from_slice(&self.backup[off..off + l]);
                }
                off += l;
            }
            for &c in &self.path[step..] {
                self.work[c] = 0.0;
            }
            return Err((j, pivot_failure_reason(ratio)));
        }
        Ok(())
    }
}

/// Appends the runs of consecutive row indices of `rows` to `runs` (see
/// [`DynamicFactor::runs`]) and returns `(first run, count)`.
fn push_runs(rows: &[u32], runs: &mut Vec<(u32, u32, u32)>) -> (u32, u32) {
    let first = runs.len();
    for (q, &r) in rows.iter().enumerate() {
        let own = runs.len() > first;
        match runs.last_mut() {
            Some((q0, r0, m)) if own && *r0 + *m == r && *q0 + *m == q as u32 => *m += 1,
            _ => runs.push((q as u32, r, 1)),
        }
    }
    (first as u32, (runs.len() - first) as u32)
}

pub(crate) fn check_alpha(alpha: f64) -> Result<(), LinalgError> {
    if !(alpha.is_finite() && alpha > 0.0) {
        return Err(LinalgError::InvalidArgument {
            what: "penalty weight alpha",
            value: alpha,
            reason: "must be finite and positive",
        });
    }
    Ok(())
}

/// Why a rank-1 sweep stopped at a pivot: `ratio` is the factor by which the pivot's
/// square would change, NaN when the updated pivot is not a positive finite number.
pub(crate) fn pivot_failure_reason(ratio: f64) -> String {
    if ratio.is_nan() {
        "the updated pivot is not a positive finite number (overflow?)".to_string()
    } else {
        format!(
            "the pivot would change by a factor of {ratio:e} in its square: the downdated matrix is not (numerically) positive definite"
        )
    }
}

#[cfg(test)]
#[path = "faer_layout_tests.rs"]
mod faer_layout_tests;

#[path = "cholesky_update_api.rs"]
mod api;
