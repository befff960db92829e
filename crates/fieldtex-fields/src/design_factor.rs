//! The kept factorisation of a field design's matrix `A₀ + diag(s)` (`A₀`: the
//! stroke-free design matrix, `s`: the summed stroke weights per edge, `#E`), brought up
//! to date after stroke edits by multiple-rank updates, by a copy of a kept earlier
//! factor plus one multiple-rank update, or by a numeric refactorisation with the kept
//! symbolic analysis.
//!
//! A stroke edit changes `A` by `Σ Δs_e e_e e_eᵀ`. Three ways to follow it, the cheapest
//! by a rule on edge counts only (never timings, so the result of an edit sequence does
//! not depend on the machine):
//! - **direct**: the current factor gets one multiple-rank update for the edges whose
//!   weight grows and one multiple-rank downdate for those whose weight shrinks
//!   (Davis & Hager 2001, "Multiple-rank modifications of a sparse Cholesky
//!   factorization", via `fieldtex_linalg::Cholesky::add_diagonal_penalties`); cost
//!   `ups + 4 · downs` (downdates run rank-1 sweeps, updates blocked reflections);
//! - **checkpoint**: a kept copy of an earlier factor with stroke diagonal `s_c ≤ s` is
//!   copied into the current factor's buffers and gets one multiple-rank update with
//!   `s − s_c`; cost `16 + #(s ≠ s_c)`. The copy moves only what can differ
//!   (`Cholesky::copy_changed_from`): the two factors were equal after the last copy
//!   between them, and each diagonal modification since changed only the columns on its
//!   edge's elimination-tree path, so the edges modified since (`dirty`) name every
//!   column to copy — for a ~250-edge stroke 1.4–1.7 ms instead of 4–13 ms for the whole
//!   2.3M-entry factor (measured under load averages 3–5; a clone with fresh pages took
//!   12–55 ms). No downdate at all: dragging a stroke costs that copy plus the update of
//!   the stroke's new edges, removing the last-added stroke the copy. The checkpoint is
//!   taken at every refactorisation and, before an edit that only adds weight, from the
//!   current factor (again only the dirty paths) when the old one lies above the new
//!   diagonal somewhere or more than 16 edges behind (so it is "everything but the
//!   stroke being drawn");
//! - **refactorisation**: when more than [`crate::FieldDesignOptions::rank1_update_limit`]
//!   (default 640) edges would be modified, after `16 ×` that many modifications since
//!   the last factorisation (rounding drift), or when a downdate is refused.
//!
//! Measurements, and what was tried for long strokes: `docs/perf/field-design-edits.md`.
//!
//! Not implemented: a Woodbury (capacitance-matrix) correction of the solve instead of a
//! factor modification: it needs `A⁻¹` at the stroke's ~250–500 edges, i.e. as many
//! sparse solves reaching the top separators, about the cost of the update itself.

use fieldtex_linalg::{Cholesky, CholeskyOptions, SparseMatrix, SymbolicCholesky};

use crate::FieldsError;

/// A downdated edge costs about this many updated edges (multiple-rank downdates run
/// the rank-1 sweeps, updates the blocked reflections; measured 60–95 ms against
/// 30–50 ms for 250 edges on the 128² grid in session 4, hence 2 then). Raised to 4
/// once restores copied only the changed paths: a 1 px-per-event mouse drag of a
/// ~250 px stroke then goes through the checkpoint (restore + update of the new edges)
/// instead of updating and downdating the changed edges, 27.8–31.0 → 23.6–24.5 ms per
/// event, 90th percentile 31–41 → 25–32 ms, other edits unchanged (`bench_fields`,
/// load 0.2–0.9, binaries interleaved).
const DOWNDATE_WEIGHT: usize = 4;

/// Cost of bringing the current factor back to the checkpoint, in updated edges: the
/// copy of the changed paths measured 1.4–1.7 ms for a ~250-edge stroke, an updated edge
/// 0.05–0.1 ms (64 while the whole 2.3M-entry factor was copied, 4–13 ms; 16 and 64
/// measured the same within noise on the stroke benchmarks, 16 with a lower 90th
/// percentile for 1 px drags).
const RESTORE_COST: usize = 16;

/// An earlier factor kept to rebuild later ones by updates only.
struct Checkpoint {
    factor: Cholesky,
    diag: Vec<f64>,
    /// Modifications accumulated in `factor` since its numeric factorisation.
    updates_since_factor: usize,
}

