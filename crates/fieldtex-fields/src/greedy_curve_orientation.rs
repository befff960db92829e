//! Greedy orientation of unoriented feature curves (Xu, Kim, Huang & Kalogerakis 2009,
//! "Feature-aligned shape texturing" — paper A, §4.1, eq. (1)), driving the harmonic
//! diffusion of [`crate::harmonic_diffusion`].
//!
//! **Score, eq. (1).** For a curve `c` with constraint vertices `V(c)` (its sampled
//! vertices, [`CurveFieldSolver::sample_curve`]) and the current field `u`, let
//! `θ_p ∈ [0, π]` be the angle between the curve's forward tangent at `p` and `u(p)`.
//! `forward = Σ_p (π − θ_p)/(π + θ_p)` scores the forward orientation (each term in
//! `[0, 1]`, 1 when aligned), `backward = Σ_p θ_p/(2π − θ_p)` the reversed one (the same
//! term for `π − θ_p`), and `g(c, u) = max(forward, backward)`, invariant to the curve's
//! orientation. The sum (not the mean) favours long consistent curves, as in the paper.
//! Vertices where `u` is not defined (component not yet solved, degenerate vector) do not
//! count ([`OrientationScore::n_points`]).
//!
//! **Greedy loop** ([`OrientationMode::Greedy`]). The longest curve (on-mesh arc length;
//! ties → lowest index) is taken first in its given (forward) orientation. Then, until
//! every curve is oriented: solve the field, score every unoriented curve, orient the
//! one with the highest `g` (ties → lowest index) by its better term (`forward ≥
//! backward` → `+1`), add its constraints as rank-1 updates. A curve whose vertices see
//! no field yet (it lies on a component no oriented curve touches) only becomes a
//! candidate when no scored curve remains; then the longest such curve starts its
//! component with `+1`.
//!
//! **Incremental solves** ([`CurveOrientationOptions::incremental_solves`], default on).
//! A round only needs the field at the vertices of the curves still pending, so after
//! the rank-1 updates the solution is corrected there alone
//! ([`CurveFieldSolver::solve_at`]: a sparse right-hand side on the new constraint
//! vertices, the elimination-tree reaches only); the last round solves fully with the
//! residual check. Same scores to rounding, hence the same orientations (the refined
//! horse: the same 178 steps and a byte-identical `field.ply`), at about a fifth of the
//! solve time.
//!
//! **Batching** (optional, not in the paper: [`CurveOrientationOptions::batch_consistency`]).
//! A round orients the best curve and also every curve whose mean consistency
//! `g / n_points` reaches `τ`, then solves once. Each solve costs two triangular solves
//! per component, which dominate the procedure on large meshes.
//!
//! **Arbitrary** ([`OrientationMode::Arbitrary`]): curve `i` gets `±1` from the random
//! stream `(seed, "curve-orientation", i)`, all constraints are added at once (one
//! factorisation per component) and solved once — the paper's Fig. 3(a) baseline.
//!
//! Curves that sample to no constraint (empty, off the mesh) are skipped with a warning
//! and get sign `0`.

use std::time::Instant;

use fieldtex_core::vec3::{self, V3};
use fieldtex_core::{Progress, Warning};
use fieldtex_mesh::{MeshGeometry, TriMesh};
use rand::RngExt;
use rayon::prelude::*;
use serde::Serialize;

use crate::FieldsError;
use crate::harmonic_diffusion::{
    CurveConstraints, CurveField, CurveFieldOptions, CurveFieldSolver,
};

/// Eq. (1) for both orientations of one curve.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct OrientationScore {
    /// `Σ (π − θ)/(π + θ)`: consistency of the forward orientation.
    pub forward: f64,
    /// `Σ θ/(2π − θ)`: consistency of the reversed orientation.
    pub backward: f64,
    /// Curve vertices where the field is defined (the terms of the sums).
    pub n_points: usize,
}

impl OrientationScore {
    /// `g(c, u) = max(forward, backward)`.
    pub fn best(&self) -> f64 {
        self.forward.max(self.backward)
    }
    /// Orientation achieving [`OrientationScore::best`]: `+1` (ties) or `−1`.
    pub fn sign(&self) -> i8 {
        if self.forward >= self.backward { 1 } else { -1 }
    }
    /// `forward − backward`: `+n` for a curve aligned with the field, `−n` reversed.
    pub fn signed(&self) -> f64 {
        self.forward - self.backward
    }
}

