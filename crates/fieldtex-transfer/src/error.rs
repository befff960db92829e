//! Errors of the transfer crate.

use thiserror::Error;

/// Failure of a transfer stage; each variant names what to do.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TransferError {
    /// The source mesh cannot provide training colours.
    #[error(
        "the source {what}; transfer needs a textured source (per-corner UVs and a base-colour texture)"
    )]
    SourceNotTextured { what: String },
    /// A mesh has nothing to sample.
    #[error("the {which} mesh has no triangle with positive area; pass a mesh with faces")]
    EmptyMesh { which: &'static str },
    /// The mask image does not match the texture.
    #[error(
        "the mask is {mask_w}×{mask_h} pixels but the source texture is {tex_w}×{tex_h}; the mask must have the texture's size"
    )]
    MaskSize { mask_w: usize, mask_h: usize, tex_w: usize, tex_h: usize },
    /// Too few usable source samples after masking.
    #[error(
        "only {found} source samples carry colour after masking (need at least {needed}); loosen the mask or add samples"
    )]
    TooFewSamples { found: usize, needed: usize },
    /// An option is out of range.
    #[error("invalid option {what}: {message}")]
    InvalidOption { what: &'static str, message: String },
    /// A numeric step failed.
    #[error("{stage}: {message}")]
    Numeric { stage: &'static str, message: String },
}

impl TransferError {
    pub(crate) fn numeric(stage: &'static str, e: impl std::fmt::Display) -> Self {
        TransferError::Numeric { stage, message: e.to_string() }
    }
    /// Whether the error is the user's input (exit code 2) rather than an internal failure.
    pub fn is_bad_input(&self) -> bool {
        !matches!(self, TransferError::Numeric { .. })
    }
}

/// [`TransferError::is_bad_input`] as an [`fieldtex_core::ErrorKind`].
impl fieldtex_core::HasErrorKind for TransferError {
    fn kind(&self) -> fieldtex_core::ErrorKind {
        if self.is_bad_input() {
            fieldtex_core::ErrorKind::BadInput
        } else {
            fieldtex_core::ErrorKind::Internal
        }
    }
}
