//! Smooth 3-D frame fields from sketched curves (paper E §3, Zhang, Du, Lai, Ni & Hu
//! 2010, "Sketch guided solid texturing", eq. 1–2).
//!
//! The field lives on the nodes of a coarse regular grid ([`FrameGrid`]; the paper's
//! shortest side has 20–30 cells). Each node holds a unit quaternion ([`crate::quaternion`])
//! whose rotation turns the world axes into the local frame. Sketched curves
//! ([`FrameCurve`]) give target frames `q̄` at the nodes they pass; the field minimises
//!
//! ```text
//! ‖L Q‖² + Σ_{v ∈ C} w_c² ‖q(v) − q̄(v)‖² + ε ‖Q‖²        (eq. 2, ε = 1e-9 keeps it SPD)
//! ```
//!
//! with `L` the graph Laplacian of the 6-neighbour grid, `(L q)ᵢ = qᵢ − (1/dᵢ) Σⱼ qⱼ`
//! (eq. 1, `dᵢ` the node degree), and `w_c = 100 · weight` (the paper's w = 100). The
//! four quaternion components are four systems with one matrix `LᵀL + εI + P`
//! (`P` the diagonal of penalties), factored once; adding or removing a curve changes
//! `P` on its nodes only and is applied by a multiple-rank update or downdate of the
//! kept factor (Davis & Hager, `fieldtex-linalg`), then the four right-hand sides are
//! solved in one pass. Solutions are normalised; a node whose interpolated quaternion
//! vanishes takes the frame of the nearest non-zero node (breadth-first, lowest index
//! first) — the paper's "arbitrary neighbouring direction".
//!
//! Signs (`q ≡ −q`): the first sample of the first curve keeps `w ≥ 0`; later samples of
//! a curve are aligned with the previous sample (continuity); on a curve added when a
//! field already exists, each sample is aligned with the current field at its node
//! instead. A *refinement* curve ([`FrameCurve::refine`]) does not bring its own normal:
//! at each sample, whichever of the six directions `±x, ±y, ±z` of the current frame is
//! closest to the curve tangent is turned onto the tangent by the smallest rotation, and
//! that turned frame is the target (the paper's six-direction alignment).
//!
//! Lookup ([`FrameField3d::frame_at`]) is trilinear in the eight surrounding nodes, each
//! aligned in sign with the node of largest weight, then normalised.

use crate::FieldsError;
pub use crate::frame_grid::FrameGrid;
use crate::quaternion::{self, Quat};
use fieldtex_linalg::{
    Cholesky, CholeskyOptions, FactorLayout, SparseMatrix, SymbolicCholesky, grid_nested_dissection,
};

/// One sketched curve, already placed: points in world coordinates with the reference
/// normal at each (the outward surface normal for curves on the surface, the plane's
/// normal for curves on an interior reference plane).
#[derive(Clone, Debug, PartialEq)]
pub struct FrameCurve {
    pub points: Vec<[f64; 3]>,
    /// One per point; ignored for refinement curves.
    pub normals: Vec<[f64; 3]>,
    /// Local axis (0 = x, 1 = y, 2 = z) the tangent becomes.
    pub axis: usize,
    /// Multiplies the constraint weight `w`. Default 1.
    pub weight: f64,
    /// Six-direction alignment against the current field instead of a full frame.
    pub refine: bool,
}

/// Options of [`FrameField3d`].
#[derive(Clone, Debug, PartialEq)]
pub struct FrameFieldOptions {
    /// Soft-constraint weight `w` of eq. 2. Default 100 (the paper's value).
    pub constraint_weight: f64,
}

impl Default for FrameFieldOptions {
    fn default() -> Self {
        Self { constraint_weight: 100.0 }
    }
}

/// Target frames of one curve: `(node, penalty α = w², target q̄)`.
#[derive(Clone, Debug)]
struct CurveTargets {
    nodes: Vec<(usize, f64, Quat)>,
}

