//! `fieldtex eval`: the image metrics of DESIGN.md §6 for a synthesised image against
//! its exemplar and, optionally, the guidance field.

use crate::{Error, Progress, Result};
use fieldtex_core::Image;
use fieldtex_eval as ev;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The guidance an output is compared with.
#[derive(Debug, Clone)]
pub enum Guidance {
    /// `.npy` H×W×2 float32 `(dx, dy)` field, x right, y down.
    FieldFile(PathBuf),
    /// One direction everywhere, degrees (x right, y down).
    Angle(f64),
}

/// Metrics of one synthesised image (the `metrics` of eval and of `orient` reports).
#[derive(Debug, Clone, Serialize)]
pub struct ImageMetrics {
    pub coherence: ev::PatchDistanceReport,
    /// Coherence with the output patches taken in the guidance field's frame
    /// (`fieldtex_eval::guided_coherence`, default stride 8); only with a field.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub guided_coherence: Option<ev::GuidedCoherenceReport>,
    /// The search-based completeness (nearest output patch of each exemplar patch);
    /// absent where `source_coverage` stands for it (orient's default).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub completeness: Option<ev::PatchDistanceReport>,
    /// Completeness read from the synthesis's own exemplar coordinates, no search
    /// (`fieldtex_eval::source_coverage`): only with a coordinate map (`orient`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub source_coverage: Option<ev::SourceCoverageReport>,
    pub color_sliced_wasserstein: ev::SlicedWassersteinReport,
    pub orientation_error: Option<ev::OrientationErrorReport>,
    /// ±1/2 singularities of the output's own orientation (structure tensor).
    pub singularities: Option<SingularitySummary>,
    pub phase_defects: Option<ev::PhaseDefectReport>,
    /// Coherent exemplar coordinates across the field's 2-RoSy representation jumps
    /// against image-wide (`fieldtex_eval::rosy_seam`); only with the texture's
    /// coordinate map (`orient`, or `eval --coords`) and a field.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rosy_seam: Option<ev::RosySeamReport>,
    /// Whether the exemplar-patch metrics (coherence, guided coherence, completeness,
    /// source coverage) read the exemplar toroidally, and the tiling test that decided.
    pub exemplar_wrap: ExemplarWrap,
    /// Metrics that could not be computed, with the reason.
    pub skipped: Vec<String>,
    /// How the nearest-patch metrics were searched and how far the approximate values
    /// may be from the exact ones.
    pub search: String,
}

/// The rule deciding whether the metrics read the exemplar toroidally: only when it
/// tiles (`fieldtex_synth::exemplar_tiling`), so that the wrap seams of a photo crop are
/// never credited as exemplar content. It depends on the exemplar alone, so every image
/// scored against one exemplar (`orient`'s texture, Embark's output, the rotated-copy
/// floor) is scored under the same rule.
#[derive(Debug, Clone, Serialize)]
pub struct ExemplarWrap {
    /// Patches across the exemplar's wrap were searched (the exemplar tiles).
    pub wrapped: bool,
    /// Wrap-jump ratios `[x, y]`, the threshold and the verdict.
    pub tiling: fieldtex_synth::TilingTest,
    /// The rule in words.
    pub rule: &'static str,
}

/// [`ExemplarWrap::rule`].
const WRAP_RULE: &str = "the exemplar is read toroidally only if it tiles: on both axes the \
    mean colour jump across its wrap is at most `threshold` times the mean jump between \
    interior neighbours (fieldtex_synth::exemplar_tiling); otherwise patches crossing its \
    border are not exemplar patches";

/// Counts and positions of the singularities found in an image.
#[derive(Debug, Clone, Serialize)]
pub struct SingularitySummary {
    pub n_positive: usize,
    pub n_negative: usize,
    pub index_sum: f64,
    /// `(x, y, index)` of each merged cluster.
    pub positions: Vec<(f64, f64, f64)>,
}

/// A synthesis's exemplar coordinates, for [`image_metrics`]'s source coverage.
pub(crate) struct SourceCoordinates<'a> {
    /// `H×W×2` exemplar coordinates `(x, y)` of the output, in pixels of the exemplar
    /// passed to [`image_metrics`] (orient's `coords.npy`).
    pub coords: &'a [f32],
    /// Also the search-based completeness.
    pub search_too: bool,
    /// Exemplar pixels per output pixel of the synthesis: the default (approximate)
    /// phase-defect count then looks for the stripes at the exemplar's own period
    /// scaled by it, instead of estimating the period on the output.
    pub per_pixel: f64,
}

