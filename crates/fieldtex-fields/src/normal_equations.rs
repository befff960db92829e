//! The normal equations `A ω = b` of the field design (see [`crate::field_design`] for
//! the energy): the operators they need, the matrix and the right-hand side.
//!
//! `A = w_s (Dᵀ ⋆0⁻¹ D + d1ᵀ ⋆2 d1 − β B) + ε diag(L)`, `#E × #E`, symmetric
//! (strokes add `diag(w_e)` on top, see [`crate::field_design`]):
//!
//! - `Dᵀ ⋆0⁻¹ D`: divergence energy, one outer product of the vertex's row of `D` per
//!   vertex (exact zeros dropped, so diagonals of a right-isosceles grid with `⋆1 = 0`
//!   add no fill);
//! - `d1ᵀ ⋆2 d1`: curl energy, a 3×3 block per triangle;
//! - `B`: the natural boundary term ([`crate::natural_boundary`]);
//! - `ε diag(L)`: Tikhonov term relative to the diagonal `L` of the bracket (floored at
//!   `1e-3 ×` its mean so that it is positive everywhere), which removes the kernel of
//!   constant fields.
//!
//! Every off-diagonal contribution is pushed together with its mirror, and duplicates
//! are summed in input order, so `A` is *bitwise* symmetric (the Cholesky layer checks).
//!
//! `b = w_s (Dᵀ ⋆0⁻¹ S + d1ᵀ ⋆2 C) − w_s β B ω* + ε diag(L) ω* + Σ w_e t_e` with
//! `S = D ω* + S_point`, `C = d1 ω* + C_point` ([`NormalEquations::right_hand_side`]).

use fieldtex_linalg::SparseMatrix;

use crate::FieldsError;
use crate::dec::Dec;
use crate::field_design::FieldDesignOptions;
use crate::natural_boundary::boundary_term_triplets;
use crate::stroke_constraints::EdgeConstraint;

/// Operators and the stroke-free matrix of one design domain.
#[derive(Debug, Clone)]
pub struct NormalEquations {
    /// `D`, `#V × #E` (divergence with boundary flux), and its transpose.
    pub div: SparseMatrix,
    pub div_t: SparseMatrix,
    /// `d1`, `#F × #E`, and its transpose.
    pub d1: SparseMatrix,
    pub d1_t: SparseMatrix,
    /// `B` of the natural boundary term (`None` when it is off).
    pub boundary: Option<SparseMatrix>,
    /// `A` without strokes.
    pub matrix: SparseMatrix,
    /// `ε diag(L)` (`#E`).
    pub regularization_diag: Vec<f64>,
    /// `w_s` and `w_s β`.
    pub smoothness_weight: f64,
    pub boundary_scale: f64,
}

impl NormalEquations {
    /// Builds the operators and assembles the stroke-free matrix.
    pub fn new(dec: &Dec, options: &FieldDesignOptions) -> Result<Self, FieldsError> {
        let div = SparseMatrix::from_triplets(
            dec.n_vertices(),
            dec.n_edges(),
            &dec.divergence_triplets(),
        )?;
        let div_t = div.transpose();
        let d1 = dec.d1();
        let d1_t = d1.transpose();
        let boundary = if options.natural_boundary && options.boundary_weight > 0.0 {
            Some(SparseMatrix::from_triplets(
                dec.n_edges(),
                dec.n_edges(),
                &boundary_term_triplets(dec),
            )?)
        } else {
            None
        };
        let (matrix, regularization_diag) =
            assemble_design_matrix(dec, &div_t, boundary.as_ref(), options)?;
        Ok(Self {
            div,
            div_t,
            d1,
            d1_t,
            boundary,
            matrix,
            regularization_diag,
            smoothness_weight: options.smoothness_weight,
            boundary_scale: options.smoothness_weight * options.boundary_weight,
        })
    }

