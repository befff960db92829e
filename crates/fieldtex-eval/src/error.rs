//! Errors of the metrics: bad shapes and impossible options, never panics.

use thiserror::Error;

/// What can be wrong with the inputs of a metric.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum EvalError {
    #[error(
        "{what}: buffer holds {found} values but {width}×{height}×{channels} needs {expected}; \
         pass interleaved row-major data (top row first) of exactly that shape"
    )]
    BufferSize {
        what: &'static str,
        width: usize,
        height: usize,
        channels: usize,
        expected: usize,
        found: usize,
    },
    #[error(
        "{what}: {found_width}×{found_height} does not match {expected_width}×{expected_height}; resample one of them first"
    )]
    SizeMismatch {
        what: &'static str,
        expected_width: usize,
        expected_height: usize,
        found_width: usize,
        found_height: usize,
    },
    #[error(
        "{what}: {a} channels vs {b} channels; compare images with the same channels (e.g. both RGB)"
    )]
    ChannelMismatch { what: &'static str, a: usize, b: usize },
    #[error(
        "{what}: image is {width}×{height} but needs at least {min}×{min} pixels for this metric"
    )]
    TooSmall { what: &'static str, width: usize, height: usize, min: usize },
    #[error("{what}: value {value} at index {index} is not finite; clean the data (NaN/Inf) first")]
    NonFinite { what: &'static str, index: usize, value: f32 },
    #[error(
        "{what}: {pairs} patch pairs to compare exceed the limit of {limit}; \
         compare smaller images (downsample or crop) or raise the limit (max_pairs)"
    )]
    TooLarge { what: &'static str, pairs: u64, limit: u64 },
    #[error("option {name} = {value} is invalid: {reason}")]
    InvalidOption { name: &'static str, value: String, reason: &'static str },
}

/// Every metric error is the caller's data or option (bad input). A pipeline that
/// measures its own outputs decides for itself that such a failure is internal.
impl fieldtex_core::HasErrorKind for EvalError {
    fn kind(&self) -> fieldtex_core::ErrorKind {
        fieldtex_core::ErrorKind::BadInput
    }
}
