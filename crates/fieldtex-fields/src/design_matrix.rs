//! Assembly of the field design's normal-equation matrix (see [`crate::field_design`]
//! for the energy):
//!
//! `A = w_s (Dᵀ ⋆0⁻¹ D + d1ᵀ ⋆2 d1 − β B) + ε diag(L)`, `#E × #E`, symmetric.
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

use fieldtex_linalg::SparseMatrix;

use crate::FieldsError;
use crate::dec::Dec;
use crate::field_design::FieldDesignOptions;

/// Returns `(A, ε diag(L))`: the matrix without strokes and its regularisation diagonal.
pub fn assemble_design_matrix(
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
