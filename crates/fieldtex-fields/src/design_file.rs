//! The TOML design format (parsed from a string; the I/O layer reads the file).
//!
//! ```toml
//! [domain]
//! kind = "plane"        # or "mesh" (the mesh is given on the command line)
//! width = 512           # plane only, pixels
//! height = 512
//! grid = 128            # cells along the longer side (default 128)
//!
//! [field]               # optional; inferred from the singularity kinds, else orientation
//! kind = "orientation"  # or "vector"
//!
//! [[singularity]]
//! kind = "wedge"        # wedge | trisector | source | sink | vortex | saddle
//! x = 230.0             # plane: pixels, origin top-left, y down
//! y = 240.0
//! # position = [x, y, z] instead of x, y on a mesh
//! angle = 45.0          # rotation α in degrees, from +x towards +y (clockwise on screen)
//! strength = 1.0        # default 1
//!
//! [[stroke]]
//! points = [[20, 440], [256, 430], [492, 440]]   # [x, y] or [x, y, z]
//! weight = 1.0          # default 1
//!
//! [weights]
//! smoothness = 1.0      # default 1
//! boundary = 1.0        # natural boundary term, 0..1 (0 = ablation); default 1
//! stroke = 4.0          # global stroke weight; default 4
//! ```
//!
//! Unknown keys are errors (typos must not be silently ignored).

use serde::{Deserialize, Serialize};

use crate::FieldsError;
use crate::design_elements::{Singularity, SingularityKind, Stroke, Symmetry};
use crate::domain::PlaneGrid;
use crate::field_design::{Domain, FieldDesign, FieldDesignOptions};
use fieldtex_mesh::TriMesh;

/// Kind of design domain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DomainKind {
    Plane,
    Mesh,
}

fn default_grid() -> usize {
    128
}
fn one() -> f64 {
    1.0
}
fn default_stroke_weight() -> f64 {
    FieldDesignOptions::default().stroke_weight
}

/// `[domain]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DomainSpec {
    pub kind: DomainKind,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<f64>,
    #[serde(default = "default_grid")]
    pub grid: usize,
}

/// `[field]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldSpec {
    pub kind: Symmetry,
}

/// One `[[singularity]]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SingularitySpec {
    pub kind: SingularityKind,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<[f64; 3]>,
    /// Degrees.
    #[serde(default)]
    pub angle: f64,
    #[serde(default = "one")]
    pub strength: f64,
}

/// One `[[stroke]]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StrokeSpec {
    pub points: Vec<Vec<f64>>,
    #[serde(default = "one")]
    pub weight: f64,
}

/// `[weights]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeightsSpec {
    #[serde(default = "one")]
    pub smoothness: f64,
    #[serde(default = "one")]
    pub boundary: f64,
    #[serde(default = "default_stroke_weight")]
    pub stroke: f64,
}

impl Default for WeightsSpec {
    fn default() -> Self {
        Self { smoothness: 1.0, boundary: 1.0, stroke: default_stroke_weight() }
    }
}

/// A whole design file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DesignFile {
    pub domain: DomainSpec,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field: Option<FieldSpec>,
    #[serde(default, rename = "singularity", skip_serializing_if = "Vec::is_empty")]
    pub singularities: Vec<SingularitySpec>,
    #[serde(default, rename = "stroke", skip_serializing_if = "Vec::is_empty")]
    pub strokes: Vec<StrokeSpec>,
    #[serde(default)]
    pub weights: WeightsSpec,
}

fn bad(message: String) -> FieldsError {
    FieldsError::DesignFile { message }
}

impl DesignFile {
    /// Parses and validates a design.
    pub fn from_toml_str(text: &str) -> Result<Self, FieldsError> {
        let d: DesignFile = toml::from_str(text).map_err(|e| bad(e.to_string()))?;
        d.validate()?;
        Ok(d)
    }

    /// The design as TOML text.
    pub fn to_toml_string(&self) -> String {
        toml::to_string(self).expect("a design always serialises")
    }