impl Checkpoint {
    /// The updates that turn this checkpoint into a factor with stroke diagonal `diag`,
    /// if no weight decreased (`None` otherwise).
    fn updates_to(&self, diag: &[f64]) -> Option<Vec<(usize, f64)>> {
        let mut ups = Vec::new();
        for (e, (&new, &old)) in diag.iter().zip(&self.diag).enumerate() {
            if new > old {
                ups.push((e, new - old));
            } else if new < old {
                return None;
            }
        }
        Some(ups)
    }
}

/// Symbolic analysis, numeric factor and the stroke diagonal it was made with.
pub(crate) struct DesignFactor {
    symbolic: SymbolicCholesky,
    /// Numeric factor of `A₀ + diag(factored_diag)`; `None` until the first solve.
    factor: Option<Cholesky>,
    factored_diag: Vec<f64>,
    /// A copy of an earlier factor (module docs); `None` until the first factorisation.
    checkpoint: Option<Checkpoint>,
    /// Position of `A₀[e][e]` in the values of `A₀` (refactorisations add `s` there).
    diagonal_positions: Vec<usize>,
    pub(crate) refactor_count: usize,
    pub(crate) rank1_update_count: usize,
    pub(crate) restore_count: usize,
    updates_since_factor: usize,
    /// Edges whose diagonal was modified in the current factor since it last equalled
    /// the checkpoint (`None`: unknown). Only the factor columns on these edges'
    /// elimination-tree paths can differ, so copies between the two move only those
    /// (`Cholesky::copy_changed_from`).
    dirty: Option<Vec<usize>>,
}

