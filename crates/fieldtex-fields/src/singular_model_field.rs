//! Exact 1-forms of the model fields of point singularities.
//!
//! Each singularity of a design is described by a model field in a local chart
//! (complex notation, `z = x + i y`, vector `u = u_x + i u_y`):
//! - index +1 (source, sink, vortex; the doubled-angle field of a wedge):
//!   `u(z) = c / conj(z − p)`, i.e. `|u| = |c| / r` with direction `e^{i(θ + arg c)}`;
//!   `Re c` is the flux and `Im c` the circulation around `p`, both times `2π`.
//! - index −1 (saddle; the doubled-angle field of a trisector):
//!   `u(z) = c / (z − p)`, direction `e^{−i(θ − arg c)}`. A saddle has no point
//!   divergence or curl: its divergence and curl are the smooth densities
//!   `Re, Im (−2c / (z − p)²)`.
//!
//! The 1-form of a model field is integrated *exactly* along each straight edge:
//! - pole: `∫_a^b conj(u) dz = conj(c) · Log((b − p)/(a − p))`,
//! - saddle: `∫_a^b conj(u) dz = conj(c) · (d / conj d) · conj(Log((b − p)/(a − p)))`
//!   with `d = b − a`,
//!
//! and the edge value is the real part (`u·dx = Re(conj(u) dz)`). A straight edge that
//! misses `p` sweeps an angle below π, so the principal logarithm is the right branch.
//! The design's prescribed divergence `S` and curl `C` are then the discrete divergence
//! and curl of the sum of these 1-forms ([`crate::field_design`]); for a source or
//! vortex they are concentrated at the singularity (a vortex's curl is exactly `2π c`
//! on the triangle that contains it, zero elsewhere), for a saddle they spread.
//!
//! Charts: on the plane the chart is the identity. On a curved patch the chart is the
//! orthogonal projection onto the tangent frame of the triangle containing `p`; far from
//! `p` this is only an approximation (documented limitation), near `p` it is accurate.

use fieldtex_core::vec3::{dot, sub};
use rayon::prelude::*;

use crate::dec::Dec;

/// Complex numbers as `[re, im]`, just what the model fields need.
pub(crate) mod cx {
    #[inline]
    pub fn mul(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
        [a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]]
    }
    #[inline]
    pub fn conj(a: [f64; 2]) -> [f64; 2] {
        [a[0], -a[1]]
    }
    #[inline]
    pub fn div(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
        let d = b[0] * b[0] + b[1] * b[1];
        [(a[0] * b[0] + a[1] * b[1]) / d, (a[1] * b[0] - a[0] * b[1]) / d]
    }
    /// Principal logarithm.
    #[inline]
    pub fn ln(a: [f64; 2]) -> [f64; 2] {
        [0.5 * (a[0] * a[0] + a[1] * a[1]).ln(), a[1].atan2(a[0])]
    }
}

/// Whether the model field has a pole (index +1) or is saddle-like (index −1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelKind {
    /// `u = c / conj(z − p)`.
    Pole,
    /// `u = c / (z − p)`.
    Saddle,
}

/// A model field placed in a chart: `p` is the origin (3-D point), `(e1, e2)` the chart
/// axes, `c` the complex coefficient.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelField {
    pub kind: ModelKind,
    pub origin: [f64; 3],
    pub e1: [f64; 3],
    pub e2: [f64; 3],
    pub c: [f64; 2],
}

impl ModelField {
    /// Chart coordinates of a 3-D point.
    #[inline]
    fn chart(&self, x: [f64; 3]) -> [f64; 2] {
        let d = sub(x, self.origin);
        [dot(d, self.e1), dot(d, self.e2)]
    }

    /// The exact integral of the field along the straight segment `a → b` (chart
    /// coordinates relative to the singularity). Segments through the singularity are
    /// kept finite by flooring `|z − p|` at `floor`.
    #[inline]
    pub fn segment_integral(&self, a: [f64; 2], b: [f64; 2], floor: f64) -> f64 {
        let fl = |z: [f64; 2]| {
            let r = (z[0] * z[0] + z[1] * z[1]).sqrt();
            if r >= floor {
                z
            } else if r > 0.0 {
                [z[0] * floor / r, z[1] * floor / r]
            } else {
                [floor, 0.0]
            }
        };
        let (a, b) = (fl(a), fl(b));
        let log = cx::ln(cx::div(b, a));
        let cc = cx::conj(self.c);
        match self.kind {
            ModelKind::Pole => cx::mul(cc, log)[0],
            ModelKind::Saddle => {
                let d = [b[0] - a[0], b[1] - a[1]];
                if d[0] == 0.0 && d[1] == 0.0 {
                    return 0.0;
                }
                let ratio = cx::div(d, cx::conj(d));
                cx::mul(cx::mul(cc, ratio), cx::conj(log))[0]
            }
        }
    }

    /// The field vector at chart point `z` (relative to the singularity), for tests.
    pub fn value(&self, z: [f64; 2]) -> [f64; 2] {
        match self.kind {
            ModelKind::Pole => cx::div(self.c, cx::conj(z)),
            ModelKind::Saddle => cx::div(self.c, z),
        }
    }

    /// Adds this field's exact 1-form to `omega` (`#E`). `floor` is the smallest
    /// distance to the singularity used in the logarithms (a small fraction of the edge
    /// length; only matters for an edge through the singularity).
    ///
    /// Same values as [`ModelField::segment_integral`] per edge, computed with one
    /// logarithm per *vertex*: `Log((b−p)/(a−p)) = (ln|b−p| − ln|a−p|) + i·wrap(θ_b − θ_a)`,
    /// where the wrapped angle difference is the principal one because a straight edge
    /// that misses `p` sweeps less than π.
    pub fn add_one_form(&self, dec: &Dec, floor: f64, omega: &mut [f64]) {
        use std::f64::consts::{PI, TAU};
        // Per vertex: chart point (floored away from p), ln r, θ.
        let polar: Vec<([f64; 2], f64, f64)> = dec
            .positions
            .par_iter()
            .map(|x| {
                let mut z = self.chart(*x);
                let r = (z[0] * z[0] + z[1] * z[1]).sqrt();
                if r < floor {
                    z = if r > 0.0 { [z[0] * floor / r, z[1] * floor / r] } else { [floor, 0.0] };
                }
                let r = (z[0] * z[0] + z[1] * z[1]).sqrt();
                (z, r.ln(), z[1].atan2(z[0]))
            })
            .collect();
        let cc = cx::conj(self.c);
        let kind = self.kind;
        let values: Vec<f64> = dec
            .topology
            .edges
            .par_iter()
            .map(|&[a, b]| {
                let (za, la, ta) = polar[a as usize];
                let (zb, lb, tb) = polar[b as usize];
                let mut dt = tb - ta;
                if dt > PI {
                    dt -= TAU;
                } else if dt <= -PI {
                    dt += TAU;
                }
                let log = [lb - la, dt];
                match kind {
                    ModelKind::Pole => cx::mul(cc, log)[0],
                    ModelKind::Saddle => {
                        let d = [zb[0] - za[0], zb[1] - za[1]];
                        if d[0] == 0.0 && d[1] == 0.0 {
                            return 0.0;
                        }
                        cx::mul(cx::mul(cc, cx::div(d, cx::conj(d))), cx::conj(log))[0]
                    }
                }
            })
            .collect();
        for (o, v) in omega.iter_mut().zip(values) {
            *o += v;
        }
    }
}
