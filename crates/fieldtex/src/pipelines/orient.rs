//! `fieldtex orient`: orientation-field guided synthesis (Liu et al., paper D).
//!
//! Design (TOML file or fingerprint preset) → DEC field on a triangulated grid
//! (`fieldtex-fields`) → per-pixel 2-RoSy field → parallel appearance-space synthesis
//! guided by the field's Jacobian with the 2-RoSy fix (`fieldtex-synth`) → texture,
//! `field.npy`, `coords.npy` (each pixel's exemplar coordinate), a preview with the
//! designed singularities marked, and a report with the metrics of `eval` plus
//! singularity and phase-defect comparisons and the seam measure of the 2-RoSy fix.
//!
//! With [`OrientOptions::mesh`] (a disk-topology patch) the work moves to
//! [`super::orient_patch`]: the patch is parameterised, the field is designed on the
//! mesh and the texture is synthesised in parameter space (paper D §4, curved patches).

use crate::outputs::{begin_command, begin_outputs, commit_outputs};
use crate::pipelines::eval::image_metrics;
use crate::{Error, Progress, Report, Result};
use fieldtex_core::{Image, Warning};
use fieldtex_fields::{DesignFile, SingularityKind};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Where the guidance field comes from.
#[derive(Debug, Clone, Serialize)]
pub enum FieldSource {
    /// A TOML design file.
    Design(PathBuf),
    /// A built-in fingerprint preset: arch, tented-arch, left-loop, right-loop, whorl.
    Preset(String),
    /// An external `.npy` field (H×W×2 float32 (dx, dy), x right, y down).
    Field(PathBuf),
}

/// Smallest `--scale`: one output pixel per 64 exemplar pixels (the pattern 64× smaller).
pub const MIN_SCALE: f64 = 1.0 / 64.0;

/// Options of [`orient`].
#[derive(Debug, Clone, Serialize)]
pub struct OrientOptions {
    pub source: FieldSource,
    pub exemplar: PathBuf,
    /// Output width and height in pixels. Default 512.
    pub size: usize,
    /// Field grid cells per side for presets. Default 128.
    pub grid: usize,
    /// Pattern size: output pixels per pixel of the exemplar file (2 = the pattern twice
    /// as large; the same meaning as `align`'s), in [`MIN_SCALE`, 16]. Default 1.
    pub scale: f64,
    /// The 2-RoSy fix of paper D §4 (off only for the ablation). Default true.
    pub rosy_fix: bool,
    /// Start the synthesis from the exemplar carried along the field by the least-squares
    /// integral of its frames (`--integrated-init`, `fieldtex_synth::SynthesisOptions::
    /// integrated_init`): for periodic exemplars (stripes, weaves) on designs without
    /// singularities. Default false.
    pub integrated_init: bool,
    pub seed: u64,
    /// A disk-topology mesh patch to texture (`--mesh`); `None` = the plane. Default None.
    pub mesh: Option<PathBuf>,
    /// With `mesh`: texture only the connected region of triangles whose centroids lie
    /// within radius `[3]` of the point `[0..3]` (`--patch X,Y,Z,R`). Default None.
    pub patch: Option<[f64; 4]>,
    /// Compute the image metrics of the report (`--no-metrics` turns them off: they take
    /// ~15 s for a 512² output, mostly the exact patch searches). Default true.
    pub metrics: bool,
    /// Exact (exhaustive) nearest-patch searches in the metrics instead of the
    /// approximate ones (`--exact-metrics`; tens of seconds at 512²). Default false.
    pub exact_metrics: bool,
    /// Also the search-based completeness beside the source coverage (completeness read
    /// from the synthesis's exemplar coordinates, `fieldtex_eval::source_coverage`,
    /// the default on the plane). Implied by `exact_metrics`; a mesh patch always uses
    /// the search. Default false.
    pub search_completeness: bool,
}

impl OrientOptions {
    /// Exemplar pixels (of the exemplar as reduced by the exemplar policy, `reduction`
    /// file pixels each) per output pixel: what the synthesis domain's Jacobians scale
    /// by.
    pub(crate) fn exemplar_pixels_per_output_pixel(&self, reduction: usize) -> f64 {
        1.0 / (self.scale * reduction.max(1) as f64)
    }

