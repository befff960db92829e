//! The error type of the texture-optimisation crate.

use fieldtex_linalg::LinalgError;
use thiserror::Error;

/// Failures of domain construction and texture optimisation. Messages say what, where
/// and what to do.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TexOptError {
    #[error(
        "the surface domain has no colour carriers: give at least one carrier (texel or vertex)"
    )]
    NoCarriers,
    #[error("the mesh has no triangles: a surface domain needs a triangle mesh")]
    EmptyMesh,
    #[error(
        "carrier {carrier} names triangle {triangle} but the mesh has {triangles} triangles: rebuild the carriers for this mesh"
    )]
    CarrierTriangle { carrier: usize, triangle: u32, triangles: usize },
    #[error(
        "carrier {carrier} has barycentric coordinates {barycentric:?}: they must be finite, in [-1e-6, 1 + 1e-6] and sum to 1"
    )]
    CarrierBarycentric { carrier: usize, barycentric: [f64; 3] },
    #[error("triangle {triangle} names vertex {vertex} but the mesh has {vertices} vertices")]
    TriangleVertex { triangle: usize, vertex: u32, vertices: usize },
    #[error("{what} holds {found} entries but {expected} are needed ({shape})")]
    Length { what: &'static str, expected: usize, found: usize, shape: &'static str },
    #[error("{what} {index} is not finite: {value:?}")]
    NonFinite { what: &'static str, index: usize, value: [f64; 3] },
    #[error(
        "the direction field is zero (or normal to the surface) at {zero} of {total} carriers: compute the field first (harmonic diffusion) or pass any non-zero tangent field"
    )]
    DegenerateField { zero: usize, total: usize },
    #[error(
        "exemplar is {width}×{height} pixels but a {patch}×{patch} patch needs at least {min} pixels per side: use a larger exemplar or smaller patch_sizes"
    )]
    ExemplarTooSmall { width: usize, height: usize, patch: usize, min: usize },
    #[error(
        "exemplar declares {width}×{height} pixels but its buffer holds {found}: the image is corrupt"
    )]
    ExemplarBufferSize { width: usize, height: usize, found: usize },
    #[error("exemplar pixel {index} has a non-finite channel value {value}")]
    NonFiniteExemplar { index: usize, value: f32 },
    #[error("invalid option {name} = {value}: {reason}")]
    InvalidOption { name: &'static str, value: f64, reason: &'static str },
    #[error("PCA of the exemplar patches of the {patch}×{patch} level failed: {source}")]
    Pca { patch: usize, source: LinalgError },
}

/// The exemplar, the options, an empty mesh or carrier set and a zero direction field are
/// bad input; carriers, triangles and per-carrier arrays that do not match (built by the
/// caller's code) and a failed patch PCA are internal.
impl fieldtex_core::HasErrorKind for TexOptError {
    fn kind(&self) -> fieldtex_core::ErrorKind {
        use fieldtex_core::ErrorKind;
        match self {
            TexOptError::NoCarriers
            | TexOptError::EmptyMesh
            | TexOptError::DegenerateField { .. }
            | TexOptError::ExemplarTooSmall { .. }
            | TexOptError::ExemplarBufferSize { .. }
            | TexOptError::NonFiniteExemplar { .. }
            | TexOptError::InvalidOption { .. } => ErrorKind::BadInput,
            TexOptError::CarrierTriangle { .. }
            | TexOptError::CarrierBarycentric { .. }
            | TexOptError::TriangleVertex { .. }
            | TexOptError::Length { .. }
            | TexOptError::NonFinite { .. }
            | TexOptError::Pca { .. } => ErrorKind::Internal,
        }
    }
}
