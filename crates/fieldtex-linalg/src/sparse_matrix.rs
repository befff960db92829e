//! Compressed-sparse-column matrix of `f64`.
//!
//! Invariants (kept by every constructor): `col_ptr.len() == ncols + 1`, row indices
//! inside each column strictly increasing (sorted, no duplicates), every value finite
//! at construction. Explicit zeros may be stored (they are kept so that patterns stay
//! stable across refactorisations).

use rayon::prelude::*;

use crate::LinalgError;

/// A sparse `nrows × ncols` matrix in compressed sparse column form.
#[derive(Clone, Debug, PartialEq)]
pub struct SparseMatrix {
    nrows: usize,
    ncols: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
}

/// Columns per parallel chunk in column-parallel kernels (fixed, so results do not
/// depend on the thread count).
const COL_CHUNK: usize = 2048;

impl SparseMatrix {
    /// Builds a matrix from `(row, col, value)` triplets; duplicate entries are summed
    /// (in input order, so the result is deterministic). Errors on an index out of
    /// range or a non-finite value. Entries that sum to zero are kept as explicit zeros.
    pub fn from_triplets(
        nrows: usize,
        ncols: usize,
        triplets: &[(usize, usize, f64)],
    ) -> Result<Self, LinalgError> {
        for (index, &(row, col, value)) in triplets.iter().enumerate() {
            if row >= nrows || col >= ncols {
                return Err(LinalgError::IndexOutOfRange { row, col, nrows, ncols });
            }
            if !value.is_finite() {
                return Err(LinalgError::NonFinite { what: "triplet value", index });
            }
        }
        // Two stable counting sorts: by row, then by column. Afterwards rows are
        // ascending inside each column and duplicates are adjacent, in input order.
        let mut row_ptr = vec![0usize; nrows + 1];
        for &(r, _, _) in triplets {
            row_ptr[r + 1] += 1;
        }
        for i in 0..nrows {
            row_ptr[i + 1] += row_ptr[i];
        }
        let mut by_row = vec![0usize; triplets.len()];
        let mut next = row_ptr.clone();
        for (t, &(r, _, _)) in triplets.iter().enumerate() {
            by_row[next[r]] = t;
            next[r] += 1;
        }
        let mut col_count = vec![0usize; ncols + 1];
        for &(_, c, _) in triplets {
            col_count[c + 1] += 1;
        }
        for j in 0..ncols {
            col_count[j + 1] += col_count[j];
        }
        let mut by_col = vec![0usize; triplets.len()];
        let mut next = col_count.clone();
        for &t in &by_row {
            let c = triplets[t].1;
            by_col[next[c]] = t;
            next[c] += 1;
        }
        let mut col_ptr = Vec::with_capacity(ncols + 1);
        let mut row_idx = Vec::with_capacity(triplets.len());
        let mut values = Vec::with_capacity(triplets.len());
        col_ptr.push(0);
        for j in 0..ncols {
            let start = row_idx.len();
            for &t in &by_col[col_count[j]..col_count[j + 1]] {
                let (r, _, v) = triplets[t];
                if row_idx.len() > start && *row_idx.last().unwrap() == r {
                    *values.last_mut().unwrap() += v;
                } else {
                    row_idx.push(r);
                    values.push(v);
                }
            }
            col_ptr.push(row_idx.len());
        }
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            return Err(LinalgError::NonFinite { what: "summed triplet value (overflow)", index });
        }
        Ok(Self { nrows, ncols, col_ptr, row_idx, values })
    }

    /// Builds a matrix from raw CSC arrays, validating every invariant (column pointers
    /// monotone, rows in range and strictly increasing per column, values finite).
    pub fn from_csc(
        nrows: usize,
        ncols: usize,
        col_ptr: Vec<usize>,
        row_idx: Vec<usize>,
        values: Vec<f64>,
    ) -> Result<Self, LinalgError> {
        LinalgError::check_len("CSC column pointers", ncols + 1, col_ptr.len())?;
        let nnz = *col_ptr.last().unwrap();
        if col_ptr[0] != 0 || row_idx.len() != nnz || values.len() != nnz {
            return Err(LinalgError::Dimension {
                what: "CSC row indices/values",
                expected: nnz,
                found: row_idx.len().min(values.len()),
            });
        }
        for j in 0..ncols {
            if col_ptr[j] > col_ptr[j + 1] {
                return Err(LinalgError::Dimension {
                    what: "CSC column pointers must be non-decreasing",
                    expected: col_ptr[j],
                    found: col_ptr[j + 1],
                });
            }
            let rows = &row_idx[col_ptr[j]..col_ptr[j + 1]];
            for (k, &r) in rows.iter().enumerate() {
                if r >= nrows || (k > 0 && rows[k - 1] >= r) {
                    return Err(LinalgError::IndexOutOfRange { row: r, col: j, nrows, ncols });
                }
            }
        }
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            return Err(LinalgError::NonFinite { what: "CSC value", index });
        }
        Ok(Self { nrows, ncols, col_ptr, row_idx, values })
    }

    /// The `n × n` identity.
    pub fn identity(n: usize) -> Self {
        Self::from_diagonal(&vec![1.0; n])
    }

    /// A square diagonal matrix (zeros on `d` are stored explicitly).
    pub fn from_diagonal(d: &[f64]) -> Self {
        let n = d.len();
        Self {
            nrows: n,
            ncols: n,
            col_ptr: (0..=n).collect(),
            row_idx: (0..n).collect(),
            values: d.to_vec(),
        }
    }

    pub fn nrows(&self) -> usize {
        self.nrows
    }
    pub fn ncols(&self) -> usize {
        self.ncols
    }
    /// Number of stored entries (explicit zeros included).
    pub fn nnz(&self) -> usize {
        self.values.len()
    }
    /// Column pointers, length `ncols + 1`.
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }
    /// Row index of each stored entry (ascending inside each column).
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }
    /// Value of each stored entry.
    pub fn values(&self) -> &[f64] {
        &self.values
    }
    /// Mutable values (the pattern stays fixed): refill a matrix and refactor it with
    /// the same [`crate::SymbolicCholesky`].
    pub fn values_mut(&mut self) -> &mut [f64] {
        &mut self.values
    }

    /// Position in `values` of entry `(i, j)`, if stored.
    pub fn find(&self, i: usize, j: usize) -> Option<usize> {
        if j >= self.ncols {
            return None;
        }
        let (a, b) = (self.col_ptr[j], self.col_ptr[j + 1]);
        self.row_idx[a..b].binary_search(&i).ok().map(|k| a + k)
    }

    /// Entry `(i, j)`; zero when not stored or out of range.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.find(i, j).map_or(0.0, |k| self.values[k])
    }

    /// All stored entries as `(row, col, value)`, column by column.
    pub fn triplets(&self) -> Vec<(usize, usize, f64)> {
        let mut out = Vec::with_capacity(self.nnz());
        for j in 0..self.ncols {
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                out.push((self.row_idx[k], j, self.values[k]));
            }
        }
        out
    }

    /// The diagonal (length `min(nrows, ncols)`), zeros where not stored.
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.nrows.min(self.ncols)).map(|i| self.get(i, i)).collect()
    }

    /// `y = A x`. Panics if `x.len() != ncols` (programmer error).
    pub fn mul_vec(&self, x: &[f64]) -> Vec<f64> {
        assert_eq!(x.len(), self.ncols, "SparseMatrix::mul_vec: x has the wrong length");
        let mut y = vec![0.0; self.nrows];
        for (j, &xj) in x.iter().enumerate() {
            if xj == 0.0 {
                continue;
            }
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                y[self.row_idx[k]] += self.values[k] * xj;
            }
        }
        y
    }

    /// `y = Aᵀ x`, parallel over columns (each output is a fixed-order dot product).
    /// Panics if `x.len() != nrows`.
    pub fn transpose_mul_vec(&self, x: &[f64]) -> Vec<f64> {
        assert_eq!(x.len(), self.nrows, "SparseMatrix::transpose_mul_vec: x has the wrong length");
        let mut y = vec![0.0; self.ncols];
        y.par_chunks_mut(COL_CHUNK).enumerate().for_each(|(c, chunk)| {
            for (o, yj) in chunk.iter_mut().enumerate() {
                let j = c * COL_CHUNK + o;
                let mut s = 0.0;
                for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                    s += self.values[k] * x[self.row_idx[k]];
                }
                *yj = s;
            }
        });
        y
    }

    /// `Aᵀ` (rows stay sorted).
    pub fn transpose(&self) -> SparseMatrix {
        let mut row_ptr = vec![0usize; self.nrows + 1];
        for &r in &self.row_idx {
            row_ptr[r + 1] += 1;
        }
        for i in 0..self.nrows {
            row_ptr[i + 1] += row_ptr[i];
        }
        let mut next = row_ptr.clone();
        let mut cols = vec![0usize; self.nnz()];
        let mut vals = vec![0.0; self.nnz()];
        for j in 0..self.ncols {
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                let r = self.row_idx[k];
                cols[next[r]] = j;
                vals[next[r]] = self.values[k];
                next[r] += 1;
            }
        }
        SparseMatrix {
            nrows: self.ncols,
            ncols: self.nrows,
            col_ptr: row_ptr,
            row_idx: cols,
            values: vals,
        }
    }

    /// `A B` (Gustavson's column-by-column product, parallel over fixed column chunks).
    /// Panics if `self.ncols != b.nrows`.
    pub fn mul(&self, b: &SparseMatrix) -> SparseMatrix {
        assert_eq!(self.ncols, b.nrows, "SparseMatrix::mul: inner dimensions differ");
        let m = self.nrows;
        let chunks: Vec<(Vec<usize>, Vec<usize>, Vec<f64>)> = (0..b.ncols.div_ceil(COL_CHUNK))
            .into_par_iter()
            .map(|c| {
                let j0 = c * COL_CHUNK;
                let j1 = (j0 + COL_CHUNK).min(b.ncols);
                let mut mark = vec![usize::MAX; m];
                let mut acc = vec![0.0; m];
                let mut counts = Vec::with_capacity(j1 - j0);
                let mut rows = Vec::new();
                let mut vals = Vec::new();
                for j in j0..j1 {
                    let start = rows.len();
                    for kb in b.col_ptr[j]..b.col_ptr[j + 1] {
                        let (k, bkj) = (b.row_idx[kb], b.values[kb]);
                        for ka in self.col_ptr[k]..self.col_ptr[k + 1] {
                            let i = self.row_idx[ka];
                            if mark[i] != j {
                                mark[i] = j;
                                acc[i] = 0.0;
                                rows.push(i);
                            }
                            acc[i] += self.values[ka] * bkj;
                        }
                    }
                    rows[start..].sort_unstable();
                    vals.extend(rows[start..].iter().map(|&i| acc[i]));
                    counts.push(rows.len() - start);
                }
                (counts, rows, vals)
            })
            .collect();
        let mut col_ptr = Vec::with_capacity(b.ncols + 1);
        col_ptr.push(0);
        let total: usize = chunks.iter().map(|c| c.1.len()).sum();
        let mut row_idx = Vec::with_capacity(total);
        let mut values = Vec::with_capacity(total);
        for (counts, rows, vals) in chunks {
            for cnt in counts {
                col_ptr.push(col_ptr.last().unwrap() + cnt);
            }
            row_idx.extend(rows);
            values.extend(vals);
        }
        SparseMatrix { nrows: m, ncols: b.ncols, col_ptr, row_idx, values }
    }

    /// `AᵀA` (`ncols × ncols`, symmetric, both triangles stored), for least squares.
    pub fn ata(&self) -> SparseMatrix {
        self.transpose().mul(self)
    }

    /// `self + alpha · other` (union of patterns). Panics on a shape mismatch.
    pub fn add_scaled(&self, other: &SparseMatrix, alpha: f64) -> SparseMatrix {
        assert!(
            self.nrows == other.nrows && self.ncols == other.ncols,
            "SparseMatrix::add_scaled: shapes differ"
        );
        let mut col_ptr = Vec::with_capacity(self.ncols + 1);
        let mut row_idx = Vec::with_capacity(self.nnz() + other.nnz());
        let mut values = Vec::with_capacity(self.nnz() + other.nnz());
        col_ptr.push(0);
        for j in 0..self.ncols {
            let (mut p, pe) = (self.col_ptr[j], self.col_ptr[j + 1]);
            let (mut q, qe) = (other.col_ptr[j], other.col_ptr[j + 1]);
            while p < pe || q < qe {
                let rp = if p < pe { self.row_idx[p] } else { usize::MAX };
                let rq = if q < qe { other.row_idx[q] } else { usize::MAX };
                if rp < rq {
                    row_idx.push(rp);
                    values.push(self.values[p]);
                    p += 1;
                } else if rq < rp {
                    row_idx.push(rq);
                    values.push(alpha * other.values[q]);
                    q += 1;
                } else {
                    row_idx.push(rp);
                    values.push(self.values[p] + alpha * other.values[q]);
                    p += 1;
                    q += 1;
                }
            }
            col_ptr.push(row_idx.len());
        }
        SparseMatrix { nrows: self.nrows, ncols: self.ncols, col_ptr, row_idx, values }
    }

    /// `self + diag(d)`; `d.len()` must be `min(nrows, ncols)` (panics otherwise).
    pub fn add_diagonal(&self, d: &[f64]) -> SparseMatrix {
        assert_eq!(
            d.len(),
            self.nrows.min(self.ncols),
            "SparseMatrix::add_diagonal: d must have min(nrows, ncols) entries"
        );
        let mut diag = SparseMatrix::from_diagonal(d);
        diag.nrows = self.nrows;
        diag.ncols = self.ncols;
        diag.col_ptr.resize(self.ncols + 1, d.len());
        self.add_scaled(&diag, 1.0)
    }

    /// Multiplies every value by `s`.
    pub fn scale(&mut self, s: f64) {
        self.values.iter_mut().for_each(|v| *v *= s);
    }

    /// First entry whose mirror differs by more than `rel_tol · max(|a_ij|, |a_ji|)`,
    /// as `(i, j, a_ij, a_ji)`; `None` for a symmetric matrix. Panics if not square.
    pub fn first_asymmetry(&self, rel_tol: f64) -> Option<(usize, usize, f64, f64)> {
        assert_eq!(self.nrows, self.ncols, "first_asymmetry needs a square matrix");
        // column-parallel; `find_map_first` keeps the answer independent of threads
        let lower = (0..self.ncols).into_par_iter().find_map_first(|j| {
            (self.col_ptr[j]..self.col_ptr[j + 1]).find_map(|k| {
                let i = self.row_idx[k];
                if i <= j {
                    return None;
                }
                let a = self.values[k];
                let m = self.get(j, i);
                ((a - m).abs() > rel_tol * a.abs().max(m.abs())).then_some((i, j, a, m))
            })
        });
        if lower.is_some() {
            return lower;
        }
        // entries stored only in the upper triangle
        (0..self.ncols).into_par_iter().find_map_first(|j| {
            (self.col_ptr[j]..self.col_ptr[j + 1]).find_map(|k| {
                let i = self.row_idx[k];
                (i < j && self.values[k] != 0.0 && self.find(j, i).is_none()).then_some((
                    i,
                    j,
                    self.values[k],
                    0.0,
                ))
            })
        })
    }

    /// Index of the first non-finite stored value.
    pub fn first_non_finite(&self) -> Option<usize> {
        self.values.iter().position(|v| !v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dense(a: &SparseMatrix) -> Vec<Vec<f64>> {
        let mut d = vec![vec![0.0; a.ncols()]; a.nrows()];
        for (i, j, v) in a.triplets() {
            d[i][j] += v;
        }
        d
    }

    #[test]
    fn triplets_sum_duplicates_and_sort() {
        let a = SparseMatrix::from_triplets(
            3,
            2,
            &[(2, 0, 1.0), (0, 0, 2.0), (2, 0, 3.0), (1, 1, -1.0)],
        )
        .unwrap();
        assert_eq!(a.nnz(), 3);
        assert_eq!(a.get(2, 0), 4.0);
        assert_eq!(a.get(0, 0), 2.0);
        assert_eq!(a.get(1, 1), -1.0);
        assert_eq!(a.get(1, 0), 0.0);
        assert_eq!(a.row_idx(), &[0, 2, 1]);
    }

    #[test]
    fn triplets_reject_bad_input() {
        assert!(matches!(
            SparseMatrix::from_triplets(2, 2, &[(2, 0, 1.0)]),
            Err(LinalgError::IndexOutOfRange { row: 2, .. })
        ));
        assert!(matches!(
            SparseMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (1, 1, f64::NAN)]),
            Err(LinalgError::NonFinite { index: 1, .. })
        ));
        assert!(matches!(
            SparseMatrix::from_triplets(2, 2, &[(0, 0, 1e308), (0, 0, 1e308)]),
            Err(LinalgError::NonFinite { .. })
        ));
    }

    #[test]
    fn products_match_dense() {
        let a = SparseMatrix::from_triplets(
            3,
            4,
            &[(0, 0, 1.0), (1, 0, 2.0), (2, 1, 3.0), (0, 2, -1.0), (2, 3, 0.5), (1, 3, 4.0)],
        )
        .unwrap();
        let d = dense(&a);
        let x = [1.0, -2.0, 0.5, 3.0];
        let y = a.mul_vec(&x);
        for i in 0..3 {
            let e: f64 = (0..4).map(|j| d[i][j] * x[j]).sum();
            assert!((y[i] - e).abs() < 1e-14);
        }
        let z = [0.3, -1.0, 2.0];
        let yt = a.transpose_mul_vec(&z);
        assert_eq!(yt, a.transpose().mul_vec(&z));
        let ata = dense(&a.ata());
        for i in 0..4 {
            for j in 0..4 {
                let e: f64 = (0..3).map(|k| d[k][i] * d[k][j]).sum();
                assert!((ata[i][j] - e).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn sums_and_diagonal() {
        let a = SparseMatrix::from_triplets(2, 2, &[(0, 1, 1.0), (1, 0, 1.0)]).unwrap();
        let b = a.add_diagonal(&[2.0, 3.0]);
        assert_eq!(dense(&b), vec![vec![2.0, 1.0], vec![1.0, 3.0]]);
        let c = b.add_scaled(&SparseMatrix::identity(2), -2.0);
        assert_eq!(dense(&c), vec![vec![0.0, 1.0], vec![1.0, 1.0]]);
        assert_eq!(c.diagonal(), vec![0.0, 1.0]);
        assert!(b.first_asymmetry(1e-12).is_none());
        let d = SparseMatrix::from_triplets(2, 2, &[(0, 1, 1.0)]).unwrap();
        assert!(d.first_asymmetry(1e-12).is_some());
        assert!(SparseMatrix::from_csc(2, 2, vec![0, 1, 2], vec![1, 1], vec![1.0, 1.0]).is_ok());
        assert!(SparseMatrix::from_csc(2, 2, vec![0, 2, 2], vec![1, 1], vec![1.0, 1.0]).is_err());
    }
}
