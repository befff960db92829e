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

/// An error type that says, per variant, whose fault it is. Every crate error of the
/// workspace implements it; the facade turns any of them into its own error through one
/// function (`fieldtex::Error::classify`), so the exit code follows the variant.
pub trait HasErrorKind: std::error::Error {
    /// Bad input (the user can fix a file or an option) or internal (our bug or a
    /// numerical breakdown on valid input).
    fn kind(&self) -> ErrorKind;
}
