//! Texture quality metrics of fieldtex (`fieldtex eval`, DESIGN.md §6), on images given
//! as flat `f32` buffers with a shape ([`ImageView`], [`FieldView`]).
//!
//! - [`coherence()`] / [`completeness()`]: exact nearest-patch distances output → exemplar
//!   and back, per pixel and channel;
//! - [`source_coverage()`]: completeness from a synthesis's own exemplar coordinates
//!   (share of exemplar patches it copies from), no search;
//! - [`guided_coherence()`]: coherence with output patches taken in the local frame of a
//!   direction field (field-guided synthesis);
//! - [`color_sliced_wasserstein()`]: distance between colour distributions;
//! - [`contrast_sharpness()`]: luminance contrast and gradient ratios against the exemplar;
//! - [`orientation_error`]: structure-tensor feature direction vs a guidance field;
//! - [`singularities()`]: ±1/2 singularities of an orientation map;
//! - [`phase_defects()`]: stripe breaks (dislocations) per 10⁴ px; [`coarse_phase_defects`]
//!   counts them on the image reduced 2× (the fast reports' default, measured error);
//! - [`rosy_seam_coherence`]: coherent exemplar coordinates across a 2-RoSy field's
//!   representation jumps vs image-wide (paper D's seams);
//! - [`surface_orientation_error`]: orientation error on a textured mesh by
//!   tangent-plane resampling; [`feature_line_coverage`]: salient-curve length on
//!   which an exemplar feature line lies.
//!
//! Every metric returns a `serde::Serialize` report for `report.json`.
//!
//! Architecture invariant: no file I/O (reading `.npy`/PNG is `fieldtex-io`'s job), no
//! printing; results are identical for any number of rayon threads.

pub mod approximate_nearest_patch;
pub mod coarse_phase_defects;
pub mod coherence;
pub mod color_sliced_wasserstein;
pub mod completeness;
pub mod contrast_sharpness;
mod error;
pub mod feature_size;
mod filters;
pub mod guided_coherence;
pub mod image_view;
pub mod nearest_patch;
pub mod nearest_patch_metrics;
pub mod orientation;
pub mod phase_defects;
pub mod query_sampling;
pub mod rosy_seam;
pub mod seam_metrics;
mod single_linkage;
pub mod singularities;
pub mod source_coverage;
pub mod surface_metrics;
pub mod transfer_fidelity;

pub use approximate_nearest_patch::ApproximateSearchOptions;
pub use coarse_phase_defects::coarse_phase_defects;
pub use coherence::coherence;
pub use color_sliced_wasserstein::{
    SlicedWassersteinOptions, SlicedWassersteinReport, color_sliced_wasserstein,
};
pub use completeness::completeness;
pub use contrast_sharpness::{
    ContrastSharpnessReport, LuminanceStatistics, contrast_sharpness, luminance_statistics,
};
pub use error::EvalError;
pub use guided_coherence::{GuidedCoherenceOptions, GuidedCoherenceReport, guided_coherence};
pub use image_view::{FieldView, ImageView, rgb_buffer};
pub use nearest_patch_metrics::{
    PatchDistanceOptions, PatchDistanceReport, coherence_and_completeness, coherence_map,
};
pub use orientation::{
    OrientationErrorOptions, OrientationErrorReport, OrientationMap, OrientationOptions,
    OrientationReference, dominant_orientation, image_orientation, luminance_orientation,
    orientation_error, orientation_error_of_map,
};
pub use phase_defects::{
    PhaseDefect, PhaseDefectOptions, PhaseDefectReport, count_defects_near, estimate_stripe_period,
    max_stripe_period, phase_defects,
};
pub use rosy_seam::{
    RosySeamOptions, RosySeamReport, SeamSubset, rosy_seam_coherence,
    rosy_seam_coherence_with_flips,
};
pub use singularities::{
    ExpectedSingularity, Singularity, SingularityCluster, SingularityMatch, SingularityOptions,
    SingularityReport, match_singularities, singularities,
};
pub use source_coverage::{SourceCoverageOptions, SourceCoverageReport, source_coverage};
pub use surface_metrics::{
    CurveSample, FeatureCoverageOptions, FeatureCoverageReport, SurfaceOrientationOptions,
    SurfaceOrientationReport, feature_line_coverage, surface_orientation_error,
};
pub use transfer_fidelity::{TransferFidelity, transfer_fidelity};
