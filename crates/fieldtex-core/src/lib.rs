//! Shared primitives of fieldtex.
//!
//! This crate sits at the bottom of the layer stack (see `ARCHITECTURE.md`): it knows
//! nothing of meshes, files or terminals. It provides
//! - [`progress`]: the [`Progress`] trait algorithm code reports through (the CLI renders it),
//! - [`rng`]: seeded random streams derived from `(seed, stage, index)` so results never
//!   depend on thread scheduling,
//! - [`warnings`]: the [`Warning`] list every algorithm returns beside its result,
//! - [`vec3`]: the handful of `[f64; 3]` helpers geometry code needs.

pub mod image;
pub mod progress;
pub mod rng;
pub mod vec3;
pub mod warnings;

pub use image::Image;
pub use progress::{NoProgress, Progress};
pub use rng::{stream, stream_seed};
pub use warnings::{Warning, Warnings};
