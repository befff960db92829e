//! One design session: a plane [`FieldDesign`] (paper D's interactive design object,
//! kept factored), the edits a page sends, and the field sampled after each edit.

use fieldtex_fields::design_file::{SingularitySpec, StrokeSpec};
use fieldtex_fields::{
    DesignFile, FieldDesign, Singularity, SingularityId, SingularityKind, Stroke, StrokeId,
};
use serde::Deserialize;
use std::time::Instant;

/// Most points in one stroke; most singularities / strokes in one design.
pub const MAX_STROKE_POINTS: usize = 4096;
pub const MAX_ELEMENTS: usize = 256;

/// An edit as the page sends it (`{"op": "add_singularity", ...}`). Coordinates are
/// design pixels (x right, y down), angles degrees.
#[derive(Debug, Deserialize)]
#[serde(tag = "op", rename_all = "snake_case")]
pub enum Edit {
    AddSingularity {
        kind: SingularityKind,
        x: f64,
        y: f64,
        #[serde(default)]
        angle_deg: f64,
        #[serde(default = "one")]
        strength: f64,
    },
    MoveSingularity {
        id: u32,
        x: f64,
        y: f64,
        angle_deg: Option<f64>,
    },
    RemoveSingularity {
        id: u32,
    },
    AddStroke {
        points: Vec<[f64; 2]>,
        #[serde(default = "one")]
        weight: f64,
    },
    MoveStroke {
        id: u32,
        points: Vec<[f64; 2]>,
    },
    RemoveStroke {
        id: u32,
    },
}

fn one() -> f64 {
    1.0
}

/// A design being edited. All methods run under the session's mutex.
pub struct Session {
    /// Domain, symmetry and weights of the design (its element lists are rebuilt from
    /// [`FieldDesign`] on export).
    base: DesignFile,
    design: FieldDesign,
    /// Side of the square grid the field is sampled on for the page.
    pub view: usize,
    /// The last sampled field (`view²` vectors).
    pub field: Vec<[f32; 2]>,
    /// Incremented by every successful edit.
    pub version: u64,
    /// Milliseconds of the last edit + solve + sample.
    pub last_solve_ms: f64,
}

fn finite(what: &str, v: f64) -> Result<(), String> {
    if v.is_finite() { Ok(()) } else { Err(format!("{what} is {v}; give a finite number")) }
}

impl Session {
    /// Builds (factors) a plane design and samples its field at `view²`.
    pub fn new(base: DesignFile, view: usize) -> Result<Self, String> {
        if base.plane_grid().is_none() {
            return Err(
                "the studio designs on the plane: [domain] kind = \"plane\" with width and height"
                    .into(),
            );
        }
        if !(8..=256).contains(&base.domain.grid) {
            return Err(format!("grid {} is outside 8..=256 cells per side", base.domain.grid));
        }
        let design = base.build(None).map_err(|e| e.to_string())?;
        let mut s = Self { base, design, view, field: Vec::new(), version: 0, last_solve_ms: 0.0 };
        s.resolve()?;
        Ok(s)
    }

    /// Width and height of the design rectangle in pixels.
    pub fn size(&self) -> (f64, f64) {
        let g = self.design.plane().expect("plane design");
        (g.width, g.height)
    }

    fn resolve(&mut self) -> Result<(), String> {
        let t = Instant::now();
        let n = self.view;
        self.design
            .solve_and_sample_into(n, n, &mut self.field)
            .map_err(|e| format!("solve: {e}"))?;
        self.last_solve_ms = t.elapsed().as_secs_f64() * 1e3;
        Ok(())
    }

