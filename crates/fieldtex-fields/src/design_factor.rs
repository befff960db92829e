//! The kept factorisation of a field design's matrix `A₀ + diag(s)` (`A₀`: the
//! stroke-free design matrix, `s`: the summed stroke weights per edge, `#E`), brought up
//! to date after stroke edits by multiple-rank updates and downdates or by a numeric
//! refactorisation with the kept symbolic analysis.
//!
//! A stroke edit changes `A` by `Σ Δs_e e_e e_eᵀ`: the edges whose weight grows get one
//! multiple-rank update, those whose weight shrinks one multiple-rank downdate
//! (Davis & Hager 2001, "Multiple-rank modifications of a sparse Cholesky factorization",
//! via `fieldtex_linalg::Cholesky::add_diagonal_penalties`). The choice between that and a
//! refactorisation depends only on the number of changed edges (never on timings), so
//! the result of an edit sequence does not depend on the machine.
//!
//! Measured on the 128² grid of the interactive benchmark (49K unknowns, 2.3M factor
//! entries, 2 cores under a load average of ~2.7, `examples/bench_fields.rs`): a
//! multiple-rank update or downdate costs ~0.15–0.25 ms per changed edge, a numeric
//! refactorisation 80–150 ms; a ~250 px stroke changes ~250 edges when added or removed
//! and ~300–500 when dragged by a few pixels. Hence the default
//! [`crate::FieldDesignOptions::rank1_update_limit`] of 640 changed edges: additions,
//! removals and drags of such strokes are updated (add/remove + solve + 512² sampling
//! 55–90 ms, drag 75–125 ms, against 100–160 ms with a refactorisation), wholesale
//! changes refactored. Issue 3's 20 ms is out of reach for long strokes either way: the
//! update of `k` edges costs `k` sweeps over the factor columns on the edges'
//! elimination-tree paths, which for a 2-D grid always include the top separators
//! (dense blocks of a few hundred rows), ~0.2 ms per edge here.
//!
//! Not implemented: a Woodbury (capacitance-matrix) correction of the solve instead of a
//! factor modification: it needs `A⁻¹` at the stroke's ~250–500 edges, i.e. as many
//! solves (or sparse triangular solves on the factor, which `fieldtex-linalg` does not
//! expose), far more than the modification itself.

use fieldtex_linalg::{Cholesky, CholeskyOptions, SparseMatrix, SymbolicCholesky};

use crate::FieldsError;

/// Symbolic analysis, numeric factor and the stroke diagonal it was made with.
pub(crate) struct DesignFactor {
    symbolic: SymbolicCholesky,
    /// Numeric factor of `A₀ + diag(factored_diag)`; `None` until the first solve.
    factor: Option<Cholesky>,
    factored_diag: Vec<f64>,
    /// Position of `A₀[e][e]` in the values of `A₀` (refactorisations add `s` there).
    diagonal_positions: Vec<usize>,
    pub(crate) refactor_count: usize,
    pub(crate) rank1_update_count: usize,
    updates_since_factor: usize,
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
            diagonal_positions,
            refactor_count: 0,
            rank1_update_count: 0,
            updates_since_factor: 0,
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

    /// Drops the numeric factor; the next sync refactors.
    pub(crate) fn invalidate(&mut self) {
        self.factor = None;
    }

    /// Makes the factor one of `base + diag(diag)`. When the number of edges whose weight
    /// changed is at most `limit` (and fewer than `16 × limit` modifications have
    /// accumulated since the last factorisation, to bound rounding drift), the factor is
    /// updated and downdated; otherwise, or if a downdate is refused (it would leave the
    /// matrix indefinite: the factor is then unchanged), it is refactored.
    pub(crate) fn sync(
        &mut self,
        base: &SparseMatrix,
        diag: &[f64],
        limit: usize,
    ) -> Result<(), FieldsError> {
        if self.factor.is_some() && diag == self.factored_diag.as_slice() {
            return Ok(());
        }
        if let Some(factor) = self.factor.as_mut() {
            let (mut ups, mut downs) = (Vec::new(), Vec::new());
            for (e, (&new, &old)) in diag.iter().zip(&self.factored_diag).enumerate() {
                if new > old {
                    ups.push((e, new - old));
                } else if new < old {
                    downs.push((e, old - new));
                }
            }
            let changes = ups.len() + downs.len();
            if changes <= limit && self.updates_since_factor + changes <= 16 * limit {
                factor.add_diagonal_penalties(&ups)?;
                // a refused downdate leaves the factor as it was: refactor below
                if factor.remove_diagonal_penalties(&downs).is_ok() {
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
        self.factor = Some(Cholesky::factor_with(&self.symbolic, &a)?.with_options(options));
        self.factored_diag.copy_from_slice(diag);
        self.refactor_count += 1;
        self.updates_since_factor = 0;
        Ok(())
    }
}
