//! The indexed triangle mesh.
//!
//! Connectivity (`triangles`) is kept separate from geometry (`positions`) so that
//! topological code asks only for what it needs. Texture coordinates live per corner
//! ([`CornerUvs`]) so that UV seams are natural: two triangles sharing a vertex may use
//! different UV values at it.
//!
//! Conventions: positions are `#V × 3` `f64`; triangles are `#F × 3` vertex indices
//! (`u32`), counter-clockwise seen from outside for a consistently oriented mesh.

use serde::Serialize;

/// Per-corner texture coordinates: `indices[f][i]` indexes `values` for corner `i`
/// of triangle `f`. UV (0,0) is the lower-left of the image (glTF flips V on write).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CornerUvs {
    /// `#UV × 2` texture coordinates.
    pub values: Vec<[f64; 2]>,
    /// `#F × 3` indices into `values`.
    pub indices: Vec<[u32; 3]>,
}

/// An indexed triangle mesh with optional attributes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// `#V × 3` vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// `#F × 3` vertex indices per triangle.
    pub triangles: Vec<[u32; 3]>,
    /// Optional per-corner texture coordinates (`indices.len() == triangles.len()`).
    pub uvs: Option<CornerUvs>,
    /// Optional `#V` vertex colours, sRGB in `[0, 1]`, RGBA.
    pub vertex_colors: Option<Vec<[f32; 4]>>,
    /// Optional `#V` vertex normals as read from a file (not recomputed).
    pub vertex_normals: Option<Vec<[f64; 3]>>,
}

/// Axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Aabb {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

impl Aabb {
    /// Length of the diagonal (0 for an empty box).
    pub fn diagonal(&self) -> f64 {
        let d = [self.max[0] - self.min[0], self.max[1] - self.min[1], self.max[2] - self.min[2]];
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
    }
    pub fn center(&self) -> [f64; 3] {
        [
            0.5 * (self.min[0] + self.max[0]),
            0.5 * (self.min[1] + self.max[1]),
            0.5 * (self.min[2] + self.max[2]),
        ]
    }
}

impl TriMesh {
    /// A mesh from positions and triangles, without attributes.
    pub fn new(positions: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Self {
        Self { positions, triangles, ..Default::default() }
    }

    pub fn n_vertices(&self) -> usize {
        self.positions.len()
    }

    pub fn n_triangles(&self) -> usize {
        self.triangles.len()
    }

    /// The three corner positions of triangle `f`.
    #[inline]
    pub fn triangle_positions(&self, f: usize) -> [[f64; 3]; 3] {
        let t = self.triangles[f];
        [
            self.positions[t[0] as usize],
            self.positions[t[1] as usize],
            self.positions[t[2] as usize],
        ]
    }

    /// Bounding box of the vertices referenced or not; `None` for an empty mesh or when
    /// no position is finite.
    pub fn bounding_box(&self) -> Option<Aabb> {
        let mut min = [f64::INFINITY; 3];
        let mut max = [f64::NEG_INFINITY; 3];
        let mut any = false;
        for p in &self.positions {
            if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
                continue;
            }
            any = true;
            for k in 0..3 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        }
        any.then_some(Aabb { min, max })
    }

    /// Checks the structural invariants every algorithm relies on: indices in range,
    /// finite positions, attribute lengths matching. Returns the first violation.
    pub fn validate(&self) -> Result<(), crate::MeshError> {
        use crate::MeshError;
        let nv = self.positions.len();
        for (v, p) in self.positions.iter().enumerate() {
            if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
                return Err(MeshError::NonFinitePosition { vertex: v });
            }
        }
        for (f, t) in self.triangles.iter().enumerate() {
            for &i in t {
                if i as usize >= nv {
                    return Err(MeshError::IndexOutOfRange {
                        triangle: f,
                        index: i as u64,
                        n_vertices: nv,
                    });
                }
            }
        }
        if let Some(uv) = &self.uvs {
            if uv.indices.len() != self.triangles.len() {
                return Err(MeshError::AttributeLength {
                    attribute: "uv indices",
                    expected: self.triangles.len(),
                    found: uv.indices.len(),
                });
            }
            let nuv = uv.values.len();
            for (f, t) in uv.indices.iter().enumerate() {
                for &i in t {
                    if i as usize >= nuv {
                        return Err(MeshError::UvIndexOutOfRange { triangle: f, index: i as u64 });
                    }
                }
            }
        }
        let per_vertex = [
            ("vertex colours", self.vertex_colors.as_ref().map(Vec::len)),
            ("vertex normals", self.vertex_normals.as_ref().map(Vec::len)),
        ];
        for (attribute, len) in per_vertex {
            if let Some(found) = len.filter(|&n| n != nv) {
                return Err(MeshError::AttributeLength { attribute, expected: nv, found });
            }
        }
        if self.triangles.is_empty() {
            return Err(MeshError::Empty);
        }
        Ok(())
    }
}