    /// A plane design with no elements.
    pub fn plane(width: f64, height: f64, grid: usize, symmetry: Symmetry) -> Self {
        Self {
            domain: DomainSpec {
                kind: DomainKind::Plane,
                width: Some(width),
                height: Some(height),
                grid,
            },
            field: Some(FieldSpec { kind: symmetry }),
            singularities: Vec::new(),
            strokes: Vec::new(),
            weights: WeightsSpec::default(),
        }
    }

    /// Checks numbers, kinds and coordinates; errors name the element and what to fix.
    pub fn validate(&self) -> Result<(), FieldsError> {
        let finite = |what: String, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(bad(format!("{what} is {v}; give a finite number")))
            }
        };
        if self.domain.kind == DomainKind::Plane {
            for (name, v) in [("width", self.domain.width), ("height", self.domain.height)] {
                match v {
                    Some(v) if v.is_finite() && v > 0.0 => {}
                    Some(v) => {
                        return Err(bad(format!(
                            "[domain] {name} = {v}; it must be a positive number of pixels"
                        )));
                    }
                    None => {
                        return Err(bad(format!(
                            "[domain] kind = \"plane\" needs `{name}` (pixels)"
                        )));
                    }
                }
            }
        }
        if !(4..=2048).contains(&self.domain.grid) {
            return Err(bad(format!(
                "[domain] grid = {}; use 4..=2048 cells (default 128)",
                self.domain.grid
            )));
        }
        let sym = self.symmetry()?;
        for (i, s) in self.singularities.iter().enumerate() {
            if s.kind.symmetry() != sym {
                return Err(bad(format!(
                    "singularity {i} is a {} but the field is a {} field; use wedge/trisector for orientation fields and source/sink/vortex/saddle for vector fields",
                    s.kind.name(),
                    sym.name()
                )));
            }
            finite(format!("singularity {i} angle"), s.angle)?;
            finite(format!("singularity {i} strength"), s.strength)?;
            self.singularity_position(i, s)?;
        }
        for (i, st) in self.strokes.iter().enumerate() {
            if st.points.len() < 2 {
                return Err(bad(format!(
                    "stroke {i} has {} point(s); a stroke needs at least two",
                    st.points.len()
                )));
            }
            for (k, p) in st.points.iter().enumerate() {
                if p.len() != 2 && p.len() != 3 {
                    return Err(bad(format!(
                        "stroke {i} point {k} has {} coordinates; give [x, y] or [x, y, z]",
                        p.len()
                    )));
                }
                for v in p {
                    finite(format!("stroke {i} point {k}"), *v)?;
                }
            }
            if !(st.weight.is_finite() && st.weight >= 0.0) {
                return Err(bad(format!("stroke {i} weight = {}; it must be ≥ 0", st.weight)));
            }
        }
        let w = &self.weights;
        if !(w.smoothness.is_finite() && w.smoothness > 0.0) {
            return Err(bad(format!("[weights] smoothness = {}; it must be > 0", w.smoothness)));
        }
        if !(w.boundary.is_finite() && (0.0..=1.0).contains(&w.boundary)) {
            return Err(bad(format!(
                "[weights] boundary = {}; it must be in [0, 1] (0 disables the natural boundary term)",
                w.boundary
            )));
        }
        if !(w.stroke.is_finite() && w.stroke >= 0.0) {
            return Err(bad(format!("[weights] stroke = {}; it must be ≥ 0", w.stroke)));
        }
        Ok(())
    }

    fn singularity_position(&self, i: usize, s: &SingularitySpec) -> Result<[f64; 3], FieldsError> {
        let p = match (s.position, s.x, s.y) {
            (Some(p), None, None) => p,
            (None, Some(x), Some(y)) => [x, y, 0.0],
            (Some(_), _, _) => {
                return Err(bad(format!(
                    "singularity {i}: give either `position` or `x` and `y`, not both"
                )));
            }
            _ => {
                return Err(bad(format!(
                    "singularity {i} needs `x` and `y` (plane, pixels) or `position = [x, y, z]` (mesh)"
                )));
            }
        };
        if p.iter().any(|v| !v.is_finite()) {
            return Err(bad(format!("singularity {i} position {p:?} is not finite")));
        }
        Ok(p)
    }

    /// The field symmetry: `[field] kind`, else inferred from the singularities (mixing
    /// vector and orientation kinds is an error), else orientation.
    pub fn symmetry(&self) -> Result<Symmetry, FieldsError> {
        if let Some(f) = &self.field {
            return Ok(f.kind);
        }
        let mut kinds = self.singularities.iter().map(|s| s.kind.symmetry());
        match kinds.next() {
            None => Ok(Symmetry::Orientation),
            Some(first) => {
                if kinds.any(|k| k != first) {
                    Err(bad("the design mixes vector kinds (source/sink/vortex/saddle) with orientation kinds (wedge/trisector); choose one and set [field] kind".into()))
                } else {
                    Ok(first)
                }
            }
        }
    }

    /// Design options from `[weights]` (everything else at its default).
    pub fn options(&self) -> FieldDesignOptions {
        FieldDesignOptions {
            smoothness_weight: self.weights.smoothness,
            natural_boundary: self.weights.boundary > 0.0,
            boundary_weight: self.weights.boundary,
            stroke_weight: self.weights.stroke,
            ..FieldDesignOptions::default()
        }
    }

    /// The plane grid of a plane design.
    pub fn plane_grid(&self) -> Option<PlaneGrid> {
        match (self.domain.kind, self.domain.width, self.domain.height) {
            (DomainKind::Plane, Some(w), Some(h)) => {
                Some(PlaneGrid::with_cells(w, h, self.domain.grid))
            }
            _ => None,
        }
    }

    /// Singularities with angles in radians.
    pub fn singularity_list(&self) -> Result<Vec<Singularity>, FieldsError> {
        self.singularities
            .iter()
            .enumerate()
            .map(|(i, s)| {
                Ok(Singularity {
                    kind: s.kind,
                    position: self.singularity_position(i, s)?,
                    angle: s.angle.to_radians(),
                    strength: s.strength,
                })
            })
            .collect()
    }

    /// Strokes with 3-D points (`z = 0` for 2-D points).
    pub fn stroke_list(&self) -> Vec<Stroke> {
        self.strokes
            .iter()
            .map(|s| Stroke {
                points: s
                    .points
                    .iter()
                    .map(|p| [p[0], p[1], p.get(2).copied().unwrap_or(0.0)])
                    .collect(),
                weight: s.weight,
            })
            .collect()
    }

    /// Builds and factors the design, then adds its singularities and strokes. A mesh
    /// design needs `mesh`; a plane design ignores it.
    pub fn build(&self, mesh: Option<TriMesh>) -> Result<FieldDesign, FieldsError> {
        self.build_with(mesh, self.options())
    }

    /// [`DesignFile::build`] for a design that is solved once and never edited (the
    /// CLI's plane `orient`): `rank1_update_limit = 0`, so the factorisation keeps no
    /// checkpoint copy for later stroke edits ([`crate::design_factor`]). The factor,
    /// the solve and so the field are bit-identical to [`DesignFile::build`]'s; only
    /// the copy's time and memory are saved.
    pub fn build_once(&self, mesh: Option<TriMesh>) -> Result<FieldDesign, FieldsError> {
        self.build_with(mesh, self.options().with_rank1_update_limit(0))
    }

    fn build_with(
        &self,
        mesh: Option<TriMesh>,
        options: FieldDesignOptions,
    ) -> Result<FieldDesign, FieldsError> {
        self.validate()?;
        let domain = match self.domain.kind {
            DomainKind::Plane => Domain::Plane(self.plane_grid().expect("validated")),
            DomainKind::Mesh => Domain::Mesh(mesh.ok_or_else(|| {
                bad("[domain] kind = \"mesh\" needs a mesh (pass --mesh PATCH)".into())
            })?),
        };
        let mut design = FieldDesign::new(domain, self.symmetry()?, options)?;
        for s in self.singularity_list()? {
            design.add_singularity(s)?;
        }
        for s in self.stroke_list() {
            design.add_stroke(s)?;
        }
        Ok(design)
    }
}
