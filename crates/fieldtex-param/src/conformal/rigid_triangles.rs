//! Rigid-triangle targets for the quasi-isometric relaxation: the local step of
//! as-rigid-as-possible parameterisation (Liu, Zhang, Xu, Gotsman & Gortler 2008, "A
//! local/global approach to mesh parameterization", eq. 3 and §3.2, the ARAP energy).
//!
//! Each triangle's rest shape is its own 3-D triangle laid flat and shrunk by the
//! global length ratio `η̄` of surface to parameter plane (so the relaxed map keeps the
//! image's total area and its lattice). The local step fits the rotation `R_f` that
//! best carries the rest edges onto the current ones (the closest rotation to the
//! cotangent-weighted edge covariance, closed form in 2-D); the targets of the global
//! step are the rotated rest edges. Where the mass-spring targets of
//! [`super::mass_spring`] only rescale each edge along its current direction, these
//! also restore the triangle's angles, so a region the conformal map compressed by
//! orders of magnitude grows without shearing its neighbours.
//!
//! Used by [`super::mass_spring::relax`] with
//! [`super::Targets::RigidTriangles`] — a substitute for the paper's eq. 2
//! forces (Wang et al. 2005, §5.1), named as one in `docs/conformal.md`. Shapes: rest
//! corners `#F × 3 × 2`, half-cotangent weights `#F × 3` for the edge of corners
//! `(k, k + 1)` (the convention of [`fieldtex_mesh::Topology::face_edges`]).

use fieldtex_mesh::{CotanOptions, MeshError, TriMesh, cotan_face_weights};

/// Rest shapes and weights of the first `n` triangles of a mesh.
pub(super) struct RigidTriangles {
    /// Rest corners in the parameter plane's units, `None` where the face is not
    /// relaxed (a slit's apex face, or a degenerate triangle).
    rest: Vec<Option<[[f64; 2]; 3]>>,
    /// Half-cotangent weight of each face edge (of the 3-D triangle, so of the rest
    /// shape too). Each triangle's block of the energy is positive semi-definite
    /// whatever the signs, as for the cotangent Laplacian.
    half_cot: Vec<[f64; 3]>,
    /// Per-face factor on the weights (1 until [`Self::reweight`]).
    omega: Vec<f64>,
}

impl RigidTriangles {
    /// `use_face[f]` says whether face `f < n` takes part; `eta_mean` is the global ratio
    /// of surface to parameter length (rest shapes are the 3-D ones divided by it).
    pub(super) fn new(
        mesh: &TriMesh,
        n: usize,
        use_face: &[bool],
        eta_mean: f64,
    ) -> Result<Self, MeshError> {
        let (mut half_cot, _) = cotan_face_weights(mesh, &CotanOptions::default())?;
        half_cot.truncate(n);
        let rest = (0..n)
            .map(|f| {
                if !use_face[f] {
                    return None;
                }
                let p = mesh.triangle_positions(f);
                let e1 = fieldtex_core::vec3::sub(p[1], p[0]);
                let e2 = fieldtex_core::vec3::sub(p[2], p[0]);
                let l1 = fieldtex_core::vec3::norm(e1);
                let n3 = fieldtex_core::vec3::cross(e1, e2);
                let y = fieldtex_core::vec3::normalize(fieldtex_core::vec3::cross(n3, e1))?;
                let x = fieldtex_core::vec3::scale(e1, 1.0 / l1);
                let (bx, by) = (fieldtex_core::vec3::dot(e2, x), fieldtex_core::vec3::dot(e2, y));
                let s = 1.0 / eta_mean;
                let shape = [[0.0, 0.0], [l1 * s, 0.0], [bx * s, by * s]];
                (shape.iter().flatten().all(|v| v.is_finite()) && by > 0.0).then_some(shape)
            })
            .collect();
        Ok(Self { rest, half_cot, omega: vec![1.0; n] })
    }

    /// Whether face `f` has a rest shape.
    pub(super) fn uses(&self, f: usize) -> bool {
        self.rest[f].is_some()
    }

    /// Weight of the edge of corners `(k, k + 1)` of face `f` (0 for unused faces).
    pub(super) fn weight(&self, f: usize, k: usize) -> f64 {
        if self.uses(f) { self.omega[f] * self.half_cot[f][k] } else { 0.0 }
    }

