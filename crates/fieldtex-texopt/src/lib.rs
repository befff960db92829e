//! Texture optimisation on surfaces: Kwatra, Essa, Bobick & Kwatra 2005 ("Texture
//! Optimization for Example-based Synthesis"), on surfaces as in Kwatra et al. 2007, with
//! the feature-to-feature alignment of paper A (Xu, Cohen-Or, Ju, Liu, Zhang, Zhou & Chen
//! 2009, "Feature-aligned shape texturing", §5.1–5.2).
//!
//! # Pieces
//! - [`SurfaceDomain`] (`surface_domain.rs`): colour *carriers* (triangle + barycentric
//!   coordinates: atlas texels or vertices) with positions, normals and tangent frames
//!   from a per-vertex direction field. Reusable by the transfer pipeline (paper B).
//! - Radius-neighbour queries go through `fieldtex_mesh::SpatialGrid` (re-exported here
//!   as [`UniformGrid`] for the callers that still name it).
//! - [`SurfaceSamples`] (`surface_samples.rs`): the carriers with a nested
//!   multi-resolution sample hierarchy and public tangent-plane neighbourhoods.
//! - [`sample_set`]: the sample set `X†` by dart throwing over the carriers at spacing
//!   `r·w·h`, salient-curve carriers first (paper A §5.1).
//! - [`optimise`]: the coarse-to-fine search/blend loop
//!   ([`texture_optimisation`]), nearest-patch search ([`patch_search`]: PCA exhaustive
//!   or strided scan + coherence + random candidates, §5.2 constrained candidates) and
//!   the robust blend ([`robust_blend`]: IRLS weights `|x_p − z_p|^(r−2)`, `r = 0.8`,
//!   Kwatra 2005 eq. 2–3; `λ_p = 1/(d + 10⁻⁶)`, paper A eq. 4).
//!
//! # Conventions
//! - Units: `h` ([`TexOptOptions::pixel_size`]) is the surface length of one exemplar
//!   pixel; patches are `w × w` exemplar pixels, i.e. `w·h` surface units wide.
//! - Orientation: patch pixel `(i, j)` sits at surface offset
//!   `(i − w/2)·h·t − (j − w/2)·h·b` from the sample, `t` the field direction (rotated by
//!   [`TexOptOptions::exemplar_angle`]) and `b = n × t`: exemplar rows run along the field
//!   and the texture is not mirrored seen from outside. An exemplar with horizontal
//!   stripes gives stripes along the field.
//! - Offsets are measured in the tangent plane of the sample (orthogonal projection), not
//!   geodesically; carriers whose normal turns away (`cos < normal_cosine`) are excluded,
//!   which keeps the two sides of thin parts apart.
//! - Colours: RGBA `f32` in the exemplar's encoding (sRGB as stored), matched on RGB.
//! - Exemplar coordinates in the output: pixel centres at `i + 0.5`.
//! - Determinism: all randomness from `fieldtex_core::rng` streams keyed by (seed, stage,
//!   level, iteration, sample); search and blend are per-item parallel maps with
//!   sequential reductions, so output is bit-identical for any thread count.
//!
//! # Substitutes and what is not implemented
//! - Large patches are described by an `8 × 8` grid every `w/8` pixels of a
//!   tent-filtered exemplar (192-D), for every `w`. Coarse levels (`w > 8`) iterate on
//!   a subset of carriers about `0.75·w/8` pixels apart and blend all carriers once at
//!   the end of the level; this stands in for Kwatra 2007's mesh hierarchy.
//! - Matches carry a sub-pixel origin offset inherited through coherence, so patches
//!   copied from one exemplar region agree exactly across rotated sample frames.
//! - The blend weights patch pixels by a Gaussian falloff from the patch centre
//!   ([`TexOptOptions::blend_falloff`], `σ = 1.5` grid units by default; `None` gives
//!   the plain Kwatra average). The plain average is visibly blurrier; even with the
//!   falloff, fine exemplar detail is softened where overlapping matches disagree.
//!   [`TexOptResult::source`] gives the sharp winner-take-all alternative.
//! - Search: no k-d tree (DEPENDENCIES.md: trees do not help at this dimension);
//!   exhaustive PCA scan within a budget, strided subsets beyond it, plus coherence and
//!   random candidates. No k-coherence precomputation.
//! - The blend is the closed-form weighted average (Kwatra 2005 eq. 3 for fixed
//!   matches), not a linear system; no per-pixel falloff inside patches.
//! - §5.2 uses unsigned distances on both sides: a patch may put the feature line on
//!   either side of its centre; the principal-feature-line choice is the caller's (it
//!   builds the distance map).
//! - Coarse to fine over the exemplar's pyramid: a level of step `s = w/8` reads the
//!   exemplar through a tent of radius `s` at origins every `max(s/2, 1)` pixels, i.e.
//!   its `s`-times reduced pyramid level (sampled at twice that level's resolution);
//!   [`pyramid_patch_sizes`] picks the coarsest `w` so that it spans the exemplar's
//!   largest structure (the caller estimates it, e.g. `fieldtex_synth::
//!   characteristic_scale`). The surface side stays at one resolution (carriers), with
//!   coarse levels iterating on a subset (above).
//! - Crisp final pass ([`TexOptOptions::crisp`]): each carrier shows one covering
//!   patch's exemplar pixel: by default the best-matching one near its centre
//!   ([`CrispChoice`], see [`robust_blend`]).
//! - Histogram step ([`TexOptOptions::histogram_match`], default on): after the crisp
//!   pass the carriers' RGB distribution is moved onto the exemplar's (Pitié et al.
//!   2005 n-D transfer). Substitute for Kopf et al. 2007's histogram reweighting inside
//!   the loop: it restores the contrast that the optimisation's preference for flat
//!   exemplar regions loses, but colours are then remaps of exemplar pixels and small
//!   outputs (whose histogram is not the exemplar's) get over-stretched.

mod error;
mod exemplar_patches;
mod options;
pub mod patch_search;
pub mod robust_blend;
mod sample_set;
mod surface_domain;
mod surface_samples;
pub mod texture_optimisation;

pub use error::TexOptError;
/// The workspace's one spatial grid, under its former texopt name.
pub use fieldtex_mesh::SpatialGrid as UniformGrid;
pub use options::{CrispChoice, FeatureAlignment, TexOptOptions, pyramid_patch_sizes};
pub use sample_set::sample_set;
pub use surface_domain::{Carrier, SurfaceDomain, vertex_carriers};
pub use surface_samples::{Neighbour, SurfaceSamples};
pub use texture_optimisation::{LevelStats, TexOptResult, optimise};