    /// `b` for the model 1-form `model` (`ω*`, `None` if there is none), point divergence
    /// `s_point` (`#V`, or empty for none) and curl `c_point` (`#F`, or empty), and the
    /// stroke constraints.
    pub fn right_hand_side<'a>(
        &self,
        dec: &Dec,
        model: Option<&[f64]>,
        s_point: &[f64],
        c_point: &[f64],
        strokes: impl Iterator<Item = &'a [EdgeConstraint]>,
    ) -> Vec<f64> {
        let ws = self.smoothness_weight;
        let mut s = match model {
            Some(m) => self.div.mul_vec(m),
            None => vec![0.0; dec.n_vertices()],
        };
        let mut c = match model {
            Some(m) => self.d1.mul_vec(m),
            None => vec![0.0; dec.n_faces()],
        };
        for (v, sv) in s.iter_mut().enumerate() {
            *sv = ws * (*sv + s_point.get(v).copied().unwrap_or(0.0)) / dec.star0[v];
        }
        for (f, cf) in c.iter_mut().enumerate() {
            *cf = ws * (*cf + c_point.get(f).copied().unwrap_or(0.0)) * dec.star2[f];
        }
        let mut b = self.div_t.mul_vec(&s);
        for (bi, ci) in b.iter_mut().zip(self.d1_t.mul_vec(&c)) {
            *bi += ci;
        }
        // The boundary term and the regularisation act on the deviation ω − ω*.
        if let Some(m) = model {
            if let Some(bm) = &self.boundary {
                for (bi, v) in b.iter_mut().zip(bm.mul_vec(m)) {
                    *bi -= self.boundary_scale * v;
                }
            }
            for ((bi, r), mi) in b.iter_mut().zip(&self.regularization_diag).zip(m) {
                *bi += r * mi;
            }
        }
        for cs in strokes {
            for &(e, _, wt) in cs {
                b[e] += wt;
            }
        }
        b
    }
}

/// Returns `(A, ε diag(L))`: the matrix without strokes and its regularisation diagonal.
fn assemble_design_matrix(
    dec: &Dec,
    div_t: &SparseMatrix,
    boundary: Option<&SparseMatrix>,
    options: &FieldDesignOptions,
) -> Result<(SparseMatrix, Vec<f64>), FieldsError> {
    let ws = options.smoothness_weight;
    let ne = dec.n_edges();
    let mut t: Vec<(usize, usize, f64)> =
        Vec::with_capacity(40 * dec.n_vertices() + 9 * dec.n_faces());
    let push_outer = |t: &mut Vec<(usize, usize, f64)>, entries: &[(usize, f64)], w: f64| {
        for (p, &(ep, vp)) in entries.iter().enumerate() {
            t.push((ep, ep, w * vp * vp));
            for &(eq, vq) in &entries[p + 1..] {
                let v = w * vp * vq;
                t.push((ep, eq, v));
                t.push((eq, ep, v));
            }
        }
    };
    // Divergence: column v of Dᵀ is row v of D (sorted edges, merged duplicates).
    let (cp, ri, vals) = (div_t.col_ptr(), div_t.row_idx(), div_t.values());
    let mut row: Vec<(usize, f64)> = Vec::with_capacity(32);
    for v in 0..dec.n_vertices() {
        row.clear();
        row.extend((cp[v]..cp[v + 1]).map(|k| (ri[k], vals[k])).filter(|e| e.1 != 0.0));
        push_outer(&mut t, &row, ws / dec.star0[v]);
    }
    for f in 0..dec.n_faces() {
        let entries: Vec<(usize, f64)> = (0..3)
            .map(|k| {
                (dec.topology.face_edges[f][k] as usize, dec.topology.face_edge_signs[f][k] as f64)
            })
            .collect();
        push_outer(&mut t, &entries, ws * dec.star2[f]);
    }
    if let Some(b) = boundary {
        let beta = ws * options.boundary_weight;
        for (i, j, v) in b.triplets() {
            t.push((i, j, -beta * v));
        }
    }
    let l = SparseMatrix::from_triplets(ne, ne, &t)?;
    let diag = l.diagonal();
    let mean = diag.iter().sum::<f64>() / ne.max(1) as f64;
    let reg: Vec<f64> = diag
        .iter()
        .map(|d| options.regularization * d.max(1e-3 * mean).max(f64::MIN_POSITIVE))
        .collect();
    Ok((l.add_diagonal(&reg), reg))
}