    /// The `read` stage: the exemplar read, then [`Self::fit_exemplar`].
    pub(crate) fn read_exemplar(
        &self,
        report: &mut Report,
        progress: &dyn Progress,
    ) -> Result<(fieldtex_synth::FittedExemplar, f64)> {
        let image = report.stage(progress, "read", || fieldtex_io::read_image(&self.exemplar))?;
        Ok(self.fit_exemplar(image, report))
    }

    /// The exemplar policy of every pipeline: `image` reduced to the size limit (a
    /// warning in `report` when it was), with its exemplar pixels per output pixel.
    pub(crate) fn fit_exemplar(
        &self,
        image: Image,
        report: &mut Report,
    ) -> (fieldtex_synth::FittedExemplar, f64) {
        let fitted = fieldtex_synth::fit_exemplar(image, fieldtex_synth::MAX_EXEMPLAR_SIDE);
        report.warnings.extend(fitted.warning.clone());
        let per_pixel = self.exemplar_pixels_per_output_pixel(fitted.factor);
        (fitted, per_pixel)
    }

    /// The synthesis options of these orient options.
    pub(crate) fn synthesis_options(&self) -> fieldtex_synth::SynthesisOptions {
        fieldtex_synth::SynthesisOptions {
            seed: self.seed,
            rosy_fix: self.rosy_fix,
            integrated_init: self.integrated_init,
            ..Default::default()
        }
    }

    pub fn new(source: FieldSource, exemplar: PathBuf) -> Self {
        Self {
            source,
            exemplar,
            size: 512,
            grid: 128,
            scale: 1.0,
            rosy_fix: true,
            integrated_init: false,
            seed: 1,
            mesh: None,
            patch: None,
            metrics: true,
            exact_metrics: false,
            search_completeness: false,
        }
    }
}

/// A designed singularity in pixel coordinates with its orientation index (±1/2, ±1).
#[derive(Debug, Clone, Serialize)]
pub struct DesignedSingularity {
    pub x: f64,
    pub y: f64,
    pub index: f64,
}

pub(crate) fn kind_index(k: SingularityKind) -> f64 {
    match k {
        SingularityKind::Wedge => 0.5,
        SingularityKind::Trisector => -0.5,
        SingularityKind::Saddle => -1.0,
        _ => 1.0,
    }
}

/// The pixel field and the designed singularities.
fn build_field(
    options: &OrientOptions,
    report: &mut Report,
) -> Result<(Vec<[f32; 2]>, Vec<DesignedSingularity>)> {
    let n = options.size;
    let design = match &options.source {
        FieldSource::Field(p) => return Ok((read_field_npy(p, n, "", "pixel")?, Vec::new())),
        FieldSource::Design(p) => {
            let text = read_design_text(p)?;
            DesignFile::from_toml_str(&text).map_err(|e| Error::classify(&e, Some(p), ""))?
        }
        FieldSource::Preset(name) => {
            fieldtex_fields::presets::preset(name, n as f64, n as f64, options.grid)
                .map_err(|e| Error::classify(&e, None, &format!("--preset {name}")))?
        }
    };
    let src = match &options.source {
        FieldSource::Design(p) => Some(p.as_path()),
        _ => None,
    };
    let mut fd = report
        .time("field_factor", || design.build_once(None))
        .map_err(|e| Error::classify(&e, src, ""))?;
    let solved = report
        .time("field_solve", || fd.solve())
        .map_err(|e| Error::classify(&e, src, "field solve"))?;
    report.metric("field_residual", solved.residual);
    let grid = fd.plane().copied().ok_or_else(|| {
        Error::bad_input(src, "orient needs a plane design here ([domain] kind = \"plane\")")
    })?;
    let pixels = report
        .time("field_sample", || {
            fieldtex_fields::orientation_field::sample_plane(&fd, &solved, n, n)
        })
        .map_err(|e| Error::internal("field sampling", e))?;
    // Design coordinates → pixels.
    let (sx, sy) = (n as f64 / grid.width, n as f64 / grid.height);
    let designed: Vec<DesignedSingularity> = fd
        .singularities()
        .into_iter()
        .map(|(_, s)| DesignedSingularity {
            x: s.position[0] * sx,
            y: s.position[1] * sy,
            index: kind_index(s.kind),
        })
        .collect();
    report.warnings.extend(fd.warnings().iter().cloned());
    if options.integrated_init && !designed.is_empty() {
        report.warnings.push(Warning::new(
            "integrated-init-singularities",
            format!(
                "--integrated-init on a design with {} singularities: around them the \
                 exemplar cannot follow the field without stretching, and the default start \
                 usually scores better there (docs/real-exemplars.md)",
                designed.len()
            ),
        ));
    }
    Ok((pixels, designed))
}

