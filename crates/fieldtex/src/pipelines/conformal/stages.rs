//! The stages of `conformal` that are more than a call: option checks, the exemplar
//! levels from the `τ` distribution, quilting every geometry image, and the metrics.

use super::report::{component_json, texel_density, weighted_quantile};
use super::{Block, ConformalOptions, PATCH_SPLIT_SPREAD, SEAM_FEATHER_BAND};
use crate::{Error, Progress, Report, Result};
use fieldtex_core::{Image, stream_seed};
use fieldtex_mesh::TriMesh;
use fieldtex_param::conformal::{ConformalComponent, ConformalMethod, GeometryImage};
use fieldtex_synth::exemplar_scales::{resample, scale_levels};
use fieldtex_synth::{QuiltTarget, QuiltingOptions, quilt};
use serde_json::json;

/// The option checks of [`super::conformal`] (exit 2 when out of range).
pub(super) fn check_options(options: &ConformalOptions) -> Result<()> {
    if !(64..=8192).contains(&options.size) {
        return Err(Error::bad_input(
            None,
            format!("--size must be in 64..=8192, got {}", options.size),
        ));
    }
    if !(8..=256).contains(&options.patch_size) || options.patch_size * 2 > options.size {
        return Err(Error::bad_input(
            None,
            format!(
                "--patch-size must be in 8..=256 and at most half of --size, got {}",
                options.patch_size
            ),
        ));
    }
    // Below 1/64 (orient's bound too) the run time grows without bound: 10⁻⁴ took 3×
    // the default's time, 10⁻⁶ and 10⁻³⁰ did not finish in a minute.
    if !(options.scale >= 1.0 / 64.0 && options.scale <= 16.0) {
        return Err(Error::bad_input(
            None,
            format!("--scale must be in [0.015625, 16], got {:?}", options.scale),
        ));
    }
    if options.levels == 0 || options.levels > 16 {
        return Err(Error::bad_input(
            None,
            format!("--levels must be in 1..=16, got {}", options.levels),
        ));
    }
    Ok(())
}

/// The exemplar's levels and the `τ` statistics that chose them.
pub(super) struct ExemplarLevels {
    /// `(τ, face area)` of every mapped face (images and fallback atlas).
    pub(super) tau_w: Vec<(f64, f64)>,
    /// Reference `τ` (level scale 1): the 5th area-weighted percentile.
    pub(super) tau_ref: f64,
    pub(super) q05: f64,
    pub(super) q95: f64,
    /// Scale of each level relative to the reference.
    pub(super) scales: Vec<f64>,
    pub(super) level_names: Vec<f64>,
    /// The exemplar resampled to each level.
    pub(super) levels: Vec<Image>,
}

impl ExemplarLevels {
    /// The level whose scale is nearest (in log) to `t / τ_ref`; the unit level for a
    /// texel without `τ` or a single level.
    pub(super) fn level_for(&self, t: f64) -> usize {
        let (scales, tau_ref) = (&self.scales, self.tau_ref);
        if !t.is_finite() || scales.len() == 1 {
            return scales.iter().position(|s| (*s - 1.0).abs() < 1e-9).unwrap_or(0);
        }
        let r = (t / tau_ref).ln();
        (0..scales.len())
            .min_by(|&i, &j| (scales[i].ln() - r).abs().total_cmp(&(scales[j].ln() - r).abs()))
            .unwrap_or(0)
    }
}

