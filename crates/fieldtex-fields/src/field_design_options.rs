//! Options of a [`crate::FieldDesign`]: weights, the natural-boundary switch, how
//! singularities enter, and when stroke edits use rank-1 factor updates.

use crate::FieldsError;

/// How singularities become prescribed divergence and curl.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SingularityModel {
    /// Discrete divergence and curl of the exact model-field 1-forms (default).
    #[default]
    ModelField,
    /// Point divergence/curl at the containing triangle (the paper's literal form;
    /// saddles and trisectors fall back to their model field).
    PointDelta,
}

/// Weights and switches of a field design.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldDesignOptions {
    /// `w_s`, weight of the smoothness (divergence + curl + boundary) energy. Default 1.
    pub smoothness_weight: f64,
    /// Include the natural boundary term (paper D §2.2). Default `true`; `false` is the
    /// ablation with Fisher et al.'s free boundary only.
    pub natural_boundary: bool,
    /// `β`, scale of the natural boundary term, in `[0, 1]` (1 = Dirichlet energy).
    /// Default 1.
    pub boundary_weight: f64,
    /// Global stroke weight, multiplied by each stroke's own weight. Default 4.
    pub stroke_weight: f64,
    /// `ε`, relative Tikhonov regularisation (times the diagonal of the smoothness
    /// matrix; on the deviation from the model fields). Default `1e-6`.
    pub regularization: f64,
    /// How singularities enter. Default [`SingularityModel::ModelField`].
    pub singularity_model: SingularityModel,
    /// Stroke edits that modify the weight of at most this many factor edges update the
    /// factorisation by multiple-rank modifications (of the current factor, or of a
    /// copy of the kept checkpoint factor, [`crate::design_factor`]) instead of
    /// refactoring (0: always refactor, no checkpoint kept). Default 640: on the 128²
    /// grid (49K unknowns, 2.3M factor entries) an update measured ~0.1–0.2 ms per edge,
    /// a downdate about twice that, and a numeric refactorisation 90–170 ms on 2 loaded
    /// cores (`examples/bench_fields.rs`), so adding, removing and dragging a ~250 px
    /// stroke (~250–500 changed edges) are updated.
    pub rank1_update_limit: usize,
}

impl Default for FieldDesignOptions {
    fn default() -> Self {
        Self {
            smoothness_weight: 1.0,
            natural_boundary: true,
            boundary_weight: 1.0,
            stroke_weight: 4.0,
            regularization: 1e-6,
            singularity_model: SingularityModel::ModelField,
            rank1_update_limit: 640,
        }
    }
}

impl FieldDesignOptions {
    pub fn with_natural_boundary(mut self, on: bool) -> Self {
        self.natural_boundary = on;
        self
    }
    pub fn with_boundary_weight(mut self, beta: f64) -> Self {
        self.boundary_weight = beta;
        self
    }
    pub fn with_smoothness_weight(mut self, w: f64) -> Self {
        self.smoothness_weight = w;
        self
    }
    pub fn with_stroke_weight(mut self, w: f64) -> Self {
        self.stroke_weight = w;
        self
    }
    pub fn with_regularization(mut self, eps: f64) -> Self {
        self.regularization = eps;
        self
    }
    pub fn with_singularity_model(mut self, model: SingularityModel) -> Self {
        self.singularity_model = model;
        self
    }
    pub fn with_rank1_update_limit(mut self, edges: usize) -> Self {
        self.rank1_update_limit = edges;
        self
    }

    pub(crate) fn validate(&self) -> Result<(), FieldsError> {
        let check = |name: &'static str, v: f64, ok: bool, expected: &'static str| {
            if ok && v.is_finite() {
                Ok(())
            } else {
                Err(FieldsError::InvalidOption { name, value: v, expected })
            }
        };
        check(
            "smoothness_weight",
            self.smoothness_weight,
            self.smoothness_weight > 0.0,
            "a number > 0",
        )?;
        check(
            "boundary_weight",
            self.boundary_weight,
            (0.0..=1.0).contains(&self.boundary_weight),
            "a number in [0, 1] (1 = Dirichlet energy)",
        )?;
        check("stroke_weight", self.stroke_weight, self.stroke_weight >= 0.0, "a number ≥ 0")?;
        check(
            "regularization",
            self.regularization,
            self.regularization > 0.0 && self.regularization < 1.0,
            "a number in (0, 1), e.g. 1e-6",
        )
    }
}