pub(crate) fn bad(e: ev::EvalError, what: &Path) -> Error {
    Error::classify(&e, Some(what), "")
}

/// Computes every metric; `field` is `H×W×2` of the output's size when present.
/// `exemplar_angle_deg` is the exemplar's own stripe direction for the orientation error
/// (the texture is expected at field angle + this; 0 = stripes along the exemplar's x).
/// With `sources` (the output's exemplar coordinates) completeness is their source
/// coverage, and the search-based completeness is computed only if asked for.
#[allow(clippy::too_many_arguments)]
pub(crate) fn image_metrics(
    output: &Image,
    exemplar: &Image,
    field: Option<&[f32]>,
    angle_deg: Option<f64>,
    exemplar_angle_deg: f64,
    sources: Option<SourceCoordinates>,
    seed: u64,
    exact: bool,
    progress: &dyn Progress,
) -> std::result::Result<ImageMetrics, ev::EvalError> {
    let stage = fieldtex_core::StageGuard::begin(
        progress,
        if exact { "metrics (exact)" } else { "metrics" },
        6,
    );
    let ob = ev::rgb_buffer(output);
    let eb = ev::rgb_buffer(exemplar);
    let o = ev::ImageView::new(&ob, output.width, output.height, 3)?;
    let e = ev::ImageView::new(&eb, exemplar.width, exemplar.height, 3)?;
    // Default: the approximate nearest-patch search (PCA + kd-tree, an upper bound of
    // the exact distances; docs/perf/orient.md gives the measured gap); `exact`: the
    // exhaustive scan.
    let approximate = (!exact).then(|| ev::ApproximateSearchOptions { seed, ..Default::default() });
    let tiling = fieldtex_synth::exemplar_tiling(exemplar);
    let wrap = tiling.tiles;
    let popts = ev::PatchDistanceOptions::default()
        .with_wrap_exemplar(wrap)
        .with_approximate(approximate.clone());
    let reference = match (field, angle_deg) {
        (Some(f), _) => Some(ev::OrientationReference::Field(ev::FieldView::new(
            f,
            output.width,
            output.height,
        )?)),
        (None, Some(a)) => Some(ev::OrientationReference::ConstantDeg(a)),
        _ => None,
    };
    // Four independent groups side by side (a join tree, so on two cores the serial
    // parts of one group — tree building, PCA eigen-solves, period estimate, merging —
    // overlap the parallel loops of another): the nearest-patch pair, guided
    // coherence, colour + orientation + singularities, phase defects. Each metric is
    // deterministic on its own; the results are assembled in a fixed order.
    let search_completeness = sources.as_ref().is_none_or(|s| s.search_too);
    let ((pair, guided), (oriented, phase)) = rayon::join(
        || {
            rayon::join(
                || {
                    let r = if search_completeness {
                        ev::coherence_and_completeness(&o, &e, &popts).map(|(c, p)| (c, Some(p)))
                    } else {
                        ev::coherence(&o, &e, &popts).map(|c| (c, None))
                    };
                    progress.advance(2);
                    r
                },
                || guided_metric(&o, &e, reference.as_ref(), wrap, approximate.clone(), seed),
            )
        },
        || {
            rayon::join(
                || {
                    colour_and_orientation(
                        &o,
                        &e,
                        reference,
                        exemplar_angle_deg,
                        seed,
                        exact,
                        progress,
                    )
                },
                || phase_metric(&o, &e, sources.as_ref().map(|s| s.per_pixel), exact, progress),
            )
        },
    );
    let (coherence, completeness) = pair?;
    let guided_coherence = guided?;
    let (color_sliced_wasserstein, orientation_error, singularities, mut skipped) = oriented?;
    let phase_defects = match phase {
        Ok(r) => Some(r),
        Err(err) => {
            skipped.push(format!("phase_defects: {err}"));
            None
        }
    };
    let source_coverage = match &sources {
        Some(s) => {
            let opts = ev::SourceCoverageOptions {
                patch_size: popts.patch_size,
                wrap_exemplar: wrap,
                ..Default::default()
            };
            Some(ev::source_coverage(s.coords, [exemplar.width, exemplar.height], &opts)?)
        }
        None => None,
    };
    drop(stage);
    let coverage_note = if source_coverage.is_some() && completeness.is_none() {
        "; completeness is source_coverage, read from the synthesis's exemplar coordinates \
         without a search (docs/first-hour.md; --search-completeness adds the search-based one)"
    } else {
        ""
    };
    Ok(ImageMetrics {
        coherence,
        guided_coherence,
        completeness,
        source_coverage,
        color_sliced_wasserstein,
        orientation_error,
        singularities,
        phase_defects,
        rosy_seam: None,
        exemplar_wrap: ExemplarWrap { wrapped: wrap, tiling, rule: WRAP_RULE },
        skipped,
        search: if exact {
            "exact: exhaustive nearest-patch searches".into()
        } else {
            let search = format!(
                "approximate: coherence, completeness and guided_coherence use the approximate \
                 nearest-patch search (one PCA basis for both images, k-d trees searched \
                 with a bounded budget, coherent candidates); coherence and completeness \
                 average a seeded sample of at most {} query patches each (runs of {}), \
                 with the standard error of the sample mean in standard_error; \
                 guided_coherence averages {} query pixels drawn at random (its \
                 standard_error likewise); the search \
                 is at most {}% above the exact distances on the test exemplars; \
                 color_sliced_wasserstein uses a \
                 seeded sample of about {} pixels per image, within {} + {}% of the all-pixel \
                 value on the test exemplars; phase_defects are counted on the image reduced \
                 2× where the stripe period is at least {} px (phase_defects.reduction), \
                 within {} + {}% of the full-resolution count on the test inputs \
                 (docs/perf/orient.md); --exact-metrics for the exhaustive versions",
                ev::ApproximateSearchOptions::default().sampled_queries,
                ev::query_sampling::RUN_LENGTH,
                ev::guided_coherence::SAMPLED_QUERIES,
                ev::approximate_nearest_patch::ERROR_BOUND_PERCENT,
                ev::color_sliced_wasserstein::SAMPLED_PIXELS,
                ev::color_sliced_wasserstein::SAMPLED_ERROR_BOUND_ABS,
                ev::color_sliced_wasserstein::SAMPLED_ERROR_BOUND_PERCENT,
                2.0 * ev::coarse_phase_defects::MIN_COARSE_PERIOD_PX,
                ev::coarse_phase_defects::COARSE_ERROR_BOUND.0,
                100.0 * ev::coarse_phase_defects::COARSE_ERROR_BOUND.1,
            );
            search + coverage_note
        },
    })
}

