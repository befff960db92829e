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
//! Not implemented: removing curves (multiple-rank downdates exist in `fieldtex_linalg`,
//! `Cholesky::remove_diagonal_penalties`, but no caller needs them yet).

use std::collections::HashMap;
use std::time::Instant;

use fieldtex_core::Warning;
use fieldtex_core::vec3::{self, V3};
use fieldtex_linalg::{Cholesky, FactorLayout, SparseMatrix, SymbolicCholesky};
use fieldtex_mesh::{
    CotanOptions, CurvatureOptions, MeshError, NormalWeighting, TriMesh, UnionFind,
    cotan_laplacian_with, principal_curvatures, vertex_normals,
};
use serde::Serialize;

use crate::FieldsError;

/// Sentinel for "no component" (a vertex used by no usable triangle).
const NONE: u32 = u32::MAX;

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

/// Options of [`CurveFieldSolver`].
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
    /// [`CurveFieldSolver::add_constraints_many`] refactors numerically instead of
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
    fn validate(&self) -> Result<(), FieldsError> {
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

/// Cost of one [`CurveFieldSolver::add_constraints`].
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

/// Cost and accuracy of one [`CurveFieldSolver::solve`].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct SolveReport {
    /// Components re-solved (only those whose constraints changed).
    pub components_solved: usize,
    pub seconds: f64,
    /// Largest relative residual `‖(L+P)x − Pb‖ / ‖Pb‖` over the right-hand sides of the
    /// full solves.
    pub max_residual: f64,
    /// Components updated incrementally ([`CurveFieldSolver::solve_at`]; no residual).
    pub incremental: usize,
}

struct Block {
    /// Global vertex indices, increasing (local index = position).
    vertices: Vec<u32>,
    laplacian: SparseMatrix,
    symbolic: Option<SymbolicCholesky>,
    factor: Option<Cholesky>,
    dirty: bool,
    failed: bool,
    /// Vertices that got their first penalty since the last solve (global indices).
    fresh: Vec<u32>,
    /// No full solve since the first factorisation, or a change an incremental solve
    /// does not cover (a target moved by `Average`): the next solve of the block is a
    /// full one. While false, `raw` solves the system of the last solve at the vertices
    /// marked in `CurveFieldSolver::current`.
    needs_full: bool,
    /// The last solve was incremental: `raw` is stale outside its `needed` vertices.
    partial: bool,
}

/// Uniform grid over vertex positions for nearest-vertex queries.
struct VertexGrid {
    origin: V3,
    /// Upper corner of the bounding box of the gridded vertices.
    upper: V3,
    cell: f64,
    dims: [usize; 3],
    offsets: Vec<u32>,
    items: Vec<u32>,
}

impl VertexGrid {
    fn new(positions: &[V3], usable: &[bool], cell: f64) -> Self {
        let pts = || positions.iter().enumerate().filter(|(v, _)| usable[*v]);
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for (_, p) in pts() {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let n = pts().count().max(1);
        let mut cell = cell;
        let dims = loop {
            let d = [0, 1, 2].map(|k| (((hi[k] - lo[k]) / cell).floor() as usize + 1).max(1));
            if d[0].saturating_mul(d[1]).saturating_mul(d[2]) <= 8 * n + 64 {
                break d;
            }
            cell *= 1.5;
        };
        let mut g =
            Self { origin: lo, upper: hi, cell, dims, offsets: Vec::new(), items: Vec::new() };
        let pairs: Vec<(u32, u32)> =
            pts().map(|(v, p)| (g.cell_index(g.coords(*p)) as u32, v as u32)).collect();
        let csr = fieldtex_mesh::Csr::from_pairs(dims[0] * dims[1] * dims[2], pairs.into_iter());
        g.offsets = csr.offsets;
        g.items = csr.items;
        g
    }

    fn coords(&self, p: V3) -> [usize; 3] {
        [0, 1, 2].map(|k| {
            let c = ((p[k] - self.origin[k]) / self.cell).floor();
            c.clamp(0.0, (self.dims[k] - 1) as f64) as usize
        })
    }

    fn cell_index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    /// Parameter range `[t0, t1] ⊂ [0, 1]` of the segment `a → b` inside the bounding
    /// box grown by `radius` (slab method), or `None` when it misses the box.
    fn clip(&self, a: V3, b: V3, radius: f64) -> Option<(f64, f64)> {
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for k in 0..3 {
            let (lo, hi) = (self.origin[k] - radius, self.upper[k] + radius);
            let d = b[k] - a[k];
            if d == 0.0 {
                if a[k] < lo || a[k] > hi {
                    return None;
                }
                continue;
            }
            let (u, v) = ((lo - a[k]) / d, (hi - a[k]) / d);
            t0 = t0.max(u.min(v));
            t1 = t1.min(u.max(v));
        }
        (t0 <= t1).then_some((t0, t1))
    }

    /// Nearest vertex within `radius` of `p` (ties: lower index).
    fn nearest(&self, positions: &[V3], p: V3, radius: f64) -> Option<u32> {
        let lo = self.coords(vec3::sub(p, [radius; 3]));
        let hi = self.coords(vec3::add(p, [radius; 3]));
        let mut best: Option<(f64, u32)> = None;
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let c = self.cell_index([x, y, z]);
                    for &v in &self.items[self.offsets[c] as usize..self.offsets[c + 1] as usize] {
                        let d = vec3::norm2(vec3::sub(positions[v as usize], p));
                        if d <= radius * radius && best.is_none_or(|(bd, bv)| (d, v) < (bd, bv)) {
                            best = Some((d, v));
                        }
                    }
                }
            }
        }
        best.map(|(_, v)| v)
    }
}

