//! Whether a failure is the input's fault or ours. Each crate's error type says it for
//! each of its variants (`fn kind(&self) -> ErrorKind`), so the facade maps a crate
//! error to an exit code without deciding call site by call site: bad input exits 2
//! (the message says which file or element and what to do), an internal error exits 1.

/// The two kinds of failure the CLI distinguishes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorKind {
    /// The input (a file, an option, a mesh element) is unusable: exit 2.
    BadInput,
    /// A bug or an unexpected numerical failure: exit 1.
    Internal,
}

impl ErrorKind {
    /// The CLI's exit code for this kind (2 bad input, 1 internal).
    pub fn exit_code(self) -> i32 {
        match self {
            ErrorKind::BadInput => 2,
            ErrorKind::Internal => 1,
        }
    }
}
