//! The facade's error type and its mapping to exit codes.

use fieldtex_core::{ErrorKind, HasErrorKind};
use std::fmt::Display;
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

impl Error {
    /// The one mapping of a crate error ([`HasErrorKind`]) to the facade's: the variant's
    /// kind decides bad input (exit 2) or internal (exit 1). `context` (may be empty)
    /// prefixes the message; `path` names the file of a bad-input error.
    pub fn classify(e: &(impl HasErrorKind + ?Sized), path: Option<&Path>, context: &str) -> Self {
        Self::of_kind(e.kind(), path, context, e)
    }

    /// `message` as an error of `kind` (see [`Error::classify`]).
    pub fn of_kind(kind: ErrorKind, path: Option<&Path>, context: &str, e: impl Display) -> Self {
        let message = if context.is_empty() { e.to_string() } else { format!("{context}: {e}") };
        match kind {
            ErrorKind::BadInput => Error::bad_input(path, message),
            ErrorKind::Internal => Error::Internal(message),
        }
    }

    /// An internal error whatever the crate error's own kind: for failures on data the
    /// pipeline built itself (its own domain, its own outputs), where the crate's "bad
    /// input" means our bug.
    pub fn internal(context: &str, e: impl Display) -> Self {
        Self::of_kind(ErrorKind::Internal, None, context, e)
    }
}

/// `?` on any crate error: [`Error::classify`] without context (the I/O layer's and the
/// other crates' messages already say what and where).
impl<E: HasErrorKind> From<E> for Error {
    fn from(e: E) -> Self {
        Error::classify(&e, None, "")
    }
}

pub type Result<T> = std::result::Result<T, Error>;

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_fields::FieldsError;
    use fieldtex_linalg::LinalgError;
    use fieldtex_synth::SynthError;

    #[test]
    fn the_variant_decides_the_exit_code() {
        let solve = LinalgError::NonFinite { what: "rhs", index: 3 };
        assert_eq!(Error::from(solve.clone()).exit_code(), 1);
        // A failed factorisation inside a field design is ours (1) ...
        assert_eq!(Error::classify(&FieldsError::Solve(solve.clone()), None, "").exit_code(), 1);
        // ... an unknown preset is the user's (2), with the file named when given.
        let preset = FieldsError::UnknownPreset { name: "x".into(), available: "y".into() };
        let e = Error::classify(&preset, Some(Path::new("d.toml")), "--preset x");
        assert_eq!(e.exit_code(), 2);
        assert_eq!(e.to_string(), "d.toml: --preset x: unknown preset `x`; available presets: y");
        // The PCA of a valid exemplar breaking down is internal; a tiny exemplar is not.
        assert_eq!(Error::from(SynthError::Pca { level: 0, source: solve }).exit_code(), 1);
        let small = SynthError::ExemplarTooSmall { width: 4, height: 4, min: 8 };
        assert_eq!(Error::from(small).exit_code(), 2);
        // A pipeline may override the kind for data it built itself.
        let eval = fieldtex_eval::EvalError::NonFinite { what: "texture", index: 0, value: 1.0 };
        assert_eq!(Error::from(eval.clone()).exit_code(), 2);
        assert_eq!(Error::internal("metrics", eval).exit_code(), 1);
    }
}
