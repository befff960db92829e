//! Geodesic distance by the heat method (Crane, Weischedel & Wardetzky 2013, "Geodesics
//! in Heat", Algorithm 1).
//!
//! 1. Heat flow: `(M + t L) u = δ_γ` (eq. 6 with our positive semi-definite `L`, see
//!    [`crate::cotan_laplacian`]; `M` the barycentric lumped mass; `δ_γ` is 1 at source
//!    vertices, or the barycentric weights of source points).
//! 2. Per triangle `X = −∇u / |∇u|` (eq. 2 of §3.2; zero where `∇u` vanishes and on
//!    zero-area triangles).
//! 3. Poisson: `L φ = −b` with the integrated divergence
//!    `b_i = ½ Σ cot θ₁ (e₁ · X) + cot θ₂ (e₂ · X)` (§3.2; the same clamped
//!    half-cotangents as `L`, so `Σ b = 0` on every component exactly).
//! 4. Shift per component so that the smallest value at its sources is 0; clamp the
//!    small negative values near sources to 0 and set source vertices to exactly 0 (with
//!    several sources the method gives them values within the discretisation error of 0).
//!
//! Accuracy follows the paper: about 1 % mean error on good triangulations; on meshes
//! whose triangle sizes vary wildly (needles hundreds of times longer than the typical
//! edge) the heat does not reach into the big triangles at `t = h²` and distances there
//! are underestimated — finite, never NaN.
//!
//! **Time step** `t = m h²` with `m` = [`HeatGeodesicOptions::time_factor`] (default 1,
//! the paper's recommendation) and `h` the *median* length of the triangle edges (the
//! paper uses the mean; on uniform meshes they agree, and the median is not thrown off by
//! a few huge outlier triangles, which would make `t` and the heat system absurd).
//!
//! **Accuracy checks.** Solves accept a relative residual up to `1e-6` (the linear-algebra
//! default is `1e-8`): the heat method only needs the direction of `∇u`, and meshes with
//! clamped slivers make the Poisson system badly conditioned.
//!
//! **Boundary conditions** (§3.3): for meshes with boundary the default averages the
//! heat solutions with zero Neumann and zero Dirichlet conditions
//! ([`HeatBoundary::Average`]), which the paper recommends for the most uniform error;
//! the Poisson step always uses the natural (Neumann) condition.
//!
//! **Factor once, solve many.** [`HeatGeodesic::new`] analyses the sparsity pattern of
//! `L` once and factors `M + t L` (Neumann), its Dirichlet variant (only when the mesh has
//! a boundary) and the pinned `L`, all with the same pattern: Dirichlet and pinned
//! vertices keep their stored entries as explicit zeros and get a unit diagonal, so one
//! symbolic analysis serves the three numeric factorisations. [`HeatGeodesic::distance`]
//! then costs two triangular solves per step and can be called for any number of source
//! sets, also in parallel ([`HeatGeodesic::distances`]).
//!
//! **Components and degenerate input.** Components are those of the graph of non-zero
//! off-diagonal entries of `L`. The Poisson step pins one vertex per component (exact:
//! `b` sums to zero on each component). Vertices of a component that holds no source get
//! `f64::INFINITY`; so do unreferenced vertices (unless they are themselves a source,
//! which gets 0). A tiny diagonal regularisation (`1e-10` of the mean diagonal) keeps
//! both systems positive definite on pathological input (components made only of
//! zero-area triangles); its effect on the distances is far below the discretisation
//! error.
//!
//! Not implemented: the intrinsic Delaunay variant (Sharp, Soliman & Crane 2019), which
//! improves accuracy on poor triangulations.

use crate::cotan_laplacian::{CotanOptions, cotan_laplacian_and_mass, vertex_corners};
use crate::{MeshError, Topology, TriMesh, UnionFind, VertexAreaKind};
use fieldtex_core::Warning;
use fieldtex_core::vec3::{self, V3};
use fieldtex_linalg::{Cholesky, CholeskyOptions, SparseMatrix, SymbolicCholesky};
use rayon::prelude::*;

/// Boundary condition of the heat step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HeatBoundary {
    /// Zero normal derivative (natural condition).
    Neumann,
    /// `u = 0` on the boundary.
    Dirichlet,
    /// Mean of the Neumann and Dirichlet solutions (default; Crane et al. 2013 §3.3).
    #[default]
    Average,
}

/// Options of [`HeatGeodesic`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeatGeodesicOptions {
    /// `m` in `t = m h²`. Default 1. Larger values smooth the distance.
    pub time_factor: f64,
    /// Boundary condition of the heat step. Default [`HeatBoundary::Average`].
    pub boundary: HeatBoundary,
    /// Options of the cotan Laplacian used throughout.
    pub cotan: CotanOptions,
}

