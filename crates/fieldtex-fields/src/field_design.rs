//! Tangent vector field design with DEC (Fisher, Schröder, Desbrun & Hoppe 2007, "Design
//! of tangent vector fields") with the natural boundary term of Liu et al. (paper D,
//! §2.1–2.2), as an editable object for interactive use.
//!
//! Unknown: a 1-form `ω` (`#E`). Notation: `Dω` is the integrated divergence per vertex
//! *with the boundary flux* ([`Dec::divergence_triplets`], Fisher's free boundary),
//! `d1 ω` the curl per face, `ωᵀBω` the natural boundary term
//! ([`crate::natural_boundary`]), so that
//! `Q_β(ω) = ‖Dω‖²_{⋆0⁻¹} + ‖d1 ω‖²_{⋆2} − β ωᵀBω` is the Dirichlet energy `∫|∇u|²` for
//! `β = 1` and Fisher et al.'s div² + curl² energy for `β = 0` (the ablation,
//! `natural_boundary: false`). Strokes give edge constraints `w_e (ω_e − t_e)²`
//! ([`crate::stroke_constraints`]). `ε ‖·‖²_diag` (default `ε = 1e-6`, relative to the
//! matrix diagonal) removes the kernel of constant fields.
//!
//! Singularities, two models ([`SingularityModel`]):
//! - **`ModelField` (default).** Every singularity has an exact model 1-form
//!   ([`crate::singular_model_field`]); `ω*` is their sum. The energy is
//!   `E(ω) = w_s Q_β(ω − ω*) + ε‖ω − ω*‖² + Σ_e w_e (ω_e − t_e)²`, i.e. the paper's least
//!   squares with prescribed divergence `S = Dω*` and curl `C = d1 ω*`, the natural
//!   boundary term and the regularisation measured on the deviation from `ω*`. Without
//!   strokes the solution is exactly `ω*` (the singularities, no constant added); strokes
//!   add the Dirichlet-smoothest correction that follows them — this is where the
//!   natural boundary matters (with `β = 0` the correction is free in all harmonic
//!   directions). A source's `S` is concentrated at it, a vortex's `C` is exactly a point
//!   curl on its triangle, and saddles/trisectors, which have no point divergence or
//!   curl, get their smooth `−2c/(z−p)²` densities.
//! - **`PointDelta`** (the paper's literal form, kept for paper D Fig. 2):
//!   `E(ω) = w_s (‖Dω − S‖² + ‖d1ω − C‖² − β ωᵀBω) + ε‖ω‖² + strokes` with point
//!   divergence `S = 2π·Re c` split barycentrically over the three vertices of the
//!   containing triangle and point curl `C = 2π·Im c` on the triangle. Saddles and
//!   trisectors still use their model field.
//!
//! Normal equations `A ω = b`:
//! `A = w_s (Dᵀ⋆0⁻¹D + d1ᵀ⋆2 d1 − βB) + ε diag + diag(w_e)` ([`crate::normal_equations`]),
//! `b = w_s (Dᵀ⋆0⁻¹ S + d1ᵀ⋆2 C) − w_s β B ω* + ε diag ω* + (w_e t_e)` — the paper's
//! `∗dS + ∗δC + ZᵀWU_Z` plus the two deviation terms (`ω* = 0` for `PointDelta` poles).
//!
//! Extra singularities: the model fields superpose, so where they cancel a zero appears —
//! two poles side by side always have a saddle between them (as two sources do), and
//! orientation designs with mutually inconsistent rotations can grow extra ±1/2 pairs;
//! rotations from [`crate::zero_pole_angles`] avoid the latter (paper D, §5, notes the
//! same limitation).
//!
//! Singularities enter only `b`. Deviation from the paper: there, a trisector is built
//! from direction constraints on a vertex one-ring, which changes `A`; here every
//! singularity keeps `A` fixed, so moving any singularity is one back-substitution (its
//! model 1-form is recomputed, the others are cached).
//!
//! Factor once: [`FieldDesign::new`] assembles `A` and analyses its pattern; the first
//! solve factors it. Strokes change the diagonal of `A` by `Σ Δw_e e_e e_eᵀ`: edits that
//! change at most [`FieldDesignOptions::rank1_update_limit`] edges (default 640) are
//! multiple-rank updates/downdates of the factor or a copy of a kept earlier factor plus
//! one update (whichever modifies fewer edges), larger ones a numeric refactorisation
//! with the kept symbolic analysis ([`crate::design_factor`]).
//! Frame costs, session by session: `docs/perf/field-design-edits.md`.
//!
//! Files: the edits (singularities, strokes) in `field_design_edits.rs`; construction,
//! factor upkeep and the solve here.

