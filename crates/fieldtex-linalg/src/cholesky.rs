//! Sparse Cholesky `A = P⁻¹ L Lᵀ P` of a symmetric positive definite matrix, on faer.
//!
//! - **Ordering**: approximate minimum degree (AMD; Amestoy, Davis & Duff 1996) computed
//!   by faer, then faer's supernodal (or, for very sparse factors, simplicial) symbolic
//!   analysis (George & Liu 1981, "Computer Solution of Large Sparse Positive Definite
//!   Systems"). [`SymbolicCholesky`] holds both and is reused by
//!   [`Cholesky::factor_with`] for matrices with the same pattern (e.g. the same mesh with
//!   new weights or a new penalty diagonal).
//! - **Input**: a full symmetric `n × n` [`SparseMatrix`] (both triangles stored). Only
//!   the lower triangle is factored; the whole matrix is used for residuals, so the two
//!   triangles are checked to agree (relative `1e-10`).
//! - **Residual check**: every solve computes `‖A x − b‖₂ / ‖b‖₂` with the *current*
//!   matrix (including rank-1 updates). If it exceeds
//!   [`CholeskyOptions::refine_above`], up to [`CholeskyOptions::max_refinement_steps`]
//!   steps of iterative refinement (`x += A⁻¹ (b − A x)` with the same factor) are taken;
//!   if it still exceeds [`CholeskyOptions::residual_tolerance`] the solve fails with
//!   [`LinalgError::SolveFailed`]. `b = 0` gives `x = 0` with residual 0. Once the
//!   factor has been downdated one refinement step is always taken
//!   ([`CholeskyOptions::refine_after_downdate`]).
//! - **Parallelism**: the numeric factorisation uses faer with the current rayon pool.
//!   Solves run faer's triangular solves with `Par::Seq` (faer's multi-RHS supernodal
//!   solve under `Par::Rayon` is 6–10× slower, DEPENDENCIES.md);
//!   [`Cholesky::solve_many`] solves up to 8 right-hand sides in one pass over the factor
//!   (`crate::multi_rhs_solve`), larger sets in parallel blocks.
//! - Not implemented: `LDLᵀ` / indefinite matrices, regularisation of singular matrices
//!   (a singular or indefinite matrix is a [`LinalgError::FactorizationFailed`]).

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky as fc;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use crate::cholesky_update::DynamicFactor;
use crate::{LinalgError, SparseMatrix};

/// Tolerances of the residual check done by every solve.
#[derive(Clone, Debug, PartialEq)]
pub struct CholeskyOptions {
    /// Largest accepted relative residual `‖A x − b‖ / ‖b‖`. Default `1e-8`: a backward
    /// stable Cholesky solve of a penalty system (Laplacian + `α = 1e8` diagonal, condition
    /// number ~1e12) gives ~1e-14…1e-11; `1e-8` leaves room for worse conditioning while
    /// still catching singular factors and asymmetric input.
    pub residual_tolerance: f64,
    /// Iterative refinement is tried when the residual exceeds this. Default `1e-11`.
    pub refine_above: f64,
    /// Most refinement steps per solve (each costs one solve and one product). Default 2.
    pub max_refinement_steps: usize,
    /// Always take one refinement step once the factor has been downdated
    /// ([`crate::UpdateSign::Down`]). Default `true`: removing a penalty `α` by a
    /// downdate leaves an error ~`ε α` in the factor, which cost ~1e-9 relative accuracy
    /// in the solution of a grid test without refinement and ~1e-15 with it.
    pub refine_after_downdate: bool,
}

impl Default for CholeskyOptions {
    fn default() -> Self {
        Self {
            residual_tolerance: 1e-8,
            refine_above: 1e-11,
            max_refinement_steps: 2,
            refine_after_downdate: true,
        }
    }
}

struct SymbolicInner {
    faer: fc::SymbolicCholesky<usize>,
    /// Pattern of the analysed matrix, to refuse numeric factorisations of another one.
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
}

/// Fill-reducing ordering plus symbolic factorisation of a symmetric sparsity pattern;
/// cheap to clone (shared), reusable for every matrix with exactly this pattern.
#[derive(Clone)]
pub struct SymbolicCholesky {
    inner: Arc<SymbolicInner>,
}

impl std::fmt::Debug for SymbolicCholesky {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SymbolicCholesky")
            .field("size", &self.size())
            .field("factor_nnz", &self.factor_nnz())
            .finish()
    }
}

