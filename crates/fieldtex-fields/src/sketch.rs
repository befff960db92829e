//! The sketch file of `fieldtex solid` (paper E §3): curves that steer a 3-D frame field.
//!
//! JSON, in mesh coordinates:
//!
//! ```json
//! {"curves": [
//!   {"points": [[0.0, 0.1, 0.2], [0.1, 0.1, 0.2]], "axis": "x", "weight": 1.0},
//!   {"points": [[0.0, 0.0, 0.0], [0.0, 0.2, 0.0]],
//!    "plane": {"point": [0, 0, 0], "normal": [0, 0, 1]}, "axis": "y"},
//!   {"points": [[0.0, 0.0, 0.1], [0.1, 0.0, 0.1]], "refine": true}
//! ]}
//! ```
//!
//! - A curve without `"plane"` lies on the surface: its points are snapped to the
//!   closest surface point, and the frame at each point is the tangent (local axis
//!   `"axis"`, default `"x"`), the outward normal (the local axis after it in the cycle
//!   x → z, y → x, z → y) and their cross product.
//! - A curve with `"plane"` lies inside on that reference plane: points are projected
//!   onto it and the plane's normal replaces the surface normal.
//! - `"weight"` (default 1) multiplies the constraint weight w = 100.
//! - `"refine": true` (default false) makes a refinement curve: the current field is
//!   turned so that its direction nearest the tangent follows the curve (no normal used).
//!
//! The parsed [`Sketch`] is checked by [`Sketch::validate`] (errors name the curve and
//! point); [`Sketch::frame_curves`] places it on a mesh.

use crate::FieldsError;
use crate::frame_field_3d::FrameCurve;
use fieldtex_mesh::{Bvh, NormalWeighting, TriMesh, vertex_normals};
use serde::{Deserialize, Serialize};

/// A reference plane for an interior curve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SketchPlane {
    pub point: [f64; 3],
    pub normal: [f64; 3],
}

/// Which local axis a curve's tangent becomes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SketchAxis {
    #[default]
    X,
    Y,
    Z,
}

impl SketchAxis {
    /// 0, 1 or 2.
    pub fn index(self) -> usize {
        match self {
            SketchAxis::X => 0,
            SketchAxis::Y => 1,
            SketchAxis::Z => 2,
        }
    }
}

/// Largest accepted curve weight. The weight multiplies w = 100 in a least-squares system
/// whose rows are squared: at 10⁶ the factorisation (and its rank-1 edits) loses
/// positive definiteness on a 2.5K-triangle torus, at 10⁴ it still holds; 10³ keeps a
/// margin (and a curve at 10³ already overrides every other constraint it meets).
pub const MAX_CURVE_WEIGHT: f64 = 1e3;

fn one() -> f64 {
    1.0
}

/// One sketched curve (module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SketchCurve {
    pub points: Vec<[f64; 3]>,
    #[serde(default)]
    pub plane: Option<SketchPlane>,
    #[serde(default)]
    pub axis: SketchAxis,
    #[serde(default = "one")]
    pub weight: f64,
    #[serde(default)]
    pub refine: bool,
}

/// A sketch: curves in drawing order (later curves take their signs from the field of
/// the earlier ones).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sketch {
    pub curves: Vec<SketchCurve>,
}

fn sketch_error(message: String) -> FieldsError {
    FieldsError::DesignFile { message }
}

impl Sketch {
    /// Checks counts and numbers; errors name the curve and point (0-based).
    pub fn validate(&self) -> Result<(), FieldsError> {
        if self.curves.is_empty() {
            return Err(sketch_error(
                "the sketch has no curve; add at least one to \"curves\"".into(),
            ));
        }
        for (c, curve) in self.curves.iter().enumerate() {
            if curve.points.len() < 2 {
                return Err(sketch_error(format!(
                    "curve {c} has {} point(s); a curve needs at least two",
                    curve.points.len()
                )));
            }
            for (k, p) in curve.points.iter().enumerate() {
                if p.iter().any(|v| !v.is_finite()) {
                    return Err(sketch_error(format!("curve {c} point {k} is not finite: {p:?}")));
                }
            }
            let moved = curve.points.windows(2).any(|w| w[0] != w[1]);
            if !moved {
                return Err(sketch_error(format!(
                    "curve {c}: all its points coincide; draw a curve with length"
                )));
            }
            if !(curve.weight > 0.0 && curve.weight <= MAX_CURVE_WEIGHT) {
                return Err(sketch_error(format!(
                    "curve {c} has weight {:?}; use a weight in (0, {MAX_CURVE_WEIGHT:e}]",
                    curve.weight
                )));
            }
            if let Some(pl) = &curve.plane {
                let n = pl.normal;
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                if !(len.is_finite() && len > 1e-12) || pl.point.iter().any(|v| !v.is_finite()) {
                    return Err(sketch_error(format!(
                        "curve {c}: the plane needs a finite point and a non-zero normal (got normal {n:?})"
                    )));
                }
            }
        }
        Ok(())
    }

    /// Places the curves: surface curves snapped to `mesh` with its outward vertex
    /// normals interpolated at the snapped points, plane curves projected onto their
    /// plane. Also returns the placed points per curve (for drawing).
    pub fn frame_curves(&self, mesh: &TriMesh) -> Result<Vec<FrameCurve>, FieldsError> {
        self.validate()?;
        let needs_surface = self.curves.iter().any(|c| c.plane.is_none());
        let surface = if needs_surface {
            let bvh = Bvh::build(mesh)?;
            let (normals, _) = vertex_normals(mesh, NormalWeighting::Angle);
            Some((bvh, normals))
        } else {
            None
        };
        let mut out = Vec::with_capacity(self.curves.len());
        for (c, curve) in self.curves.iter().enumerate() {
            let mut points = Vec::with_capacity(curve.points.len());
            let mut normals = Vec::with_capacity(curve.points.len());
            for (k, &p) in curve.points.iter().enumerate() {
                if let Some(pl) = &curve.plane {
                    let n = pl.normal;
                    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                    let n = [n[0] / len, n[1] / len, n[2] / len];
                    let d = (p[0] - pl.point[0]) * n[0]
                        + (p[1] - pl.point[1]) * n[1]
                        + (p[2] - pl.point[2]) * n[2];
                    points.push([p[0] - d * n[0], p[1] - d * n[1], p[2] - d * n[2]]);
                    normals.push(n);
                } else {
                    let (bvh, vn) = surface.as_ref().expect("built above");
                    let cp = bvh.closest_point(p).ok_or_else(|| {
                        sketch_error(format!(
                            "curve {c} point {k}: no closest surface point (empty mesh?)"
                        ))
                    })?;
                    let t = mesh.triangles[cp.triangle as usize];
                    let b = cp.barycentric;
                    let mut n = [0.0; 3];
                    for v in 0..3 {
                        for a in 0..3 {
                            n[a] += b[v] * vn[t[v] as usize][a];
                        }
                    }
                    points.push(cp.point);
                    normals.push(n);
                }
            }
            out.push(FrameCurve {
                points,
                normals,
                axis: curve.axis.index(),
                weight: curve.weight,
                refine: curve.refine,
            });
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_curve_and_point() {
        let s = Sketch {
            curves: vec![SketchCurve {
                points: vec![[0.0; 3], [1.0, f64::NAN, 0.0]],
                plane: None,
                axis: SketchAxis::X,
                weight: 1.0,
                refine: false,
            }],
        };
        let e = s.validate().unwrap_err().to_string();
        assert!(e.contains("curve 0 point 1"), "{e}");
    }
}