impl DesignFactor {
    /// Analyses the pattern of `base` (`A₀`, whose diagonal must be stored).
    pub(crate) fn new(base: &SparseMatrix) -> Result<Self, FieldsError> {
        let symbolic = SymbolicCholesky::analyze(base)?;
        let diagonal_positions = (0..base.nrows())
            .map(|e| {
                base.find(e, e).ok_or(FieldsError::InvalidOption {
                    name: "design matrix diagonal",
                    value: e as f64,
                    expected: "a stored diagonal entry for every edge (regularisation > 0)",
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            symbolic,
            factor: None,
            factored_diag: vec![0.0; base.nrows()],
            checkpoint: None,
            diagonal_positions,
            refactor_count: 0,
            rank1_update_count: 0,
            restore_count: 0,
            updates_since_factor: 0,
            dirty: None,
        })
    }

    /// The current factor (`None` before the first [`DesignFactor::sync`]).
    pub(crate) fn factor(&self) -> Option<&Cholesky> {
        self.factor.as_ref()
    }

    /// The factor, mutable (sparse solves take it over for updates on first use).
    pub(crate) fn factor_mut(&mut self) -> Option<&mut Cholesky> {
        self.factor.as_mut()
    }

    /// Drops the numeric factor and the checkpoint; the next sync refactors.
    pub(crate) fn invalidate(&mut self) {
        self.factor = None;
        self.checkpoint = None;
        self.dirty = None;
    }

    /// Makes the factor one of `base + diag(diag)`, by the cheapest of (module docs):
    /// a copy of the checkpoint plus one multiple-rank update (when no weight is below
    /// the checkpoint's), updates and downdates of the current factor, or a numeric
    /// refactorisation. The first two need at most `limit` modified edges and fewer than
    /// `16 × limit` modifications accumulated since the last factorisation (to bound
    /// rounding drift); a refused downdate (it would leave the matrix indefinite: the
    /// factor is then unchanged) also refactors. The choice depends only on counts.
    pub(crate) fn sync(
        &mut self,
        base: &SparseMatrix,
        diag: &[f64],
        limit: usize,
    ) -> Result<(), FieldsError> {
        if self.factor.is_some() && diag == self.factored_diag.as_slice() {
            return Ok(());
        }
        let drift_limit = 16 * limit;
        if self.factor.is_some() {
            let (mut ups, mut downs) = (Vec::new(), Vec::new());
            for (e, (&new, &old)) in diag.iter().zip(&self.factored_diag).enumerate() {
                if new > old {
                    ups.push((e, new - old));
                } else if new < old {
                    downs.push((e, old - new));
                }
            }
            let direct = ups.len() + DOWNDATE_WEIGHT * downs.len();
            if let Some(c) = &self.checkpoint
                && let Some(c_ups) = c.updates_to(diag)
                && RESTORE_COST + c_ups.len() < direct
                && c_ups.len() <= limit
                && c.updates_since_factor + c_ups.len() <= drift_limit
            {
                let factor = self.factor.as_mut().expect("checked");
                // into the current factor's buffers (no fresh pages)
                copy_factor(factor, &c.factor, self.dirty.take());
                if let Err(e) = factor.add_diagonal_penalties(&c_ups) {
                    // the factor is the checkpoint's now: refactor on the next sync
                    self.factor = None;
                    return Err(e.into());
                }
                self.updates_since_factor = c.updates_since_factor + c_ups.len();
                self.rank1_update_count += c_ups.len();
                self.restore_count += 1;
                self.dirty = Some(c_ups.iter().map(|&(e, _)| e).collect());
                self.factored_diag.copy_from_slice(diag);
                return Ok(());
            }
            let changes = ups.len() + downs.len();
            if changes <= limit && self.updates_since_factor + changes <= drift_limit {
                if downs.is_empty() {
                    self.save_checkpoint_before_adding(diag);
                }
                let factor = self.factor.as_mut().expect("checked");
                let mut dirty = self.dirty.take();
                factor.add_diagonal_penalties(&ups)?;
                if let Some(d) = &mut dirty {
                    d.extend(ups.iter().chain(&downs).map(|&(e, _)| e));
                }
                // a refused downdate leaves the factor as it was: refactor below
                if factor.remove_diagonal_penalties(&downs).is_ok() {
                    self.dirty = dirty;
                    self.updates_since_factor += changes;
                    self.rank1_update_count += changes;
                    self.factored_diag.copy_from_slice(diag);
                    return Ok(());
                }
            }
        }
        let mut a = base.clone();
        let values = a.values_mut();
        for (&p, &s) in self.diagonal_positions.iter().zip(diag) {
            values[p] += s;
        }
        // Stroke weights are of the order of the matrix diagonal (not 1e8 penalties), so a
        // downdate loses nothing measurable: skip the forced refinement step after one;
        // every solve still checks its residual and refines above 1e-11.
        let options =
            CholeskyOptions { refine_after_downdate: false, ..CholeskyOptions::default() };
        let mut factor = Cholesky::factor_with(&self.symbolic, &a)?.with_options(options);
        // take it over for updates now (the first solve would), so the checkpoint is too
        factor.prepare_updates()?;
        self.dirty = (limit > 0).then(Vec::new);
        match &mut self.checkpoint {
            // no updates allowed: no checkpoint either
            _ if limit == 0 => self.checkpoint = None,
            Some(c) => {
                c.factor.clone_from(&factor);
                c.diag.copy_from_slice(diag);
                c.updates_since_factor = 0;
            }
            None => {
                self.checkpoint = Some(Checkpoint {
                    factor: factor.clone(),
                    diag: diag.to_vec(),
                    updates_since_factor: 0,
                })
            }
        }
        self.factor = Some(factor);
        self.factored_diag.copy_from_slice(diag);
        self.refactor_count += 1;
        self.updates_since_factor = 0;
        Ok(())
    }

    /// Before an edit that only adds weight (`new_diag ≥` the current one), keeps a copy
    /// of the current factor as the checkpoint when the old checkpoint would not serve
    /// the edits that follow: it lies above the new diagonal somewhere, or more than
    /// [`RESTORE_COST`] edges behind the current factor (then undoing this edit from it
    /// would cost more than this copy).
    fn save_checkpoint_before_adding(&mut self, new_diag: &[f64]) {
        let Some(factor) = &self.factor else { return };
        let stale = match &self.checkpoint {
            None => true,
            Some(c) => {
                let behind = c.diag.iter().zip(&self.factored_diag).filter(|(a, b)| a != b).count();
                behind > RESTORE_COST || c.updates_to(new_diag).is_none()
            }
        };
        if !stale {
            return;
        }
        match &mut self.checkpoint {
            Some(c) => {
                copy_factor(&mut c.factor, factor, self.dirty.take());
                c.diag.copy_from_slice(&self.factored_diag);
                c.updates_since_factor = self.updates_since_factor;
            }
            None => {
                self.checkpoint = Some(Checkpoint {
                    factor: factor.clone(),
                    diag: self.factored_diag.clone(),
                    updates_since_factor: self.updates_since_factor,
                })
            }
        }
        self.dirty = Some(Vec::new());
    }
}

/// `*dst = src.clone()` into `dst`'s buffers: only the paths of the `dirty` edges when
/// they are known (the two factors differ nowhere else), else the whole factor.
fn copy_factor(dst: &mut Cholesky, src: &Cholesky, dirty: Option<Vec<usize>>) {
    match dirty {
        Some(edges) => {
            dst.copy_changed_from(src, &edges);
        }
        None => dst.clone_from(src),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 5-point Laplacian of a `side²` grid plus a small diagonal (SPD).
    fn grid(side: usize) -> SparseMatrix {
        let n = side * side;
        let mut t = Vec::new();
        for y in 0..side {
            for x in 0..side {
                let i = y * side + x;
                t.push((i, i, 1e-3));
                for j in [(x + 1 < side).then(|| i + 1), (y + 1 < side).then(|| i + side)]
                    .into_iter()
                    .flatten()
                {
                    t.extend([(i, i, 1.0), (j, j, 1.0), (i, j, -1.0), (j, i, -1.0)]);
                }
            }
        }
        SparseMatrix::from_triplets(n, n, &t).unwrap()
    }

    fn solution_bits(f: &DesignFactor, n: usize) -> Vec<u64> {
        let b: Vec<f64> = (0..n).map(|i| (i % 7) as f64 - 3.0).collect();
        f.factor().unwrap().solve(&b).unwrap().iter().map(|v| v.to_bits()).collect()
    }

    /// Copies of only the changed paths (the `dirty` edges) give the same factor, bit for
    /// bit, as full copies, through an edit sequence that takes every path: adds (direct
    /// updates, checkpoint saves), drags (restores plus an update), removals (restores)
    /// and direct downdates. (Checked by hand that it can fail: leaving the downdated
    /// edges out of `dirty` leaves a stale checkpoint, and the restore after "add near the
    /// shrink" then fails its residual check.)
    #[test]
    fn path_copies_equal_full_copies_through_stroke_edits() {
        let side = 40;
        let n = side * side;
        let base = grid(side);
        let stroke = |row: usize, len: usize, w: f64| {
            // two rows, like the ~4 edges per cell of a stroke on the field grid
            let mut d = vec![0.0; n];
            for x in 3..3 + len {
                d[row * side + x] = w;
                d[(row + 1) * side + x] = w;
            }
            d
        };
        let sum = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p + q).collect::<Vec<_>>();
        let zero = vec![0.0; n];
        let s1 = stroke(10, 34, 2.0);
        let s2 = stroke(25, 20, 1.5);
        let steps = [
            zero.clone(),
            s1.clone(),                     // add: direct update, checkpoint saved
            stroke(12, 34, 2.0),            // drag: restore + update
            stroke(14, 34, 2.0),            // drag again
            zero.clone(),                   // remove: restore
            s1.clone(),                     // add again
            sum(&s1, &s2),                  // a second stroke
            sum(&stroke(10, 32, 2.0), &s2), // shrink the first: direct downdate
            sum(&sum(&stroke(10, 32, 2.0), &s2), &stroke(35, 34, 1.0)), // add: save
            sum(&stroke(10, 32, 2.0), &s2), // remove it: restore
            sum(&sum(&stroke(10, 32, 2.0), &s2), &stroke(8, 36, 1.0)), // add near the shrink
            sum(&stroke(10, 32, 2.0), &s2), // remove it: restore
            sum(&s1, &s2),                  // grow the first back
            sum(&stroke(16, 34, 2.0), &s2), // drag the first
            s2.clone(),                     // remove the first
            sum(&s2, &stroke(30, 2, 0.5)),  // a short stroke
            stroke(25, 18, 1.5),            // shrink: direct downdate
            zero,
        ];
        let (mut paths, mut full) =
            (DesignFactor::new(&base).unwrap(), DesignFactor::new(&base).unwrap());
        for (k, diag) in steps.iter().enumerate() {
            paths.sync(&base, diag, 640).unwrap();
            full.dirty = None; // forces full copies
            full.sync(&base, diag, 640).unwrap();
            assert_eq!(paths.refactor_count, full.refactor_count, "step {k}");
            assert_eq!(paths.restore_count, full.restore_count, "step {k}");
            assert_eq!(solution_bits(&paths, n), solution_bits(&full, n), "step {k}");
        }
        assert!(paths.restore_count >= 5, "{} restores", paths.restore_count);
        assert_eq!(paths.refactor_count, 1);
    }
}
