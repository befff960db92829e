//! Completeness: how much of the exemplar shows up in the output.
//!
//! The reverse direction of [`coherence`](crate::coherence()) (the "completeness" term
//! of bidirectional similarity, Simakov, Caspi, Shechtman & Irani 2008): for each
//! exemplar `N×N` patch, the squared distance to its nearest output patch, divided by
//! `N·N·C`, averaged over exemplar patches. Low when every part of the exemplar is
//! reproduced somewhere; high when the output repeats only part of it. Exact search.

use crate::EvalError;
use crate::image_view::ImageView;
use crate::nearest_patch_metrics::{
    PatchDistanceOptions, PatchDistanceReport, completeness_distances,
};

/// Completeness of `output` with respect to `exemplar`; `wrap_exemplar` makes the
/// exemplar's patches wrap around its edges. To get coherence as well,
/// [`crate::coherence_and_completeness`] does both in one scan.
pub fn completeness(
    output: &ImageView,
    exemplar: &ImageView,
    options: &PatchDistanceOptions,
) -> Result<PatchDistanceReport, EvalError> {
    completeness_distances(output, exemplar, options)
}
