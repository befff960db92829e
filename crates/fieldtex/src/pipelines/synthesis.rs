//! Glue between the pipelines and `fieldtex-synth`: exemplar analysis through an
//! explicit [`AnalysisCache`], and image-domain synthesis from a per-pixel direction field.

use super::orient::OrientOptions;
use crate::{Error, Progress, Report, Result};
use fieldtex_core::Image;
use fieldtex_synth::{AnalysisOptions, ExemplarAnalysis, ImageDomain, synthesize};
use std::sync::{Arc, Mutex};

/// A cache of the most recent exemplar analysis, keyed by a hash of the exemplar pixels
/// and the analysis options: an explicit object that an interactive caller (the
/// studio) keeps and passes to each re-synthesis with a new field, so the analysis is
/// computed once per exemplar. One-shot pipelines (`orient`, the curved patch, the
/// field texture without a cache of its own) use [`AnalysisCache::process`], the
/// instance shared by the whole process, which only saves work when a process runs
/// several of them on the same exemplar.
#[derive(Debug, Default)]
pub struct AnalysisCache {
    slot: Mutex<Option<(u64, Arc<ExemplarAnalysis>)>>,
}

/// The instance behind [`AnalysisCache::process`].
static PROCESS_CACHE: AnalysisCache = AnalysisCache::new();

impl AnalysisCache {
    /// An empty cache.
    pub const fn new() -> Self {
        Self { slot: Mutex::new(None) }
    }

    /// The cache shared by every caller in this process that does not keep its own.
    pub fn process() -> &'static AnalysisCache {
        &PROCESS_CACHE
    }

    /// The analysis of `exemplar` with `options`, from the cache when the last request
    /// had the same exemplar and options (the `bool`), else computed and kept.
    pub fn analysis(
        &self,
        exemplar: &Image,
        options: &AnalysisOptions,
        progress: &dyn Progress,
    ) -> std::result::Result<(Arc<ExemplarAnalysis>, bool), fieldtex_synth::SynthError> {
        let key = analysis_key(exemplar, options);
        let mut guard = self.slot.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((k, a)) = guard.as_ref()
            && *k == key
        {
            return Ok((a.clone(), true));
        }
        let a = Arc::new(ExemplarAnalysis::new(exemplar, options, progress)?);
        *guard = Some((key, a.clone()));
        Ok((a, false))
    }
}

fn analysis_key(exemplar: &Image, options: &AnalysisOptions) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |x: u64| {
        h ^= x;
        h = h.wrapping_mul(0x0000_0100_0000_01B3);
    };
    eat(exemplar.width as u64);
    eat(exemplar.height as u64);
    for p in &exemplar.pixels {
        for c in p {
            eat(u64::from(c.to_bits()));
        }
    }
    eat(options.k as u64);
    eat(options.coherence_radius as u64);
    eat(options.max_size as u64);
    eat(options.coherence_scan as u64);
    eat(u64::from(options.tileable));
    eat(options.margin_divisor as u64);
    h
}

/// The analysis of `exemplar` at the default analysis options, through `cache`, timed
/// as `analysis` in `report` (with the metric `analysis_cached`).
pub(crate) fn analyse_exemplar(
    exemplar: &Image,
    cache: &AnalysisCache,
    report: &mut Report,
    progress: &dyn Progress,
) -> Result<Arc<ExemplarAnalysis>> {
    let aopts = AnalysisOptions::default();
    let (analysis, cached) = report
        .stage(progress, "analysis", || cache.analysis(exemplar, &aopts, progress))
        .map_err(|e| Error::classify(&e, None, "exemplar"))?;
    report.metric("analysis_cached", cached);
    Ok(analysis)
}

/// Synthesises a `width × height` texture whose exemplar x axis follows `field`, at
/// `per_pixel` exemplar pixels per output pixel: the whole synthesis result (colours,
/// the exemplar coordinate of every pixel in exemplar pixels, the flip indicators).
#[allow(clippy::too_many_arguments)]
pub(crate) fn synthesize_image_result(
    exemplar: &Image,
    field: &[[f32; 2]],
    width: usize,
    height: usize,
    per_pixel: f64,
    options: &OrientOptions,
    cache: &AnalysisCache,
    report: &mut Report,
    progress: &dyn Progress,
) -> Result<fieldtex_synth::SynthesisResult> {
    let analysis = analyse_exemplar(exemplar, cache, report, progress)?;
    synthesize_analysed(&analysis, field, width, height, per_pixel, options, report, progress)
}

/// [`synthesize_image_result`] from an analysis already made ([`analyse_exemplar`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn synthesize_analysed(
    analysis: &ExemplarAnalysis,
    field: &[[f32; 2]],
    width: usize,
    height: usize,
    per_pixel: f64,
    options: &OrientOptions,
    report: &mut Report,
    progress: &dyn Progress,
) -> Result<fieldtex_synth::SynthesisResult> {
    let flat: Vec<f32> = field.iter().flat_map(|v| [v[0], v[1]]).collect();
    let domain = ImageDomain::from_direction_field(width, height, &flat, per_pixel as f32)
        .map_err(|e| Error::internal("synthesis domain", e))?;
    let sopts = options.synthesis_options();
    let result = report
        .stage(progress, "synthesis", || synthesize(analysis, &domain, &sopts, progress))
        .map_err(|e| Error::internal("synthesis", e))?;
    Ok(result)
}
