//! Warnings returned beside results.
//!
//! Bad data that an algorithm can repair or work around is reported, not printed:
//! each function that may degrade returns its warnings, the facade collects them into
//! the report and the CLI shows them.

use serde::Serialize;

/// One thing the user should know about: what happened, where, what was done.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Warning {
    /// A stable machine-readable code, e.g. `"degenerate-triangles-dropped"`.
    pub code: String,
    /// A sentence for people: what, where, and what was done about it.
    pub message: String,
}

impl Warning {
    pub fn new(code: impl Into<String>, message: impl Into<String>) -> Self {
        Self { code: code.into(), message: message.into() }
    }
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.code, self.message)
    }
}

/// An ordered list of warnings.
pub type Warnings = Vec<Warning>;
