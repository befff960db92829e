//! The per-component systems of the curve-constrained diffusion
//! (`harmonic_diffusion.rs`, paper A §4.2 eq. (2)): a component's block of the cotan
//! Laplacian, `L_c + α diag(constrained)`, its right-hand sides `α b`, and the first
//! factorisation (AMD or nested-dissection ordering) prepared for later rank-1 updates.

use fieldtex_core::vec3::V3;
use fieldtex_linalg::{Cholesky, FactorLayout, SparseMatrix, SymbolicCholesky};
use fieldtex_mesh::{MeshError, TriMesh};

use crate::FieldsError;
use crate::curve_field_types::FillOrdering;

/// One connected component's system: its Laplacian block and kept factorisation.
pub(crate) struct Block {
    /// Global vertex indices, increasing (local index = position).
    pub(crate) vertices: Vec<u32>,
    pub(crate) laplacian: SparseMatrix,
    pub(crate) symbolic: Option<SymbolicCholesky>,
    pub(crate) factor: Option<Cholesky>,
    pub(crate) dirty: bool,
    pub(crate) failed: bool,
    /// Vertices that got their first penalty since the last solve (global indices).
    pub(crate) fresh: Vec<u32>,
    /// No full solve since the first factorisation, or a change an incremental solve
    /// does not cover (a target moved by `Average`): the next solve of the block is a
    /// full one. While false, `raw` solves the system of the last solve at the vertices
    /// marked in `CurveFieldSolver::current`.
    pub(crate) needs_full: bool,
    /// The last solve was incremental: `raw` is stale outside its `needed` vertices.
    pub(crate) partial: bool,
}

/// The block of `l` on `verts` (increasing global indices). Entries reaching outside the
/// block are structural zeros of skipped triangles and are dropped.
pub(crate) fn extract_block(
    l: &SparseMatrix,
    verts: &[u32],
    local: &[u32],
    component: &[u32],
    c: u32,
) -> Result<SparseMatrix, FieldsError> {
    let (cp, ri, va) = (l.col_ptr(), l.row_idx(), l.values());
    let mut col_ptr = Vec::with_capacity(verts.len() + 1);
    let mut row_idx = Vec::new();
    let mut values = Vec::new();
    col_ptr.push(0);
    let mut has_diag = true;
    for (j, &g) in verts.iter().enumerate() {
        let g = g as usize;
        let mut diag = false;
        for k in cp[g]..cp[g + 1] {
            if component[ri[k]] != c {
                continue;
            }
            let r = local[ri[k]];
            diag |= r as usize == j;
            row_idx.push(r as usize);
            values.push(va[k]);
        }
        has_diag &= diag;
        col_ptr.push(row_idx.len());
    }
    if !has_diag {
        return Err(FieldsError::InvalidMesh(MeshError::Precondition {
            operation: "curve-constrained field",
            requirement: "a cotan Laplacian with a stored diagonal",
            found: "a column without diagonal entry".into(),
        }));
    }
    Ok(SparseMatrix::from_csc(verts.len(), verts.len(), col_ptr, row_idx, values)?)
}

/// `L_c + α diag(constrained)` of one block.
pub(crate) fn penalised_matrix(
    block: &Block,
    targets: &[Option<(V3, V3)>],
    alpha: f64,
) -> SparseMatrix {
    let d: Vec<f64> = block
        .vertices
        .iter()
        .map(|&v| if targets[v as usize].is_some() { alpha } else { 0.0 })
        .collect();
    block.laplacian.add_diagonal(&d)
}

/// The three right-hand sides `α b` of one block.
pub(crate) fn block_rhs(verts: &[u32], targets: &[Option<(V3, V3)>], alpha: f64) -> Vec<Vec<f64>> {
    (0..3)
        .map(|k| {
            verts.iter().map(|&v| targets[v as usize].map_or(0.0, |(t, _)| alpha * t[k])).collect()
        })
        .collect()
}

/// First factorisation of a block (symbolic analysis kept for later comparisons).
pub(crate) fn factor_block(
    block: &mut Block,
    targets: &[Option<(V3, V3)>],
    alpha: f64,
    ordering: FillOrdering,
    mesh: &TriMesh,
) -> Result<(), FieldsError> {
    let a = penalised_matrix(block, targets, alpha);
    // The pattern of `L + P` is that of `L` (diagonal present), so a kept analysis serves
    // every later refactorisation.
    let symbolic = match block.symbolic.take() {
        Some(s) => s,
        None => match ordering {
            FillOrdering::Amd => SymbolicCholesky::analyze(&a)?,
            FillOrdering::NestedDissection => {
                let positions: Vec<V3> =
                    block.vertices.iter().map(|&v| mesh.positions[v as usize]).collect();
                let l = &block.laplacian;
                let perm = crate::nested_dissection::nested_dissection_order(
                    &positions,
                    l.col_ptr(),
                    l.row_idx(),
                );
                SymbolicCholesky::analyze_with_ordering(&a, FactorLayout::Auto, &perm)?
            }
        },
    };
    let mut factor = Cholesky::factor_with(&symbolic, &a)?;
    // later constraints are rank-1 updates: prepare the factor for them now
    factor.prepare_updates()?;
    block.symbolic = Some(symbolic);
    block.factor = Some(factor);
    Ok(())
}
