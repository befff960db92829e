//! The elements a user places in a field design: singularities and strokes, and the
//! symmetry of the designed field.
//!
//! Angles are in radians here (degrees only in the TOML design file) and turn from `+x`
//! towards `+y` of the domain (on the plane, with `y` down, that is clockwise on
//! screen; see [`crate::domain`]).

use serde::{Deserialize, Serialize};

use crate::singular_model_field::ModelKind;

/// Symmetry of the designed field: a plain vector field (`N = 1`) or an orientation
/// field / 2-RoSy field (`N = 2`), designed as the vector field of the doubled angle
/// (paper D, §3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Symmetry {
    Vector,
    #[default]
    Orientation,
}

impl Symmetry {
    /// `N` of the N-RoSy field: 1 or 2.
    pub fn n(self) -> u32 {
        match self {
            Symmetry::Vector => 1,
            Symmetry::Orientation => 2,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Symmetry::Vector => "vector",
            Symmetry::Orientation => "orientation",
        }
    }
}

/// Kinds of singularities. The first four belong to vector designs, the last two to
/// orientation designs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SingularityKind {
    /// Index +1, positive divergence: `u ∝ e^{i(θ + α)} / r` (α rotates it into a spiral).
    Source,
    /// Index +1, negative divergence: `u ∝ e^{i(θ + π + α)} / r`.
    Sink,
    /// Index +1, positive curl (turning from +x to +y): `u ∝ e^{i(θ + π/2 + α)} / r`;
    /// a negative strength turns it the other way.
    Vortex,
    /// Index −1: `u ∝ e^{−i(θ + α)} / r`.
    Saddle,
    /// Orientation index +1/2 (a core or loop): orientation `e^{i(θ/2 + α)}`, the
    /// doubled-angle field is a pole `e^{i(θ + 2α)} / r`. Its single radial ridge points
    /// in the direction `2α`.
    Wedge,
    /// Orientation index −1/2 (a delta): orientation `e^{−i(θ/2 + α)}`, doubled field
    /// `e^{−i(θ + 2α)} / r`. Its three radial ridges point in the directions
    /// `−2α/3 + k·120°`.
    Trisector,
}

impl SingularityKind {
    pub const ALL: [SingularityKind; 6] = [
        SingularityKind::Source,
        SingularityKind::Sink,
        SingularityKind::Vortex,
        SingularityKind::Saddle,
        SingularityKind::Wedge,
        SingularityKind::Trisector,
    ];

    pub fn name(self) -> &'static str {
        match self {
            SingularityKind::Source => "source",
            SingularityKind::Sink => "sink",
            SingularityKind::Vortex => "vortex",
            SingularityKind::Saddle => "saddle",
            SingularityKind::Wedge => "wedge",
            SingularityKind::Trisector => "trisector",
        }
    }

    /// The symmetry this kind belongs to.
    pub fn symmetry(self) -> Symmetry {
        match self {
            SingularityKind::Wedge | SingularityKind::Trisector => Symmetry::Orientation,
            _ => Symmetry::Vector,
        }
    }

    /// Index of the singularity in its own field (±1, or ±1/2 for orientation fields).
    pub fn index(self) -> f64 {
        match self {
            SingularityKind::Source | SingularityKind::Sink | SingularityKind::Vortex => 1.0,
            SingularityKind::Saddle => -1.0,
            SingularityKind::Wedge => 0.5,
            SingularityKind::Trisector => -0.5,
        }
    }

    /// Model field of the *designed* vector field (doubled for orientation kinds):
    /// kind and coefficient `c` (see [`crate::singular_model_field`]) for rotation
    /// `angle` and magnitude `scale` (= strength × reference radius).
    pub fn model(self, angle: f64, scale: f64) -> (ModelKind, [f64; 2]) {
        use std::f64::consts::{FRAC_PI_2, PI};
        let (kind, arg) = match self {
            SingularityKind::Source => (ModelKind::Pole, angle),
            SingularityKind::Sink => (ModelKind::Pole, PI + angle),
            SingularityKind::Vortex => (ModelKind::Pole, FRAC_PI_2 + angle),
            SingularityKind::Saddle => (ModelKind::Saddle, -angle),
            SingularityKind::Wedge => (ModelKind::Pole, 2.0 * angle),
            SingularityKind::Trisector => (ModelKind::Saddle, -2.0 * angle),
        };
        (kind, [scale * arg.cos(), scale * arg.sin()])
    }
}

/// A singularity: kind, position (domain coordinates; on the plane `[x, y, 0]` in
/// pixels), rotation `angle` (radians) and `strength` (magnitude of the model field,
/// relative to unit stroke vectors, at a quarter of the domain size; default 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Singularity {
    pub kind: SingularityKind,
    pub position: [f64; 3],
    pub angle: f64,
    pub strength: f64,
}

impl Singularity {
    /// A singularity with angle 0 and strength 1.
    pub fn new(kind: SingularityKind, position: [f64; 3]) -> Self {
        Self { kind, position, angle: 0.0, strength: 1.0 }
    }
    /// On the plane, at pixel `(x, y)`.
    pub fn at_pixel(kind: SingularityKind, x: f64, y: f64) -> Self {
        Self::new(kind, [x, y, 0.0])
    }
    pub fn with_angle(mut self, angle: f64) -> Self {
        self.angle = angle;
        self
    }
    pub fn with_strength(mut self, strength: f64) -> Self {
        self.strength = strength;
        self
    }
}

/// A direction stroke: a polyline the field should follow (for vector designs in the
/// direction of the points' order; orientation designs ignore the sign), with a
/// weight (default 1) multiplying the design's stroke weight.
#[derive(Debug, Clone, PartialEq)]
pub struct Stroke {
    pub points: Vec<[f64; 3]>,
    pub weight: f64,
}

impl Stroke {
    pub fn new(points: Vec<[f64; 3]>) -> Self {
        Self { points, weight: 1.0 }
    }
    /// On the plane, from pixel coordinates.
    pub fn from_pixels(points: &[[f64; 2]]) -> Self {
        Self::new(points.iter().map(|p| [p[0], p[1], 0.0]).collect())
    }
    pub fn with_weight(mut self, weight: f64) -> Self {
        self.weight = weight;
        self
    }
}

/// Rotation angles (radians) that make each wedge/trisector agree, near itself, with the
/// zero-pole model of fingerprint orientation (Sherlock & Monro 1993):
/// `2θ(z) = 2θ₀ + Σ_wedges arg(z − c) − Σ_trisectors arg(z − d)`, `θ₀ = background`.
/// For a wedge `α_k = θ₀ + ½ Σ_{j≠k} s_j arg(p_k − p_j)`, for a trisector the negative
/// (`s = +1` wedge, `−1` trisector); other kinds get 0. Uses the `x, y` of positions
/// (plane designs). Rotations chosen this way avoid the extra singularities that
/// mutually inconsistent rotations can force (paper D, §5 "Limitations").
pub fn zero_pole_angles(singularities: &[Singularity], background: f64) -> Vec<f64> {
    let sign = |k: SingularityKind| match k {
        SingularityKind::Wedge => 1.0,
        SingularityKind::Trisector => -1.0,
        _ => 0.0,
    };
    singularities
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let sk = sign(s.kind);
            if sk == 0.0 {
                return 0.0;
            }
            let mut a = background;
            for (j, o) in singularities.iter().enumerate() {
                if j != k {
                    a += 0.5
                        * sign(o.kind)
                        * (s.position[1] - o.position[1]).atan2(s.position[0] - o.position[0]);
                }
            }
            sk * a
        })
        .collect()
}