/// A `--field` file: an `n`×`n`×2 float32 `.npy` of finite vectors. `extra` adds to
/// the expected-shape message, `unit` names a cell (pixel or texel) in errors.
pub(super) fn read_field_npy(p: &Path, n: usize, extra: &str, unit: &str) -> Result<Vec<[f32; 2]>> {
    let (shape, data) = fieldtex_io::read_npy_f32(p)?;
    if shape != [n, n, 2] {
        return Err(Error::bad_input(
            Some(p),
            format!(
                "the field has shape {shape:?}; --size {n} needs [{n}, {n}, 2] (H×W×2 float32{extra})"
            ),
        ));
    }
    let field: Vec<[f32; 2]> = data.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
    if let Some(i) = field.iter().position(|v| !(v[0].is_finite() && v[1].is_finite())) {
        return Err(Error::bad_input(Some(p), format!("non-finite vector at {unit} {i}")));
    }
    Ok(field)
}

/// Reads a design file (UTF-8 TOML) through the bounded reader.
pub(crate) fn read_design_text(p: &Path) -> Result<String> {
    let bytes =
        fieldtex_io::read_input_file(p, fieldtex_io::InputKind::Text, "read the design file")?;
    String::from_utf8(bytes)
        .map_err(|_| Error::bad_input(Some(p), "the design file is not UTF-8 text (TOML)"))
}