use std::sync::Arc;

use fieldtex_core::Warnings;
use fieldtex_core::vec3::{add, scale};
use fieldtex_linalg::SparseMatrix;
use fieldtex_mesh::TriMesh;
use rayon::prelude::*;

use crate::FieldsError;
use crate::dec::Dec;
use crate::design_elements::{Singularity, SingularityKind, Stroke, Symmetry};
use crate::design_factor::DesignFactor;
use crate::domain::{Frame, PlaneGrid, locate_in_mesh};
pub use crate::field_design_options::{FieldDesignOptions, SingularityModel};
use crate::normal_equations::NormalEquations;
use crate::reference_frames::reference_frames;
use crate::singular_model_field::{ModelField, ModelKind};
use crate::stroke_constraints::{EdgeConstraint, stroke_edge_constraints};

#[path = "field_design_edits.rs"]
mod edits;

/// The domain of a design.
#[derive(Debug, Clone, PartialEq)]
pub enum Domain {
    /// A `W × H` rectangle in pixel units, triangulated as a grid.
    Plane(PlaneGrid),
    /// A disk-like triangle mesh patch.
    Mesh(TriMesh),
}

/// Stable handle of a singularity in a [`FieldDesign`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SingularityId(pub u32);

/// Stable handle of a stroke in a [`FieldDesign`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct StrokeId(pub u32);

/// A solved design: the 1-form and its per-triangle vectors (for orientation designs
/// these are the *doubled-angle* vectors; see [`crate::orientation_field`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SolvedField {
    pub symmetry: Symmetry,
    /// `#E` 1-form.
    pub one_form: Vec<f64>,
    /// `#F` Whitney vectors at the barycentres (3-D, tangent).
    pub face_vectors: Vec<[f64; 3]>,
    /// Relative residual of the linear solve (of the deviation from the model fields
    /// where [`FieldDesign::solve`] solves for it; 0 when no solve was needed).
    pub residual: f64,
}

#[derive(Debug, Clone)]
struct SingularityEntry {
    singularity: Singularity,
    /// Containing triangle and barycentric coordinates (`None`: outside the plane).
    face: Option<(usize, [f64; 3])>,
    /// Nudged position used for the model field.
    origin: [f64; 3],
    one_form: Option<Arc<Vec<f64>>>,
}

/// An editable field design with a kept factorisation. See the module docs.
pub struct FieldDesign {
    dec: Dec,
    plane: Option<PlaneGrid>,
    symmetry: Symmetry,
    options: FieldDesignOptions,
    frames: Vec<Frame>,
    reference_radius: f64,
    equations: NormalEquations,
    /// Factor of `A₀ + diag(stroke_diag)`, kept current by updates or refactorisation.
    factor: DesignFactor,
    /// Summed stroke weights per edge (`#E`), in stroke-id order; `None` after an edit.
    stroke_diag: Option<Vec<f64>>,
    singularities: Vec<Option<SingularityEntry>>,
    strokes: Vec<Option<(Stroke, Vec<EdgeConstraint>)>>,
    warnings: Warnings,
}

impl std::fmt::Debug for FieldDesign {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FieldDesign")
            .field("symmetry", &self.symmetry)
            .field("edges", &self.dec.n_edges())
            .field("singularities", &self.singularities().len())
            .field("strokes", &self.strokes().len())
            .finish()
    }
}

