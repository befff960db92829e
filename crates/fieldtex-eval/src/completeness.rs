//! Completeness: how much of the exemplar shows up in the output.
//!
//! The reverse direction of [`coherence`](crate::coherence()) (the "completeness" term
//! of bidirectional similarity, Simakov, Caspi, Shechtman & Irani 2008): for each
//! exemplar `N×N` patch, the squared distance to its nearest output patch, divided by
//! `N·N·C`, averaged over exemplar patches. Low when every part of the exemplar is
//! reproduced somewhere; high when the output repeats only part of it. Exact search.

use crate::EvalError;
use crate::image_view::ImageView;
use crate::nearest_patch::{
    PatchDistanceOptions, PatchDistanceReport, PatchGrid, nearest_patch_ssd, summarize,
};

/// Completeness of `output` with respect to `exemplar`; `wrap_exemplar` makes the
/// exemplar's query patches wrap around its edges.
pub fn completeness(
    output: &ImageView,
    exemplar: &ImageView,
    options: &PatchDistanceOptions,
) -> Result<PatchDistanceReport, EvalError> {
    options.validate()?;
    if output.channels != exemplar.channels {
        return Err(EvalError::ChannelMismatch {
            what: "completeness",
            a: output.channels,
            b: exemplar.channels,
        });
    }
    let n = options.patch_size;
    let query = PatchGrid::new(exemplar, n, options.wrap_exemplar, "completeness exemplar")?;
    let db = PatchGrid::new(output, n, false, "completeness output")?;
    let (d, evals) = nearest_patch_ssd(&query, &db, options.pruning_dims);
    Ok(summarize(&d, query.dim(), db.count(), n, evals))
}
