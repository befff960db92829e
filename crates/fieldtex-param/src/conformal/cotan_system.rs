//! The cotangent Dirichlet energy restricted to a subset of triangles, and solves with
//! fixed values, for the harmonic functions and 1-forms of the global conformal
//! parameterisation.
//!
//! The half-cotangent weights come from [`fieldtex_mesh::cotan_face_weights`] (the one
//! home of the cotangent formula). They are *not* clamped to be non-negative: a
//! conformal map needs the true cotan Hodge star `⋆1`, and the assembled matrix is a sum
//! of per-triangle positive semi-definite blocks, so it stays positive semi-definite.
//! Edge indexing follows [`Topology`]: `w[e]` for `topology.edges[e]` (low → high).

use crate::ParamError;
use fieldtex_linalg::{Cholesky, SparseMatrix};
use fieldtex_mesh::Topology;

/// Per-edge cotan weights `w_e = ½ Σ cot` over the triangles with `keep[f]`.
pub fn edge_weights(topology: &Topology, half_cot: &[[f64; 3]], keep: &[bool]) -> Vec<f64> {
    let mut w = vec![0.0; topology.n_edges()];
    for (f, fe) in topology.face_edges.iter().enumerate() {
        if !keep[f] {
            continue;
        }
        for k in 0..3 {
            w[fe[k] as usize] += half_cot[f][k];
        }
    }
    w
}

/// A factorised Laplacian `L` (`#V × #V`, `L_ij = −w_ij`, `L_ii = Σ w_ij`) with some
/// vertices held at fixed values; solves `L x = b` on the free vertices.
pub struct FixedLaplacian {
    /// Position of each vertex among the free unknowns (`usize::MAX` when fixed).
    slot: Vec<usize>,
    edges: Vec<[u32; 2]>,
    weights: Vec<f64>,
    factor: Cholesky,
    fixed_values: Vec<f64>,
}

impl FixedLaplacian {
    /// `fixed[v] = Some(value)` holds vertex `v`; vertices touched by no weighted edge
    /// must be fixed (they would make the matrix singular).
    pub fn new(
        topology: &Topology,
        weights: &[f64],
        fixed: &[Option<f64>],
    ) -> Result<Self, ParamError> {
        let n = topology.n_vertices;
        let mut slot = vec![usize::MAX; n];
        let mut nfree = 0;
        for v in 0..n {
            if fixed[v].is_none() {
                slot[v] = nfree;
                nfree += 1;
            }
        }
        if nfree == 0 {
            return Err(conformal_error("every vertex is fixed; nothing to solve"));
        }
        let mut diag = vec![0.0; nfree];
        let mut trip: Vec<(usize, usize, f64)> = Vec::with_capacity(4 * topology.n_edges());
        for (e, ed) in topology.edges.iter().enumerate() {
            let w = weights[e];
            if w == 0.0 {
                continue;
            }
            let (a, b) = (slot[ed[0] as usize], slot[ed[1] as usize]);
            if a != usize::MAX {
                diag[a] += w;
            }
            if b != usize::MAX {
                diag[b] += w;
            }
            if a != usize::MAX && b != usize::MAX {
                trip.push((a, b, -w));
                trip.push((b, a, -w));
            }
        }
        for (i, d) in diag.iter().enumerate() {
            trip.push((i, i, *d));
        }
        let m = SparseMatrix::from_triplets(nfree, nfree, &trip)
            .map_err(|e| conformal_error(&format!("Laplacian assembly: {e}")))?;
        let factor = Cholesky::factor(&m).map_err(|e| {
            conformal_error(&format!(
                "factorising the {nfree}×{nfree} cotan Laplacian failed ({e}); the component may have isolated or degenerate parts"
            ))
        })?;
        let fixed_values = fixed.iter().map(|f| f.unwrap_or(0.0)).collect();
        Ok(Self {
            slot,
            edges: topology.edges.clone(),
            weights: weights.to_vec(),
            factor,
            fixed_values,
        })
    }

    /// Solves `L x = rhs` for the free vertices (fixed ones keep their values).
    pub fn solve(&self, rhs: &[f64]) -> Result<Vec<f64>, ParamError> {
        let nfree = self.factor.size();
        let mut b = vec![0.0; nfree];
        for (v, &s) in self.slot.iter().enumerate() {
            if s != usize::MAX {
                b[s] = rhs[v];
            }
        }
        for (e, ed) in self.edges.iter().enumerate() {
            let w = self.weights[e];
            let (i, j) = (ed[0] as usize, ed[1] as usize);
            let (si, sj) = (self.slot[i], self.slot[j]);
            if si != usize::MAX && sj == usize::MAX {
                b[si] += w * self.fixed_values[j];
            }
            if sj != usize::MAX && si == usize::MAX {
                b[sj] += w * self.fixed_values[i];
            }
        }
        let y = self
            .factor
            .solve(&b)
            .map_err(|e| conformal_error(&format!("cotan Laplacian solve: {e}")))?;
        Ok((0..self.slot.len())
            .map(
                |v| if self.slot[v] == usize::MAX { self.fixed_values[v] } else { y[self.slot[v]] },
            )
            .collect())
    }
}

pub(crate) fn conformal_error(reason: &str) -> ParamError {
    ParamError::Conformal { reason: reason.to_string() }
}
