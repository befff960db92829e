//! Errors of the salient-curve crate.

use fieldtex_core::HasErrorKind;
use fieldtex_mesh::MeshError;
use thiserror::Error;

/// What went wrong while detecting or preprocessing salient curves.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum FeaturesError {
    /// The mesh breaks a structural invariant (index out of range, NaN position, ...).
    #[error("{0}")]
    Mesh(#[from] MeshError),
    /// The mesh has no triangle to detect curves on.
    #[error("the mesh has no triangles; crest lines need a triangle mesh")]
    EmptyMesh,
    /// Every edge has zero length, so no length scale exists.
    #[error("all {n_edges} edges of the mesh have zero length; run `fieldtex repair` first")]
    NoLengthScale { n_edges: usize },
    /// An option is outside its valid range.
    #[error("option `{name}` = {value} is invalid: it must be {requirement}")]
    InvalidOption { name: &'static str, value: f64, requirement: &'static str },
    /// A user-given curve has a point with a NaN or infinite coordinate.
    #[error("curve {curve} has a non-finite coordinate at point {point}; fix or drop that curve")]
    NonFiniteCurvePoint { curve: usize, point: usize },
}

/// Checks `value` against a predicate, naming the option on failure.
pub(crate) fn check_option(
    name: &'static str,
    value: f64,
    ok: bool,
    requirement: &'static str,
) -> Result<(), FeaturesError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(FeaturesError::InvalidOption { name, value, requirement })
    }
}

/// The mesh's own kind for mesh errors; everything else (an empty or degenerate mesh, an
/// option, a curve point) is bad input.
impl HasErrorKind for FeaturesError {
    fn kind(&self) -> fieldtex_core::ErrorKind {
        match self {
            FeaturesError::Mesh(e) => e.kind(),
            FeaturesError::EmptyMesh
            | FeaturesError::NoLengthScale { .. }
            | FeaturesError::InvalidOption { .. }
            | FeaturesError::NonFiniteCurvePoint { .. } => fieldtex_core::ErrorKind::BadInput,
        }
    }
}
