//! Progress reporting without I/O.
//!
//! Algorithm crates never print. Long-running work calls a [`Progress`] implementation
//! that the caller provides; the CLI renders it as a progress bar, tests pass
//! [`NoProgress`]. Implementations must be cheap and thread-safe: `advance` may be called
//! from rayon workers.

/// Receives progress of a long computation, stage by stage.
pub trait Progress: Sync {
    /// A new stage begins; `total` is the number of work units (0 when unknown).
    fn stage(&self, name: &str, total: u64);
    /// `n` more units of the current stage are done.
    fn advance(&self, n: u64);
    /// The current stage is finished.
    fn finish_stage(&self) {}
    /// Whether the caller asked to stop. Pipelines check it between stages and return
    /// early (the facade answers `Error::Cancelled`, writing no outputs); the default
    /// never cancels.
    fn cancelled(&self) -> bool {
        false
    }
}

/// A [`Progress`] that ignores everything.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn stage(&self, _name: &str, _total: u64) {}
    fn advance(&self, _n: u64) {}
}