/// Storage layout of the factor chosen at symbolic analysis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FactorLayout {
    /// faer decides from the estimated flop count (simplicial for very sparse factors).
    #[default]
    Auto,
    /// Column-by-column factor.
    Simplicial,
    /// Dense supernodal blocks (fast for mesh-sized systems).
    Supernodal,
}

impl SymbolicCholesky {
    /// AMD ordering + symbolic analysis of the pattern of `a` (square; values ignored).
    pub fn analyze(a: &SparseMatrix) -> Result<Self, LinalgError> {
        Self::analyze_with(a, FactorLayout::Auto)
    }

    /// As [`SymbolicCholesky::analyze`], with a forced factor layout.
    pub fn analyze_with(a: &SparseMatrix, layout: FactorLayout) -> Result<Self, LinalgError> {
        let threshold = match layout {
            FactorLayout::Auto => SupernodalThreshold::AUTO,
            FactorLayout::Simplicial => SupernodalThreshold::FORCE_SIMPLICIAL,
            FactorLayout::Supernodal => SupernodalThreshold::FORCE_SUPERNODAL,
        };
        Self::analyze_ordered(a, threshold, fc::SymmetricOrdering::Amd)
    }

    /// As [`SymbolicCholesky::analyze_with`], with a given fill-reducing ordering
    /// instead of AMD: `perm[k]` = original index of the `k`-th eliminated unknown (a
    /// permutation of `0..n`, else [`LinalgError::InvalidArgument`]). `Auto` means
    /// supernodal here (faer cannot estimate the flops of a given ordering).
    pub fn analyze_with_ordering(
        a: &SparseMatrix,
        layout: FactorLayout,
        perm: &[usize],
    ) -> Result<Self, LinalgError> {
        let n = check_square(a)?;
        LinalgError::check_len("ordering length", n, perm.len())?;
        let mut inv = vec![usize::MAX; n];
        for (k, &i) in perm.iter().enumerate() {
            if i >= n || inv[i] != usize::MAX {
                return Err(LinalgError::InvalidArgument {
                    what: "ordering entry",
                    value: i as f64,
                    reason: "the ordering must be a permutation of 0..n",
                });
            }
            inv[i] = k;
        }
        let threshold = match layout {
            FactorLayout::Auto | FactorLayout::Supernodal => SupernodalThreshold::FORCE_SUPERNODAL,
            FactorLayout::Simplicial => SupernodalThreshold::FORCE_SIMPLICIAL,
        };
        let ordering = faer::perm::PermRef::new_checked(perm, &inv, n);
        Self::analyze_ordered(a, threshold, fc::SymmetricOrdering::Custom(ordering))
    }

    fn analyze_ordered(
        a: &SparseMatrix,
        threshold: SupernodalThreshold,
        ordering: fc::SymmetricOrdering<'_, usize>,
    ) -> Result<Self, LinalgError> {
        let n = check_square(a)?;
        let params = fc::CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: threshold,
            ..Default::default()
        };
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, a.col_ptr(), None, a.row_idx());
        let faer = fc::factorize_symbolic_cholesky(pattern, Side::Lower, ordering, params)
            .map_err(|e| LinalgError::FactorizationFailed {
                size: n,
                reason: format!("symbolic analysis failed: {e:?}"),
            })?;
        Ok(Self {
            inner: Arc::new(SymbolicInner {
                faer,
                col_ptr: a.col_ptr().to_vec(),
                row_idx: a.row_idx().to_vec(),
            }),
        })
    }

    /// Matrix size `n`.
    pub fn size(&self) -> usize {
        self.inner.col_ptr.len() - 1
    }

    /// Whether faer chose (or was told to use) the supernodal layout.
    pub fn is_supernodal(&self) -> bool {
        matches!(self.inner.faer.raw(), fc::SymbolicCholeskyRaw::Supernodal(_))
    }

    /// Stored entries of the factor `L` (supernodal storage counts whole blocks).
    pub fn factor_nnz(&self) -> usize {
        self.inner.faer.len_val()
    }

    /// `perm[k]` = original index of the `k`-th eliminated unknown (identity if none).
    pub fn permutation(&self) -> Vec<usize> {
        match self.inner.faer.perm() {
            Some(p) => p.arrays().0.to_vec(),
            None => (0..self.size()).collect(),
        }
    }

    fn check_pattern(&self, a: &SparseMatrix) -> Result<(), LinalgError> {
        let n = check_square(a)?;
        LinalgError::check_len("matrix size vs symbolic analysis", self.size(), n)?;
        if a.col_ptr() != self.inner.col_ptr.as_slice() {
            return Err(LinalgError::PatternMismatch { what: "column counts differ" });
        }
        if a.row_idx() != self.inner.row_idx.as_slice() {
            return Err(LinalgError::PatternMismatch { what: "row indices differ" });
        }
        Ok(())
    }
}

