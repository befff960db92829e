//! The error type of the synthesis crate.

use fieldtex_core::ErrorKind;
use fieldtex_linalg::LinalgError;
use thiserror::Error;

/// Failures of exemplar analysis and synthesis. Messages say what, where and what to do.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SynthError {
    #[error(
        "exemplar is {width}×{height} pixels; synthesis needs at least {min} pixels per side (5×5 neighbourhoods on a Gaussian stack): use a larger exemplar"
    )]
    ExemplarTooSmall { width: usize, height: usize, min: usize },
    #[error(
        "exemplar is {width}×{height} pixels; the limit is {max} pixels per side (AnalysisOptions::max_size): downsample the exemplar first"
    )]
    ExemplarTooLarge { width: usize, height: usize, max: usize },
    #[error(
        "exemplar declares {width}×{height} pixels but its buffer holds {found}: the image is corrupt"
    )]
    ExemplarBufferSize { width: usize, height: usize, found: usize },
    #[error("exemplar pixel {index} (x = {x}, y = {y}) has a non-finite channel value {value}")]
    NonFiniteExemplar { index: usize, x: usize, y: usize, value: f32 },
    #[error(
        "feature mask of plane {plane} is {}×{} pixels but its exemplar is {}×{}: the mask must match the exemplar pixel for pixel",
        mask.0, mask.1, exemplar.0, exemplar.1
    )]
    FeatureMaskSize { plane: &'static str, mask: (usize, usize), exemplar: (usize, usize) },
    #[error("invalid option {name} = {value}: {reason}")]
    InvalidOption { name: &'static str, value: f64, reason: &'static str },
    #[error(
        "direction field holds {found} values but a {width}×{height} field needs {expected} (H × W × 2, [row, col] = (dx, dy))"
    )]
    FieldSize { width: usize, height: usize, expected: usize, found: usize },
    #[error("direction field value at pixel (x = {x}, y = {y}) is not finite: ({dx}, {dy})")]
    NonFiniteField { x: usize, y: usize, dx: f32, dy: f32 },
    #[error(
        "synthesis domain: sample {sample} of level {level} has an invalid Jacobian {jacobian:?} ({reason})"
    )]
    InvalidJacobian { level: usize, sample: usize, jacobian: [f32; 4], reason: &'static str },
    #[error("synthesis domain is invalid: {reason}")]
    InvalidDomain { reason: String },
    #[error("appearance-space PCA failed at stack level {level}: {source}")]
    Pca { level: usize, source: LinalgError },
}

impl SynthError {
    /// Whose fault ([`ErrorKind`]): everything about the exemplar, the options, the
    /// direction field and the domain the caller built is bad input; a failed
    /// appearance-space PCA (a numerical breakdown on a valid exemplar) is internal.
    pub fn kind(&self) -> ErrorKind {
        match self {
            SynthError::Pca { .. } => ErrorKind::Internal,
            SynthError::ExemplarTooSmall { .. }
            | SynthError::ExemplarTooLarge { .. }
            | SynthError::ExemplarBufferSize { .. }
            | SynthError::NonFiniteExemplar { .. }
            | SynthError::FeatureMaskSize { .. }
            | SynthError::InvalidOption { .. }
            | SynthError::FieldSize { .. }
            | SynthError::NonFiniteField { .. }
            | SynthError::InvalidJacobian { .. }
            | SynthError::InvalidDomain { .. } => ErrorKind::BadInput,
        }
    }
}

impl fieldtex_core::HasErrorKind for SynthError {
    fn kind(&self) -> ErrorKind {
        SynthError::kind(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_split_input_from_internal_failures() {
        let small = SynthError::ExemplarTooSmall { width: 3, height: 3, min: 8 };
        assert_eq!(small.kind(), ErrorKind::BadInput);
        assert_eq!(small.kind().exit_code(), 2);
        let source = LinalgError::NonFinite { what: "covariance", index: 0 };
        let pca = SynthError::Pca { level: 1, source };
        assert_eq!(pca.kind(), ErrorKind::Internal);
        assert_eq!(pca.kind().exit_code(), 1);
    }
}
