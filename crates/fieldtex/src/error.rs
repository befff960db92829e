//! The facade's error type and its mapping to exit codes.

use std::path::{Path, PathBuf};
use thiserror::Error;

/// Failure of a pipeline. [`Error::exit_code`] gives the CLI's exit status:
/// 2 for bad input or usage, 1 for internal failures.
#[derive(Debug, Error)]
pub enum Error {
    /// An input file or option is unusable; the message says what to do.
    #[error("{}{message}", path.as_ref().map(|p| format!("{}: ", p.display())).unwrap_or_default())]
    BadInput { path: Option<PathBuf>, message: String },
    /// Something failed inside fieldtex (a solver, a numeric breakdown).
    #[error("internal failure: {0}")]
    Internal(String),
    /// The caller's [`crate::Progress::cancelled`] said stop; no outputs were written.
    #[error("cancelled")]
    Cancelled,
}

impl Error {
    pub fn bad_input(path: Option<&Path>, message: impl Into<String>) -> Self {
        Error::BadInput { path: path.map(Path::to_path_buf), message: message.into() }
    }
    /// Names `path` in a bad-input error that does not name a file yet.
    pub fn with_path(self, path: &Path) -> Self {
        match self {
            Error::BadInput { path: None, message } => {
                Error::BadInput { path: Some(path.to_path_buf()), message }
            }
            other => other,
        }
    }

    pub fn exit_code(&self) -> i32 {
        match self {
            Error::BadInput { .. } => 2,
            Error::Internal(_) => 1,
            Error::Cancelled => 130,
        }
    }
}

impl From<fieldtex_io::IoError> for Error {
    fn from(e: fieldtex_io::IoError) -> Self {
        // The I/O layer's messages already name the file.
        Error::BadInput { path: None, message: e.to_string() }
    }
}

impl From<fieldtex_linalg::LinalgError> for Error {
    fn from(e: fieldtex_linalg::LinalgError) -> Self {
        Error::Internal(e.to_string())
    }
}

pub type Result<T> = std::result::Result<T, Error>;