/// Numeric Cholesky factorisation of a symmetric positive definite matrix; keeps a copy
/// of the matrix for residual checks. Rank-1 updates modify the factor in place (see
/// [`Cholesky::update`]).
pub struct Cholesky {
    symbolic: SymbolicCholesky,
    /// faer's factor values (supernodal or simplicial layout); moved into `dynamic` by
    /// the first rank-1 update.
    values: Vec<f64>,
    /// Updatable factor (faer's values taken over), created by the first rank-1 update.
    pub(crate) dynamic: Option<DynamicFactor>,
    /// The factored matrix, kept current under rank-1 updates whose pattern it holds.
    pub(crate) matrix: SparseMatrix,
    /// Rank-1 terms `sign · w wᵀ` whose pattern is not in `matrix`.
    pub(crate) extra_terms: Vec<(Vec<(usize, f64)>, f64)>,
    /// Whether a downdate has been applied (see [`CholeskyOptions::refine_after_downdate`]).
    pub(crate) downdated: bool,
    options: CholeskyOptions,
    last_residual: AtomicU64,
}

impl Clone for Cholesky {
    fn clone(&self) -> Self {
        Self {
            symbolic: self.symbolic.clone(),
            values: self.values.clone(),
            dynamic: self.dynamic.clone(),
            matrix: self.matrix.clone(),
            extra_terms: self.extra_terms.clone(),
            downdated: self.downdated,
            options: self.options.clone(),
            last_residual: AtomicU64::new(self.last_residual.load(Ordering::Relaxed)),
        }
    }

    /// `*self = src.clone()`, reusing `self`'s buffers when both are updatable factors of
    /// the same matrix pattern, ordering and options: a memory copy instead of fresh
    /// allocations, whose page faults made a clone of the 2.3M-entry field-design factor
    /// cost 12–55 ms on a loaded machine (4–13 ms this way). Otherwise a clone.
    fn clone_from(&mut self, src: &Self) {
        let compatible = match (&self.dynamic, &src.dynamic) {
            (Some(d), Some(s)) => {
                d.perm == s.perm
                    && self.options == src.options
                    && self.symbolic.factor_nnz() == src.symbolic.factor_nnz()
                    && self.matrix.col_ptr() == src.matrix.col_ptr()
                    && self.matrix.row_idx() == src.matrix.row_idx()
            }
            _ => false,
        };
        if !compatible {
            *self = src.clone();
            return;
        }
        let (d, s) = (self.dynamic.as_mut(), src.dynamic.as_ref());
        d.expect("checked").copy_same_pattern_from(s.expect("checked"));
        // same pattern (checked above): the values only
        self.matrix.values_mut().copy_from_slice(src.matrix.values());
        self.extra_terms.clone_from(&src.extra_terms);
        self.downdated = src.downdated;
        self.last_residual.store(src.last_residual.load(Ordering::Relaxed), Ordering::Relaxed);
    }
}

