//! The public rank-1 update API of [`Cholesky`] (`update`, `downdate` and their helpers),
//! over the dynamic factor of the parent module (`cholesky_update.rs`), which holds the
//! storage, the in-place takeover of faer's factor and the sweep (Davis & Hager 1999).

use super::*;

impl Cholesky {
    /// Rank-1 modification of the factorisation: afterwards this factors `A + w wᵀ`
    /// ([`UpdateSign::Up`]) or `A − w wᵀ` ([`UpdateSign::Down`]). `w` is sparse as
    /// `(index, value)` pairs (duplicates summed, zeros ignored). Solves and their
    /// residual checks use the modified matrix. The first call takes over faer's factor
    /// in place (builds a row-index array, ~50 ms at 200K unknowns). Cost: the stored
    /// entries of the factor columns on the elimination-tree path from the first nonzero
    /// of `w` (~0.5 M entries, ~1 ms at 200K unknowns), see [`Cholesky::update_path_cost`].
    ///
    /// Errors: index out of range or non-finite value ([`LinalgError::IndexOutOfRange`],
    /// [`LinalgError::NonFinite`]); a downdate that leaves the matrix indefinite
    /// ([`LinalgError::UpdateFailed`], factor and matrix unchanged).
    pub fn update(&mut self, w: &[(usize, f64)], sign: UpdateSign) -> Result<(), LinalgError> {
        let n = self.size();
        for (index, &(i, v)) in w.iter().enumerate() {
            if i >= n {
                return Err(LinalgError::IndexOutOfRange { row: i, col: 0, nrows: n, ncols: 1 });
            }
            if !v.is_finite() {
                return Err(LinalgError::NonFinite { what: "rank-1 update vector", index });
            }
        }
        let mut merged: Vec<(usize, f64)> = w.to_vec();
        merged.sort_by_key(|&(i, _)| i);
        merged.dedup_by(|b, a| {
            if a.0 == b.0 {
                a.1 += b.1;
                true
            } else {
                false
            }
        });
        merged.retain(|&(_, v)| v != 0.0);
        if merged.is_empty() {
            return Ok(());
        }
        if let Some(index) = merged.iter().position(|&(_, v)| !(v * v).is_finite()) {
            return Err(LinalgError::NonFinite {
                what: "rank-1 update vector (square overflows)",
                index,
            });
        }
        let dynamic = self.ensure_dynamic()?;
        let permuted: Vec<(usize, f64)> =
            merged.iter().map(|&(i, v)| (dynamic.inv[i], v)).collect();
        let up = sign == UpdateSign::Up;
        dynamic.update(&permuted, up).map_err(|(j, reason)| LinalgError::UpdateFailed {
            kind: if up { "update" } else { "downdate" },
            column: dynamic.perm[j],
            reason,
        })?;
        self.downdated |= !up;
        // keep the matrix used by residual checks current
        let s = if up { 1.0 } else { -1.0 };
        let positions: Option<Vec<usize>> = merged
            .iter()
            .flat_map(|&(i, _)| merged.iter().map(move |&(j, _)| (i, j)))
            .map(|(i, j)| self.matrix.find(i, j))
            .collect();
        match positions {
            Some(pos) => {
                let vals = self.matrix.values_mut();
                let mut k = 0;
                for &(_, a) in &merged {
                    for &(_, b) in &merged {
                        vals[pos[k]] += s * a * b;
                        k += 1;
                    }
                }
            }
            None => self.extra_terms.push((merged, s)),
        }
        Ok(())
    }

    /// The updatable factor, taking over faer's factor on first use (needs `n < 2³²`).
    pub(crate) fn ensure_dynamic(&mut self) -> Result<&mut DynamicFactor, LinalgError> {
        if self.dynamic.is_none() {
            let n = self.size();
            if n >= u32::MAX as usize {
                return Err(LinalgError::Dimension {
                    what: "rank-1 updates support n < 2³²",
                    expected: u32::MAX as usize - 1,
                    found: n,
                });
            }
            let (sym, values) = self.take_faer_values();
            self.dynamic = Some(DynamicFactor::from_faer(sym, values));
        }
        Ok(self.dynamic.as_mut().expect("created above"))
    }

    /// Takes the factor over for updates now (row indices and runs beside faer's
    /// values, ~50–90 ms at 200K unknowns) instead of in the first update, so that a
    /// caller who will update can count that cost with the factorisation. Solves keep
    /// working. Idempotent.
    pub fn prepare_updates(&mut self) -> Result<(), LinalgError> {
        self.ensure_dynamic().map(|_| ())
    }

    /// Adds the penalty `α eᵢ eᵢᵀ` (a soft constraint on unknown `i`); `α` finite, > 0.
    pub fn add_diagonal_penalty(&mut self, i: usize, alpha: f64) -> Result<(), LinalgError> {
        check_alpha(alpha)?;
        self.update(&[(i, alpha.sqrt())], UpdateSign::Up)
    }

    /// Removes a penalty added by [`Cholesky::add_diagonal_penalty`] (a downdate).
    pub fn remove_diagonal_penalty(&mut self, i: usize, alpha: f64) -> Result<(), LinalgError> {
        check_alpha(alpha)?;
        self.update(&[(i, alpha.sqrt())], UpdateSign::Down)
    }

    /// Cost of a single-entry update at unknown `i` (e.g. a penalty): the number of
    /// factor columns on its elimination-tree path and their stored entries. `None`
    /// before the first update (the simplicial copy does not exist yet) or if `i` is out
    /// of range.
    pub fn update_path_cost(&self, i: usize) -> Option<(usize, usize)> {
        let d = self.dynamic.as_ref()?;
        (i < d.n()).then(|| d.path_cost(d.inv[i]))
    }

    /// Columns and stored entries on the union of the elimination-tree paths of `indices`
    /// (original numbering; out-of-range indices are ignored): the cost of a multiple-rank
    /// update at those unknowns, or of a sparse triangular solve reaching them. `None`
    /// before the first update.
    pub fn union_path_cost(&self, indices: &[usize]) -> Option<(usize, usize)> {
        let d = self.dynamic.as_ref()?;
        let mut seen = vec![false; d.n()];
        let (mut cols, mut entries) = (0, 0);
        for &i in indices.iter().filter(|&&i| i < d.n()) {
            let mut j = d.inv[i];
            while j != NONE && !seen[j] {
                seen[j] = true;
                cols += 1;
                entries += d.len[j];
                j = d.parent[j];
            }
        }
        Some((cols, entries))
    }

    /// Whether the factor has been taken over for rank-1 updates.
    pub fn is_updated(&self) -> bool {
        self.dynamic.is_some()
    }

    /// Stored entries of the updatable factor (`None` before the first update).
    pub fn updated_factor_nnz(&self) -> Option<usize> {
        self.dynamic.as_ref().map(DynamicFactor::nnz)
    }
}