/// An editable 3-D frame field with a kept factorisation (module docs).
pub struct FrameField3d {
    grid: FrameGrid,
    options: FrameFieldOptions,
    /// `LᵀL + εI`, full symmetric.
    base: SparseMatrix,
    factor: Option<Cholesky>,
    curves: Vec<Option<CurveTargets>>,
    frames: Vec<Quat>,
    solved: bool,
}

const EPSILON: f64 = 1e-9;

impl FrameField3d {
    /// The field on `grid` with no curve yet (identity frames everywhere).
    pub fn new(grid: FrameGrid, options: FrameFieldOptions) -> Result<Self, FieldsError> {
        if !(options.constraint_weight.is_finite() && options.constraint_weight > 0.0) {
            return Err(FieldsError::InvalidOption {
                name: "constraint_weight",
                value: options.constraint_weight,
                expected: "a finite weight > 0",
            });
        }
        let base = laplacian_normal_matrix(&grid)?;
        let n = grid.len();
        Ok(Self {
            grid,
            options,
            base,
            factor: None,
            curves: Vec::new(),
            frames: vec![quaternion::IDENTITY; n],
            solved: false,
        })
    }

    /// The node grid.
    pub fn grid(&self) -> &FrameGrid {
        &self.grid
    }

    /// Unit frame per node (identity before the first curve).
    pub fn frames(&self) -> &[Quat] {
        &self.frames
    }

    /// Stored entries of the kept Cholesky factor (`None` before the first curve).
    pub fn factor_nnz(&self) -> Option<usize> {
        self.factor.as_ref().map(|f| f.symbolic().factor_nnz())
    }

    /// Largest relative residual `‖A x − b‖ / ‖b‖` of the last solve (0 before one).
    pub fn last_residual(&self) -> f64 {
        self.factor.as_ref().map_or(0.0, |f| f.last_residual())
    }

    /// Ids of the curves currently in the field.
    pub fn curve_ids(&self) -> Vec<usize> {
        (0..self.curves.len()).filter(|&i| self.curves[i].is_some()).collect()
    }

    /// Adds `curve` (targets with signs against the current field, module docs), updates
    /// the factor and re-solves. Returns the curve's id.
    pub fn add_curve(&mut self, curve: &FrameCurve) -> Result<usize, FieldsError> {
        let id = self.curves.len();
        let targets = self.curve_targets(curve, id)?;
        let penalties: Vec<(usize, f64)> = targets.nodes.iter().map(|&(i, a, _)| (i, a)).collect();
        if let Some(f) = self.factor.as_mut() {
            f.add_diagonal_penalties(&penalties)?;
        }
        self.curves.push(Some(targets));
        self.solve()?;
        Ok(id)
    }

    /// Removes curve `id` (a downdate of the kept factor) and re-solves.
    pub fn remove_curve(&mut self, id: usize) -> Result<(), FieldsError> {
        let Some(Some(targets)) = self.curves.get(id).cloned() else {
            return Err(FieldsError::UnknownId { what: "curve", id: id as u32 });
        };
        if let Some(f) = self.factor.as_mut() {
            let penalties: Vec<(usize, f64)> =
                targets.nodes.iter().map(|&(i, a, _)| (i, a)).collect();
            f.remove_diagonal_penalties(&penalties)?;
        }
        self.curves[id] = None;
        self.solve()?;
        Ok(())
    }

    /// Replaces curve `id` by `curve` (a moved or redrawn stroke) as one edit: the old
    /// penalties are downdated and the new ones updated in the kept factor, then one
    /// solve. Targets take their signs from the field before the edit. The id stays.
    pub fn replace_curve(&mut self, id: usize, curve: &FrameCurve) -> Result<(), FieldsError> {
        let Some(Some(old)) = self.curves.get(id).cloned() else {
            return Err(FieldsError::UnknownId { what: "curve", id: id as u32 });
        };
        let targets = self.curve_targets(curve, id)?;
        if let Some(f) = self.factor.as_mut() {
            let down: Vec<(usize, f64)> = old.nodes.iter().map(|&(i, a, _)| (i, a)).collect();
            let up: Vec<(usize, f64)> = targets.nodes.iter().map(|&(i, a, _)| (i, a)).collect();
            // Update first so that no intermediate matrix loses the old constraints
            // before it has the new ones (the downdate then stays well conditioned).
            f.add_diagonal_penalties(&up)?;
            f.remove_diagonal_penalties(&down)?;
        }
        self.curves[id] = Some(targets);
        self.solve()
    }

