//! The error type of the synthesis crate.

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
