//! Coherence: how well every output neighbourhood is explained by the exemplar.
//!
//! The texture-optimisation energy of Kwatra, Essa, Bobick & Kwatra (2005, "Texture
//! optimization for example-based synthesis", eq. 1) evaluated on a finished output:
//! for each `N×N` output patch (every position, stride 1, fully inside the output),
//! the squared distance to its nearest exemplar patch, divided by `N·N·C`, averaged
//! over patches. 0 means every output neighbourhood appears verbatim in the exemplar.
//! The search is exact (see [`crate::nearest_patch`]).

use crate::EvalError;
use crate::image_view::ImageView;
use crate::nearest_patch_metrics::{
    PatchDistanceOptions, PatchDistanceReport, coherence_distances,
};

/// Coherence of `output` with respect to `exemplar` (same channel count; values
/// usually sRGB in `[0, 1]`). Errors when either image is smaller than the patch. To
/// get completeness as well, [`crate::coherence_and_completeness`] does both in one
/// scan.
pub fn coherence(
    output: &ImageView,
    exemplar: &ImageView,
    options: &PatchDistanceOptions,
) -> Result<PatchDistanceReport, EvalError> {
    coherence_distances(output, exemplar, options, false).map(|r| r.0)
}
