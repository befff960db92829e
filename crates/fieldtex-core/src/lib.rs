//! Shared primitives of fieldtex.
//!
//! This crate sits at the bottom of the layer stack (see `ARCHITECTURE.md`): it knows
//! nothing of meshes, files or terminals. It provides
//! - [`progress`]: the [`Progress`] trait algorithm code reports through (the CLI renders it),
//!   and [`stage_guard`]: a stage as a scope (timed, nested, cancellable),
//! - [`error_kind`]: [`ErrorKind`], bad input (exit 2) or internal (exit 1), which each
//!   crate's error reports per variant,
//! - [`rng`]: seeded random streams derived from `(seed, stage, index)` so results never
//!   depend on thread scheduling,
//! - [`warnings`]: the [`Warning`] list every algorithm returns beside its result,
//! - [`vec3`]: the handful of `[f64; 3]` helpers geometry code needs.

pub mod error_kind;
pub mod image;
pub mod progress;
pub mod rng;
pub mod stage_guard;
pub mod vec3;
pub mod warnings;

pub use error_kind::{ErrorKind, HasErrorKind};
pub use image::Image;
pub use progress::{NoProgress, Progress};
pub use rng::{stream, stream_seed};
pub use stage_guard::{Cancelled, StageGuard, StageTiming, StageTimings};
pub use warnings::{Warning, Warnings};