/// Eq. (1) of `tangents` (unit, forward orientation) against `field(i)`, the unit field
/// at the `i`-th point (`None` where undefined; such points are skipped).
pub fn orientation_score(tangents: &[V3], field: impl Fn(usize) -> Option<V3>) -> OrientationScore {
    use std::f64::consts::PI;
    let mut s = OrientationScore::default();
    for (i, &t) in tangents.iter().enumerate() {
        let Some(u) = field(i) else { continue };
        let theta = vec3::norm(vec3::cross(t, u)).atan2(vec3::dot(t, u));
        if !theta.is_finite() {
            continue;
        }
        s.forward += (PI - theta) / (PI + theta);
        s.backward += theta / (2.0 * PI - theta);
        s.n_points += 1;
    }
    s
}

/// How curve orientations are chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum OrientationMode {
    /// Paper A §4.1 (module docs). Default.
    #[default]
    Greedy,
    /// Random signs from `(seed, "curve-orientation", i)`, all constraints at once.
    Arbitrary { seed: u64 },
}

/// Options of [`orient_curves`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurveOrientationOptions {
    /// Default [`OrientationMode::Greedy`].
    pub mode: OrientationMode,
    /// Options of the diffusion (penalty `1e8`, sampling, overlap, fallback).
    pub field: CurveFieldOptions,
    /// Greedy batching (not in the paper): `Some(τ)` also orients, in the same round and
    /// before one shared solve, every curve whose mean consistency
    /// `g / n_points ≥ τ` (`τ = 0.9` ⇔ mean angle to the field ≲ 9.5°). Such curves
    /// agree with the field already, so adding them changes it little; this saves
    /// solves at the risk of orienting differently from the one-per-step greedy.
    /// Default `None` (the paper's algorithm). Must lie in `(0, 1]`.
    pub batch_consistency: Option<f64>,
    /// Greedy: after each round, update the solution only at the vertices of the curves
    /// still pending ([`CurveFieldSolver::solve_at`], the same values to rounding) instead
    /// of a full solve; the last round solves fully. Default `true`.
    pub incremental_solves: bool,
}

impl Default for CurveOrientationOptions {
    fn default() -> Self {
        Self {
            mode: OrientationMode::default(),
            field: CurveFieldOptions::default(),
            batch_consistency: None,
            incremental_solves: true,
        }
    }
}

/// One orientation step (greedy), or the single step of the arbitrary mode
/// (`curve = usize::MAX`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OrientationStep {
    /// Input index of the curve oriented in this step.
    pub curve: usize,
    /// `+1`: as given; `−1`: reversed.
    pub sign: i8,
    /// Greedy round (one solve per round; one curve per round unless batching).
    pub round: usize,
    /// `g(c, u)` against the field before this step (`NaN` for a curve that starts a
    /// component and the arbitrary step).
    pub score: f64,
    /// `g / n_points` (mean consistency in `[0, 1]`; `NaN` as above).
    pub normalized_score: f64,
    /// Penalties added in this step (rank-1 updates, or a first factorisation).
    pub new_constraints: usize,
    /// Time of the rank-1 updates of this step.
    pub update_ms: f64,
    /// Time of first factorisations in this step (the first curve of a component).
    pub factor_ms: f64,
    /// Time of the solve after this step (only the last curve of a batched round).
    pub solve_ms: f64,
    /// Largest relative residual of the full solves after this step (0 when the solve
    /// was incremental only; the final full solve is checked).
    pub residual: f64,
    /// Whether the solve after this step was incremental (at the pending curves'
    /// vertices only, [`CurveFieldSolver::solve_at`]).
    pub incremental: bool,
}

/// Result of [`orient_curves`].
pub struct CurveOrientationResult<'m> {
    /// Per input curve: `+1`, `−1`, or `0` for curves that gave no constraint.
    pub signs: Vec<i8>,
    /// Constraints of every input curve (forward orientation).
    pub curves: Vec<CurveConstraints>,
    pub steps: Vec<OrientationStep>,
    /// The final field (projected, normalised, fallback applied).
    pub field: CurveField,
    /// The solver with the final factorisation (for metrics and comparisons).
    pub solver: CurveFieldSolver<'m>,
    /// Wall time of the whole procedure (sampling, factorisations, updates, solves,
    /// scoring), in milliseconds.
    pub total_ms: f64,
    pub warnings: Vec<Warning>,
}

/// Orients `curves` (polylines, `#points × 3` each) and solves the constrained field on
/// `mesh` (module docs). Errors: invalid mesh or options, failed solves.
pub fn orient_curves<'m>(
    mesh: &'m TriMesh,
    curves: &[Vec<V3>],
    options: &CurveOrientationOptions,
    progress: &dyn Progress,
) -> Result<CurveOrientationResult<'m>, FieldsError> {
    orient_curves_with_geometry(&MeshGeometry::new(mesh), curves, options, progress)
}