/// Colour, orientation error and singularities of [`image_metrics`], with the list of
/// skipped metrics.
type OrientedMetrics = (
    ev::SlicedWassersteinReport,
    Option<ev::OrientationErrorReport>,
    Option<SingularitySummary>,
    Vec<String>,
);

/// Guided coherence of `o` against `e` in the frame of a field `reference` (none for a
/// constant angle or no reference), its queries drawn with `seed`; `wrap`: the exemplar
/// tiles, so its patches are read toroidally.
fn guided_metric(
    o: &ev::ImageView,
    e: &ev::ImageView,
    reference: Option<&ev::OrientationReference>,
    wrap: bool,
    approximate: Option<ev::ApproximateSearchOptions>,
    seed: u64,
) -> std::result::Result<Option<ev::GuidedCoherenceReport>, ev::EvalError> {
    match reference {
        Some(ev::OrientationReference::Field(f)) => {
            // Default: the approximate search on a seeded sample of query pixels (the
            // gap to the exact search on the stride grid is pinned by fieldtex-eval's
            // tests/approximate_metrics.rs); exact: the exhaustive search on the grid.
            let sampled_queries =
                if approximate.is_some() { ev::guided_coherence::SAMPLED_QUERIES } else { 0 };
            let gopts = ev::GuidedCoherenceOptions {
                approximate,
                sampled_queries,
                seed,
                wrap_exemplar: wrap,
                ..Default::default()
            };
            Ok(Some(ev::guided_coherence(o, e, f, &gopts)?))
        }
        _ => Ok(None),
    }
}

