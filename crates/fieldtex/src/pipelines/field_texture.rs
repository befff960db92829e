//! Texture synthesis from an in-memory direction field, for interactive front ends
//! (`fieldtex studio`): the same exemplar analysis (cached per exemplar) and guided
//! synthesis as [`super::orient::orient`] (paper D), without files or metrics.

use super::orient::{FieldSource, OrientOptions};
use super::synthesis::AnalysisCache;
use crate::{Error, Progress, Report, Result};
use fieldtex_core::Image;
use std::path::PathBuf;

/// Options of [`synthesize_field_texture`].
#[derive(Debug, Clone, Copy)]
pub struct FieldTextureOptions {
    /// Exemplar pixels per output pixel (below 1 enlarges the pattern). Default 1.
    pub scale: f64,
    /// The 2-RoSy fix of paper D §4. Default true.
    pub rosy_fix: bool,
    pub seed: u64,
}

impl Default for FieldTextureOptions {
    fn default() -> Self {
        Self { scale: 1.0, rosy_fix: true, seed: 1 }
    }
}

/// Synthesises a `width × height` texture whose exemplar x axis follows `field`
/// (`width · height` unit vectors `(dx, dy)`, row-major, x right, y down). Returns the
/// texture and a report holding the stage timings (`analysis`, `synthesis`) and
/// whether the exemplar analysis came from the cache.
///
/// The exemplar analysis goes through the process-wide [`AnalysisCache::process`]; a
/// caller that keeps its own cache uses [`synthesize_field_texture_with`].
pub fn synthesize_field_texture(
    exemplar: &Image,
    field: &[[f32; 2]],
    width: usize,
    height: usize,
    options: &FieldTextureOptions,
    progress: &dyn Progress,
) -> Result<(Image, Report)> {
    let cache = AnalysisCache::process();
    synthesize_field_texture_with(exemplar, field, width, height, options, cache, progress)
}

/// [`synthesize_field_texture`] with the caller's own analysis cache (one per studio
/// session or exemplar set, say).
pub fn synthesize_field_texture_with(
    exemplar: &Image,
    field: &[[f32; 2]],
    width: usize,
    height: usize,
    options: &FieldTextureOptions,
    cache: &AnalysisCache,
    progress: &dyn Progress,
) -> Result<(Image, Report)> {
    if width == 0 || height == 0 || field.len() != width * height {
        return Err(Error::bad_input(
            None,
            format!(
                "the field has {} vectors; a {width}×{height} texture needs {}",
                field.len(),
                width * height
            ),
        ));
    }
    if !(options.scale > 0.0 && options.scale <= 16.0) {
        return Err(Error::bad_input(
            None,
            format!("scale must be in (0, 16], got {}", options.scale),
        ));
    }
    let mut orient = OrientOptions::new(FieldSource::Preset(String::new()), PathBuf::new());
    orient.scale = options.scale;
    orient.rosy_fix = options.rosy_fix;
    orient.seed = options.seed;
    orient.size = width.max(height);
    orient.metrics = false;
    let mut report = Report::new("field_texture", options.seed, serde_json::Value::Null);
    let (fitted, per_pixel) = orient.fit_exemplar(exemplar.clone(), &mut report);
    let image = super::synthesis::synthesize_image_result(
        &fitted.image,
        field,
        width,
        height,
        per_pixel,
        &orient,
        cache,
        &mut report,
        progress,
    )?
    .colors;
    Ok((image, report))
}