impl Cholesky {
    /// Makes `self` equal to `src` (as [`Clone::clone_from`] would) by copying only what
    /// can differ, **given** that the two were equal (a clone or `clone_from` of each
    /// other, or of the same factor) and that since then each received only diagonal
    /// modifications ([`Cholesky::add_diagonal_penalties`],
    /// [`Cholesky::remove_diagonal_penalties`], [`Cholesky::add_diagonal_penalty`]) at
    /// the indices in `changed` (repeats allowed). A diagonal modification of index `i`
    /// changes only the factor columns on the elimination-tree path from `i` to the root
    /// (it creates no fill), so only those columns and the matrix diagonal at `changed`
    /// are copied: for a stroke of ~250 edges on the 128² field-design grid that is a
    /// fraction of the 2.3M-entry factor. Falls back to [`Clone::clone_from`] when the
    /// factors are not both updatable factors with the same layout. Returns the number
    /// of factor values copied.
    ///
    /// The caller is responsible for the precondition: columns off those paths are not
    /// compared (that would cost as much as the copy).
    pub fn copy_changed_from(&mut self, src: &Self, changed: &[usize]) -> usize {
        let n = self.size();
        let compatible = match (&self.dynamic, &src.dynamic) {
            // one analysis (checked at factorisation against the matrix pattern): same
            // ordering and matrix pattern, without comparing the 3 MB of indices
            (Some(_), Some(_)) => {
                Arc::ptr_eq(&self.symbolic.inner, &src.symbolic.inner)
                    && self.options == src.options
                    && changed.iter().all(|&i| i < n)
            }
            _ => false,
        };
        let copied = if compatible {
            let (d, s) =
                (self.dynamic.as_mut().expect("checked"), src.dynamic.as_ref().expect("checked"));
            let from: Vec<usize> = changed.iter().map(|&i| s.inv[i]).collect();
            d.copy_paths_from(s, &from)
        } else {
            None
        };
        let Some(copied) = copied else {
            self.clone_from(src);
            return self.dynamic.as_ref().map_or(self.values.len(), |d| d.values().len());
        };
        let (dst, from) = (self.matrix.values_mut(), src.matrix.values());
        for &i in changed {
            // a diagonal modification changed `A[i][i]` (stored) or an extra term
            if let Some(p) = src.matrix.find(i, i) {
                dst[p] = from[p];
            }
        }
        self.extra_terms.clone_from(&src.extra_terms);
        self.downdated = src.downdated;
        self.last_residual.store(src.last_residual.load(Ordering::Relaxed), Ordering::Relaxed);
        copied
    }
}

impl std::fmt::Debug for Cholesky {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Cholesky")
            .field("size", &self.size())
            .field("updated", &self.dynamic.is_some())
            .field("last_residual", &self.last_residual())
            .finish()
    }
}

impl Cholesky {
    /// Symbolic analysis + numeric factorisation of `a` (full symmetric, SPD).
    pub fn factor(a: &SparseMatrix) -> Result<Self, LinalgError> {
        let symbolic = SymbolicCholesky::analyze(a)?;
        Self::factor_with(&symbolic, a)
    }

