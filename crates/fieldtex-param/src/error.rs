//! Errors of the parameterisation crate.

use thiserror::Error;

/// What went wrong while building an atlas, a texel map or a bake, with the element and
/// value concerned and what to do about it.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ParamError {
    /// The mesh fails a structural check (non-finite position, index out of range, ...).
    #[error("the mesh cannot be parameterised: {0}")]
    InvalidMesh(#[from] fieldtex_mesh::MeshError),
    /// An option is outside its valid range.
    #[error("option `{name}` = {value} is invalid: {reason}")]
    InvalidOption { name: &'static str, value: String, reason: &'static str },
    /// The charts do not fit into the atlas even at the smallest scale tried.
    #[error(
        "{charts} charts do not fit into a {resolution}×{resolution} atlas with a gutter of {gutter} texels \
         even at {texels_per_unit:e} texels per unit; raise the resolution or lower the gutter"
    )]
    PackingFailed { charts: usize, resolution: u32, gutter: u32, texels_per_unit: f64 },
    /// An attribute has the wrong length (e.g. per-vertex colours for another mesh).
    #[error("{what}: expected {expected} entries, found {found}")]
    AttributeLength { what: &'static str, expected: usize, found: usize },
    /// A texel map was used with a mesh it was not built for.
    #[error(
        "texel {texel} refers to triangle {triangle} but the mesh has only {n_triangles} triangles; \
         build the texel map from this mesh's atlas"
    )]
    TriangleOutOfRange { texel: usize, triangle: u32, n_triangles: usize },
    /// The mesh has no texture coordinates where they are needed.
    #[error("{operation} needs per-corner UVs, but the mesh has none; run build_atlas first")]
    MissingUvs { operation: &'static str },
    /// The global conformal parameterisation of a component failed.
    #[error("global conformal parameterisation failed: {reason}")]
    Conformal { reason: String },
}

/// The mesh's own kind for mesh errors; options and a packing that does not fit (raise
/// the resolution) are bad input; an attribute, texel map or UV set that does not match
/// its mesh is a caller's bug, and a failed conformal solve is internal.
impl fieldtex_core::HasErrorKind for ParamError {
    fn kind(&self) -> fieldtex_core::ErrorKind {
        use fieldtex_core::ErrorKind;
        match self {
            ParamError::InvalidMesh(e) => e.kind(),
            ParamError::InvalidOption { .. } | ParamError::PackingFailed { .. } => {
                ErrorKind::BadInput
            }
            ParamError::AttributeLength { .. }
            | ParamError::TriangleOutOfRange { .. }
            | ParamError::MissingUvs { .. }
            | ParamError::Conformal { .. } => ErrorKind::Internal,
        }
    }
}