/// Colour sliced Wasserstein, orientation error and singularities of `o` against `e`
/// (see [`image_metrics`]); the last two share one structure-tensor orientation map
/// (the default σ of both, so the values are those of computing it twice).
fn colour_and_orientation(
    o: &ev::ImageView,
    e: &ev::ImageView,
    reference: Option<ev::OrientationReference>,
    exemplar_angle_deg: f64,
    seed: u64,
    exact: bool,
    progress: &dyn Progress,
) -> std::result::Result<OrientedMetrics, ev::EvalError> {
    // Default: a seeded sample of the pixels of a large image (the gap to all pixels
    // is pinned by fieldtex-eval's tests/approximate_metrics.rs).
    let max_pixels = (!exact).then_some(ev::color_sliced_wasserstein::SAMPLED_PIXELS);
    let swo = ev::SlicedWassersteinOptions { seed, max_pixels, ..Default::default() };
    let color_sliced_wasserstein = ev::color_sliced_wasserstein(o, e, &swo)?;
    progress.advance(1);
    let mut skipped = Vec::new();
    let opts = ev::OrientationErrorOptions { exemplar_angle_deg, ..Default::default() };
    let map = ev::image_orientation(o, &opts.structure);
    let orientation_error = match reference {
        Some(r) => match &map {
            Ok(m) => Some(ev::orientation_error_of_map(m, &r, &opts)?),
            // The error `orientation_error` itself returns (same map, same checks).
            Err(_) => Some(ev::orientation_error(o, &r, &opts)?),
        },
        None => {
            skipped.push("orientation_error: no guidance field or angle given".to_string());
            None
        }
    };
    progress.advance(1);
    let singularities = match map {
        Ok(map) => {
            let r = ev::singularities(&map, &ev::SingularityOptions::default());
            Some(SingularitySummary {
                n_positive: r.n_positive,
                n_negative: r.n_negative,
                index_sum: r.index_sum,
                positions: r.merged.iter().map(|c| (c.x, c.y, c.index)).collect(),
            })
        }
        Err(err) => {
            skipped.push(format!("singularities: {err}"));
            None
        }
    };
    progress.advance(1);
    Ok((color_sliced_wasserstein, orientation_error, singularities, skipped))
}

/// Phase defects of `o` (default: counted on the image reduced 2× where the stripes are
/// long enough; the gap to full resolution is pinned by fieldtex-eval's
/// tests/approximate_metrics.rs).
/// Phase defects of `o`: exact, or on the image reduced 2×. With `per_pixel` (the
/// synthesis's exemplar pixels per output pixel) the reduced count looks for the
/// stripes at the period the synthesis was asked to make, the exemplar `e`'s own
/// ([`ev::estimate_stripe_period`], on the small exemplar) divided by `per_pixel` and
/// clamped as the output's own estimate would be, instead of estimating it on the
/// output (most of the count's cost; docs/first-hour.md).
fn phase_metric(
    o: &ev::ImageView,
    e: &ev::ImageView,
    per_pixel: Option<f64>,
    exact: bool,
    progress: &dyn Progress,
) -> std::result::Result<ev::PhaseDefectReport, ev::EvalError> {
    let mut pdo = ev::PhaseDefectOptions::default();
    if !exact
        && let Some(step) = per_pixel.filter(|s| s.is_finite() && *s > 0.0)
        && let Ok(t) = ev::estimate_stripe_period(e)
    {
        pdo.period_px = Some((t / step).clamp(3.0, ev::max_stripe_period(o.width, o.height)));
    }
    let pd = if exact { ev::phase_defects(o, &pdo) } else { ev::coarse_phase_defects(o, &pdo) };
    progress.advance(1);
    pd
}

/// The exemplar-coordinate map of a synthesised image, for the seam measure of
/// [`ImageMetrics::rosy_seam`] in [`eval_files`].
#[derive(Debug, Clone)]
pub struct SeamCoordinates {
    /// `.npy` H×W×2 float32 exemplar coordinates `(x, y)` of each pixel (`coords.npy`
    /// of `fieldtex orient`), in pixels of the exemplar as the synthesis used it (after
    /// the exemplar policy's reduction).
    pub path: PathBuf,
    /// The pattern size the texture was made with (`orient --scale`: output pixels per
    /// exemplar file pixel).
    pub scale: f64,
}