/// [`orient_curves`] over a pipeline's [`MeshGeometry`] (the solver takes its vertex
/// normals from it: [`CurveFieldSolver::with_geometry`]).
pub fn orient_curves_with_geometry<'m>(
    geometry: &MeshGeometry<'m>,
    curves: &[Vec<V3>],
    options: &CurveOrientationOptions,
    progress: &dyn Progress,
) -> Result<CurveOrientationResult<'m>, FieldsError> {
    let t_start = Instant::now();
    if let Some(tau) = options.batch_consistency
        && !(tau > 0.0 && tau <= 1.0)
    {
        return Err(FieldsError::InvalidOption {
            name: "batch_consistency",
            value: tau,
            expected: "a number in (0, 1]",
        });
    }
    let mut solver = CurveFieldSolver::with_geometry(geometry, &options.field)?;
    let sampled: Vec<CurveConstraints> =
        curves.par_iter().map(|c| solver.sample_curve(c)).collect();
    let mut warnings = Vec::new();
    let mut signs = vec![0i8; curves.len()];
    let mut pending: Vec<usize> = Vec::new();
    let (mut n_empty, mut n_dropped) = (0usize, 0usize);
    for (i, c) in sampled.iter().enumerate() {
        n_dropped += c.dropped_samples;
        if c.vertices.is_empty() {
            n_empty += 1;
        } else {
            pending.push(i);
        }
    }
    if n_empty > 0 {
        warnings.push(Warning::new(
            "curves-without-constraints",
            format!(
                "{n_empty} of {} curves are empty, too short or off the mesh and were ignored",
                curves.len()
            ),
        ));
    }
    if n_dropped > 0 {
        warnings.push(Warning::new(
            "curve-samples-off-mesh",
            format!(
                "{n_dropped} curve samples were non-finite or farther than {} mean edge lengths \
                 from the mesh and were dropped",
                options.field.max_distance
            ),
        ));
    }
    progress.stage("orient curves", pending.len() as u64);
    let mut steps = Vec::new();
    match options.mode {
        OrientationMode::Arbitrary { seed } => {
            let mut step = empty_step(usize::MAX, 0);
            for &i in &pending {
                let sign = if fieldtex_core::stream(seed, "curve-orientation", i as u64).random() {
                    1
                } else {
                    -1
                };
                signs[i] = sign;
            }
            let all: Vec<_> = pending.iter().map(|&i| (&sampled[i], f64::from(signs[i]))).collect();
            let r = solver.add_constraints_many(&all)?;
            step.new_constraints += r.new_vertices;
            step.update_ms += 1e3 * r.update_seconds;
            step.factor_ms += 1e3 * r.factor_seconds;
            progress.advance(pending.len() as u64);
            let s = solver.solve()?;
            step.solve_ms = 1e3 * s.seconds;
            step.residual = s.max_residual;
            steps.push(step);
        }
        OrientationMode::Greedy => {
            let batch = options.batch_consistency;
            let incremental = options.incremental_solves;
            let mut round = 0;
            while !pending.is_empty() {
                let scores: Vec<OrientationScore> = pending
                    .par_iter()
                    .map(|&i| {
                        let c = &sampled[i];
                        orientation_score(&c.tangents, |k| {
                            solver.tangent_at(c.vertices[k] as usize)
                        })
                    })
                    .collect();
                let chosen = choose(&pending, &scores, &sampled, batch);
                // vertices of the curves still pending after this round: the only places
                // the next round scores, so the solve after it is incremental there
                let mut taken: Vec<usize> = chosen.iter().map(|&(k, _)| k).collect();
                taken.sort_unstable();
                let needed: Vec<u32> = pending
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| taken.binary_search(k).is_err())
                    .flat_map(|(_, &i)| sampled[i].vertices.iter().copied())
                    .collect();
                for (n, &(k, sign)) in chosen.iter().enumerate() {
                    let i = pending[k];
                    signs[i] = sign;
                    let mut step = empty_step(i, sign);
                    step.round = round;
                    if scores[k].n_points > 0 {
                        step.score = scores[k].best();
                        step.normalized_score = step.score / scores[k].n_points as f64;
                    }
                    let r = solver.add_constraints(&sampled[i], f64::from(sign))?;
                    step.new_constraints = r.new_vertices;
                    step.update_ms = 1e3 * r.update_seconds;
                    step.factor_ms = 1e3 * r.factor_seconds;
                    if n + 1 == chosen.len() {
                        let s = if needed.is_empty() || !incremental {
                            solver.solve()?
                        } else {
                            solver.solve_at(&needed)?
                        };
                        step.solve_ms = 1e3 * s.seconds;
                        step.residual = s.max_residual;
                        step.incremental = s.incremental > 0;
                    }
                    steps.push(step);
                    progress.advance(1);
                }
                for k in taken.into_iter().rev() {
                    pending.remove(k);
                }
                round += 1;
            }
        }
    }
    progress.finish_stage();
    let field = solver.field()?;
    warnings.extend(field.warnings.iter().cloned());
    Ok(CurveOrientationResult {
        signs,
        curves: sampled,
        steps,
        field,
        solver,
        total_ms: 1e3 * t_start.elapsed().as_secs_f64(),
        warnings,
    })
}

