//! The error type of `fieldtex-fields`.

use thiserror::Error;

/// Everything that can go wrong while building operators, designing or sampling a field.
/// Variants carry the element and the value; messages say what to do.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum FieldsError {
    #[error(
        "the design mesh is invalid: {0} (repair the mesh first, e.g. `fieldtex inspect --repair`)"
    )]
    InvalidMesh(#[from] fieldtex_mesh::MeshError),
    #[error(
        "triangle {triangle} repeats vertex {vertex}: drop degenerate triangles before designing a field"
    )]
    DegenerateTriangle { triangle: usize, vertex: u32 },
    #[error(
        "edge {edge} (vertices {a}–{b}) is shared by {faces} triangles: field design needs a manifold patch"
    )]
    NonManifoldEdge { edge: usize, a: u32, b: u32, faces: usize },
    #[error(
        "the triangles at edge {edge} (vertices {a}–{b}) are oriented inconsistently: orient the mesh first"
    )]
    InconsistentOrientation { edge: usize, a: u32, b: u32 },
    #[error("design option `{name}` = {value} is invalid: {expected}")]
    InvalidOption { name: &'static str, value: f64, expected: &'static str },
    #[error("{what} {index} has a non-finite {field} ({value}); give finite numbers")]
    NonFinite { what: &'static str, index: usize, field: &'static str, value: f64 },
    #[error("{what} at ({x}, {y}, {z}) lies outside the design domain; move it inside")]
    OutsideDomain { what: &'static str, x: f64, y: f64, z: f64 },
    #[error("stroke {stroke} has {points} point(s); a stroke needs at least two")]
    StrokeTooShort { stroke: usize, points: usize },
    #[error("stroke {stroke} does not cross the design domain; draw it inside the domain")]
    StrokeMissesDomain { stroke: usize },
    #[error("no {what} with id {id} exists in this design (it may have been removed)")]
    UnknownId { what: &'static str, id: u32 },
    #[error(
        "a {kind} singularity does not belong in a {symmetry} design: use wedge/trisector for orientation fields and source/sink/vortex/saddle for vector fields"
    )]
    WrongSymmetry { kind: &'static str, symmetry: &'static str },
    #[error("the field design system could not be solved: {0}")]
    Solve(#[from] fieldtex_linalg::LinalgError),
    #[error("the design file is invalid: {message}")]
    DesignFile { message: String },
    #[error("unknown preset `{name}`; available presets: {available}")]
    UnknownPreset { name: String, available: String },
    #[error(
        "field array has {found} entries for a {width}×{height} image; expected width·height = {expected}"
    )]
    FieldSize { width: usize, height: usize, expected: usize, found: usize },
    #[error(
        "the curve field is current at only some vertices ({stale} stale after an incremental solve); call CurveFieldSolver::solve first"
    )]
    StaleSolution { stale: usize },
}

/// The design's mesh, options, constraints, strokes, design files and presets are bad
/// input; a failed solve, and asking a solver for a stale solution (a caller's bug), are
/// internal.
impl fieldtex_core::HasErrorKind for FieldsError {
    fn kind(&self) -> fieldtex_core::ErrorKind {
        use fieldtex_core::ErrorKind;
        match self {
            FieldsError::InvalidMesh(e) => e.kind(),
            FieldsError::Solve(_) | FieldsError::StaleSolution { .. } => ErrorKind::Internal,
            FieldsError::DegenerateTriangle { .. }
            | FieldsError::NonManifoldEdge { .. }
            | FieldsError::InconsistentOrientation { .. }
            | FieldsError::InvalidOption { .. }
            | FieldsError::NonFinite { .. }
            | FieldsError::OutsideDomain { .. }
            | FieldsError::StrokeTooShort { .. }
            | FieldsError::StrokeMissesDomain { .. }
            | FieldsError::UnknownId { .. }
            | FieldsError::WrongSymmetry { .. }
            | FieldsError::DesignFile { .. }
            | FieldsError::UnknownPreset { .. }
            | FieldsError::FieldSize { .. } => ErrorKind::BadInput,
        }
    }
}
