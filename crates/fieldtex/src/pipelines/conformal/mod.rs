//! `fieldtex conformal` (paper C: Wang, Gu, Mueller & Yau 2005): uniform texture
//! synthesis on a global conformal parameterisation.
//!
//! Read → repair → global conformal map per component (`fieldtex_param::conformal`),
//! on the mesh refined where it is too coarse for a conformal map (`refinement.rs`) →
//! optional quasi-isometric relaxation → one geometry image per component with its `τ`
//! map → multi-scale quilting with graph-cut seams and periodic margins
//! (`fieldtex_synth::quilt`) → images stacked into one texture → `model.glb`,
//! `preview.png`, `report.json` (+ `--keep` artefacts). A genus ≥ 2 component's image
//! holds its critical-trajectory patches, linked across the cuts by ghost margins.
//! Failed components fall back to a chart atlas (LSCM charts), laid out as one more
//! component whose seams' margins are linked by similarity ghosts and synthesised the
//! same way; the report says so. Report pieces live in `report.rs`, texture
//! blocks and `--keep` artefacts in `blocks.rs`.

use crate::outputs::{begin_command, begin_outputs, commit_outputs};
use crate::{Error, Progress, Report, Result};
use fieldtex_core::Image;
use fieldtex_mesh::TriMesh;
use fieldtex_param::conformal::{ConformalComponent, GeometryImage, MassSpringOptions};
use serde::Serialize;

mod blocks;
mod refinement;
mod report;
mod stages;
use blocks::{assemble, fallback_atlas, write_keep};
pub use refinement::{
    REFINE_ABOVE, REFINE_MAX_LEVELS, REFINE_MAX_TRIANGLES, REFINE_SEAM_GROWTH, Refine,
};
use report::add_notes;
use serde_json::json;
use stages::{RunParts, check_options, conformal_metrics, exemplar_levels, quilt_blocks};
use std::path::{Path, PathBuf};

/// A quilting patch whose texels' `τ` spans more than this factor is placed as four
/// half-size patches with a level each (`QuiltingOptions::split_spread`). Session 13,
/// fertility, three seeds: 2 gave feature-size CV ratios 0.42–0.45 against 0.49–0.50
/// with whole patches; 1.25, 1.5 and 3 were no better (docs/conformal.md).
pub const PATCH_SPLIT_SPREAD: f64 = 2.0;

/// Texels over which the seam feathering fades (`GeometryImage::feather_seams`); the
/// correction falls by about a fifth per texel, so a longer fade changes nothing
/// (docs/conformal.md, session 16).
pub const SEAM_FEATHER_BAND: usize = 4;

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
    /// Genus 0: slits at protrusion tips and the double cover where the two-point slit
    /// cylinder squeezes protrusions (`fieldtex_param::conformal::protrusion_slits`).
    /// Default true.
    pub protrusion_slits: bool,
    /// Conformal polish: each chart of a slit-cylinder or patch layout re-solved as a
    /// free-boundary least squares conformal map held near the holomorphic map
    /// (`fieldtex_param::conformal::conformal_polish`); not with `quasi_isometric`,
    /// which relaxes the map instead. Default true.
    pub polish: bool,
    /// Seam feathering after the margin copy
    /// (`fieldtex_param::conformal::GeometryImage::feather_seams`, band
    /// [`SEAM_FEATHER_BAND`]). Default true.
    pub seam_feather: bool,
    /// Midpoint subdivision of coarse meshes before the map (`refinement.rs`): `Auto`
    /// refines while the map's angle distortion is above [`REFINE_ABOVE`]. Default `Auto`.
    pub refine: Refine,
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
            protrusion_slits: true,
            polish: true,
            seam_feather: true,
            refine: Refine::Auto,
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
    check_options(options)?;
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

    // 1–2. Global conformal parameterisation per component and the conformal polish,
    // on the mesh refined where it is too coarse for a conformal piecewise-linear map.
    let mapped = refinement::map_refined(mesh, options, &mut report, progress)?;
    let (mesh, mut comps) = (mapped.mesh, mapped.comps);
    report.warnings.extend(mapped.warnings);
    report.metric("refinement", &mapped.summary);
    // The optional quasi-isometric relaxation.
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
    // 3. Components without a map go to a chart atlas with linked margins (one more
    // component); geometry images and their τ maps.
    let fallback_faces: Vec<u32> =
        comps.iter().filter(|c| !c.has_uv()).flat_map(|c| c.faces.iter().copied()).collect();
    if !fallback_faces.is_empty() {
        let id = comps.len();
        let atlas = report.stage(progress, "fallback-atlas", || {
            fallback_atlas(&mesh, &fallback_faces, options.size, id, progress)
        })?;
        comps.push(atlas);
    }
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
    // 4. τ reference and exemplar levels (global, so features match across images).
    let lv = exemplar_levels(&mut report, progress, options, &exemplar, &images);
    // 5. Quilting per geometry image (and the fallback atlas).
    let quilting = fieldtex_core::StageGuard::begin(progress, "quilting", 0);
    let (blocks, quilt_stats, split_spread) =
        quilt_blocks(progress, options, &comps, &images, &lv)?;
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
    let run = RunParts { comps: &comps, images: &images, levels: &lv, split_spread };
    conformal_metrics(
        &mut report,
        progress,
        options,
        &run,
        quilt_stats,
        relax_stats,
        &out_mesh,
        &texture,
    );
    add_notes(&mut report, &comps, options);
    if options.keep {
        report.stage(progress, "keep", || write_keep(&stage, &mesh, &comps, &blocks))?;
    }
    commit_outputs(out, &mut report)?;
    Ok(report)
}

/// Surface area of `c`'s faces in `mesh`.
pub(super) fn component_area(mesh: &TriMesh, c: &ConformalComponent) -> f64 {
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