/// The curves oriented in one greedy round, as `(position in pending, sign)`: the best
/// scored curve (ties → lowest index) or, when no pending curve sees a field, the
/// longest one with `+1`; with `batch = Some(τ)` also every other scored curve whose
/// normalised score reaches `τ`, by decreasing score.
fn choose(
    pending: &[usize],
    scores: &[OrientationScore],
    sampled: &[CurveConstraints],
    batch: Option<f64>,
) -> Vec<(usize, i8)> {
    let mut pick: Option<usize> = None;
    for (k, s) in scores.iter().enumerate() {
        if s.n_points > 0 && pick.is_none_or(|b| s.best() > scores[b].best()) {
            pick = Some(k);
        }
    }
    let Some(best) = pick else {
        let mut k = 0;
        for j in 1..pending.len() {
            if sampled[pending[j]].length > sampled[pending[k]].length {
                k = j;
            }
        }
        return vec![(k, 1)];
    };
    let mut chosen = vec![(best, scores[best].sign())];
    if let Some(tau) = batch {
        let mut extra: Vec<usize> = (0..scores.len())
            .filter(|&k| {
                k != best
                    && scores[k].n_points > 0
                    && scores[k].best() >= tau * scores[k].n_points as f64
            })
            .collect();
        extra.sort_by(|&a, &b| scores[b].best().total_cmp(&scores[a].best()).then(a.cmp(&b)));
        chosen.extend(extra.into_iter().map(|k| (k, scores[k].sign())));
    }
    chosen
}

fn empty_step(curve: usize, sign: i8) -> OrientationStep {
    OrientationStep {
        curve,
        sign,
        round: 0,
        score: f64::NAN,
        normalized_score: f64::NAN,
        new_constraints: 0,
        update_ms: 0.0,
        factor_ms: 0.0,
        solve_ms: 0.0,
        residual: 0.0,
        incremental: false,
    }
}

/// Diffuses the field of `curves` with given orientations (`signs[i]`: `+1` as given,
/// `−1` reversed, `0` skip) on `mesh`: all penalties at once (one factorisation per
/// component), one solve. Curves that sample to no constraint on `mesh` get sign 0.
/// Errors: `signs.len() != curves.len()`, invalid mesh or options, failed solves.
pub fn orient_curves_with_signs<'m>(
    mesh: &'m TriMesh,
    curves: &[Vec<V3>],
    signs: &[i8],
    options: &CurveFieldOptions,
) -> Result<CurveOrientationResult<'m>, FieldsError> {
    let t0 = Instant::now();
    if signs.len() != curves.len() {
        return Err(FieldsError::InvalidOption {
            name: "signs (one per curve)",
            value: signs.len() as f64,
            expected: "as many signs as curves",
        });
    }
    let mut solver = CurveFieldSolver::new(mesh, options)?;
    let sampled: Vec<CurveConstraints> =
        curves.par_iter().map(|c| solver.sample_curve(c)).collect();
    let mut out_signs = vec![0i8; curves.len()];
    let mut all = Vec::new();
    for (i, (c, &s)) in sampled.iter().zip(signs).enumerate() {
        if s != 0 && !c.vertices.is_empty() {
            out_signs[i] = s.signum();
            all.push((c, f64::from(s.signum())));
        }
    }
    let added = solver.add_constraints_many(&all)?;
    let solved = solver.solve()?;
    let field = solver.field()?;
    let warnings = field.warnings.clone();
    let step = OrientationStep {
        curve: usize::MAX,
        sign: 0,
        round: 0,
        score: f64::NAN,
        normalized_score: f64::NAN,
        new_constraints: added.new_vertices,
        update_ms: 1e3 * added.update_seconds,
        factor_ms: 1e3 * added.factor_seconds,
        solve_ms: 1e3 * solved.seconds,
        residual: solved.max_residual,
        incremental: false,
    };
    Ok(CurveOrientationResult {
        signs: out_signs,
        curves: sampled,
        steps: vec![step],
        field,
        solver,
        total_ms: 1e3 * t0.elapsed().as_secs_f64(),
        warnings,
    })
}