/// The seam measure of a coordinate map `coords` (H×W×2, exemplar pixels) made with
/// `field` (H×W×2) on an exemplar of `exemplar_size` pixels at `step` exemplar pixels
/// per output pixel.
pub(crate) fn rosy_seam_metric(
    coords: &[f32],
    field: &[f32],
    width: usize,
    height: usize,
    exemplar_size: [usize; 2],
    step: f64,
) -> std::result::Result<ev::RosySeamReport, ev::EvalError> {
    let fv = ev::FieldView::new(field, width, height)?;
    ev::rosy_seam_coherence(coords, &fv, exemplar_size, step, &ev::RosySeamOptions::default())
}

/// Reads the images (and field) and computes [`ImageMetrics`]; `exact` replaces the
/// approximate nearest-patch searches by the exhaustive ones (slow: minutes at 1024²).
pub fn eval_files(
    image: &Path,
    exemplar: &Path,
    guidance: Option<&Guidance>,
    coordinates: Option<&SeamCoordinates>,
    seed: u64,
    exact: bool,
    progress: &dyn Progress,
) -> Result<ImageMetrics> {
    crate::outputs::begin_command();
    let out = fieldtex_io::read_image(image)?;
    let ex = fieldtex_io::read_image(exemplar)?;
    // Name the file that is too small (regression: a tiny exemplar was blamed on IMG).
    let min = ev::PatchDistanceOptions::default().patch_size;
    for (im, path, what) in [(&out, image, "image"), (&ex, exemplar, "exemplar")] {
        if im.width < min || im.height < min {
            return Err(Error::bad_input(
                Some(path),
                format!(
                    "the {what} is {}×{} pixels; eval compares {min}×{min} patches, so it needs \
                     at least {min}×{min}",
                    im.width, im.height
                ),
            ));
        }
    }
    let (field, angle) = match guidance {
        Some(Guidance::FieldFile(p)) => {
            let (shape, data) = fieldtex_io::read_npy_f32(p)?;
            if shape != [out.height, out.width, 2] {
                return Err(Error::bad_input(
                    Some(p),
                    format!(
                        "the field has shape {shape:?} but the image needs [{}, {}, 2] (H×W×2 float32)",
                        out.height, out.width
                    ),
                ));
            }
            (Some(data), None)
        }
        Some(Guidance::Angle(a)) => {
            if !a.is_finite() {
                return Err(Error::bad_input(None, "--angle must be a finite number of degrees"));
            }
            (None, Some(*a))
        }
        None => (None, None),
    };
    let seam = match (coordinates, &field) {
        (None, _) => None,
        (Some(c), None) => {
            return Err(Error::bad_input(
                Some(&c.path),
                "--coords needs the guidance field the texture was made with (--field)",
            ));
        }
        (Some(c), Some(f)) => {
            if !(c.scale.is_finite() && c.scale > 0.0) {
                return Err(Error::bad_input(None, "--scale must be a positive number"));
            }
            let (shape, data) = fieldtex_io::read_npy_f32(&c.path)?;
            if shape != [out.height, out.width, 2] {
                return Err(Error::bad_input(
                    Some(&c.path),
                    format!(
                        "the coordinate map has shape {shape:?} but the image needs [{}, {}, 2] \
                         (H×W×2 float32 exemplar coordinates, orient's coords.npy)",
                        out.height, out.width
                    ),
                ));
            }
            // The synthesis saw the exemplar as reduced by the exemplar policy; its
            // coordinates are in those pixels.
            let fitted =
                fieldtex_synth::fit_exemplar(ex.clone(), fieldtex_synth::MAX_EXEMPLAR_SIDE);
            let size = [fitted.image.width, fitted.image.height];
            let step = 1.0 / (c.scale * fitted.factor as f64);
            let r = rosy_seam_metric(&data, f, out.width, out.height, size, step)
                .map_err(|e| bad(e, &c.path))?;
            Some(r)
        }
    };
    let mut metrics =
        image_metrics(&out, &ex, field.as_deref(), angle, 0.0, None, seed, exact, progress)
            .map_err(|e| {
                let about_exemplar = match &e {
                    ev::EvalError::TooSmall { what, .. }
                    | ev::EvalError::NonFinite { what, .. }
                    | ev::EvalError::BufferSize { what, .. } => what.starts_with("exemplar"),
                    _ => false,
                };
                bad(e, if about_exemplar { exemplar } else { image })
            })?;
    metrics.rosy_seam = seam;
    Ok(metrics)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_core::NoProgress;

    /// A `w × h` exemplar of `f(x, y)` in the red channel and a shifted copy in green.
    fn exemplar(w: usize, h: usize, f: impl Fn(f64, f64) -> f64) -> Image {
        Image::from_fn(w, h, |x, y| {
            let (xf, yf) = (x as f64, y as f64);
            [f(xf, yf) as f32, f(xf + 5.0, yf + 3.0) as f32, 0.5, 1.0]
        })
    }

    /// `e` repeated `2 × 2`: its wrap seams copied into the middle of the image.
    fn tiled(e: &Image) -> Image {
        let (w, h) = (e.width, e.height);
        let mut out = Image::new(2 * w, 2 * h, [0.0; 4]);
        for y in 0..2 * h {
            for x in 0..2 * w {
                out.pixels[y * 2 * w + x] = e.pixels[(y % h) * w + x % w];
            }
        }
        out
    }

    /// Exact metrics of `out` against `e` at a constant 0° field.
    fn metrics(out: &Image, e: &Image) -> ImageMetrics {
        let field: Vec<f32> = (0..out.width * out.height).flat_map(|_| [1.0, 0.0]).collect();
        image_metrics(out, e, Some(&field), None, 0.0, None, 1, true, &NoProgress).unwrap()
    }

    #[test]
    fn a_copied_wrap_seam_costs_only_when_the_exemplar_does_not_tile() {
        use std::f64::consts::TAU;
        // Periods that do not divide 40: a crop, with a seam at its wrap.
        let crop = exemplar(40, 40, |x, y| {
            0.5 + 0.25 * (TAU * (x / 17.3 + y / 29.1)).sin() + 0.2 * (TAU * y / 13.7).cos()
        });
        // Whole periods over 40 pixels: it tiles.
        let tile = exemplar(40, 40, |x, y| {
            0.5 + 0.25 * (TAU * (x / 20.0 + y / 40.0)).sin() + 0.2 * (TAU * y / 10.0).cos()
        });
        let m = metrics(&tiled(&crop), &crop);
        assert!(!m.exemplar_wrap.wrapped && !m.exemplar_wrap.tiling.tiles);
        assert!(m.exemplar_wrap.tiling.jump_ratio.iter().any(|&r| r > 1.4));
        // The old rule (always toroidal) finds every patch of the 2 × 2 repeat in the
        // exemplar; the honest one charges the patches across the copied seams.
        let (ob, eb) = (ev::rgb_buffer(&tiled(&crop)), ev::rgb_buffer(&crop));
        let o = ev::ImageView::new(&ob, 80, 80, 3).unwrap();
        let e = ev::ImageView::new(&eb, 40, 40, 3).unwrap();
        let wrapped =
            ev::coherence(&o, &e, &ev::PatchDistanceOptions::default().with_wrap_exemplar(true))
                .unwrap();
        assert!(wrapped.mean < 1e-9, "{}", wrapped.mean);
        assert!(m.coherence.mean > 1e-4, "{}", m.coherence.mean);
        let guided = m.guided_coherence.as_ref().unwrap().mean;
        let fv: Vec<f32> = (0..80 * 80).flat_map(|_| [1.0, 0.0]).collect();
        let f = ev::FieldView::new(&fv, 80, 80).unwrap();
        let gw =
            ev::guided_coherence(&o, &e, &f, &ev::GuidedCoherenceOptions::default()).unwrap().mean;
        assert!(guided > 1e-4 && guided > 10.0 * gw, "no wrap {guided}, wrap {gw}");

        let m = metrics(&tiled(&tile), &tile);
        assert!(m.exemplar_wrap.wrapped && m.exemplar_wrap.tiling.tiles, "{:?}", m.exemplar_wrap);
        assert!(m.coherence.mean < 1e-9, "{}", m.coherence.mean);
        assert!(m.guided_coherence.unwrap().mean < 1e-9);
        // Reported in the JSON with the rule.
        let json = serde_json::to_value(&m.exemplar_wrap).unwrap();
        assert_eq!(json["wrapped"], true);
        assert!(json["rule"].as_str().unwrap().contains("exemplar_tiling"));
        assert_eq!(json["tiling"]["threshold"], fieldtex_synth::TILING_JUMP_RATIO);
    }
}