    /// Numeric factorisation reusing `symbolic`, which must have been made for a matrix
    /// with exactly the pattern of `a` ([`LinalgError::PatternMismatch`] otherwise).
    pub fn factor_with(symbolic: &SymbolicCholesky, a: &SparseMatrix) -> Result<Self, LinalgError> {
        symbolic.check_pattern(a)?;
        let n = a.nrows();
        if let Some(index) = a.first_non_finite() {
            return Err(LinalgError::NonFinite { what: "matrix value", index });
        }
        if let Some((row, col, value, mirror)) = a.first_asymmetry(1e-10) {
            return Err(LinalgError::NotSymmetric { row, col, value, mirror });
        }
        let fsym = &symbolic.inner.faer;
        let mut values = vec![0.0f64; fsym.len_val()];
        if n > 0 {
            let par = Par::rayon(0);
            let mat = SparseColMatRef::new(
                SymbolicSparseColMatRef::new_checked(n, n, a.col_ptr(), None, a.row_idx()),
                a.values(),
            );
            let mut mem = MemBuffer::try_new(
                fsym.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
            )
            .map_err(|_| failed(n, "out of memory for the factorisation workspace".into()))?;
            fsym.factorize_numeric_llt(
                &mut values,
                mat,
                Side::Lower,
                LltRegularization::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|e| {
                let faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index } = e;
                let original = symbolic.permutation().get(index).copied().unwrap_or(index);
                failed(
                    n,
                    format!(
                        "pivot {index} (original row {original}) is not positive: the matrix is not positive definite"
                    ),
                )
            })?;
            if let Some(k) = values.iter().position(|v| !v.is_finite()) {
                return Err(failed(n, format!("factor entry {k} is not finite (overflow)")));
            }
        }
        Ok(Self {
            symbolic: symbolic.clone(),
            values,
            dynamic: None,
            matrix: a.clone(),
            extra_terms: Vec::new(),
            downdated: false,
            options: CholeskyOptions::default(),
            last_residual: AtomicU64::new(0f64.to_bits()),
        })
    }

    /// Replaces the residual-check options (see [`CholeskyOptions`]).
    pub fn with_options(mut self, options: CholeskyOptions) -> Self {
        self.options = options;
        self
    }

    pub fn options(&self) -> &CholeskyOptions {
        &self.options
    }

    /// Matrix size `n`.
    pub fn size(&self) -> usize {
        self.matrix.nrows()
    }

    /// The symbolic analysis this factor was built with.
    pub fn symbolic(&self) -> &SymbolicCholesky {
        &self.symbolic
    }

    /// The matrix currently factored, rank-1 updates included (materialised).
    pub fn current_matrix(&self) -> SparseMatrix {
        let mut m = self.matrix.clone();
        for (w, sign) in &self.extra_terms {
            let t: Vec<_> =
                w.iter().flat_map(|&(i, a)| w.iter().map(move |&(j, b)| (i, j, a * b))).collect();
            let outer = SparseMatrix::from_triplets(m.nrows(), m.ncols(), &t)
                .expect("rank-1 terms were validated when added");
            m = m.add_scaled(&outer, *sign);
        }
        m
    }

    /// Largest relative residual `‖A x − b‖ / ‖b‖` of the most recent successful solve
    /// (over all right-hand sides of [`Cholesky::solve_many`]); 0 before any solve.
    pub fn last_residual(&self) -> f64 {
        f64::from_bits(self.last_residual.load(Ordering::Relaxed))
    }

    /// Solves `A x = b`, checking the residual (see the module docs).
    pub fn solve(&self, b: &[f64]) -> Result<Vec<f64>, LinalgError> {
        let (x, r) = self.solve_with_residual(b)?;
        self.last_residual.store(r.to_bits(), Ordering::Relaxed);
        Ok(x)
    }

    /// Solves `A x = b` and returns `x` with its relative residual.
    pub fn solve_with_residual(&self, b: &[f64]) -> Result<(Vec<f64>, f64), LinalgError> {
        let n = self.size();
        LinalgError::check_len("right-hand side", n, b.len())?;
        let (x, rel) = self.solve_block(b, 1)?;
        Ok((x, rel[0]))
    }

    pub(crate) fn store_last_residual(&self, r: f64) {
        self.last_residual.store(r.to_bits(), Ordering::Relaxed);
    }

    /// `X ← A⁻¹ X` for a column-major `n × k` block with the current factor, no checks:
    /// one forward and one backward pass over the factor for all `k` columns.
    pub(crate) fn raw_solve_block_in_place(&self, x: &mut [f64], k: usize) {
        let n = self.size();
        if n == 0 || k == 0 {
            return;
        }
        let values = match &self.dynamic {
            Some(d) if d.has_supernodal_layout() && k <= 8 => {
                d.solve_supernodal_in_place(x, k);
                return;
            }
            Some(d) if !d.faer_layout => {
                d.solve_block_in_place(x, k);
                return;
            }
            Some(d) => &d.values()[..self.symbolic.inner.faer.len_val()],
            None => &self.values[..],
        };
        let fsym = &self.symbolic.inner.faer;
        let llt = fc::LltRef::new(fsym, values);
        let mut mem = MemBuffer::new(fsym.solve_in_place_scratch::<f64>(k, Par::Seq));
        let rhs = MatMut::from_column_major_slice_mut(x, n, k);
        llt.solve_in_place_with_conj(Conj::No, rhs, Par::Seq, MemStack::new(&mut mem));
    }

    /// faer's symbolic structure and (moved-out) values, for the updatable factor.
    pub(crate) fn take_faer_values(&mut self) -> (&fc::SymbolicCholesky<usize>, Vec<f64>) {
        (&self.symbolic.inner.faer, std::mem::take(&mut self.values))
    }
}

pub(crate) fn failed(size: usize, reason: String) -> LinalgError {
    LinalgError::FactorizationFailed { size, reason }
}

fn check_square(a: &SparseMatrix) -> Result<usize, LinalgError> {
    LinalgError::check_len("Cholesky needs a square matrix (columns)", a.nrows(), a.ncols())?;
    Ok(a.nrows())
}

/// Euclidean norm, sequential (deterministic) and scaled against overflow.
pub(crate) fn norm2(v: &[f64]) -> f64 {
    let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return scale;
    }
    let s: f64 = v.iter().map(|x| (x / scale) * (x / scale)).sum();
    scale * s.sqrt()
}