/// Runs the orient pipeline into `out_dir`.
pub fn orient(out_dir: &Path, options: &OrientOptions, progress: &dyn Progress) -> Result<Report> {
    begin_command();
    if !(16..=4096).contains(&options.size) {
        return Err(Error::bad_input(
            None,
            format!("--size must be in 16..=4096, got {}", options.size),
        ));
    }
    // Regression: 1e-30 passed here and failed later as an "internal failure".
    if !(options.scale >= MIN_SCALE && options.scale <= 16.0) {
        return Err(Error::bad_input(
            None,
            format!(
                "--scale must be in [{MIN_SCALE}, 16] output pixels per exemplar pixel (2 = the \
                 pattern twice as large), got {}",
                options.scale
            ),
        ));
    }
    if options.patch.is_some() && options.mesh.is_none() {
        return Err(Error::bad_input(None, "--patch X,Y,Z,R cuts a region of --mesh; give --mesh"));
    }
    if let Some(mesh) = &options.mesh {
        return super::orient_patch::orient_patch(out_dir, options, mesh, progress);
    }
    let mut report =
        Report::new("orient", options.seed, serde_json::to_value(options).unwrap_or_default());
    let (fitted, per_pixel) = options.read_exemplar(&mut report, progress)?;
    let exemplar = fitted.image;
    if options.integrated_init {
        report.warnings.extend(integrated_start_warning(&exemplar));
    }
    report.input = serde_json::json!({
        "exemplar": options.exemplar.display().to_string(),
        "exemplar_size": [exemplar.width * fitted.factor, exemplar.height * fitted.factor],
        "exemplar_reduction": fitted.factor,
    });
    // The field design (serial: sparse factorisation) and the exemplar analysis do not
    // depend on each other: they run side by side, each timed in a report part that is
    // merged in the serial order. Errors keep their serial precedence: the field's, the
    // output folder's, the analysis's.
    let part = || Report::new("orient", options.seed, serde_json::Value::Null);
    let ((field_part, field_report), (analysis, analysis_report)) = rayon::join(
        || {
            let mut r = part();
            (build_field(options, &mut r), r)
        },
        || {
            let mut r = part();
            let cache = super::synthesis::AnalysisCache::process();
            (super::synthesis::analyse_exemplar(&exemplar, cache, &mut r, progress), r)
        },
    );
    let (field, designed) = field_part?;
    report.absorb(field_report);
    let out = begin_outputs(
        out_dir,
        &["texture.png", "field.npy", "coords.npy", "preview.png", "report.json"],
    )?;
    let stage = out.staging();
    let n = options.size;
    report.absorb(analysis_report);
    let analysis = analysis.map_err(|e| e.with_path(&options.exemplar))?;
    let result = super::synthesis::synthesize_analysed(
        &analysis,
        &field,
        n,
        n,
        per_pixel,
        options,
        &mut report,
        progress,
    )
    .map_err(|e| e.with_path(&options.exemplar))?;
    let synth = &result.colors;
    let flat: Vec<f32> = field.iter().flat_map(|v| [v[0], v[1]]).collect();
    // Exemplar coordinates of each pixel, in pixels of the exemplar as synthesised
    // (after the exemplar policy's reduction): what `eval --coords` reads.
    let coords: Vec<f32> = result.coords.iter().flat_map(|c| [c[0], c[1]]).collect();
    fieldtex_io::write_png(&stage.join("texture.png"), synth)?;
    fieldtex_io::write_npy_f32(&stage.join("field.npy"), &[n, n, 2], &flat)?;
    fieldtex_io::write_npy_f32(&stage.join("coords.npy"), &[n, n, 2], &coords)?;
    report.metric("designed_singularities", &designed);
    if options.metrics {
        orient_metrics(
            &mut report,
            &result,
            &exemplar,
            &flat,
            &coords,
            &designed,
            per_pixel,
            options,
            progress,
        )?;
    } else {
        report.notes.push("image metrics skipped (--no-metrics)".into());
    }
    let preview = preview_with_singularities(synth, &designed);
    fieldtex_io::write_png(&stage.join("preview.png"), &preview)?;
    commit_outputs(out, &mut report)?;
    Ok(report)
}

/// The plane orient pipeline on an exemplar in memory, for the demo: field, synthesis
/// and (with `options.metrics`) the metrics into `report`; returns the preview (texture
/// with the designed singularities marked). Writes nothing.
pub(crate) fn orient_in_memory(
    options: &OrientOptions,
    exemplar: &Image,
    report: &mut Report,
    progress: &dyn Progress,
) -> Result<Image> {
    let (field, designed) = build_field(options, report)?;
    let n = options.size;
    // In-memory exemplars (the demo's procedural ones) are never reduced.
    let per_pixel = options.exemplar_pixels_per_output_pixel(1);
    let cache = super::synthesis::AnalysisCache::process();
    let result = super::synthesis::synthesize_image_result(
        exemplar, &field, n, n, per_pixel, options, cache, report, progress,
    )?;
    let synth = &result.colors;
    let flat: Vec<f32> = field.iter().flat_map(|v| [v[0], v[1]]).collect();
    report.metric("designed_singularities", &designed);
    if options.metrics {
        let coords: Vec<f32> = result.coords.iter().flat_map(|c| [c[0], c[1]]).collect();
        orient_metrics(
            report, &result, exemplar, &flat, &coords, &designed, per_pixel, options, progress,
        )?;
    }
    Ok(preview_with_singularities(synth, &designed))
}

