//! Rank-1 update/downdate of a sparse Cholesky factor (work in progress: phase 2).

/// Direction of a rank-1 modification `A ± w wᵀ`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpdateSign {
    /// `A + w wᵀ`
    Up,
    /// `A − w wᵀ`
    Down,
}

/// Simplicial factor in permuted space (filled in by the rank-1 update code).
#[derive(Clone, Debug)]
pub(crate) struct DynamicFactor {}

impl DynamicFactor {
    pub(crate) fn solve_in_place(&self, _x: &mut [f64]) {
        unreachable!("no rank-1 updates exist yet")
    }
}