    /// Applies an edit, re-solves and re-samples. Returns the id of an added element.
    pub fn apply(&mut self, edit: Edit) -> Result<Option<u32>, String> {
        let t = Instant::now();
        let count = self.design.singularities().len() + self.design.strokes().len();
        let check_points = |pts: &[[f64; 2]]| -> Result<(), String> {
            if pts.len() < 2 || pts.len() > MAX_STROKE_POINTS {
                return Err(format!(
                    "a stroke needs 2 to {MAX_STROKE_POINTS} points, got {}",
                    pts.len()
                ));
            }
            for p in pts {
                finite("a stroke point", p[0])?;
                finite("a stroke point", p[1])?;
            }
            Ok(())
        };
        let to3 = |pts: &[[f64; 2]]| pts.iter().map(|p| [p[0], p[1], 0.0]).collect::<Vec<_>>();
        let mut added = None;
        match edit {
            Edit::AddSingularity { kind, x, y, angle_deg, strength } => {
                if count >= MAX_ELEMENTS {
                    return Err(format!("at most {MAX_ELEMENTS} elements per design"));
                }
                finite("x", x)?;
                finite("y", y)?;
                finite("angle_deg", angle_deg)?;
                if !(strength.is_finite() && strength > 0.0 && strength <= 100.0) {
                    return Err(format!("strength {strength} is outside (0, 100]"));
                }
                let s = Singularity::at_pixel(kind, x, y)
                    .with_angle(angle_deg.to_radians())
                    .with_strength(strength);
                let id = self.design.add_singularity(s).map_err(|e| e.to_string())?;
                added = Some(id.0);
            }
            Edit::MoveSingularity { id, x, y, angle_deg } => {
                finite("x", x)?;
                finite("y", y)?;
                let sid = SingularityId(id);
                let mut s =
                    self.design.singularity(sid).ok_or_else(|| format!("no singularity {id}"))?;
                s.position = [x, y, 0.0];
                if let Some(a) = angle_deg {
                    finite("angle_deg", a)?;
                    s.angle = a.to_radians();
                }
                self.design.set_singularity(sid, s).map_err(|e| e.to_string())?;
            }
            Edit::RemoveSingularity { id } => {
                self.design.remove_singularity(SingularityId(id)).map_err(|e| e.to_string())?;
            }
            Edit::AddStroke { points, weight } => {
                if count >= MAX_ELEMENTS {
                    return Err(format!("at most {MAX_ELEMENTS} elements per design"));
                }
                check_points(&points)?;
                if !(weight.is_finite() && weight > 0.0 && weight <= 100.0) {
                    return Err(format!("stroke weight {weight} is outside (0, 100]"));
                }
                let id = self
                    .design
                    .add_stroke(Stroke::new(to3(&points)).with_weight(weight))
                    .map_err(|e| e.to_string())?;
                added = Some(id.0);
            }
            Edit::MoveStroke { id, points } => {
                check_points(&points)?;
                let sid = StrokeId(id);
                let weight =
                    self.design.stroke(sid).ok_or_else(|| format!("no stroke {id}"))?.weight;
                self.design
                    .set_stroke(sid, Stroke::new(to3(&points)).with_weight(weight))
                    .map_err(|e| e.to_string())?;
            }
            Edit::RemoveStroke { id } => {
                self.design.remove_stroke(StrokeId(id)).map_err(|e| e.to_string())?;
            }
        }
        self.resolve()?;
        self.version += 1;
        self.last_solve_ms = t.elapsed().as_secs_f64() * 1e3;
        Ok(added)
    }

    /// The field sampled at `n²` (for synthesis and export), without changing the view.
    pub fn sample(&mut self, n: usize) -> Result<Vec<[f32; 2]>, String> {
        let mut out = Vec::new();
        self.design.solve_and_sample_into(n, n, &mut out).map_err(|e| format!("solve: {e}"))?;
        Ok(out)
    }

    /// The design as a design file (angles in degrees), loadable by `fieldtex orient --design`.
    pub fn design_file(&self) -> DesignFile {
        let mut d = self.base.clone();
        d.singularities = self
            .design
            .singularities()
            .into_iter()
            .map(|(_, s)| SingularitySpec {
                kind: s.kind,
                x: Some(s.position[0]),
                y: Some(s.position[1]),
                position: None,
                angle: s.angle.to_degrees(),
                strength: s.strength,
            })
            .collect();
        d.strokes = self
            .design
            .strokes()
            .into_iter()
            .map(|(_, s)| StrokeSpec {
                points: s.points.iter().map(|p| vec![p[0], p[1]]).collect(),
                weight: s.weight,
            })
            .collect();
        d
    }

    /// The elements and field metadata as JSON (the page's state).
    pub fn state_json(&self, session: &str) -> serde_json::Value {
        let (w, h) = self.size();
        let sings: Vec<_> = self
            .design
            .singularities()
            .into_iter()
            .map(|(id, s)| {
                serde_json::json!({
                    "id": id.0, "kind": s.kind.name(), "x": s.position[0], "y": s.position[1],
                    "angle_deg": s.angle.to_degrees(), "strength": s.strength,
                })
            })
            .collect();
        let strokes: Vec<_> = self
            .design
            .strokes()
            .into_iter()
            .map(|(id, s)| {
                let pts: Vec<[f64; 2]> = s.points.iter().map(|p| [p[0], p[1]]).collect();
                serde_json::json!({ "id": id.0, "points": pts, "weight": s.weight })
            })
            .collect();
        let kinds: Vec<&str> = fieldtex_fields::field_design::kinds_for(self.design.symmetry())
            .iter()
            .map(|k| k.name())
            .collect();
        let warnings: Vec<String> =
            self.design.warnings().iter().map(|w| w.message.clone()).collect();
        serde_json::json!({
            "session": session,
            "version": self.version,
            "width": w,
            "height": h,
            "grid": self.base.domain.grid,
            "symmetry": self.design.symmetry().name(),
            "kinds": kinds,
            "singularities": sings,
            "strokes": strokes,
            "field_size": self.view,
            "solve_ms": self.last_solve_ms,
            "warnings": warnings,
        })
    }
}