/// The metric stage of both orient pipelines: the texture metrics of the synthesis
/// `result` (field `flat`, exemplar coordinates `coords`, both `H×W×2`) with the phase
/// defects near the `designed` singularities, and the seam measure, into
/// `report`'s `texture` metrics.
#[allow(clippy::too_many_arguments)]
fn orient_metrics(
    report: &mut Report,
    result: &fieldtex_synth::SynthesisResult,
    exemplar: &Image,
    flat: &[f32],
    coords: &[f32],
    designed: &[DesignedSingularity],
    per_pixel: f64,
    options: &OrientOptions,
    progress: &dyn Progress,
) -> Result<()> {
    let pts: Vec<[f64; 2]> = designed.iter().map(|s| [s.x, s.y]).collect();
    // The seam measure (a serial scan of every neighbour pair) runs beside the image
    // metrics, whose join tree leaves a core idle part of the time.
    let (texture, seam) = rayon::join(
        || {
            texture_metrics(
                report,
                &result.colors,
                exemplar,
                flat,
                Some((coords, per_pixel)),
                &pts,
                options,
                progress,
            )
        },
        || seam_metric(coords, flat, &result.flips, options.size, exemplar, per_pixel),
    );
    let (mut metrics, _) = texture?;
    metrics.rosy_seam = Some(seam?);
    report.metric("texture", &metrics);
    Ok(())
}

/// The seam measure (`fieldtex_eval::rosy_seam`) of an `n × n` synthesis: its exemplar
/// coordinates `coords` against its field `flat`, at `per_pixel` exemplar pixels per
/// output pixel, split by its flip indicators `flips` into repaired jumps and
/// effective (forced) seams.
fn seam_metric(
    coords: &[f32],
    flat: &[f32],
    flips: &[bool],
    n: usize,
    exemplar: &Image,
    per_pixel: f64,
) -> Result<fieldtex_eval::RosySeamReport> {
    let size = [exemplar.width, exemplar.height];
    let fail = |e: fieldtex_eval::EvalError| Error::internal("seam metric", e);
    let fv = fieldtex_eval::FieldView::new(flat, n, n).map_err(fail)?;
    let options = fieldtex_eval::RosySeamOptions::default();
    fieldtex_eval::rosy_seam_coherence_with_flips(
        coords,
        &fv,
        Some(flips),
        size,
        per_pixel,
        &options,
    )
    .map_err(fail)
}

/// The image metrics of an orient texture (`flat`: its `H×W×2` field) against the field
/// turned by the exemplar's own stripe direction, which is reported as
/// `exemplar_orientation` (as `align` measures on surfaces; 0 when the exemplar has no
/// measurable orientation), plus the phase defects within 3 exemplar periods of the
/// designed singularities `points`. With the synthesis's exemplar coordinates `coords`
/// (`H×W×2`, pixels of `exemplar`, and the exemplar pixels per output pixel),
/// completeness is their source coverage (no search) unless `options` asks for the
/// search too, and phase defects are looked for at the exemplar's period scaled to the
/// output. Returns the metrics and that direction in
/// degrees.
#[allow(clippy::too_many_arguments)]
pub(crate) fn texture_metrics(
    report: &mut Report,
    texture: &Image,
    exemplar: &Image,
    flat: &[f32],
    coords: Option<(&[f32], f64)>,
    points: &[[f64; 2]],
    options: &OrientOptions,
    progress: &dyn Progress,
) -> Result<(super::eval::ImageMetrics, f64)> {
    let (seed, exact) = (options.seed, options.exact_metrics);
    let own = exemplar_orientation(exemplar);
    let angle = own.as_ref().map_or(0.0, |o| o.dominant_angle_deg);
    if let Some(own) = &own {
        report.metric("exemplar_orientation", own);
    }
    let metrics = report
        .stage(progress, "metrics", || {
            let sources = coords.map(|(coords, per_pixel)| super::eval::SourceCoordinates {
                coords,
                search_too: exact || options.search_completeness,
                per_pixel,
            });
            image_metrics(
                texture,
                exemplar,
                Some(flat),
                None,
                angle,
                sources,
                seed,
                exact,
                progress,
            )
        })
        .map_err(|e| Error::internal("metrics", e))?;
    if let Some(pd) = &metrics.phase_defects {
        let near = fieldtex_eval::count_defects_near(&pd.defects, points, 3.0 * pd.period_px);
        report.metric("phase_defects_near_singularities", near);
    }
    Ok((metrics, angle))
}