    /// Per constrained node of every curve: the rotation angle (degrees) between the
    /// solved frame and the curve's target there.
    pub fn constraint_errors_deg(&self) -> Vec<f64> {
        self.curves
            .iter()
            .flatten()
            .flat_map(|c| c.nodes.iter())
            .map(|&(i, _, q)| quaternion::angle_between_deg(self.frames[i], q))
            .collect()
    }

    /// The frame at world point `p` (trilinear, sign-aligned, normalised; clamped to the grid).
    pub fn frame_at(&self, p: [f64; 3]) -> Quat {
        frame_at(&self.grid, &self.frames, p)
    }

    fn solve(&mut self) -> Result<(), FieldsError> {
        let n = self.grid.len();
        let mut rhs = vec![vec![0.0; n]; 4];
        let mut any = false;
        for c in self.curves.iter().flatten() {
            for &(i, a, q) in &c.nodes {
                for (r, qc) in rhs.iter_mut().zip(q) {
                    r[i] += a * qc;
                }
                any = true;
            }
        }
        if !any {
            self.frames = vec![quaternion::IDENTITY; n];
            self.solved = false;
            return Ok(());
        }
        if self.factor.is_none() {
            let mut diag = vec![0.0; n];
            for c in self.curves.iter().flatten() {
                for &(i, a, _) in &c.nodes {
                    diag[i] += a;
                }
            }
            // Geometric nested dissection (separator slabs two nodes thick: `LᵀL`
            // couples nodes two steps apart) fills less than AMD on this grid.
            let a = self.base.add_diagonal(&diag);
            let order = grid_nested_dissection(self.grid.dims, 2);
            let symbolic =
                SymbolicCholesky::analyze_with_ordering(&a, FactorLayout::Supernodal, &order)?;
            // No forced refinement after downdates: removing a penalty α = w² = 1e4
            // leaves an error ~ε·α ≈ 2e-12 in the factor, far below what a frame
            // needs; the residual check (and refinement above 1e-11) still runs.
            let options = CholeskyOptions { refine_after_downdate: false, ..Default::default() };
            let mut f = Cholesky::factor_with(&symbolic, &a)?.with_options(options);
            f.prepare_updates()?;
            self.factor = Some(f);
        }
        let x = self.factor.as_ref().expect("factored above").solve_many(&rhs)?;
        let mut frames: Vec<Option<Quat>> =
            (0..n).map(|i| quaternion::normalize([x[0][i], x[1][i], x[2][i], x[3][i]])).collect();
        fill_zero_frames(&self.grid, &mut frames);
        self.frames = frames.into_iter().map(|q| q.unwrap_or(quaternion::IDENTITY)).collect();
        self.solved = true;
        Ok(())
    }

