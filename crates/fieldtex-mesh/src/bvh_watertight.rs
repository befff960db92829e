//! Watertight ray/triangle test of Woop, Benthin & Wald 2013 ("Watertight Ray/Triangle
//! Intersection", JCGT 2(1)), in `f32`, on triangles stored by coordinate rows.
//!
//! A triangle is kept as three rows `[x0 x1 x2]`, `[y0 y1 y2]`, `[z0 z1 z2]` (one SIMD
//! register each), so the paper's axis permutation `(kx, ky, kz)` is just a choice of
//! rows and the shear of all three corners, the three edge functions and the `t`
//! numerator are 3-wide SIMD operations. Every lane performs exactly the scalar
//! operations of the paper in the same order (no fused multiply–add), so a corner shared
//! by two triangles gets bit-identical sheared coordinates and an edge shared by two
//! triangles gets edge functions of opposite sign: a ray never slips between them.
//! Edge functions that are exactly zero in `f32` are recomputed in `f64` (§3.3).
//!
//! Not implemented: back-face culling (both sides count) and the paper's axis swap that
//! keeps the winding for culling; without culling it only flips all signs.

use glam::{Vec3A, Vec3Swizzles};
use obvhs::ray::Ray as ORay;
use obvhs::triangle::Triangle;

/// A triangle by coordinate rows: `rows[k]` holds coordinate `k` of corners 0, 1, 2.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct RowTriangle {
    rows: [Vec3A; 3],
}

impl RowTriangle {
    pub(super) fn new(t: &Triangle) -> Self {
        Self {
            rows: [
                Vec3A::new(t.v0.x, t.v1.x, t.v2.x),
                Vec3A::new(t.v0.y, t.v1.y, t.v2.y),
                Vec3A::new(t.v0.z, t.v1.z, t.v2.z),
            ],
        }
    }

    /// The corners as an obvhs triangle.
    pub(super) fn triangle(&self) -> Triangle {
        let [x, y, z] = self.rows;
        Triangle {
            v0: Vec3A::new(x.x, y.x, z.x),
            v1: Vec3A::new(x.y, y.y, z.y),
            v2: Vec3A::new(x.z, y.z, z.z),
        }
    }
}

/// Per-ray constants of the watertight test (Woop et al. 2013, §3): the dominant axis
/// `kz` of the direction, the two others, the shear and the ray origin and range.
#[derive(Clone, Copy)]
pub(super) struct Shear {
    k: [usize; 3],
    s: [f32; 3],
    org: [f32; 3],
    pub(super) tmin: f32,
    pub(super) tmax: f32,
}

impl Shear {
    pub(super) fn new(r: &ORay) -> Self {
        let d = r.direction;
        let kz = if d.x.abs() >= d.y.abs() && d.x.abs() >= d.z.abs() {
            0
        } else if d.y.abs() >= d.z.abs() {
            1
        } else {
            2
        };
        let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
        let o = r.origin;
        Self {
            k: [kx, ky, kz],
            s: [d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]],
            org: [o[kx], o[ky], o[kz]],
            tmin: r.tmin,
            tmax: r.tmax,
        }
    }

    /// Ray parameter of the hit with triangle `tri` within `[tmin, tmax]`, or
    /// `f32::INFINITY`.
    #[inline(always)]
    pub(super) fn intersect(&self, tri: &RowTriangle) -> f32 {
        let [kx, ky, kz] = self.k;
        let [sx, sy, sz] = self.s;
        // Corners relative to the origin, permuted: x = (ax, bx, cx) and so on.
        let x = tri.rows[kx] - Vec3A::splat(self.org[0]);
        let y = tri.rows[ky] - Vec3A::splat(self.org[1]);
        let z = tri.rows[kz] - Vec3A::splat(self.org[2]);
        // Shear: ax - sx·az per lane.
        let x = x - Vec3A::splat(sx) * z;
        let y = y - Vec3A::splat(sy) * z;
        // (u, v, w) = (cx·by − cy·bx, ax·cy − ay·cx, bx·ay − by·ax).
        let mut uvw = x.zxy() * y.yzx() - y.zxy() * x.yzx();
        if uvw.cmpeq(Vec3A::ZERO).any() {
            // Exactly on an edge in f32: decide in f64 (§3.3 of the paper).
            let (x, y) = (x.as_dvec3(), y.as_dvec3());
            uvw = (x.zxy() * y.yzx() - y.zxy() * x.yzx()).as_vec3a();
        }
        if uvw.cmplt(Vec3A::ZERO).any() && uvw.cmpgt(Vec3A::ZERO).any() {
            return f32::INFINITY;
        }
        let det = uvw.x + uvw.y + uvw.z;
        if det == 0.0 {
            return f32::INFINITY;
        }
        let p = uvw * (Vec3A::splat(sz) * z);
        let t = (p.x + p.y + p.z) / det;
        if t >= self.tmin && t <= self.tmax { t } else { f32::INFINITY }
    }
}