/// The exemplar's dominant stripe direction and its own orientation error against it.
#[derive(Debug, Clone, serde::Serialize)]
pub(crate) struct ExemplarOrientation {
    /// Coherence-weighted mean stripe direction (structure tensor), degrees in [0, 180).
    pub dominant_angle_deg: f64,
    /// Coherence of that mean direction, in [0, 1].
    pub dominant_coherence: f64,
    /// The exemplar's orientation error against its dominant direction (same structure
    /// tensor and weighting as `texture.orientation_error`): the floor that a synthesis
    /// reproducing the exemplar's local structure cannot go below. A wavy exemplar (e.g.
    /// curved bands) scores tens of degrees here, and its guided outputs about as much.
    pub self_error_deg: f64,
}

/// The warning for an integrated start (`--integrated-init` of `orient` and `solid`)
/// on an exemplar that neither tiles ([`fieldtex_synth::exemplar_tiling`]) nor shows a
/// period along its axes ([`fieldtex_synth::characteristic_scale`]): carried along the
/// field as one warp, such an exemplar shows its repeats and its wrap seams (measured
/// on woodgrain, docs/real-exemplars.md and docs/solid.md, session 18). `None` for
/// tiling or periodic exemplars (stripes, weaves, bricks).
pub(crate) fn integrated_start_warning(exemplar: &Image) -> Option<Warning> {
    let tiling = fieldtex_synth::exemplar_tiling(exemplar);
    let scale = fieldtex_synth::characteristic_scale(exemplar);
    let periodic = scale.directions[0].1 || scale.directions[2].1;
    (!tiling.tiles && !periodic).then(|| {
        Warning::new(
            "integrated-init-irregular-exemplar",
            format!(
                "--integrated-init with an exemplar that neither tiles (wrap-jump ratio {:.2} \
                 / {:.2}) nor repeats along its axes: the exemplar carried along the field \
                 may show its repeats and its wrap seams; the default start suits irregular \
                 exemplars (wood, stone) better",
                tiling.jump_ratio[0], tiling.jump_ratio[1]
            ),
        )
    })
}

/// [`ExemplarOrientation`] of an exemplar; `None` when it has no measurable orientation.
pub(crate) fn exemplar_orientation(exemplar: &Image) -> Option<ExemplarOrientation> {
    let buf = fieldtex_eval::rgb_buffer(exemplar);
    let view = fieldtex_eval::ImageView::new(&buf, exemplar.width, exemplar.height, 3).ok()?;
    let (angle, coherence) = fieldtex_eval::dominant_orientation(&view).ok()?;
    let reference = fieldtex_eval::OrientationReference::ConstantDeg(angle);
    let own = fieldtex_eval::orientation_error(
        &view,
        &reference,
        &fieldtex_eval::OrientationErrorOptions::default(),
    )
    .ok()?;
    Some(ExemplarOrientation {
        dominant_angle_deg: angle,
        dominant_coherence: coherence,
        self_error_deg: own.mean_error_deg,
    })
}

/// The texture with designed singularities marked: wedges (+1/2) as red discs,
/// trisectors (−1/2) as blue triangles, other kinds as squares.
pub(crate) fn preview_with_singularities(
    texture: &Image,
    designed: &[DesignedSingularity],
) -> Image {
    use fieldtex_render::{
        ImageOverlay, ImageOverlayOptions, Marker2, MarkerShape, render_image_overlay,
    };
    let mut overlay = ImageOverlay::default();
    for s in designed {
        let (shape, color) = if s.index > 0.0 && s.index < 1.0 {
            (MarkerShape::Disc, [0.9, 0.15, 0.1, 1.0])
        } else if s.index < 0.0 && s.index > -1.0 {
            (MarkerShape::Triangle, [0.1, 0.35, 0.95, 1.0])
        } else {
            (MarkerShape::Square, [0.95, 0.8, 0.1, 1.0])
        };
        overlay
            .markers
            .push(Marker2::new([s.x, s.y]).with_shape(shape).with_color(color).with_radius(6.0));
    }
    render_image_overlay(texture, &overlay, &ImageOverlayOptions::default())
}
