//! Curve-constrained harmonic diffusion of a tangent vector field (Xu, Kim, Huang &
//! Kalogerakis 2009, "Feature-aligned shape texturing" — paper A, §4.2, eq. (2)).
//!
//! **System.** Each ambient component `x, y, z` of the field is the minimiser of
//! `½ xᵀ L x + ‖P^½ (x − b)‖²`, i.e. the solution of `(L + P) x = P b`, where `L` is the
//! `#V × #V` cotan Laplacian of `fieldtex_mesh` (positive semi-definite, `L·1 = 0`),
//! `P = α · diag(constrained)` with `α` = [`CurveFieldOptions::penalty`] (paper: `1e8`),
//! and `b` the `#V × 3` constraint tangents. The three components share one factor of
//! `L + P` (three right-hand sides). The ambient result is projected onto the vertex
//! tangent planes (angle-weighted vertex normals) and normalised; a vertex whose
//! projection vanishes (`|x_t| < 1e-9`) is [`VertexFieldStatus::Degenerate`] (zero).
//!
//! **Constraints from curves** ([`CurveFieldSolver::sample_curve`]). A polyline is
//! resampled every `sample_spacing · h` (`h` = mean edge length); every sample goes to
//! its *nearest mesh vertex* within `max_distance · h` (farther samples are dropped:
//! the curve is off the mesh there). A vertex collects the length-weighted sum of the
//! segment directions of its samples; projected to its tangent plane and normalised, that
//! is its constraint tangent for the polyline's own (forward) orientation. A vertex where
//! the directions cancel (a hairpin) or the curve runs along the normal is dropped. The
//! nearest-vertex rule is the paper's (its curves are vertex sequences); the vertices of
//! the crossed triangles would constrain a band three times as wide and blur the field.
//!
//! **Components.** Connected components (triangles sharing a vertex, ignoring triangles
//! whose corners coincide) are independent blocks, each with its own factor. A block is
//! factored (symbolic + numeric) when it receives its first constraints; **every later
//! constraint updates that factor by `+ Σ α eᵢ eᵢᵀ`**: the new penalties of one call
//! form one multiple-rank update (Davis & Hager 2001, equal to rank-1 updates in turn but
//! walking the union of their elimination-tree paths once; via
//! `fieldtex_linalg::Cholesky::add_diagonal_penalties`), never a refactorisation. A
//! component without constraints gets [`UnconstrainedFallback`] and a warning.
//!
//! **A vertex constrained twice** (curves crossing or touching), [`OverlapPolicy`]:
//! `KeepFirst` (default) keeps the first curve's tangent — the greedy orientation adds
//! the most consistent curves first; `Average` replaces the target by the normalised sum
//! of all oriented tangents at the vertex (only `b` changes, the factor does not).
//!
//! The three components are solved together, one pass over the factor for all three
//! right-hand sides (`fieldtex_linalg::Cholesky::solve_many`).
//!
//! Files: options, constraints and reports in `curve_field_types.rs`; constraint
//! sampling from curves in `curve_constraint_sampling.rs`; the per-component block
//! systems and their first factorisation in `curve_field_blocks.rs`; the solver here.
//!
//! Not implemented: removing curves (multiple-rank downdates exist in `fieldtex_linalg`,
//! `Cholesky::remove_diagonal_penalties`, but no caller needs them yet).

use std::collections::HashMap;
use std::time::Instant;

use fieldtex_core::Warning;
use fieldtex_core::vec3::{self, V3};
use fieldtex_linalg::Cholesky;
use fieldtex_mesh::{
    CotanOptions, CurvatureOptions, MeshError, MeshGeometry, NormalWeighting, SpatialGrid, TriMesh,
    UnionFind, cotan_laplacian_with, principal_curvatures,
};

use crate::FieldsError;
use crate::curve_field_blocks::{Block, block_rhs, extract_block, factor_block, penalised_matrix};
pub use crate::curve_field_types::{
    AddReport, CurveConstraints, CurveField, CurveFieldOptions, FillOrdering, OverlapPolicy,
    SolveReport, UnconstrainedFallback, VertexFieldStatus,
};

/// Sentinel for "no component" (a vertex used by no usable triangle).
const NONE: u32 = u32::MAX;

