//! Errors of the mesh crate.

use thiserror::Error;

/// What is wrong with a mesh, with the element concerned.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MeshError {
    #[error("the mesh has no triangles")]
    Empty,
    #[error(
        "vertex {vertex} has a NaN or infinite coordinate; run `fieldtex repair` or fix the file"
    )]
    NonFinitePosition { vertex: usize },
    #[error(
        "triangle {triangle} refers to vertex {index} but the mesh has only {n_vertices} vertices"
    )]
    IndexOutOfRange { triangle: usize, index: u64, n_vertices: usize },
    #[error("triangle {triangle} refers to texture coordinate {index}, which does not exist")]
    UvIndexOutOfRange { triangle: usize, index: u64 },
    #[error("{attribute}: expected {expected} entries, found {found}")]
    AttributeLength { attribute: &'static str, expected: usize, found: usize },
    #[error("{operation} needs {requirement}, but {found}")]
    Precondition { operation: &'static str, requirement: &'static str, found: String },
    #[error(transparent)]
    Linalg(#[from] fieldtex_linalg::LinalgError),
}

/// A mesh that breaks an invariant or a precondition is bad input (repair or re-export
/// it); a failed solve inside a mesh operator is internal.
impl fieldtex_core::HasErrorKind for MeshError {
    fn kind(&self) -> fieldtex_core::ErrorKind {
        use fieldtex_core::ErrorKind;
        match self {
            MeshError::Linalg(_) => ErrorKind::Internal,
            MeshError::Empty
            | MeshError::NonFinitePosition { .. }
            | MeshError::IndexOutOfRange { .. }
            | MeshError::UvIndexOutOfRange { .. }
            | MeshError::AttributeLength { .. }
            | MeshError::Precondition { .. } => ErrorKind::BadInput,
        }
    }
}