    /// Target frames of `curve`, grouped per nearest node (sign-aligned sum, normalised).
    fn curve_targets(&self, curve: &FrameCurve, id: usize) -> Result<CurveTargets, FieldsError> {
        let pts = &curve.points;
        if pts.len() < 2 {
            return Err(FieldsError::StrokeTooShort { stroke: id, points: pts.len() });
        }
        if !curve.refine && curve.normals.len() != pts.len() {
            return Err(FieldsError::InvalidOption {
                name: "curve normals",
                value: curve.normals.len() as f64,
                expected: "one normal per curve point",
            });
        }
        if !(curve.weight.is_finite() && curve.weight > 0.0) {
            return Err(FieldsError::InvalidOption {
                name: "curve weight",
                value: curve.weight,
                expected: "a finite weight > 0",
            });
        }
        for (k, p) in pts.iter().enumerate() {
            if let Some(&v) = p.iter().find(|v| !v.is_finite()) {
                return Err(FieldsError::NonFinite {
                    what: "curve point",
                    index: k,
                    field: "coordinate",
                    value: v,
                });
            }
        }
        let alpha = (self.options.constraint_weight * curve.weight).powi(2);
        // Samples about half a cell apart along each segment.
        let step = 0.5 * self.grid.spacing;
        let mut nodes: Vec<(usize, Quat)> = Vec::new();
        let mut prev: Option<Quat> = None;
        for s in 0..pts.len() - 1 {
            let (a, b) = (pts[s], pts[s + 1]);
            let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if len < 1e-12 {
                continue;
            }
            let count = (len / step).ceil().max(1.0) as usize;
            let last = s + 2 == pts.len();
            for t in 0..count + usize::from(last) {
                let f = t as f64 / count as f64;
                let p = [a[0] + f * d[0], a[1] + f * d[1], a[2] + f * d[2]];
                let node = self.grid.nearest(p);
                let current = self.frames[node];
                let q = if curve.refine {
                    refine_target(current, d, curve.axis)
                } else {
                    let na = curve.normals[s];
                    let nb = curve.normals[s + 1];
                    let nrm = [
                        na[0] + f * (nb[0] - na[0]),
                        na[1] + f * (nb[1] - na[1]),
                        na[2] + f * (nb[2] - na[2]),
                    ];
                    match quaternion::frame_from_tangent_normal(d, nrm, curve.axis) {
                        Some(q) => q,
                        None => continue,
                    }
                };
                let q = if self.solved {
                    quaternion::align_sign(q, current)
                } else if let Some(pq) = prev {
                    quaternion::align_sign(q, pq)
                } else if q[0] < 0.0 {
                    quaternion::align_sign(q, quaternion::IDENTITY)
                } else {
                    q
                };
                prev = Some(q);
                match nodes.iter_mut().find(|(i, _)| *i == node) {
                    Some((_, acc)) => {
                        let q = quaternion::align_sign(q, *acc);
                        for c in 0..4 {
                            acc[c] += q[c];
                        }
                    }
                    None => nodes.push((node, q)),
                }
            }
        }
        if nodes.is_empty() {
            return Err(FieldsError::StrokeMissesDomain { stroke: id });
        }
        Ok(CurveTargets {
            nodes: nodes
                .into_iter()
                .filter_map(|(i, q)| quaternion::normalize(q).map(|q| (i, alpha, q)))
                .collect(),
        })
    }
}

/// The frame of `current` turned so that the closest of its six directions `±x, ±y, ±z`
/// lies along `tangent` (paper E §3, refinement curves). `axis` is unused by the choice
/// (every direction competes) and kept for symmetry with full curves.
fn refine_target(current: Quat, tangent: [f64; 3], _axis: usize) -> Quat {
    let n = (tangent[0] * tangent[0] + tangent[1] * tangent[1] + tangent[2] * tangent[2]).sqrt();
    if n < 1e-12 {
        return current;
    }
    let t = [tangent[0] / n, tangent[1] / n, tangent[2] / n];
    let mut best = ([1.0, 0.0, 0.0], f64::NEG_INFINITY);
    for a in 0..3 {
        let v = quaternion::axis_of(current, a);
        let d = v[0] * t[0] + v[1] * t[1] + v[2] * t[2];
        for (s, dd) in [(1.0, d), (-1.0, -d)] {
            if dd > best.1 {
                best = ([s * v[0], s * v[1], s * v[2]], dd);
            }
        }
    }
    let r = quaternion::rotation_between(best.0, t);
    quaternion::normalize(quaternion::mul(r, current)).unwrap_or(current)
}