/// The diffusion system of one mesh with its kept factorisations (module docs).
///
/// Typical use: [`CurveFieldSolver::new`], then per curve
/// [`CurveFieldSolver::sample_curve`] and [`CurveFieldSolver::add_constraints`] with a
/// sign, [`CurveFieldSolver::solve`], and finally [`CurveFieldSolver::field`].
pub struct CurveFieldSolver<'m> {
    pub(crate) mesh: &'m TriMesh,
    pub(crate) options: CurveFieldOptions,
    pub(crate) normals: Vec<V3>,
    component: Vec<u32>,
    local: Vec<u32>,
    blocks: Vec<Block>,
    /// Per vertex: the unit target and the sum of oriented tangents (for `Average`).
    targets: Vec<Option<(V3, V3)>>,
    /// Constrained vertices in the order they were added.
    constrained: Vec<u32>,
    raw: Vec<V3>,
    /// Whether `raw[v]` is current (false outside the `needed` set of an incremental
    /// solve, [`CurveFieldSolver::solve_at`]).
    current: Vec<bool>,
    pub(crate) mean_edge: f64,
    /// The usable vertices, for nearest-vertex queries.
    pub(crate) grid: SpatialGrid,
    warnings: Vec<Warning>,
}

impl<'m> CurveFieldSolver<'m> {
    /// Builds `L`, the components and the vertex normals. Errors: invalid mesh (indices,
    /// non-finite positions), a mesh without usable triangles, invalid options.
    pub fn new(mesh: &'m TriMesh, options: &CurveFieldOptions) -> Result<Self, FieldsError> {
        Self::with_geometry(&MeshGeometry::new(mesh), options)
    }

