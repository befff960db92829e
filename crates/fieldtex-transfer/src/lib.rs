//! Texture transfer by geometry correlation (paper B: Mertens, Kautz, Chen, Bekaert &
//! Durand 2006, "Texture transfer using geometry correlation").
//!
//! A textured source mesh teaches how colour depends on shape; the target mesh gets a
//! new texture with the same dependence. The work happens on uniform surface samples:
//!
//! 1. [`surface_samples`]: nested Poisson-disk samples at several resolutions and Gaussian /
//!    Laplacian pyramids over them (Turk 2001).
//! 2. [`source_colors`]: source colours through the per-corner UVs, with a mask.
//! 3. [`descriptors`]: 12 geometric descriptors (height, normal, solid-angle curvature
//!    at 4 radii, SH bands 0–1 of directional occlusion).
//! 4. [`guidance`]: CCA of descriptors against colour → 3-D guidance (or PCA, ablation).
//! 5. [`feature_matching`]: n-D histogram matching of the target guidance, on values or
//!    on every Laplacian level (Pitié et al. 2005).
//! 6. [`parametric_synthesis`]: k-means segmentation, feathering, per-cluster linear
//!    regression and Heeger–Bergen histograms with interpolated inverse CDFs.
//! 7. [`nonparametric_synthesis`]: image analogies over tangent-plane neighbourhoods
//!    ([`surface_stencils`]) with Ashikhmin coherence, coarse to fine.
//! 8. [`transfer()`]: all of the above; the caller bakes `target_colors` into an atlas
//!    with [`values_at_surface_points`].
//!
//! Layer rules: no file I/O, no printing; progress through `fieldtex_core::Progress`,
//! randomness from `fieldtex_core::rng` streams, results identical for any thread count.

// Small dense kernels (3-D, 4×4) index several arrays with one loop variable.
#![allow(clippy::needless_range_loop)]

pub mod descriptors;
mod error;
pub mod feature_matching;
pub mod guidance;
pub mod nonparametric_synthesis;
pub mod parametric_synthesis;
pub mod scattered_interpolation;
pub mod source_colors;
pub mod surface_samples;
pub mod surface_stencils;
mod transfer;

pub use descriptors::{
    DESCRIPTOR_NAMES, DescriptorOptions, N_DESCRIPTORS, UpAxis, compute_descriptors,
};
pub use error::TransferError;
pub use feature_matching::{MatchMode, MatchStep, match_features};
pub use guidance::{Guidance, Reduction, build_guidance};
pub use nonparametric_synthesis::{
    NonparametricLevel, NonparametricOptions, NonparametricStats, nonparametric_synthesis,
};
pub use parametric_synthesis::{ParametricOptions, ParametricStats, parametric_synthesis};
pub use scattered_interpolation::Interpolator;
pub use source_colors::{source_sample_colors, surface_colors};
pub use surface_samples::{SamplePyramid, SampleSet, sample_surface};
pub use transfer::{Engine, TransferOptions, TransferResult, transfer, values_at_surface_points};