/// `τ` reference and exemplar levels, global so that features match across images.
pub(super) fn exemplar_levels(
    report: &mut Report,
    progress: &dyn Progress,
    options: &ConformalOptions,
    exemplar: &Image,
    images: &[Option<GeometryImage>],
) -> ExemplarLevels {
    let mut tau_w: Vec<(f64, f64)> = Vec::new();
    for img in images.iter().flatten() {
        for (l, a) in img.face_lambda.iter().zip(&img.face_area) {
            if l.is_finite() && *l > 0.0 {
                tau_w.push((1.0 / l, *a));
            }
        }
    }
    // The paper places the original sample "close to the lowest level" (§4.2): the
    // reference is the 5th area-weighted percentile of τ, so almost every patch takes an
    // enlarged level and only the 1 % tail below needs a minified one (at least one
    // patch wide).
    let tau_ref = weighted_quantile(&mut tau_w.clone(), 0.05).unwrap_or(1.0);
    let q05 = tau_ref;
    let q01 = weighted_quantile(&mut tau_w.clone(), 0.01).unwrap_or(1.0);
    let q95 = weighted_quantile(&mut tau_w.clone(), 0.95).unwrap_or(1.0);
    let q99 = weighted_quantile(&mut tau_w.clone(), 0.99).unwrap_or(1.0);
    let ex_side = exemplar.width.min(exemplar.height) as f64;
    // Never above 1: an exemplar whose short side is under patch + 8 px (accepted: one
    // patch fits) gets no minified level instead of an empty range.
    let min_scale = ((options.patch_size as f64 + 8.0) / ex_side).clamp(0.25, 1.0);
    // Largest enlargement: 12×, and no level over 2048 px on its short side.
    let max_scale = (2048.0 / (ex_side * options.scale)).clamp(1.0, 12.0);
    let (scales, level_names) = if options.multiscale {
        let lo = (q01 / tau_ref).clamp(min_scale, 1.0);
        let hi = (q99 / tau_ref).clamp(1.0, max_scale);
        // At least one level per factor 1.3 of the range (at most 14).
        let n = options.levels.max(((hi / lo).ln() / 1.3f64.ln()).ceil() as usize + 1).min(14);
        let s = scale_levels(lo, hi, n);
        (s.clone(), s)
    } else {
        (vec![1.0], vec![1.0])
    };
    let levels: Vec<Image> = report.stage(progress, "exemplar-levels", || {
        scales.iter().map(|s| resample(exemplar, s * options.scale)).collect()
    });
    ExemplarLevels { tau_w, tau_ref, q05, q95, scales, level_names, levels }
}

/// Quilts every geometry image (margins copied to their partners afterwards; the
/// fallback atlas is one of them): the texture blocks, the per-image statistics and the
/// patch-split spread used.
pub(super) fn quilt_blocks(
    progress: &dyn Progress,
    options: &ConformalOptions,
    comps: &[ConformalComponent],
    images: &[Option<GeometryImage>],
    lv: &ExemplarLevels,
) -> Result<(Vec<Block>, Vec<serde_json::Value>, f64)> {
    let qbase = QuiltingOptions {
        patch_size: options.patch_size,
        overlap: (options.patch_size / 5).max(2),
        // A 40-px patch over a fast τ change (near zero points, across neighbouring
        // charts) is placed as four half-size patches, each with its own level; the
        // ablation keeps whole patches (one level, nothing to choose).
        split_spread: if options.multiscale { PATCH_SPLIT_SPREAD } else { f64::INFINITY },
        seed: options.seed,
        ..Default::default()
    };
    let level_for = |t: f64| lv.level_for(t);
    let mut blocks: Vec<Block> = Vec::new();
    let mut quilt_stats = Vec::new();
    for (c, img) in comps.iter().zip(images) {
        let Some(img) = img else { continue };
        let partners = |i: usize, j: usize, out: &mut Vec<(usize, usize)>| img.partners(i, j, out);
        let target = QuiltTarget {
            width: img.width,
            height: img.height,
            tau: &img.tau,
            level_for: &level_for,
            partners: &partners,
        };
        let q = QuiltingOptions {
            seed: stream_seed(options.seed, "conformal-image", c.component as u64),
            ..qbase
        };
        crate::outputs::check_cancelled(progress)?;
        let (mut image, st) = quilt(&lv.levels, &target, &q, progress);
        // Margins across patch cuts take their partners' colours (§4.2); count those the
        // quilting left different from their partner (both sides written in one patch).
        let changed = img
            .margin_copies
            .iter()
            .filter(|&&(g, r, _)| image.pixels[g as usize] != image.pixels[r as usize])
            .count();
        let pairs_changed = img
            .seam_pairs
            .iter()
            .filter(|&&(a, b)| image.pixels[a as usize] != image.pixels[b as usize])
            .count();
        img.copy_margins(&mut image.pixels);
        let feathered = if options.seam_feather {
            img.feather_seams(&mut image.pixels, SEAM_FEATHER_BAND)
        } else {
            0
        };
        quilt_stats.push(json!({"component": c.component, "stats": st, "margin_texels_copied": img.margin_copies.len(), "margin_texels_changed_by_copy": changed, "seam_texel_pairs": img.seam_pairs.len(), "seam_texel_pairs_changed_by_copy": pairs_changed, "feathered_pairs": feathered}));
        let faces = c.faces.iter().copied().zip(img.corner_texel.iter().copied()).collect();
        blocks.push(Block {
            image,
            faces,
            tau: img.tau.clone(),
            label: if c.method == ConformalMethod::ChartAtlas {
                "fallback_atlas".into()
            } else {
                format!("component{}", c.component)
            },
        });
    }
    Ok((blocks, quilt_stats, qbase.split_spread))
}