impl Default for HeatGeodesicOptions {
    fn default() -> Self {
        Self { time_factor: 1.0, boundary: HeatBoundary::Average, cotan: CotanOptions::default() }
    }
}

/// A point source on the surface: triangle index and barycentric coordinates.
pub type SurfacePoint = (u32, [f64; 3]);

/// Precomputed heat-method solver for one mesh (module docs).
#[derive(Debug, Clone)]
pub struct HeatGeodesic {
    triangles: Vec<[u32; 3]>,
    n_vertices: usize,
    /// Per triangle: `N × e_i` for the three edges opposite the corners (unnormalised
    /// gradient basis), or `None` for a zero-area triangle.
    grad_basis: Vec<Option<[V3; 3]>>,
    /// Per triangle: edge vectors from corner `k` to `k + 1` and the half-cotangents.
    edges: Vec<[V3; 3]>,
    half_cot: Vec<[f64; 3]>,
    corner_offsets: Vec<u32>,
    corners: Vec<u32>,
    /// Component of each vertex (`u32::MAX` for unreferenced / isolated vertices).
    component: Vec<u32>,
    /// Poisson rows pinned to zero: the first vertex of each component, isolated ones.
    pinned_rows: Vec<usize>,
    boundary: HeatBoundary,
    heat_neumann: Cholesky,
    heat_dirichlet: Option<Cholesky>,
    poisson: Cholesky,
    /// The time step used.
    pub time_step: f64,
    warnings: Vec<Warning>,
}

/// Residual tolerance of the heat-method solves (module docs).
fn solve_options() -> CholeskyOptions {
    CholeskyOptions { residual_tolerance: 1e-6, ..Default::default() }
}

/// `a` with the rows and columns of `pinned` vertices zeroed (kept as explicit zeros)
/// and a unit diagonal there.
fn pin(a: &SparseMatrix, pinned: &[bool]) -> Result<SparseMatrix, MeshError> {
    let n = a.ncols();
    let mut values = a.values().to_vec();
    for c in 0..n {
        let range = a.col_ptr()[c]..a.col_ptr()[c + 1];
        for (val, &r) in values[range.clone()].iter_mut().zip(&a.row_idx()[range]) {
            if pinned[r] || pinned[c] {
                *val = if r == c { 1.0 } else { 0.0 };
            }
        }
    }
    Ok(SparseMatrix::from_csc(n, n, a.col_ptr().to_vec(), a.row_idx().to_vec(), values)?)
}

