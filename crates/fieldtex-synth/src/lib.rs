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
//! - [`synthesize`] (`parallel_synthesis.rs`): coarse-to-fine upsampling with the
//!   Jacobian, seeded jitter, correction passes with 2×2 subpasses over four-corner
//!   neighbourhoods, and the 2-RoSy flip indicator of paper D §4
//!   ([`SynthesisOptions::rosy_fix`]).
//!
//! # Measured against the issue 3 targets
//! `cargo run --release -p fieldtex-synth --example orient_probe -- EXEMPLAR DIR… --both
//! --const 0` on the fields of `out/orient-bench/<exemplar>-<preset>` (512², seed 1,
//! the `fieldtex orient` metrics: guided coherence at stride 8, phase defects within 3
//! periods of the designed singularities), load 2–4 (another engineer compiling).
//! Guided coherence over the five presets, 2-RoSy fix on, before (engine of 5fe893f) →
//! after, against Embark `texture-synthesis` unguided (scored at a constant 0°):
//!
//! | exemplar | before | after | after, constant 0° | exact rotated copy 10–45° | Embark |
//! |---|---|---|---|---|---|
//! | stripes | .00109–.00174 | .00092–.00144 | .00033 | .00018–.00026 | .00137 |
//! | bands | .00055–.00058 | .00044–.00046 | .00027 | .00023–.00026 | .00024 |
//! | woodgrain | .000080–.000082 | .000070–.000077 | .000046 | .000037–.000038 | .000039 |
//! | weave-diagonal | .0047–.0050 | .0031–.0035 | .0024 | .0010–.0013 | .0026 |
//!
//! The "exact rotated copy" column is the exemplar itself rotated to a constant field
//! (`orient_probe --ideal DEG`): for bands and woodgrain even a perfect rotated copy
//! scores about Embark's unguided value, so the target "no worse than Embark" cannot
//! be met by any rotated output of those two under this metric; unguided (constant 0°)
//! the engine is below Embark on stripes and weave and within 15–20 % on the others.
//! Phase defects near singularities (fix / `--no-rosy-fix`, 16 cells with
//! singularities): stripes 9/4, 4/7, 3/7, 4/7 (tented-arch, left-loop, right-loop,
//! whorl); on bands, woodgrain and weave the counts (2–18) equal what the image-wide
//! defect density (500–850 defects per image) puts into the discs, with or without
//! the fix, so that criterion cannot separate the two there (see
//! [`parallel_synthesis`] for the analysis). Synthesis of 512² after analysis: 545–704
//! ms wall through `fieldtex orient` (load 1.0–1.7). Same-session A/B (`orient_probe
//! --no-metrics --runs 7`, whorl, median, load ≈ 2.2, alternating): the previous
//! defaults (`--free-flips --no-comb --nearest --unjittered 0 --passes 4 --no-snap`)
//! 483–520 ms, the new ones 547–591 ms (+14 %: the two extra coarse passes; kept flips
//! and the unjittered finest level make each pass cheaper); 8 coarse passes would cost
//! 591–698 ms for a gain on weave only.
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
pub mod color_lookup;
pub mod domain;
mod error;
pub mod exemplar_analysis;
pub mod flip_combing;
pub mod gaussian_stack;
pub mod k_coherence;
mod level_tables;
pub mod parallel_synthesis;
pub mod synthesis_options;

pub use color_lookup::{ColorFilter, color_lookup};
pub use domain::{ImageDomain, SynthesisDomain};
pub use error::SynthError;
pub use exemplar_analysis::{APPEARANCE_DIMS, AnalysisLevel, AnalysisOptions, ExemplarAnalysis};
pub use parallel_synthesis::{SynthesisOptions, SynthesisResult, synthesize};