impl FieldDesign {
    /// Builds the operators, assembles the design matrix and analyses its sparsity
    /// pattern (the expensive, once-per-domain step); the numeric factorisation follows
    /// on the first solve, with the strokes added by then. On a mesh, the matrix is
    /// factored now to compute the per-triangle reference frames as the design solution
    /// with one fixed vector (paper D, §3).
    pub fn new(
        domain: Domain,
        symmetry: Symmetry,
        options: FieldDesignOptions,
    ) -> Result<Self, FieldsError> {
        options.validate()?;
        let (mesh, plane) = match domain {
            Domain::Plane(g) => {
                if g.nx == 0 || g.ny == 0 || g.nx.saturating_mul(g.ny) > 1 << 22 {
                    return Err(FieldsError::InvalidOption {
                        name: "grid cells",
                        value: g.nx as f64 * g.ny as f64,
                        expected: "between 1 and 4 194 304 cells (e.g. 128 × 128)",
                    });
                }
                for (name, v) in [("width", g.width), ("height", g.height)] {
                    if !(v.is_finite() && v > 0.0) {
                        return Err(FieldsError::InvalidOption {
                            name,
                            value: v,
                            expected: "a positive size",
                        });
                    }
                }
                (g.mesh(), Some(g))
            }
            Domain::Mesh(m) => (m, None),
        };
        let (dec, mut warnings) = Dec::new(&mesh)?;
        if plane.is_none() {
            // Orientation designs measure angles in frames made from one fixed vector, which
            // needs a single disk-like patch (paper D, §3: trivial topology).
            let (_, components) = dec.topology.face_components(&dec.triangles);
            let euler = dec.topology.euler_characteristic();
            if components != 1 || euler != 1 {
                warnings.push(fieldtex_core::Warning::new(
                    "field-domain-not-a-disk",
                    format!(
                        "the field design mesh has {components} component(s) and Euler characteristic {euler}; designs assume one disk-like patch (1 and 1), so frames and angles may be inconsistent — cut or parameterise the mesh into a disk first"
                    ),
                ));
            }
        }
        let equations = NormalEquations::new(&dec, &options)?;
        let factor = DesignFactor::new(&equations.matrix)?;
        let area: f64 = dec.face_areas.iter().sum();
        let reference_radius = 0.25 * area.sqrt();
        let mut design = Self {
            frames: Vec::new(),
            plane,
            symmetry,
            reference_radius,
            dec,
            options,
            equations,
            factor,
            stroke_diag: None,
            singularities: Vec::new(),
            strokes: Vec::new(),
            warnings,
        };
        design.frames = if design.plane.is_some() {
            vec![([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]); design.dec.n_faces()]
        } else {
            design.refactor_if_needed()?;
            reference_frames(&design.dec, design.factor.factor().expect("just factored"))?
        };
        Ok(design)
    }

    /// The DEC operators of the domain.
    pub fn dec(&self) -> &Dec {
        &self.dec
    }
    /// The plane grid, for plane domains.
    pub fn plane(&self) -> Option<&PlaneGrid> {
        self.plane.as_ref()
    }
    pub fn symmetry(&self) -> Symmetry {
        self.symmetry
    }
    pub fn options(&self) -> &FieldDesignOptions {
        &self.options
    }
    /// Per-triangle tangent frames `(e1, e2)` in which angles are measured.
    pub fn frames(&self) -> &[Frame] {
        &self.frames
    }
    /// Warnings from building the operators (degenerate triangles, clamped stars).
    pub fn warnings(&self) -> &Warnings {
        &self.warnings
    }
    /// Number of numeric factorisations done so far (the first one included).
    pub fn refactor_count(&self) -> usize {
        self.factor.refactor_count
    }
    /// Number of rank-1 factor updates done for stroke edits so far.
    pub fn rank1_update_count(&self) -> usize {
        self.factor.rank1_update_count
    }
    /// Number of stroke edits that rebuilt the factor from the kept checkpoint factor
    /// (a copy plus one multiple-rank update, instead of downdates;
    /// [`crate::design_factor`]).
    pub fn checkpoint_restore_count(&self) -> usize {
        self.factor.restore_count
    }
    /// Magnitude scale of singularity model fields: a quarter of `sqrt(area)`.
    pub fn reference_radius(&self) -> f64 {
        self.reference_radius
    }
    /// The assembled design matrix without strokes.
    pub fn base_matrix(&self) -> &SparseMatrix {
        &self.equations.matrix
    }

