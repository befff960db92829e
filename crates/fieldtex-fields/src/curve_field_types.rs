//! Options, per-curve constraints and reports of the curve-constrained harmonic field
//! ([`crate::harmonic_diffusion::CurveFieldSolver`], paper A §4.2): the vocabulary the
//! solver, the greedy orientation and the facade share.

use fieldtex_core::Warning;
use fieldtex_core::vec3::{self, V3};
use serde::Serialize;

use crate::FieldsError;

/// What to do at a vertex that a second curve also constrains (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum OverlapPolicy {
    /// Keep the tangent of the curve added first. Default.
    #[default]
    KeepFirst,
    /// Target = normalised sum of every oriented tangent at the vertex (`b` only).
    Average,
}

/// Field of a connected component that no curve touches.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub enum UnconstrainedFallback {
    /// The smoothest line field, aligned to principal curvature only where it is
    /// clearly anisotropic (Knöppel et al. 2013; [`crate::smoothest_field`]). Default.
    #[default]
    Smoothest,
    /// Direction of maximal principal curvature at every vertex (Rusinkiewicz 2004
    /// estimate; a line field, its sign is arbitrary; swirls on flat parts).
    PrincipalDirection,
    /// A global direction projected onto each tangent plane (where it is along the
    /// normal, any tangent).
    Direction([f64; 3]),
    /// Zero vectors.
    Zero,
}

/// Options of [`crate::CurveFieldSolver`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurveFieldOptions {
    /// Penalty weight `α` of eq. (2). Default `1e8` (paper A). Must be finite and `> 0`.
    pub penalty: f64,
    /// Curve resampling step, in mean edge lengths. Default `0.5`. Must lie in
    /// `(0.001, 1000]`.
    pub sample_spacing: f64,
    /// Largest distance from a curve sample to its vertex, in mean edge lengths; farther
    /// samples are dropped as off the mesh. Default `2.0`. Must lie in `(0, 1000]`.
    pub max_distance: f64,
    /// Vertices constrained by several curves. Default [`OverlapPolicy::KeepFirst`].
    pub overlap: OverlapPolicy,
    /// Components without constraints. Default [`UnconstrainedFallback::PrincipalDirection`].
    pub fallback: UnconstrainedFallback,
    /// New penalties on an already factored component beyond which
    /// [`crate::CurveFieldSolver::add_constraints_many`] refactors numerically instead of
    /// applying them as one multiple-rank update. Default 200: one rank-1 update cost ~1/220 of a
    /// refactorisation from fandisk to the refined horse (`examples/bench_orientation.rs`,
    /// `refactor_over_rank1`). A greedy step (one curve, tens of vertices) stays below.
    pub refactor_above: usize,
    /// Fill-reducing ordering of each component's factor. Default
    /// [`FillOrdering::NestedDissection`].
    pub ordering: FillOrdering,
}

/// Ordering of the unknowns before factorisation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum FillOrdering {
    /// Approximate minimum degree (faer).
    Amd,
    /// Geometric nested dissection ([`crate::nested_dissection`]): a balanced
    /// elimination tree with short leaf-to-root paths, which the greedy orientation's
    /// rank-1 updates and partial solves walk. Default.
    #[default]
    NestedDissection,
}

impl Default for CurveFieldOptions {
    fn default() -> Self {
        Self {
            penalty: 1e8,
            sample_spacing: 0.5,
            max_distance: 2.0,
            overlap: OverlapPolicy::KeepFirst,
            fallback: UnconstrainedFallback::Smoothest,
            refactor_above: 200,
            ordering: FillOrdering::default(),
        }
    }
}

impl CurveFieldOptions {
    pub(crate) fn validate(&self) -> Result<(), FieldsError> {
        let check = |name, value: f64, lo: f64, hi: f64, expected| {
            if value.is_finite() && value > lo && value <= hi {
                Ok(())
            } else {
                Err(FieldsError::InvalidOption { name, value, expected })
            }
        };
        check("penalty", self.penalty, 0.0, f64::MAX, "a finite number > 0 (paper: 1e8)")?;
        let spacing = "a number of mean edge lengths in (0.001, 1000]";
        check("sample_spacing", self.sample_spacing, 1e-3, 1e3, spacing)?;
        check(
            "max_distance",
            self.max_distance,
            0.0,
            1e3,
            "a number of mean edge lengths in (0, 1000]",
        )?;
        if let UnconstrainedFallback::Direction(d) = self.fallback {
            let n = vec3::norm(d);
            if !(n.is_finite() && n > 0.0) {
                return Err(FieldsError::InvalidOption {
                    name: "fallback direction length",
                    value: n,
                    expected: "a finite, non-zero direction X,Y,Z",
                });
            }
        }
        Ok(())
    }
}

/// The constraints one polyline puts on the mesh, for its forward orientation.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CurveConstraints {
    /// Constrained vertices, in the order the curve first reaches them.
    pub vertices: Vec<u32>,
    /// Unit tangent per vertex, in its tangent plane, along the polyline's direction.
    pub tangents: Vec<V3>,
    /// Arc length of the parts of the polyline that lie on the mesh.
    pub length: f64,
    /// Curve samples farther than `max_distance` from the mesh, or non-finite points.
    pub dropped_samples: usize,
}

/// How a vertex of a solved field was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum VertexFieldStatus {
    /// Diffused from the constraints of its component.
    Solved,
    /// The diffused vector is (nearly) normal to the surface or zero: vector set to 0.
    Degenerate,
    /// Its component has no constraint (or could not be factored): the fallback.
    Fallback,
    /// Used by no usable triangle: vector 0.
    Isolated,
}

/// A per-vertex tangent field: `#V × 3` unit vectors (0 where not defined).
#[derive(Debug, Clone, PartialEq)]
pub struct CurveField {
    pub vectors: Vec<V3>,
    pub status: Vec<VertexFieldStatus>,
    pub warnings: Vec<Warning>,
}

/// Cost of one [`crate::CurveFieldSolver::add_constraints`].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct AddReport {
    /// Vertices that received a penalty now.
    pub new_vertices: usize,
    /// Vertices already constrained by an earlier curve (see [`OverlapPolicy`]).
    pub overlapping_vertices: usize,
    /// Penalties added by updates of an existing factor (rank-1 terms of the
    /// multiple-rank updates) and their total time.
    pub rank1_updates: usize,
    pub update_seconds: f64,
    /// First factorisations of components (symbolic + numeric) and their time.
    pub factorisations: usize,
    pub factor_seconds: f64,
}

/// Cost and accuracy of one [`crate::CurveFieldSolver::solve`].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct SolveReport {
    /// Components re-solved (only those whose constraints changed).
    pub components_solved: usize,
    pub seconds: f64,
    /// Largest relative residual `‖(L+P)x − Pb‖ / ‖Pb‖` over the right-hand sides of the
    /// full solves.
    pub max_residual: f64,
    /// Components updated incrementally ([`crate::CurveFieldSolver::solve_at`]; no residual).
    pub incremental: usize,
}