/// What the metrics read from the run.
pub(super) struct RunParts<'a> {
    pub(super) comps: &'a [ConformalComponent],
    pub(super) images: &'a [Option<GeometryImage>],
    pub(super) levels: &'a ExemplarLevels,
    pub(super) split_spread: f64,
}

/// The report's metrics: components, levels, quilting, mass-spring, seams, feature size
/// (per texel, centre-λ, fixed window), whole-mesh distortion and texel density.
#[allow(clippy::too_many_arguments)]
pub(super) fn conformal_metrics(
    report: &mut Report,
    progress: &dyn Progress,
    options: &ConformalOptions,
    run: &RunParts,
    quilt_stats: Vec<serde_json::Value>,
    relax_stats: Vec<serde_json::Value>,
    out_mesh: &TriMesh,
    texture: &Image,
) {
    let comp_json: Vec<serde_json::Value> =
        run.comps.iter().zip(run.images).map(|(c, img)| component_json(c, img.as_ref())).collect();
    report.metric("components", comp_json);
    report.metric("exemplar_levels", json!({"scales": run.levels.level_names, "tau_reference": run.levels.tau_ref, "tau_q05": run.levels.q05, "tau_q95": run.levels.q95, "multiscale": options.multiscale, "patch_split_spread": run.split_spread}));
    report.metric("quilting", quilt_stats);
    if options.quasi_isometric {
        report.metric("mass_spring", relax_stats);
    }
    let seams = report.stage(progress, "eval-seams", || {
        fieldtex_eval::seam_metrics::seam_metrics(out_mesh, texture)
    });
    report.metric("seams", seams);
    let feature = report.stage(progress, "eval-feature-size", || {
        fieldtex_eval::feature_size::feature_size_variation(out_mesh, texture, 24, true, true)
    });
    report.metric("feature_size", feature);
    let feature_centre = report.stage(progress, "eval-feature-size-centre", || {
        fieldtex_eval::feature_size::feature_size_variation(out_mesh, texture, 24, true, false)
    });
    report.metric("feature_size_centre_lambda", feature_centre);
    let feature24 = report.stage(progress, "eval-feature-size-fixed", || {
        fieldtex_eval::feature_size::feature_size_variation(out_mesh, texture, 24, false, false)
    });
    report.metric("feature_size_fixed_window", feature24);
    // Whole-mesh distortion in texel units (the texture is not square).
    let whole = out_mesh.uvs.as_ref().and_then(|uv| {
        let mut texel_uv = uv.clone();
        for v in texel_uv.values.iter_mut() {
            *v = [v[0] * texture.width as f64, v[1] * texture.height as f64];
        }
        fieldtex_param::parameterization_distortion(out_mesh, &texel_uv).ok()
    });
    report.metric("distortion_all_faces", whole);
    report.metric("texel_density", texel_density(&run.levels.tau_w));
}
