//! `fieldtex conformal` (paper C: Wang, Gu, Mueller & Yau 2005): uniform texture
//! synthesis on a global conformal parameterisation.
//!
//! Read → repair → global conformal map per component (`fieldtex_param::conformal`) →
//! optional quasi-isometric relaxation → one geometry image per component with its `τ`
//! map → multi-scale quilting with graph-cut seams and periodic margins
//! (`fieldtex_synth::quilt`) → images stacked into one texture → `model.glb`,
//! `preview.png`, `report.json` (+ `--keep` artefacts). A genus ≥ 2 component's image
//! holds its critical-trajectory patches, linked across the cuts by ghost margins.
//! Failed components fall back to a chart atlas (LSCM charts) synthesised the same way
//! without partners; the report says so. Report pieces live in `report.rs`, texture
//! blocks and `--keep` artefacts in `blocks.rs`.

use crate::outputs::{begin_command, begin_outputs, commit_outputs};
use crate::{Error, Progress, Report, Result};
use fieldtex_core::{Image, stream_seed};
use fieldtex_mesh::TriMesh;
use fieldtex_param::conformal::{
    ConformalComponent, GeometryImage, MassSpringOptions, global_conformal,
};
use fieldtex_synth::exemplar_scales::{resample, scale_levels};
use fieldtex_synth::{QuiltTarget, QuiltingOptions, quilt};
use serde::Serialize;

mod blocks;
mod report;
use blocks::{assemble, fallback_atlas, write_keep};
use report::{add_notes, component_json, texel_density, weighted_quantile};
use serde_json::json;
use std::path::{Path, PathBuf};

/// A quilting patch whose texels' `τ` spans more than this factor is placed as four
/// half-size patches with a level each (`QuiltingOptions::split_spread`). Session 13,
/// fertility, three seeds: 2 gave feature-size CV ratios 0.42–0.45 against 0.49–0.50
/// with whole patches; 1.25, 1.5 and 3 were no better (docs/conformal.md).
pub const PATCH_SPLIT_SPREAD: f64 = 2.0;

/// Options of [`conformal`].
#[derive(Debug, Clone, Serialize)]
pub struct ConformalOptions {
    pub mesh: PathBuf,
    pub exemplar: PathBuf,
    /// Long side `C` of each geometry image in texels (paper: 1024). Default 1024.
    pub size: usize,
    /// Quasi-isometric relaxation before synthesis (§5; `fieldtex_param::conformal::mass_spring`). Default false.
    pub quasi_isometric: bool,
    /// Pick the exemplar level per patch from `τ` (§4.2). Default true.
    pub multiscale: bool,
    /// Number of exemplar levels. Default 6.
    pub levels: usize,
    /// Exemplar texels per texture texel where `τ` is at its reference (the 5th
    /// area-weighted percentile). Default 1.
    pub scale: f64,
    /// Quilting patch side (paper: 30–50). Default 40.
    pub patch_size: usize,
    /// Write patches.ply, trajectories.obj, geometry images and τ maps. Default false.
    pub keep: bool,
    pub seed: u64,
}

impl Default for ConformalOptions {
    fn default() -> Self {
        Self {
            mesh: PathBuf::new(),
            exemplar: PathBuf::new(),
            size: 1024,
            quasi_isometric: false,
            multiscale: true,
            levels: 6,
            scale: 1.0,
            patch_size: 40,
            keep: false,
            seed: 1,
        }
    }
}

/// One synthesised block of the final texture.
pub(super) struct Block {
    pub(super) image: Image,
    /// Per global face it textures: canvas texel coordinates of its corners.
    pub(super) faces: Vec<(u32, [[f64; 2]; 3])>,
    pub(super) tau: Vec<f32>,
    pub(super) label: String,
}