    /// Live singularities with their ids, in id order.
    pub fn singularities(&self) -> Vec<(SingularityId, Singularity)> {
        self.singularities
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.as_ref().map(|s| (SingularityId(i as u32), s.singularity)))
            .collect()
    }

    /// The singularity with this id, if it is live.
    pub fn singularity(&self, id: SingularityId) -> Option<Singularity> {
        self.singularities.get(id.0 as usize)?.as_ref().map(|e| e.singularity)
    }

    /// The stroke with this id, if it is live.
    pub fn stroke(&self, id: StrokeId) -> Option<&Stroke> {
        self.strokes.get(id.0 as usize)?.as_ref().map(|s| &s.0)
    }

    /// Live strokes with their ids, in id order.
    pub fn strokes(&self) -> Vec<(StrokeId, &Stroke)> {
        self.strokes
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.as_ref().map(|s| (StrokeId(i as u32), &s.0)))
            .collect()
    }

    /// Point location: triangle and barycentric coordinates, `None` outside.
    pub fn locate(&self, p: [f64; 3]) -> Option<(usize, [f64; 3])> {
        match &self.plane {
            Some(g) => g.contains(p[0], p[1]).then(|| g.locate(p[0], p[1])),
            None => {
                let (f, b, d) = locate_in_mesh(&self.dec, p)?;
                (d <= self.dec.mean_edge_length).then_some((f, b))
            }
        }
    }

    /// Sum of the stroke diagonals, in stroke-id order (deterministic).
    fn stroke_diagonal(&self) -> Vec<f64> {
        let mut d = vec![0.0; self.dec.n_edges()];
        for (_, cs) in self.strokes.iter().flatten() {
            for &(e, w, _) in cs {
                d[e] += w;
            }
        }
        d
    }

    /// Brings the numeric factorisation up to date with the strokes (no-op when it is;
    /// the first call makes it). A stroke edit changes `A` by `Σ Δw_e e_e e_eᵀ`: when at
    /// most [`FieldDesignOptions::rank1_update_limit`] edges change weight, the factor
    /// gets one multiple-rank update for the edges gaining weight and one multiple-rank
    /// downdate for those losing it (`Cholesky::add_diagonal_penalties`, Davis & Hager
    /// 2001); otherwise, if a downdate is refused, or after `16 ×` that many
    /// modifications since the last factorisation (to bound rounding drift), it is
    /// refactored numerically with the kept symbolic analysis
    /// ([`crate::design_factor`]).
    pub fn refactor_if_needed(&mut self) -> Result<(), FieldsError> {
        if self.stroke_diag.is_none() {
            self.stroke_diag = Some(self.stroke_diagonal());
        }
        let diag = self.stroke_diag.as_deref().expect("just made");
        let (factor, matrix) = (&mut self.factor, &self.equations.matrix);
        in_pool(|| factor.sync(matrix, diag, self.options.rank1_update_limit))
    }

    /// Refactors numerically now (e.g. when a front end is idle after many stroke edits,
    /// to drop the rounding drift of the accumulated updates and downdates).
    pub fn refresh_factorization(&mut self) -> Result<(), FieldsError> {
        self.factor.invalidate();
        self.refactor_if_needed()
    }

    /// Model 1-forms summed (`ω*`, `None` without model singularities), point divergence
    /// (`#V`) and point curl (`#F`) of `PointDelta` poles (empty for the model-field
    /// model), and whether there are any of the latter. Model fields of new or moved
    /// singularities are computed (in parallel over edges) and cached; the others are
    /// reused and summed in id order (the same sum for any edit history).
    fn singular_terms(&mut self) -> (Option<Vec<f64>>, Vec<f64>, Vec<f64>, bool) {
        let ne = self.dec.n_edges();
        let floor = 1e-3 * self.dec.mean_edge_length;
        let mut model: Option<Vec<f64>> = None;
        let point = self.options.singularity_model == SingularityModel::PointDelta;
        let (mut s_point, mut c_point) = if point {
            (vec![0.0; self.dec.n_vertices()], vec![0.0; self.dec.n_faces()])
        } else {
            (Vec::new(), Vec::new())
        };
        let mut any_point = false;
        for i in 0..self.singularities.len() {
            let Some(entry) = &self.singularities[i] else { continue };
            let s = entry.singularity;
            let (kind, c) = s.kind.model(s.angle, s.strength * self.reference_radius);
            if point && kind == ModelKind::Pole {
                let (f, b) = entry.face.expect("point singularities lie inside");
                let two_pi = 2.0 * std::f64::consts::PI;
                for k in 0..3 {
                    s_point[self.dec.triangles[f][k] as usize] += two_pi * c[0] * b[k];
                }
                c_point[f] += two_pi * c[1];
                any_point = true;
                continue;
            }
            let one_form = match &entry.one_form {
                Some(w) => w.clone(),
                None => {
                    let (e1, e2) = match entry.face {
                        Some((f, _)) => self.frames[f],
                        None => ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
                    };
                    let m = ModelField { kind, origin: entry.origin, e1, e2, c };
                    let mut w = vec![0.0; ne];
                    m.add_one_form(&self.dec, floor, &mut w);
                    let w = Arc::new(w);
                    self.singularities[i].as_mut().expect("live").one_form = Some(w.clone());
                    w
                }
            };
            match &mut model {
                Some(sum) => {
                    for (a, b) in sum.iter_mut().zip(one_form.iter()) {
                        *a += b;
                    }
                }
                None => model = Some(one_form.to_vec()),
            }
        }
        (model, s_point, c_point, any_point)
    }

    /// The right-hand side `b` (`#E`) of `A ω = b` for the current singularities and
    /// strokes (the full normal equations; [`FieldDesign::solve`] solves the cheaper
    /// deviation system where it can, see there).
    pub fn right_hand_side(&mut self) -> Vec<f64> {
        let (model, s_point, c_point, _) = self.singular_terms();
        self.equations.right_hand_side(
            &self.dec,
            model.as_deref(),
            &s_point,
            &c_point,
            self.strokes.iter().flatten().map(|(_, cs)| &cs[..]),
        )
    }

    /// Solves the design: refactors (or rank-1 updates) if strokes changed, rebuilds the
    /// right-hand side (recomputing only the model fields of edited singularities),
    /// back-substitutes.
    ///
    /// Without `PointDelta` poles the normal equations read `A ω = A₀ ω* + W t` (`A₀`:
    /// the stroke-free matrix, `W`, `t`: stroke weights and targets), so the deviation
    /// `δ = ω − ω*` solves `A δ = W (t − ω*)`, whose right-hand side lives on the stroke
    /// edges only: no sparse products, and no solve at all without strokes (`δ = 0`).
    /// `residual` is then the relative residual of the deviation system. With point
    /// poles the full `b` of [`FieldDesign::right_hand_side`] is solved.
    ///
    /// The whole solve runs as one job in the rayon pool: called from a thread outside
    /// the pool (a front end's UI thread), that is one hand-over instead of one per
    /// parallel loop, each of which waits for a sleeping worker to be scheduled.
    pub fn solve(&mut self) -> Result<SolvedField, FieldsError> {
        in_pool(|| self.solve_in_pool())
    }

    /// [`FieldDesign::solve`], then the field sampled on a `width × height` pixel grid
    /// into `pixels` ([`crate::orientation_field::sample_plane_into`]), in one job in the
    /// rayon pool: one interactive frame (plane designs only).
    pub fn solve_and_sample_into(
        &mut self,
        width: usize,
        height: usize,
        pixels: &mut Vec<[f32; 2]>,
    ) -> Result<SolvedField, FieldsError> {
        in_pool(|| {
            let field = self.solve_in_pool()?;
            crate::orientation_field::sample_plane_into(self, &field, width, height, pixels)?;
            Ok(field)
        })
    }

    fn solve_in_pool(&mut self) -> Result<SolvedField, FieldsError> {
        self.refactor_if_needed()?;
        let (model, s_point, c_point, any_point) = self.singular_terms();
        let factor = self.factor.factor_mut().expect("refactor_if_needed made the factor");
        let (one_form, residual) = match model {
            Some(model) if !any_point => {
                let mut b = vec![0.0; self.dec.n_edges()];
                let mut any = false;
                for (_, cs) in self.strokes.iter().flatten() {
                    for &(e, w, wt) in cs {
                        b[e] += wt - w * model[e];
                        any = true;
                    }
                }
                if any {
                    // `b` lives on the stroke edges: the forward solve visits their reach only
                    let (delta, residual) = factor.solve_sparse_with_residual(&b)?;
                    let mut omega = model;
                    omega.par_iter_mut().zip(delta.par_iter()).for_each(|(o, d)| *o += d);
                    (omega, residual)
                } else {
                    (model, 0.0)
                }
            }
            model => {
                let b = self.equations.right_hand_side(
                    &self.dec,
                    model.as_deref(),
                    &s_point,
                    &c_point,
                    self.strokes.iter().flatten().map(|(_, cs)| &cs[..]),
                );
                factor.solve_with_residual(&b)?
            }
        };
        let face_vectors = self.dec.face_vectors(&one_form);
        Ok(SolvedField { symmetry: self.symmetry, one_form, face_vectors, residual })
    }
}

/// Runs `op` as one job in the current rayon pool (inline when already on one of its
/// threads). Called from a thread outside the pool — a front end's UI thread — every
/// parallel loop would otherwise be handed over separately and wait for the sleeping
/// workers to be scheduled: on 2 loaded cores that measured ~1.5 ms per loop, 7.8 ms
/// instead of 2.5 ms for a 512² sampling (3 loops). Results do not change.
pub(crate) fn in_pool<R: Send>(op: impl FnOnce() -> R + Send) -> R {
    rayon::scope(|_| op())
}

/// Kinds valid for a symmetry (for UIs and the design file).
pub fn kinds_for(symmetry: Symmetry) -> Vec<SingularityKind> {
    SingularityKind::ALL.into_iter().filter(|k| k.symmetry() == symmetry).collect()
}