impl HeatGeodesic {
    /// Builds the operators and factorisations for `mesh`.
    pub fn new(mesh: &TriMesh, options: &HeatGeodesicOptions) -> Result<Self, MeshError> {
        crate::checks::check_indices(mesh)?;
        let n = mesh.n_vertices();
        let (l, mass, stats) =
            cotan_laplacian_and_mass(mesh, &options.cotan, VertexAreaKind::Barycentric)?;
        let mut warnings = stats.warnings();
        // Components of the graph of non-zero couplings.
        let mut uf = UnionFind::new(n);
        let mut coupled = vec![false; n];
        for c in 0..n {
            for k in l.col_ptr()[c]..l.col_ptr()[c + 1] {
                let r = l.row_idx()[k];
                if r != c && l.values()[k] != 0.0 {
                    uf.union(r, c);
                    coupled[r] = true;
                }
            }
        }
        let mut component = vec![u32::MAX; n];
        let mut pinned = vec![false; n];
        let mut n_comp = 0u32;
        let mut root_label = vec![u32::MAX; n];
        for v in 0..n {
            if !coupled[v] {
                pinned[v] = true; // isolated: nothing to solve for
                continue;
            }
            let r = uf.find(v);
            if root_label[r] == u32::MAX {
                root_label[r] = n_comp;
                n_comp += 1;
                pinned[v] = true; // one pinned vertex per component
            }
            component[v] = root_label[r];
        }
        // Time step from the median edge length.
        let mut lengths: Vec<f64> = mesh
            .triangles
            .iter()
            .flat_map(|t| {
                [0, 1, 2].map(|i| {
                    vec3::norm(vec3::sub(
                        mesh.positions[t[i] as usize],
                        mesh.positions[t[(i + 1) % 3] as usize],
                    ))
                })
            })
            .filter(|d| d.is_finite() && *d > 0.0)
            .collect();
        let h = if lengths.is_empty() {
            1.0
        } else {
            let mid = lengths.len() / 2;
            *lengths.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        let factor = if options.time_factor > 0.0 && options.time_factor.is_finite() {
            options.time_factor
        } else {
            1.0
        };
        let time_step = factor * h * h;
        // A = M + t L + reg, dead (isolated) vertices pinned.
        let mean_mass = mass.iter().sum::<f64>() / n.max(1) as f64;
        let reg_heat = 1e-10 * mean_mass.max(f64::MIN_POSITIVE);
        let mut a = l.clone();
        a.scale(time_step);
        let diag: Vec<f64> = mass.iter().map(|m| m + reg_heat).collect();
        let a = a.add_diagonal(&diag);
        let isolated: Vec<bool> = (0..n).map(|v| !coupled[v]).collect();
        let a_neumann = pin(&a, &isolated)?;
        let symbolic = SymbolicCholesky::analyze(&a_neumann).map_err(MeshError::from)?;
        let heat_neumann =
            Cholesky::factor_with(&symbolic, &a_neumann)?.with_options(solve_options());
        let topo_boundary = Topology::build(n, &mesh.triangles).boundary_vertices();
        let has_boundary = topo_boundary.iter().any(|&b| b);
        let heat_dirichlet = if has_boundary && options.boundary != HeatBoundary::Neumann {
            let mut fixed = topo_boundary;
            for (v, f) in fixed.iter_mut().enumerate() {
                *f |= isolated[v];
            }
            Some(Cholesky::factor_with(&symbolic, &pin(&a, &fixed)?)?.with_options(solve_options()))
        } else {
            None
        };
        let mean_diag = l.diagonal().iter().sum::<f64>() / n.max(1) as f64;
        let reg_poisson = 1e-10 * mean_diag.max(f64::MIN_POSITIVE);
        let lp = l.add_diagonal(&vec![reg_poisson; n]);
        let poisson =
            Cholesky::factor_with(&symbolic, &pin(&lp, &pinned)?)?.with_options(solve_options());
        // Per-face geometry for gradient and divergence.
        let (fw, _) = crate::cotan_laplacian::cotan_face_weights(mesh, &options.cotan)?;
        let per_face: Vec<(Option<[V3; 3]>, [V3; 3])> = mesh
            .triangles
            .par_iter()
            .with_min_len(2048)
            .map(|t| {
                let p = t.map(|i| mesh.positions[i as usize]);
                let e = [0, 1, 2].map(|k| vec3::sub(p[(k + 1) % 3], p[k]));
                let basis = vec3::normalize(vec3::cross(e[0], e[1]))
                    .map(|nrm| [0, 1, 2].map(|i| vec3::cross(nrm, e[(i + 1) % 3])));
                (basis, e)
            })
            .collect();
        let (corner_offsets, corners) = vertex_corners(n, &mesh.triangles);
        if n_comp > 1 {
            warnings.push(Warning::new(
                "geodesic-components",
                format!(
                    "the mesh has {n_comp} connected components; distances are infinite in \
                     components without a source"
                ),
            ));
        }
        let pinned_rows = (0..n).filter(|&v| pinned[v]).collect();
        Ok(Self {
            triangles: mesh.triangles.clone(),
            n_vertices: n,
            grad_basis: per_face.iter().map(|p| p.0).collect(),
            edges: per_face.iter().map(|p| p.1).collect(),
            half_cot: fw,
            corner_offsets,
            corners,
            component,
            pinned_rows,
            boundary: options.boundary,
            heat_neumann,
            heat_dirichlet,
            poisson,
            time_step,
            warnings,
        })
    }

    /// Warnings collected while building (clamped triangles, several components).
    pub fn warnings(&self) -> &[Warning] {
        &self.warnings
    }

    /// `#V` geodesic distances from the source vertices (module docs). Errors on a
    /// source index out of range or a failed solve.
    pub fn distance(&self, sources: &[usize]) -> Result<Vec<f64>, MeshError> {
        let mut delta = vec![0.0; self.n_vertices];
        for &s in sources {
            if s >= self.n_vertices {
                return Err(MeshError::Precondition {
                    operation: "heat geodesic distance",
                    requirement: "source vertices below the vertex count",
                    found: format!("source {s} with {} vertices", self.n_vertices),
                });
            }
            delta[s] = 1.0;
        }
        let groups: Vec<Vec<(usize, f64)>> = sources.iter().map(|&s| vec![(s, 1.0)]).collect();
        self.solve(delta, &groups)
    }

    /// `#V` geodesic distances from points on the surface (e.g. samples of a curve);
    /// barycentric coordinates are normalised, invalid ones are an error.
    pub fn distance_from_points(&self, points: &[SurfacePoint]) -> Result<Vec<f64>, MeshError> {
        let mut delta = vec![0.0; self.n_vertices];
        let mut groups = Vec::with_capacity(points.len());
        for (k, &(f, b)) in points.iter().enumerate() {
            let s = b[0] + b[1] + b[2];
            let valid = (f as usize) < self.triangles.len()
                && b.iter().all(|x| x.is_finite() && *x >= -1e-9)
                && s > 0.0;
            if !valid {
                return Err(MeshError::Precondition {
                    operation: "heat geodesic distance",
                    requirement: "source points on existing triangles with barycentric \
                                  coordinates ≥ 0",
                    found: format!("point {k}: triangle {f}, coordinates {b:?}"),
                });
            }
            let t = self.triangles[f as usize];
            let mut g = Vec::with_capacity(3);
            for i in 0..3 {
                let w = b[i].max(0.0) / s;
                delta[t[i] as usize] += w;
                g.push((t[i] as usize, w));
            }
            groups.push(g);
        }
        self.solve(delta, &groups)
    }

    /// Distances for several source sets, solved in parallel (deterministic).
    pub fn distances(&self, source_sets: &[Vec<usize>]) -> Result<Vec<Vec<f64>>, MeshError> {
        source_sets.par_iter().map(|s| self.distance(s)).collect()
    }

    /// Steps 1–4 for a right-hand side `delta`; `sources` are groups of `(vertex,
    /// weight)` whose weighted value is a zero of the distance.
    fn solve(&self, delta: Vec<f64>, sources: &[Vec<(usize, f64)>]) -> Result<Vec<f64>, MeshError> {
        let n = self.n_vertices;
        // 1. Heat flow (isolated vertices are pinned to 0 in the systems).
        let mut rhs = delta.clone();
        for (v, r) in rhs.iter_mut().enumerate() {
            if self.component[v] == u32::MAX {
                *r = 0.0;
            }
        }
        let u = match (&self.heat_dirichlet, self.boundary) {
            (Some(d), HeatBoundary::Dirichlet) => d.solve(&rhs)?,
            (Some(d), _) => {
                let (un, ud) = rayon::join(|| self.heat_neumann.solve(&rhs), || d.solve(&rhs));
                let (un, ud) = (un?, ud?);
                un.iter().zip(&ud).map(|(a, b)| 0.5 * (a + b)).collect::<Vec<f64>>()
            }
            (None, _) => self.heat_neumann.solve(&rhs)?,
        };
        // 2. Normalised negative gradient per triangle.
        let x: Vec<V3> = self
            .triangles
            .par_iter()
            .zip(&self.grad_basis)
            .with_min_len(2048)
            .map(|(t, basis)| {
                let Some(b) = basis else { return [0.0; 3] };
                let mut g = [0.0; 3];
                for i in 0..3 {
                    g = vec3::add(g, vec3::scale(b[i], u[t[i] as usize]));
                }
                vec3::normalize(g).map_or([0.0; 3], |d| vec3::scale(d, -1.0))
            })
            .collect();
        // 3. Integrated divergence (gathered per vertex, triangle order) and Poisson.
        let mut b: Vec<f64> = (0..n)
            .into_par_iter()
            .with_min_len(2048)
            .map(|v| {
                let range = self.corner_offsets[v] as usize..self.corner_offsets[v + 1] as usize;
                let mut s = 0.0;
                for &c in &self.corners[range] {
                    let (f, k) = ((c / 3) as usize, (c % 3) as usize);
                    let (e, w, xf) = (self.edges[f], self.half_cot[f], x[f]);
                    // Edges leaving corner k: e[k] (to k+1) and −e[k+2] (to k+2).
                    s +=
                        w[k] * vec3::dot(e[k], xf) - w[(k + 2) % 3] * vec3::dot(e[(k + 2) % 3], xf);
                }
                -s
            })
            .collect();
        for &v in &self.pinned_rows {
            b[v] = 0.0;
        }
        let phi = self.poisson.solve(&b)?;
        // 4. Shift per component to zero at the sources.
        let n_comp = self.component.iter().filter(|&&c| c != u32::MAX).max().map_or(0, |&c| c + 1);
        let mut shift = vec![f64::INFINITY; n_comp as usize];
        let mut is_source = vec![false; n];
        let mut is_vertex_source = vec![false; n];
        for g in sources {
            if let [(v, w)] = g[..]
                && w == 1.0
            {
                is_vertex_source[v] = true;
            }
            let mut val = 0.0;
            let mut comp = u32::MAX;
            for &(v, w) in g {
                val += w * phi[v];
                is_source[v] = true;
                if self.component[v] != u32::MAX {
                    comp = self.component[v];
                }
            }
            if comp != u32::MAX {
                shift[comp as usize] = shift[comp as usize].min(val);
            }
        }
        let out = (0..n)
            .map(|v| match self.component[v] {
                u32::MAX => {
                    if is_source[v] {
                        0.0
                    } else {
                        f64::INFINITY
                    }
                }
                _ if is_vertex_source[v] => 0.0,
                c => {
                    let s = shift[c as usize];
                    if s.is_finite() { (phi[v] - s).max(0.0) } else { f64::INFINITY }
                }
            })
            .collect();
        Ok(out)
    }
}

#[cfg(test)]
#[path = "heat_geodesic_tests.rs"]
mod tests;