/// Runs the pipeline (see the module docs).
pub fn conformal(
    options: &ConformalOptions,
    out_dir: &Path,
    progress: &dyn Progress,
) -> Result<Report> {
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
    let mut report =
        Report::new("conformal", options.seed, serde_json::to_value(options).unwrap_or_default());
    begin_command();
    let loaded = report.stage(progress, "read", || fieldtex_io::read_mesh(&options.mesh))?;
    report.warnings.extend(loaded.warnings.iter().cloned());
    let exemplar = fieldtex_io::read_image(&options.exemplar)?;
    if exemplar.width < options.patch_size || exemplar.height < options.patch_size {
        return Err(Error::bad_input(
            Some(&options.exemplar),
            format!(
                "the exemplar is {}×{}; it must be at least one patch ({} px) on each side",
                exemplar.width, exemplar.height, options.patch_size
            ),
        ));
    }
    let out = begin_outputs(
        out_dir,
        &["model.glb", "preview.png", "report.json", "patches.ply", "trajectories.obj"],
    )?;
    let stage = out.staging().to_path_buf();
    let mesh = super::repair_stage::repair_into_report(
        &loaded.mesh,
        Some(&options.mesh),
        None,
        &mut report,
    )?;
    report.input = json!({
        "mesh": options.mesh.display().to_string(),
        "exemplar": options.exemplar.display().to_string(),
        "vertices": mesh.n_vertices(),
        "triangles": mesh.n_triangles(),
        "exemplar_size": [exemplar.width, exemplar.height],
    });

    // 1. Global conformal parameterisation, per component.
    let (mut comps, warnings) = report
        .stage(progress, "conformal-map", || global_conformal(&mesh, progress))
        .map_err(|e| Error::classify(&e, None, "conformal map"))?;
    report.warnings.extend(warnings);
    crate::outputs::check_cancelled(progress)?;
    // 2. Optional quasi-isometric relaxation.
    let mut relax_stats = Vec::new();
    if options.quasi_isometric {
        report.stage(progress, "mass-spring", || {
            for c in comps.iter_mut() {
                if let Some(s) = c.relax_quasi_isometric(&MassSpringOptions::default()) {
                    relax_stats.push(json!({"component": c.component, "stats": s}));
                }
            }
        });
    }
    // 3. Geometry images and their τ maps; components without a map go to the atlas.
    let total_area: Vec<f64> = comps.iter().map(|c| component_area(&mesh, c)).collect();
    let max_area = total_area.iter().cloned().fold(0.0, f64::max);
    let images: Vec<Option<GeometryImage>> = report.stage(progress, "geometry-images", || {
        comps
            .iter()
            .zip(&total_area)
            .map(|(c, a)| {
                c.has_uv().then(|| {
                    let side =
                        ((options.size as f64) * (a / max_area).sqrt()).round().max(64.0) as usize;
                    GeometryImage::new(c, side)
                })
            })
            .collect()
    });
    let fallback_faces: Vec<u32> =
        comps.iter().filter(|c| !c.has_uv()).flat_map(|c| c.faces.iter().copied()).collect();
    let fallback = if fallback_faces.is_empty() {
        None
    } else {
        Some(report.stage(progress, "fallback-atlas", || {
            fallback_atlas(&mesh, &fallback_faces, options.size, progress)
        })?)
    };
    // 4. τ reference and exemplar levels (global, so features match across images).
    let mut tau_w: Vec<(f64, f64)> = Vec::new();
    for img in images.iter().flatten() {
        for (l, a) in img.face_lambda.iter().zip(&img.face_area) {
            if l.is_finite() && *l > 0.0 {
                tau_w.push((1.0 / l, *a));
            }
        }
    }
    if let Some(fb) = &fallback {
        for (l, a) in fb.face_lambda.iter().zip(&fb.face_area) {
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
        scales.iter().map(|s| resample(&exemplar, s * options.scale)).collect()
    });
    let level_for = |t: f64| -> usize {
        if !t.is_finite() || scales.len() == 1 {
            return scales.iter().position(|s| (*s - 1.0).abs() < 1e-9).unwrap_or(0);
        }
        let r = (t / tau_ref).ln();
        (0..scales.len())
            .min_by(|&i, &j| (scales[i].ln() - r).abs().total_cmp(&(scales[j].ln() - r).abs()))
            .unwrap_or(0)
    };
    // 5. Quilting per geometry image (and the fallback atlas).
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
    let mut blocks: Vec<Block> = Vec::new();
    let mut quilt_stats = Vec::new();
    let quilting = fieldtex_core::StageGuard::begin(progress, "quilting", 0);
    for (c, img) in comps.iter().zip(&images) {
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
        let (mut image, st) = quilt(&levels, &target, &q, progress);
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
        quilt_stats.push(json!({"component": c.component, "stats": st, "margin_texels_copied": img.margin_copies.len(), "margin_texels_changed_by_copy": changed, "seam_texel_pairs": img.seam_pairs.len(), "seam_texel_pairs_changed_by_copy": pairs_changed}));
        let faces = c.faces.iter().copied().zip(img.corner_texel.iter().copied()).collect();
        blocks.push(Block {
            image,
            faces,
            tau: img.tau.clone(),
            label: format!("component{}", c.component),
        });
    }
    if let Some(fb) = &fallback {
        let none = |_: usize, _: usize, _: &mut Vec<(usize, usize)>| {};
        let target = QuiltTarget {
            width: fb.width,
            height: fb.height,
            tau: &fb.tau,
            level_for: &level_for,
            partners: &none,
        };
        let q = QuiltingOptions { seed: stream_seed(options.seed, "conformal-atlas", 0), ..qbase };
        let (image, st) = quilt(&levels, &target, &q, progress);
        quilt_stats.push(json!({"component": "fallback-atlas", "stats": st}));
        blocks.push(Block {
            image,
            faces: fb.faces.clone(),
            tau: fb.tau.clone(),
            label: "fallback_atlas".into(),
        });
    }
    report.timings_ms.push(("quilting".into(), quilting.elapsed_ms()));
    drop(quilting);
    crate::outputs::check_cancelled(progress)?;
    // 6. One texture: blocks stacked vertically; per-corner UVs.
    let (texture, out_mesh) = report.stage(progress, "assemble", || assemble(&mesh, &blocks));
    // 7. Outputs.
    report.stage(progress, "write", || super::write_model(&stage, &out_mesh, Some(&texture)))?;
    let preview = report.stage(progress, "preview", || {
        super::render::preview(&out_mesh, Some(&texture), 800, None)
    });
    fieldtex_io::write_png(&stage.join("preview.png"), &preview)?;
    // 8. Metrics.
    let comp_json: Vec<serde_json::Value> =
        comps.iter().zip(&images).map(|(c, img)| component_json(c, img.as_ref())).collect();
    report.metric("components", comp_json);
    report.metric("exemplar_levels", json!({"scales": level_names, "tau_reference": tau_ref, "tau_q05": q05, "tau_q95": q95, "multiscale": options.multiscale, "patch_split_spread": qbase.split_spread}));
    report.metric("quilting", quilt_stats);
    if options.quasi_isometric {
        report.metric("mass_spring", relax_stats);
    }
    let seams = report.stage(progress, "eval-seams", || {
        fieldtex_eval::seam_metrics::seam_metrics(&out_mesh, &texture)
    });
    report.metric("seams", seams);
    let feature = report.stage(progress, "eval-feature-size", || {
        fieldtex_eval::feature_size::feature_size_variation(&out_mesh, &texture, 24, true, true)
    });
    report.metric("feature_size", feature);
    let feature_centre = report.stage(progress, "eval-feature-size-centre", || {
        fieldtex_eval::feature_size::feature_size_variation(&out_mesh, &texture, 24, true, false)
    });
    report.metric("feature_size_centre_lambda", feature_centre);
    let feature24 = report.stage(progress, "eval-feature-size-fixed", || {
        fieldtex_eval::feature_size::feature_size_variation(&out_mesh, &texture, 24, false, false)
    });
    report.metric("feature_size_fixed_window", feature24);
    // Whole-mesh distortion in texel units (the texture is not square).
    let whole = out_mesh.uvs.as_ref().and_then(|uv| {
        let mut texel_uv = uv.clone();
        for v in texel_uv.values.iter_mut() {
            *v = [v[0] * texture.width as f64, v[1] * texture.height as f64];
        }
        fieldtex_param::parameterization_distortion(&out_mesh, &texel_uv).ok()
    });
    report.metric("distortion_all_faces", whole);
    report.metric("texel_density", texel_density(&tau_w));
    add_notes(&mut report, &comps, options);
    if options.keep {
        report.stage(progress, "keep", || write_keep(&stage, &mesh, &comps, &blocks))?;
    }
    commit_outputs(out, &mut report)?;
    Ok(report)
}

fn component_area(mesh: &TriMesh, c: &ConformalComponent) -> f64 {
    c.faces
        .iter()
        .map(|&f| {
            let p = mesh.triangle_positions(f as usize);
            0.5 * fieldtex_core::vec3::norm(fieldtex_core::vec3::cross(
                fieldtex_core::vec3::sub(p[1], p[0]),
                fieldtex_core::vec3::sub(p[2], p[0]),
            ))
        })
        .sum()
}