/// `LᵀL + εI` for the 6-neighbour grid Laplacian `(L q)ᵢ = qᵢ − (1/dᵢ) Σⱼ qⱼ`.
fn laplacian_normal_matrix(grid: &FrameGrid) -> Result<SparseMatrix, FieldsError> {
    let n = grid.len();
    let [nx, ny, nz] = grid.dims;
    let mut trip = Vec::with_capacity(n * 7);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let row = grid.index(i, j, k);
                let mut nb = Vec::with_capacity(6);
                if i > 0 {
                    nb.push(grid.index(i - 1, j, k));
                }
                if i + 1 < nx {
                    nb.push(grid.index(i + 1, j, k));
                }
                if j > 0 {
                    nb.push(grid.index(i, j - 1, k));
                }
                if j + 1 < ny {
                    nb.push(grid.index(i, j + 1, k));
                }
                if k > 0 {
                    nb.push(grid.index(i, j, k - 1));
                }
                if k + 1 < nz {
                    nb.push(grid.index(i, j, k + 1));
                }
                trip.push((row, row, 1.0));
                let w = -1.0 / nb.len().max(1) as f64;
                for c in nb {
                    trip.push((row, c, w));
                }
            }
        }
    }
    let l = SparseMatrix::from_triplets(n, n, &trip)?;
    Ok(l.ata().add_diagonal(&vec![EPSILON; n]))
}

/// Replaces `None` frames by the frame of the nearest set node (breadth-first from all
/// set nodes at once, neighbours visited in index order: deterministic).
fn fill_zero_frames(grid: &FrameGrid, frames: &mut [Option<Quat>]) {
    let mut queue: std::collections::VecDeque<usize> =
        (0..frames.len()).filter(|&i| frames[i].is_some()).collect();
    if queue.is_empty() {
        return;
    }
    let [nx, ny, _] = grid.dims;
    while let Some(i) = queue.pop_front() {
        let q = frames[i];
        let (x, y, z) = (i % nx, (i / nx) % ny, i / (nx * ny));
        let mut visit = |c: usize| {
            if frames[c].is_none() {
                frames[c] = q;
                queue.push_back(c);
            }
        };
        if x > 0 {
            visit(i - 1);
        }
        if x + 1 < nx {
            visit(i + 1);
        }
        if y > 0 {
            visit(i - nx);
        }
        if y + 1 < ny {
            visit(i + nx);
        }
        if z > 0 {
            visit(i - nx * ny);
        }
        if z + 1 < grid.dims[2] {
            visit(i + nx * ny);
        }
    }
}

/// Trilinear, sign-aligned lookup of `frames` (one per node of `grid`) at `p`.
pub fn frame_at(grid: &FrameGrid, frames: &[Quat], p: [f64; 3]) -> Quat {
    let mut base = [0usize; 3];
    let mut f = [0.0; 3];
    for a in 0..3 {
        let t = ((p[a] - grid.origin[a]) / grid.spacing).clamp(0.0, (grid.dims[a] - 1) as f64);
        let b = (t.floor() as usize).min(grid.dims[a].saturating_sub(2));
        base[a] = b;
        f[a] = (t - b as f64).clamp(0.0, 1.0);
    }
    let mut corners = [(0.0, quaternion::IDENTITY); 8];
    for (c, slot) in corners.iter_mut().enumerate() {
        let (dx, dy, dz) = (c & 1, (c >> 1) & 1, (c >> 2) & 1);
        let w = (if dx == 1 { f[0] } else { 1.0 - f[0] })
            * (if dy == 1 { f[1] } else { 1.0 - f[1] })
            * (if dz == 1 { f[2] } else { 1.0 - f[2] });
        let i = grid.index(
            (base[0] + dx).min(grid.dims[0] - 1),
            (base[1] + dy).min(grid.dims[1] - 1),
            (base[2] + dz).min(grid.dims[2] - 1),
        );
        *slot = (w, frames[i]);
    }
    let reference = corners
        .iter()
        .fold((f64::NEG_INFINITY, quaternion::IDENTITY), |b, c| if c.0 > b.0 { *c } else { b });
    let mut acc = [0.0; 4];
    for (w, q) in corners {
        let q = quaternion::align_sign(q, reference.1);
        for c in 0..4 {
            acc[c] += w * q[c];
        }
    }
    quaternion::normalize(acc).unwrap_or(reference.1)
}

#[cfg(test)]
#[path = "frame_field_3d_tests.rs"]
mod tests;