    /// [`Self::new`] taking the vertex normals from a pipeline's [`MeshGeometry`]
    /// (computed once per mesh; the same values, so the same field).
    pub fn with_geometry(
        geometry: &MeshGeometry<'m>,
        options: &CurveFieldOptions,
    ) -> Result<Self, FieldsError> {
        let mesh = geometry.mesh();
        options.validate()?;
        mesh.validate()?;
        let nv = mesh.n_vertices();
        let p = &mesh.positions;
        let usable_tri = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|i| p[i as usize]);
            !(a == b && b == c)
        };
        let mut uf = UnionFind::new(nv);
        let mut used = vec![false; nv];
        let (mut edge_sum, mut edge_count) = (0.0, 0usize);
        for t in mesh.triangles.iter().filter(|t| usable_tri(t)) {
            uf.union(t[0] as usize, t[1] as usize);
            uf.union(t[0] as usize, t[2] as usize);
            for i in 0..3 {
                used[t[i] as usize] = true;
                edge_sum += vec3::norm(vec3::sub(p[t[i] as usize], p[t[(i + 1) % 3] as usize]));
                edge_count += 1;
            }
        }
        let mean_edge = edge_sum / edge_count.max(1) as f64;
        if edge_count == 0 || !(mean_edge > 0.0 && mean_edge.is_finite()) {
            return Err(FieldsError::InvalidMesh(MeshError::Precondition {
                operation: "curve-constrained field",
                requirement: "at least one triangle with distinct corners",
                found: format!("{} triangles, none usable", mesh.n_triangles()),
            }));
        }
        // Components numbered by their lowest vertex; local indices increase globally.
        let mut component = vec![NONE; nv];
        let mut local = vec![NONE; nv];
        let mut root_label: HashMap<usize, u32> = HashMap::new();
        let mut members: Vec<Vec<u32>> = Vec::new();
        for v in (0..nv).filter(|&v| used[v]) {
            let r = uf.find(v);
            let c = *root_label.entry(r).or_insert_with(|| {
                members.push(Vec::new());
                (members.len() - 1) as u32
            });
            component[v] = c;
            local[v] = members[c as usize].len() as u32;
            members[c as usize].push(v as u32);
        }
        let (l, stats) = cotan_laplacian_with(mesh, &CotanOptions::default())?;
        let mut warnings = stats.warnings();
        let isolated = nv - used.iter().filter(|&&u| u).count();
        if isolated > 0 {
            warnings.push(Warning::new(
                "field-isolated-vertices",
                format!(
                    "{isolated} vertices belong to no usable triangle; their field vector is zero"
                ),
            ));
        }
        let blocks = members
            .into_iter()
            .enumerate()
            .map(|(c, verts)| {
                let laplacian = extract_block(&l, &verts, &local, &component, c as u32)?;
                Ok(Block {
                    vertices: verts,
                    laplacian,
                    symbolic: None,
                    factor: None,
                    dirty: false,
                    failed: false,
                    fresh: Vec::new(),
                    needs_full: true,
                    partial: false,
                })
            })
            .collect::<Result<Vec<_>, FieldsError>>()?;
        let normals = geometry.require_vertex_normals(NormalWeighting::Angle).0.to_vec();
        let boxes: Vec<(V3, V3)> = (0..nv)
            .map(|v| if used[v] { (p[v], p[v]) } else { ([f64::NAN; 3], [f64::NAN; 3]) })
            .collect();
        let grid = SpatialGrid::from_boxes(&boxes, mean_edge);
        Ok(Self {
            mesh,
            options: options.clone(),
            normals,
            component,
            local,
            blocks,
            targets: vec![None; nv],
            constrained: Vec::new(),
            raw: vec![[0.0; 3]; nv],
            current: vec![true; nv],
            mean_edge,
            grid,
            warnings,
        })
    }

    /// Mean edge length `h` of the usable triangles.
    pub fn mean_edge_length(&self) -> f64 {
        self.mean_edge
    }

    /// Number of connected components (independent blocks).
    pub fn n_components(&self) -> usize {
        self.blocks.len()
    }

    /// Component of vertex `v`, `None` for isolated vertices.
    pub fn component_of(&self, v: usize) -> Option<usize> {
        (self.component[v] != NONE).then_some(self.component[v] as usize)
    }

    /// The unit vertex normals used for projection.
    pub fn normals(&self) -> &[V3] {
        &self.normals
    }

    /// Warnings gathered so far (Laplacian clamping, isolated vertices, failed blocks).
    pub fn warnings(&self) -> &[Warning] {
        &self.warnings
    }

    /// Every constrained vertex with its unit target tangent, in insertion order.
    pub fn constraints(&self) -> Vec<(u32, V3)> {
        self.constrained
            .iter()
            .map(|&v| (v, self.targets[v as usize].expect("constrained vertex has a target").0))
            .collect()
    }

    /// Whether vertex `v` carries a penalty.
    pub fn is_constrained(&self, v: usize) -> bool {
        self.targets[v].is_some()
    }

    /// Adds the constraints of one curve with orientation `sign` (`+1` forward, `−1`
    /// reversed): a component's first constraints factor it, later ones are rank-1
    /// updates. Marks the touched components for [`CurveFieldSolver::solve`].
    pub fn add_constraints(
        &mut self,
        curve: &CurveConstraints,
        sign: f64,
    ) -> Result<AddReport, FieldsError> {
        self.add_constraints_many(&[(curve, sign)])
    }

    /// Adds the constraints of several curves at once (`(curve, sign)` in order, as
    /// repeated [`CurveFieldSolver::add_constraints`] would): every target is set
    /// first, then each touched component is factored once — a first factorisation
    /// with all its penalties, rank-1 updates of an existing factor, or, when the new
    /// penalties outnumber [`CurveFieldOptions::refactor_above`], a numeric
    /// refactorisation with the kept symbolic analysis. Same field as one curve at a
    /// time (to rounding), without a rank-1 update per vertex after the first curve.
    pub fn add_constraints_many(
        &mut self,
        curves: &[(&CurveConstraints, f64)],
    ) -> Result<AddReport, FieldsError> {
        let mut report = AddReport::default();
        let mut fresh: Vec<Vec<u32>> = vec![Vec::new(); self.blocks.len()];
        for &(curve, sign) in curves {
            let s = if sign < 0.0 { -1.0 } else { 1.0 };
            for (&v, &t) in curve.vertices.iter().zip(&curve.tangents) {
                let vi = v as usize;
                if vi >= self.targets.len() || self.component[vi] == NONE {
                    continue;
                }
                let t = vec3::scale(t, s);
                let c = self.component[vi] as usize;
                match (&mut self.targets[vi], self.options.overlap) {
                    (Some(_), OverlapPolicy::KeepFirst) => report.overlapping_vertices += 1,
                    (Some((target, sum)), OverlapPolicy::Average) => {
                        report.overlapping_vertices += 1;
                        *sum = vec3::add(*sum, t);
                        if let Some(u) = vec3::normalize(*sum) {
                            *target = u;
                        }
                        self.blocks[c].dirty = true;
                        self.blocks[c].needs_full = true;
                    }
                    (slot @ None, _) => {
                        *slot = Some((t, t));
                        self.constrained.push(v);
                        fresh[c].push(v);
                        self.blocks[c].fresh.push(v);
                        report.new_vertices += 1;
                    }
                }
            }
        }
        let alpha = self.options.penalty;
        let refactor_above = self.options.refactor_above;
        for (c, verts) in fresh.into_iter().enumerate().filter(|(_, f)| !f.is_empty()) {
            let block = &mut self.blocks[c];
            block.dirty = true;
            if block.failed {
                continue;
            }
            if let Some(factor) = block.factor.as_mut().filter(|_| verts.len() <= refactor_above) {
                let t0 = Instant::now();
                let penalties: Vec<(usize, f64)> =
                    verts.iter().map(|&v| (self.local[v as usize] as usize, alpha)).collect();
                factor.add_diagonal_penalties(&penalties)?;
                report.update_seconds += t0.elapsed().as_secs_f64();
                report.rank1_updates += verts.len();
                continue;
            }
            if block.factor.is_none() {
                block.needs_full = true;
            }
            let t0 = Instant::now();
            let result =
                factor_block(block, &self.targets, alpha, self.options.ordering, self.mesh);
            report.factor_seconds += t0.elapsed().as_secs_f64();
            report.factorisations += 1;
            if let Err(e) = result {
                block.failed = true;
                self.warnings.push(Warning::new(
                    "field-component-unsolvable",
                    format!(
                        "component {c} ({} vertices) could not be factored ({e}); it gets the \
                         fallback field — repair the mesh (degenerate triangles?)",
                        block.vertices.len()
                    ),
                ));
            }
        }
        Ok(report)
    }

    /// Solves `(L + P) x = P b` (3 right-hand sides) on every component whose constraints
    /// changed since the last solve or whose last solve was incremental (full solves
    /// with the residual check of `fieldtex_linalg`).
    pub fn solve(&mut self) -> Result<SolveReport, FieldsError> {
        let t0 = Instant::now();
        let mut report = SolveReport::default();
        for c in 0..self.blocks.len() {
            if self.blocks[c].dirty || self.blocks[c].partial {
                self.full_solve(c, &mut report)?;
            }
        }
        report.seconds = t0.elapsed().as_secs_f64();
        Ok(report)
    }

    fn full_solve(&mut self, c: usize, report: &mut SolveReport) -> Result<(), FieldsError> {
        let alpha = self.options.penalty;
        let block = &mut self.blocks[c];
        block.dirty = false;
        let Some(factor) = block.factor.as_ref() else { return Ok(()) };
        let rhs = block_rhs(&block.vertices, &self.targets, alpha);
        let x = factor.solve_many(&rhs)?;
        report.max_residual = report.max_residual.max(factor.last_residual());
        for (i, &v) in block.vertices.iter().enumerate() {
            self.raw[v as usize] = [x[0][i], x[1][i], x[2][i]];
            self.current[v as usize] = true;
        }
        block.partial = false;
        block.fresh.clear();
        block.needs_full = false;
        report.components_solved += 1;
        Ok(())
    }

    /// Brings the solution up to date **at the vertices `needed` only** (an incremental
    /// solve for the greedy orientation, which scores curves on their own vertices).
    /// If `x` solved the system before the new penalties, the new solution is
    /// `x' = x + (L + P')⁻¹ r` with `r = α (b_v − x_v)` on the newly constrained vertices
    /// `v` and zero elsewhere; `fieldtex_linalg::Cholesky::solve_sparse_at` computes the
    /// correction at `needed` from the two elimination-tree reaches alone. This needs
    /// `x` current at the new vertices and at `needed` (all of them in the `needed` of
    /// every incremental solve since the last full one — the greedy loop's pending
    /// curves only shrink); otherwise, and after a first factorisation or an `Average`
    /// target change, the component gets a full solve. Elsewhere the solution is left
    /// stale ([`CurveFieldSolver::tangent_at`] gives `None` there) until the next
    /// [`CurveFieldSolver::solve`]; [`CurveFieldSolver::field`] refuses stale vertices.
    /// No residual check for the incremental part (`max_residual` covers the full solves
    /// only); the final full solve checks it.
    pub fn solve_at(&mut self, needed: &[u32]) -> Result<SolveReport, FieldsError> {
        let t0 = Instant::now();
        let mut report = SolveReport::default();
        let alpha = self.options.penalty;
        let mut per_block: Vec<Vec<u32>> = vec![Vec::new(); self.blocks.len()];
        for &v in needed {
            if let Some(&c) = self.component.get(v as usize).filter(|&&c| c != NONE) {
                per_block[c as usize].push(v);
            }
        }
        // a vertex on two pending curves must get its correction once
        for need in &mut per_block {
            need.sort_unstable();
            need.dedup();
        }
        for (c, need) in per_block.iter().enumerate() {
            let need_current = need.iter().all(|&v| self.current[v as usize]);
            if !self.blocks[c].dirty && need_current {
                continue;
            }
            let block = &self.blocks[c];
            let incremental = block.factor.is_some()
                && !block.needs_full
                && need_current
                && block.fresh.iter().all(|&v| self.current[v as usize]);
            if !incremental {
                self.full_solve(c, &mut report)?;
                continue;
            }
            let residuals: Vec<(usize, [f64; 3])> = block
                .fresh
                .iter()
                .filter_map(|&v| {
                    let (t, _) = self.targets[v as usize]?;
                    let x = self.raw[v as usize];
                    let r = [0, 1, 2].map(|k| alpha * (t[k] - x[k]));
                    Some((self.local[v as usize] as usize, r))
                })
                .collect();
            let rhs: Vec<(usize, &[f64])> = residuals.iter().map(|(i, r)| (*i, &r[..])).collect();
            let local: Vec<usize> = need.iter().map(|&v| self.local[v as usize] as usize).collect();
            let block = &mut self.blocks[c];
            let factor = block.factor.as_mut().expect("checked above");
            let z = factor.solve_sparse_at(&rhs, &local, 3)?;
            for &v in &block.vertices {
                self.current[v as usize] = false;
            }
            for (q, &v) in need.iter().enumerate() {
                let x = &mut self.raw[v as usize];
                for k in 0..3 {
                    x[k] += z[q * 3 + k];
                }
                self.current[v as usize] = true;
            }
            block.fresh.clear();
            block.dirty = false;
            block.partial = true;
            report.components_solved += 1;
            report.incremental += 1;
        }
        report.seconds = t0.elapsed().as_secs_f64();
        Ok(report)
    }

    /// The last ambient solution `x` (`#V × 3`, before projection; 0 outside solved
    /// components; stale outside the `needed` set of an incremental
    /// [`CurveFieldSolver::solve_at`] until the next full [`CurveFieldSolver::solve`]).
    pub fn raw_solution(&self) -> &[V3] {
        &self.raw
    }

    /// The unit tangent field at `v` from the last solve, `None` where it is not defined
    /// (component without factor, isolated or degenerate vertex, or left stale by an
    /// incremental [`CurveFieldSolver::solve_at`]).
    pub fn tangent_at(&self, v: usize) -> Option<V3> {
        let c = self.component[v];
        if c == NONE || self.blocks[c as usize].factor.is_none() || !self.current[v] {
            return None;
        }
        project_unit(self.raw[v], self.normals[v])
    }

    /// For comparison with the updated factors: factors `L + P` of every constrained
    /// component from scratch (numeric factorisation, reusing the symbolic analysis),
    /// solves, and returns the ambient solution and the total numeric-factorisation time
    /// in seconds. The solver state is unchanged.
    pub fn refactored_solution(&self) -> Result<(Vec<V3>, f64), FieldsError> {
        let mut raw = vec![[0.0; 3]; self.raw.len()];
        let mut seconds = 0.0;
        let alpha = self.options.penalty;
        for block in self.blocks.iter().filter(|b| b.factor.is_some()) {
            let symbolic = block.symbolic.as_ref().expect("factored blocks keep the analysis");
            let a = penalised_matrix(block, &self.targets, alpha);
            let t0 = Instant::now();
            let factor = Cholesky::factor_with(symbolic, &a)?;
            seconds += t0.elapsed().as_secs_f64();
            let x = factor.solve_many(&block_rhs(&block.vertices, &self.targets, alpha))?;
            for (i, &v) in block.vertices.iter().enumerate() {
                raw[v as usize] = [x[0][i], x[1][i], x[2][i]];
            }
        }
        Ok((raw, seconds))
    }

    /// The projected, normalised field of the last solve, with the fallback on
    /// components without constraints (module docs) and warnings about both.
    pub fn field(&self) -> Result<CurveField, FieldsError> {
        let nv = self.raw.len();
        let stale = self
            .blocks
            .iter()
            .filter(|b| b.factor.is_some())
            .flat_map(|b| &b.vertices)
            .filter(|&&v| !self.current[v as usize])
            .count();
        if stale > 0 {
            return Err(FieldsError::StaleSolution { stale });
        }
        let mut vectors = vec![[0.0; 3]; nv];
        let mut status = vec![VertexFieldStatus::Isolated; nv];
        let mut warnings = self.warnings.clone();
        let mut fallback_vertices = 0usize;
        let mut fallback_components = 0usize;
        for block in &self.blocks {
            if block.factor.is_some() {
                for &v in &block.vertices {
                    let v = v as usize;
                    match project_unit(self.raw[v], self.normals[v]) {
                        Some(u) => (vectors[v], status[v]) = (u, VertexFieldStatus::Solved),
                        None => status[v] = VertexFieldStatus::Degenerate,
                    }
                }
            } else {
                fallback_components += 1;
                fallback_vertices += block.vertices.len();
                for &v in &block.vertices {
                    status[v as usize] = VertexFieldStatus::Fallback;
                }
            }
        }
        let degenerate = status.iter().filter(|&&s| s == VertexFieldStatus::Degenerate).count();
        if degenerate > 0 {
            warnings.push(Warning::new(
                "field-degenerate-vertices",
                format!(
                    "{degenerate} vertices got a diffused vector normal to the surface or zero \
                     (between opposing curves); their field vector is zero"
                ),
            ));
        }
        if fallback_components > 0 {
            let what = match self.options.fallback {
                UnconstrainedFallback::PrincipalDirection => {
                    let (pc, _) = principal_curvatures(self.mesh, &CurvatureOptions::default())?;
                    for (v, s) in status.iter().enumerate() {
                        if *s == VertexFieldStatus::Fallback {
                            vectors[v] = pc.dir_max[v];
                        }
                    }
                    "the maximal principal curvature direction"
                }
                UnconstrainedFallback::Smoothest => {
                    let smooth = crate::smoothest_field::smoothest_field(self.mesh)?;
                    for (v, s) in status.iter().enumerate() {
                        if *s == VertexFieldStatus::Fallback {
                            vectors[v] = smooth.vectors[v];
                        }
                    }
                    "the smoothest line field, along principal curvature where it is clearly \
                     anisotropic"
                }
                UnconstrainedFallback::Direction(d) => {
                    for (v, s) in status.iter().enumerate() {
                        if *s == VertexFieldStatus::Fallback {
                            let n = self.normals[v];
                            vectors[v] =
                                project_unit(d, n).unwrap_or_else(|| vec3::any_orthonormal(n));
                        }
                    }
                    "the given direction projected onto the surface"
                }
                UnconstrainedFallback::Zero => "zero vectors",
            };
            warnings.push(Warning::new(
                "field-unconstrained-components",
                format!(
                    "{fallback_components} components ({fallback_vertices} vertices) have no \
                     curve constraint; their field is {what} — pass curves that touch them"
                ),
            ));
        }
        Ok(CurveField { vectors, status, warnings })
    }
}

/// `x` projected onto the plane of unit normal `n` and normalised; `None` when the
/// projection is shorter than `1e-9`.
fn project_unit(x: V3, n: V3) -> Option<V3> {
    let t = vec3::sub(x, vec3::scale(n, vec3::dot(x, n)));
    let len = vec3::norm(t);
    (len > 1e-9 && len.is_finite()).then(|| vec3::scale(t, 1.0 / len))
}