    /// Reweights face `f` from its current corners `c` for the symmetric Dirichlet
    /// energy `σ1² + σ1⁻² + σ2² + σ2⁻²` of the rest-to-current Jacobian (Rabinovich,
    /// Poranne, Panozzo & Sorkine-Hornung 2017, "Scalable locally injective mappings",
    /// §4 weights `w_i² = (σ_i + 1)(σ_i² + 1)/σ_i³`), averaged over the two singular
    /// directions and normalised to 1 at an isometry: an isotropic simplification of
    /// SLIM's `W_f` that keeps the two coordinates' systems apart. A compressed face
    /// (small `σ`) gets a weight growing like `σ⁻³`, so the steps open the regions the
    /// conformal map squeezed first.
    pub(super) fn reweight(&mut self, f: usize, c: &[[f64; 2]; 3]) {
        let Some(r) = self.rest[f] else { return };
        let (d1, d2) =
            ([c[1][0] - c[0][0], c[1][1] - c[0][1]], [c[2][0] - c[0][0], c[2][1] - c[0][1]]);
        let (e1, e2) =
            ([r[1][0] - r[0][0], r[1][1] - r[0][1]], [r[2][0] - r[0][0], r[2][1] - r[0][1]]);
        let det = e1[0] * e2[1] - e1[1] * e2[0];
        if det.abs() <= 0.0 || !det.is_finite() {
            return;
        }
        // J = [d1 d2] [e1 e2]⁻¹.
        let inv = [[e2[1] / det, -e2[0] / det], [-e1[1] / det, e1[0] / det]];
        let j = [
            [d1[0] * inv[0][0] + d2[0] * inv[1][0], d1[0] * inv[0][1] + d2[0] * inv[1][1]],
            [d1[1] * inv[0][0] + d2[1] * inv[1][0], d1[1] * inv[0][1] + d2[1] * inv[1][1]],
        ];
        let (s1, s2) = crate::distortion::singular_values_2x2(j);
        let w2 = |s: f64| {
            let s = s.max(1e-4);
            (s + 1.0) * (s * s + 1.0) / (s * s * s)
        };
        let omega = 0.125 * (w2(s1) + w2(s2));
        if omega.is_finite() {
            self.omega[f] = omega.clamp(1e-3, 1e6);
        }
    }

    /// The local step on face `f` with current corners `c`: the rotated rest edges
    /// `R_f (r_{k+1} − r_k)`, one per corner pair `(k, k + 1)`; `None` for unused faces.
    pub(super) fn targets(&self, f: usize, c: &[[f64; 2]; 3]) -> Option<[[f64; 2]; 3]> {
        let r = self.rest[f]?;
        let edge = |p: &[[f64; 2]; 3], k: usize| {
            let l = (k + 1) % 3;
            [p[l][0] - p[k][0], p[l][1] - p[k][1]]
        };
        // S = Σ w_k d_k r_kᵀ; the closest rotation has angle atan2(S10 − S01, S00 + S11).
        let (mut a, mut b) = (0.0, 0.0);
        for k in 0..3 {
            let (d, e) = (edge(c, k), edge(&r, k));
            let w = self.half_cot[f][k];
            a += w * (d[0] * e[0] + d[1] * e[1]);
            b += w * (d[1] * e[0] - d[0] * e[1]);
        }
        let norm = (a * a + b * b).sqrt();
        let (cos, sin) =
            if norm > 0.0 && norm.is_finite() { (a / norm, b / norm) } else { (1.0, 0.0) };
        let mut t = [[0.0; 2]; 3];
        for (k, tk) in t.iter_mut().enumerate() {
            let e = edge(&r, k);
            *tk = [cos * e[0] - sin * e[1], sin * e[0] + cos * e[1]];
        }
        Some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A right triangle in 3-D (legs 2 and 1), rest shapes at η̄ = 2.
    fn one_triangle() -> (TriMesh, RigidTriangles) {
        let mesh =
            TriMesh::new(vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]);
        let rt = RigidTriangles::new(&mesh, 1, &[true], 2.0).unwrap();
        (mesh, rt)
    }

    #[test]
    fn targets_are_the_rest_edges_rotated_onto_the_current_triangle() {
        let (_, rt) = one_triangle();
        // The rest shape (legs 1 and 0.5) rotated by 30° and moved: targets equal its
        // edges exactly.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let rot = |p: [f64; 2]| [c * p[0] - s * p[1] + 5.0, s * p[0] + c * p[1] - 1.0];
        let cur = [rot([0.0, 0.0]), rot([1.0, 0.0]), rot([0.0, 0.5])];
        let t = rt.targets(0, &cur).unwrap();
        for k in 0..3 {
            let l = (k + 1) % 3;
            let d = [cur[l][0] - cur[k][0], cur[l][1] - cur[k][1]];
            assert!((t[k][0] - d[0]).abs() < 1e-12 && (t[k][1] - d[1]).abs() < 1e-12, "{k}");
        }
        // A sheared, enlarged triangle gets rest-size targets (lengths 1, 0.5).
        let cur = [[0.0, 0.0], [3.0, 0.2], [1.0, 2.0]];
        let t = rt.targets(0, &cur).unwrap();
        let len = |v: [f64; 2]| v[0].hypot(v[1]);
        assert!((len(t[0]) - 1.0).abs() < 1e-12 && (len(t[2]) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn unused_faces_have_no_targets_and_no_weight() {
        let (mesh, _) = one_triangle();
        let rt = RigidTriangles::new(&mesh, 1, &[false], 1.0).unwrap();
        assert!(rt.targets(0, &[[0.0; 2]; 3]).is_none());
        assert_eq!(rt.weight(0, 1), 0.0);
    }
}