/// The diffusion system of one mesh with its kept factorisations (module docs).
///
/// Typical use: [`CurveFieldSolver::new`], then per curve
/// [`CurveFieldSolver::sample_curve`] and [`CurveFieldSolver::add_constraints`] with a
/// sign, [`CurveFieldSolver::solve`], and finally [`CurveFieldSolver::field`].
pub struct CurveFieldSolver<'m> {
    mesh: &'m TriMesh,
    options: CurveFieldOptions,
    normals: Vec<V3>,
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
    mean_edge: f64,
    grid: VertexGrid,
    warnings: Vec<Warning>,
}

impl<'m> CurveFieldSolver<'m> {
    /// Builds `L`, the components and the vertex normals. Errors: invalid mesh (indices,
    /// non-finite positions), a mesh without usable triangles, invalid options.
    pub fn new(mesh: &'m TriMesh, options: &CurveFieldOptions) -> Result<Self, FieldsError> {
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
        let (normals, _) = vertex_normals(mesh, NormalWeighting::Angle);
        let grid = VertexGrid::new(p, &used, mean_edge);
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

    /// Constraints of `polyline` (module docs) for its forward orientation. Never fails:
    /// non-finite points and samples off the mesh are counted in `dropped_samples`.
    pub fn sample_curve(&self, polyline: &[V3]) -> CurveConstraints {
        let h = self.mean_edge;
        let step = self.options.sample_spacing * h;
        let radius = self.options.max_distance * h;
        let mut out = CurveConstraints::default();
        let mut slot: HashMap<u32, usize> = HashMap::new();
        let mut sums: Vec<(V3, f64)> = Vec::new();
        let mut prev: Option<V3> = None;
        for &q in polyline {
            if !vec3::is_finite(q) {
                out.dropped_samples += 1;
                prev = None;
                continue;
            }
            if let Some(a) = prev {
                let d = vec3::sub(q, a);
                let len = vec3::norm(d);
                // Only the part near the mesh is sampled (bounds the work for far or
                // huge segments); an overflowing length counts as off the mesh.
                let span = if len.is_finite() { self.grid.clip(a, q, radius) } else { None };
                if len > 0.0 && span.is_none() {
                    out.dropped_samples += 1;
                }
                if let (true, Some((t0, t1))) = (len > 0.0, span) {
                    let dir = vec3::scale(d, 1.0 / len);
                    let k = (len * (t1 - t0) / step).ceil().max(1.0) as usize;
                    let w = len * (t1 - t0) / k as f64;
                    for s in 0..k {
                        let t = t0 + (t1 - t0) * (s as f64 + 0.5) / k as f64;
                        let x = vec3::lerp(a, q, t);
                        let Some(v) = self.grid.nearest(&self.mesh.positions, x, radius) else {
                            out.dropped_samples += 1;
                            continue;
                        };
                        out.length += w;
                        let i = *slot.entry(v).or_insert_with(|| {
                            out.vertices.push(v);
                            sums.push(([0.0; 3], 0.0));
                            sums.len() - 1
                        });
                        sums[i].0 = vec3::add(sums[i].0, vec3::scale(dir, w));
                        sums[i].1 += w;
                    }
                }
            }
            prev = Some(q);
        }
        let mut keep = Vec::with_capacity(out.vertices.len());
        for (&v, &(s, w)) in out.vertices.iter().zip(&sums) {
            let n = self.normals[v as usize];
            let t = vec3::sub(s, vec3::scale(n, vec3::dot(s, n)));
            let tn = vec3::norm(t);
            if tn > 1e-3 * w {
                keep.push(v);
                out.tangents.push(vec3::scale(t, 1.0 / tn));
            }
        }
        out.vertices = keep;
        out
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

/// The block of `l` on `verts` (increasing global indices). Entries reaching outside the
/// block are structural zeros of skipped triangles and are dropped.
fn extract_block(
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
fn penalised_matrix(block: &Block, targets: &[Option<(V3, V3)>], alpha: f64) -> SparseMatrix {
    let d: Vec<f64> = block
        .vertices
        .iter()
        .map(|&v| if targets[v as usize].is_some() { alpha } else { 0.0 })
        .collect();
    block.laplacian.add_diagonal(&d)
}

/// The three right-hand sides `α b` of one block.
fn block_rhs(verts: &[u32], targets: &[Option<(V3, V3)>], alpha: f64) -> Vec<Vec<f64>> {
    (0..3)
        .map(|k| {
            verts.iter().map(|&v| targets[v as usize].map_or(0.0, |(t, _)| alpha * t[k])).collect()
        })
        .collect()
}

/// First factorisation of a block (symbolic analysis kept for later comparisons).
fn factor_block(
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
