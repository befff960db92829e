//! Exemplar analysis and texture synthesis engines for fieldtex.
//!
//! # Parallel controllable synthesis (Lefebvre & Hoppe 2005, 2006; paper D §4)
//! - [`ExemplarAnalysis`] (`exemplar_analysis.rs`): computed once per exemplar and
//!   [`AnalysisOptions`]: toroidal Gaussian stack ([`gaussian_stack`]), an 8-D PCA
//!   appearance space of 5×5 neighbourhoods per level for the exemplar and its 180°
//!   rotation ([`appearance_space`]), k-coherence candidate sets ([`k_coherence`]).
//! - [`SynthesisDomain`] (`domain.rs`): what the engine runs over: a hierarchy of 2-D
//!   sample grids with neighbours, parents and a per-sample Jacobian (domain offsets →
//!   exemplar offsets). [`ImageDomain`] is the plane (image output) built from an
//!   `H × W × 2` direction field; atlas charts and other domains implement the trait.
//! - [`LatticeDomain`] (`lattice_domain.rs`): the dimension-generic domain the engine
//!   really runs over (`D`-dimensional offsets, a 2 × `D` Jacobian, `2^D` subpass
//!   classes); [`PlanarDomain`] presents a [`SynthesisDomain`] as one, and
//!   [`RegularLattice`] is a box of samples in 2-D or 3-D computed arithmetically.
//!   [`synthesize_volume`] runs the same engine on a 3-D lattice with the one 2-D
//!   exemplar type.
//! - [`synthesize_rotated`] (`rotated_exemplar.rs`): the same engine against a copy of
//!   the exemplar pre-rotated to one angle, so that a design at that angle copies whole
//!   pixels instead of resampling every one (off unless called; one angle, not bins).
//! - [`synthesize`] (`parallel_synthesis.rs`): coarse-to-fine upsampling with the
//!   Jacobian, seeded jitter, correction passes with 2×2 subpasses over four-corner
//!   neighbourhoods, and the 2-RoSy flip indicator of paper D §4
//!   ([`SynthesisOptions::rosy_fix`]).
//!
//! - [`exemplar_tiling`] (`exemplar_tiling.rs`): whether an exemplar tiles (wrap-jump
//!   ratio), the one test the pipelines and their metrics use before reading an exemplar
//!   toroidally.
//!
//! # Measurements
//! Quality and speed against the orient targets, and what was tried and dropped:
//! `docs/perf/orient-synthesis.md`.
//!
//! # Conventions
//! - Colours are sRGB-encoded `f32` as stored in [`fieldtex_core::Image`]; the engine
//!   compares neighbourhoods in that (perceptual) encoding, it never linearises.
//! - Exemplar coordinates are continuous pixel units: `u ∈ [0, W) × [0, H)`, x right,
//!   y down; coordinate `u` shows exemplar pixel `(⌊u.x⌋, ⌊u.y⌋)`. The exemplar is
//!   treated as toroidal (coordinates wrap).
//! - Jacobians are row-major `[j00, j01, j10, j11]` 2×2 matrices mapping a domain
//!   offset (in samples of the level) to an exemplar offset (in exemplar pixels of
//!   the finest level, before the level spacing `2^level` is applied).
//! - Determinism: randomness only from `fieldtex_core::rng::hash_unit(seed, …)`; all
//!   parallel work writes disjoint outputs, so results are bit-identical for any
//!   rayon thread count.

pub mod appearance_space;
pub mod characteristic_scale;
pub mod color_lookup;
pub mod domain;
mod error;
pub mod exemplar_analysis;
mod exemplar_level;
pub mod exemplar_policy;
pub mod exemplar_scales;
pub mod exemplar_tiling;
pub mod flip_combing;
pub mod gaussian_stack;
pub mod graph_cut;
pub mod image_quilting;
mod integrated_coordinates;
pub mod k_coherence;
pub mod lattice_domain;
mod level_tables;
pub mod parallel_synthesis;
mod prefetch;
pub mod regular_lattice;
pub mod rotated_exemplar;
pub mod solid;
pub mod synthesis_options;
mod synthesis_subset;
pub mod volume_synthesis;
pub mod warped_neighbourhood;

pub use characteristic_scale::{CharacteristicScale, characteristic_scale};
pub use color_lookup::{ColorFilter, color_lookup};
pub use domain::{ImageDomain, SynthesisDomain};
pub use error::SynthError;
pub use exemplar_analysis::{APPEARANCE_DIMS, AnalysisLevel, AnalysisOptions, ExemplarAnalysis};
pub use exemplar_policy::{FittedExemplar, MAX_EXEMPLAR_SIDE, fit_exemplar};
pub use exemplar_tiling::{TILING_JUMP_RATIO, TilingTest, exemplar_tiling};
pub use image_quilting::{QuiltStats, QuiltTarget, QuiltingOptions, quilt};
pub use lattice_domain::{Jacobian, LatticeDomain, PlanarDomain};
pub use parallel_synthesis::{
    SubsetSynthesis, SynthesisOptions, SynthesisResult, synthesize, synthesize_subset,
};
pub use regular_lattice::{JacobianField, RegularLattice};
pub use rotated_exemplar::{RotatedExemplar, synthesize_rotated};
pub use volume_synthesis::synthesize_volume;
