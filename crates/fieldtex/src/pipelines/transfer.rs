//! `fieldtex transfer`: texture transfer by geometry correlation (paper B, Mertens et al.
//! 2006; algorithms in `fieldtex-transfer`).
//!
//! Steps: read the textured source and the target (and the mask); repair both; transfer
//! on surface samples (descriptors → CCA guidance → feature matching → parametric or
//! non-parametric synthesis); an atlas of the target and its texel map; bake the synthesised sample
//! colours into it (Gaussian-weighted interpolation of the nearest target samples at
//! every covered texel, gutters dilated); write `model.glb`, `preview.png` (source and
//! target side by side, same view), `report.json` and, with `keep`, `guidance.ply`
//! (per-vertex descriptors, guidance and colour of the target).
//!
//! The source texture is the mesh's base-colour texture (OBJ `map_Kd`, glTF
//! `baseColorTexture`) unless `source_texture` names an image, which then replaces it:
//! that is how an OBJ with UVs but no MTL file (e.g. `spot`) is used.

use crate::outputs::{begin_command, begin_outputs, commit_outputs};
use crate::pipelines::align::{CarrierAtlas, carrier_atlas, carrier_texture};
use crate::pipelines::atlas::atlas_options;
use crate::{Error, Progress, Report, Result};
use fieldtex_core::Image;
use fieldtex_mesh::TriMesh;
use fieldtex_render::{RenderOptions, Scene, render};
use fieldtex_transfer::{
    DESCRIPTOR_NAMES, Engine, MatchMode, N_DESCRIPTORS, Reduction, TransferError, TransferOptions,
    UpAxis, values_at_surface_points,
};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Options of [`transfer_files`].
#[derive(Debug, Clone, Serialize)]
pub struct TransferCommandOptions {
    pub source: PathBuf,
    /// Base-colour image for the source's UVs, replacing its material's texture (for an
    /// OBJ with UVs and no MTL file).
    pub source_texture: Option<PathBuf>,
    pub target: PathBuf,
    /// Texels to ignore (white), same size as the source texture.
    pub mask: Option<PathBuf>,
    /// Atlas resolution of the output texture. Default 1024.
    pub size: usize,
    /// Also write `guidance.ply`.
    pub keep: bool,
    /// Algorithm options (samples, levels, up axis, reduction, matching, engine, seed).
    pub transfer: TransferOptions,
}

impl Default for TransferCommandOptions {
    fn default() -> Self {
        Self {
            source: PathBuf::new(),
            source_texture: None,
            target: PathBuf::new(),
            mask: None,
            size: 1024,
            keep: false,
            transfer: TransferOptions::default(),
        }
    }
}

/// Parses `x|y|z`.
pub fn parse_up_axis(s: &str) -> Option<UpAxis> {
    match s {
        "x" => Some(UpAxis::X),
        "y" => Some(UpAxis::Y),
        "z" => Some(UpAxis::Z),
        _ => None,
    }
}

/// Parses `none|marginals|multiscale`.
pub fn parse_match_mode(s: &str) -> Option<MatchMode> {
    match s {
        "none" => Some(MatchMode::None),
        "marginals" => Some(MatchMode::Marginals),
        "multiscale" => Some(MatchMode::Multiscale),
        _ => None,
    }
}

/// Parses `cca|cca-weighted|pca`.
pub fn parse_reduction(s: &str) -> Option<Reduction> {
    match s {
        "cca" => Some(Reduction::Cca),
        "cca-weighted" => Some(Reduction::CcaWeighted),
        "pca" => Some(Reduction::Pca),
        _ => None,
    }
}

/// Parses `parametric|nonparametric`.
pub fn parse_engine(s: &str) -> Option<Engine> {
    match s {
        "parametric" => Some(Engine::Parametric),
        "nonparametric" => Some(Engine::Nonparametric),
        _ => None,
    }
}

fn transfer_error(e: TransferError, options: &TransferCommandOptions) -> Error {
    match &e {
        TransferError::SourceNotTextured { .. } => {
            Error::bad_input(Some(&options.source), e.to_string())
        }
        TransferError::EmptyMesh { which: "target" } => {
            Error::bad_input(Some(&options.target), e.to_string())
        }
        TransferError::EmptyMesh { .. } => Error::bad_input(Some(&options.source), e.to_string()),
        TransferError::MaskSize { .. } => Error::bad_input(options.mask.as_deref(), e.to_string()),
        _ if e.is_bad_input() => Error::bad_input(None, e.to_string()),
        _ => Error::Internal(format!("transfer: {e}")),
    }
}

/// Source and target rendered with the same view, side by side.
fn side_by_side(left: &Image, right: &Image) -> Image {
    let h = left.height.max(right.height);
    let mut out = Image::new(left.width + right.width, h, [1.0; 4]);
    for y in 0..left.height {
        for x in 0..left.width {
            out.set(x, y, left.get(x, y));
        }
    }
    for y in 0..right.height {
        for x in 0..right.width {
            out.set(left.width + x, y, right.get(x, y));
        }
    }
    out
}

/// Runs `fieldtex transfer` into `out_dir` (module docs).
pub fn transfer_files(
    out_dir: &Path,
    options: &TransferCommandOptions,
    progress: &dyn Progress,
) -> Result<Report> {
    let aopts = atlas_options(options.size, 4)?;
    let mut report = Report::new(
        "transfer",
        options.transfer.seed,
        serde_json::to_value(options).unwrap_or_default(),
    );
    begin_command();
    let src = report.stage(progress, "read_source", || fieldtex_io::read_mesh(&options.source))?;
    report.warnings.extend(src.warnings.iter().cloned());
    let given_texture = match &options.source_texture {
        Some(p) => {
            Some(report.stage(progress, "read_source_texture", || fieldtex_io::read_image(p))?)
        }
        None => None,
    };
    let Some(texture) = given_texture.as_ref().or(src.base_color.as_ref()) else {
        return Err(Error::bad_input(
            Some(&options.source),
            "the source has no base-colour texture (OBJ map_Kd or glTF baseColorTexture that loads); transfer needs a textured source. If the mesh has UVs and its texture is a separate image (an OBJ without an MTL file), pass the image with --source-texture IMAGE",
        ));
    };
    if src.mesh.uvs.is_none() {
        return Err(Error::bad_input(
            Some(&options.source),
            "the source has no texture coordinates; transfer needs per-corner UVs to read its texture",
        ));
    }
    let tgt = report.stage(progress, "read_target", || fieldtex_io::read_mesh(&options.target))?;
    report.warnings.extend(tgt.warnings.iter().cloned());
    if tgt.mesh.n_triangles() == 0 {
        return Err(Error::bad_input(
            Some(&options.target),
            "the target mesh has no faces (a point cloud?); transfer needs a triangle mesh",
        ));
    }
    let mask = match &options.mask {
        Some(p) => Some(fieldtex_io::read_image(p)?),
        None => None,
    };
    let out = begin_outputs(out_dir, &["model.glb", "preview.png", "report.json", "guidance.ply"])?;
    // Everything below writes into the staging folder, moved into place at the end.
    let stage = out.staging().to_path_buf();
    let out_dir = stage.as_path();
    let source_mesh = super::repair_stage::repair_into_report(
        &src.mesh,
        Some(&options.source),
        Some("source"),
        &mut report,
    )?;
    if source_mesh.uvs.is_none() {
        return Err(Error::bad_input(
            Some(&options.source),
            "repair had to drop the source's texture coordinates (see the warnings); fix the UVs of the source",
        ));
    }
    let target_mesh = super::repair_stage::repair_into_report(
        &tgt.mesh,
        Some(&options.target),
        Some("target"),
        &mut report,
    )?;
    report.input = serde_json::json!({
        "source": options.source.display().to_string(),
        "source_vertices": source_mesh.n_vertices(),
        "source_triangles": source_mesh.n_triangles(),
        "source_texture": [texture.width, texture.height],
        "source_texture_file": options.source_texture.as_ref().map(|p| p.display().to_string()),
        "target": options.target.display().to_string(),
        "target_vertices": target_mesh.n_vertices(),
        "target_triangles": target_mesh.n_triangles(),
    });
    crate::outputs::check_cancelled(progress)?;
    // Transfer on surface samples.
    let result = fieldtex_transfer::transfer(
        &source_mesh,
        texture,
        mask.as_ref(),
        &target_mesh,
        &options.transfer,
        progress,
    )
    .map_err(|e| transfer_error(e, options))?;
    report.timings_ms.extend(result.timings_ms.iter().cloned());
    report.warnings.extend(result.warnings.iter().cloned());
    crate::outputs::check_cancelled(progress)?;
    // Atlas of the target and baking.
    let CarrierAtlas { atlas, map, covered, carriers } =
        carrier_atlas(&target_mesh, &aopts, options.size, &mut report, progress)?;
    let texture_out = report.stage(progress, "bake", || {
        let points: Vec<(u32, [f64; 3])> =
            carriers.iter().map(|c| (c.triangle, c.barycentric)).collect();
        let v = values_at_surface_points(
            &atlas.mesh,
            &result.target_samples,
            &result.target_colors,
            3,
            &points,
        );
        let colors: Vec<[f32; 4]> =
            v.chunks_exact(3).map(|c| [c[0] as f32, c[1] as f32, c[2] as f32, 1.0]).collect();
        carrier_texture(&map, &covered, &colors).0
    });
    // Report.
    transfer_metrics_and_notes(&mut report, options, &result);
    // Outputs.
    report.stage(progress, "write", || {
        super::write_model(out_dir, &atlas.mesh, Some(&texture_out))
    })?;
    let preview = report.stage(progress, "preview", || {
        let opts = RenderOptions { size: 600, ..Default::default() };
        let left = render(&Scene::new(&source_mesh).with_texture(texture), &opts);
        let right = render(&Scene::new(&atlas.mesh).with_texture(&texture_out), &opts);
        side_by_side(&left, &right)
    });
    fieldtex_io::write_png(&out_dir.join("preview.png"), &preview)?;
    if options.keep {
        report.stage(progress, "keep", || {
            write_guidance_ply(&out_dir.join("guidance.ply"), &target_mesh, &result)
        })?;
    }
    commit_outputs(out, &mut report)?;
    Ok(report)
}

/// The transfer's metrics (samples, guidance, feature matching, engine statistics) and
/// the notes naming its substitutes.
fn transfer_metrics_and_notes(
    report: &mut Report,
    options: &TransferCommandOptions,
    result: &fieldtex_transfer::TransferResult,
) {
    let named = |w: &[f64]| -> serde_json::Map<String, serde_json::Value> {
        DESCRIPTOR_NAMES.iter().zip(w).map(|(n, v)| (n.to_string(), serde_json::json!(v))).collect()
    };
    let cca = options.transfer.reduction != Reduction::Pca;
    report.metric(
        "samples",
        serde_json::json!({
            "source": result.source_samples.len(),
            "source_usable": result.source_valid.iter().filter(|&&v| v).count(),
            "target": result.target_samples.len(),
            "source_spacing": result.source_samples.spacing,
            "target_spacing": result.target_samples.spacing,
        }),
    );
    report.metric(
        "guidance",
        serde_json::json!({
            "reduction": options.transfer.reduction,
            if cca { "canonical_correlations" } else { "explained_variance_fractions" }: result.strengths,
            "descriptor_weights": named(&result.descriptor_weights),
            "directions": result.directions.iter().map(|d| named(d)).collect::<Vec<_>>(),
        }),
    );
    report.metric(
        "feature_matching",
        serde_json::json!({ "mode": options.transfer.matching, "steps": result.matching }),
    );
    if let Some(p) = &result.parametric {
        report.metric("parametric", p);
    }
    if let Some(n) = &result.nonparametric {
        report.metric("nonparametric", n);
    }
    report.notes.push(
        "surface samples: nested Poisson-disk dart throwing (each level holds every coarser one, as in Turk's hierarchy) stands in for Turk's point repulsion (same purpose: an even blue-noise spread; spacing statistics in docs/transfer.md)".into(),
    );
    report.notes.push(
        "solid-angle curvature: analytic, as in the paper (signed solid angles of the triangles clipped to each sphere, exact circular segments); each radius evaluated on min(descriptor samples, 64·area/r²) points and interpolated".into(),
    );
    report.notes.push(format!(
        "SH occlusion (ray cast) and the smallest solid-angle radii computed on {} samples and interpolated to level 0; height and normal exact per sample",
        options.transfer.descriptors.samples.min(result.target_samples.len())
    ));
    match options.transfer.engine {
        Engine::Parametric => report.notes.push(
            "parametric engine: k-means fitted on at most 65 536 strided samples, all samples labelled; feathering over the 4 nearest clusters".into(),
        ),
        Engine::Nonparametric => {
            report.notes.push(
                "non-parametric engine: every pass recomputes all target samples from the previous pass (parallel, full neighbourhoods) instead of the paper's one-sample-at-a-time sweep with causal neighbourhoods".into(),
            );
            report.notes.push(
                "non-parametric engine: neighbourhood search by PCA projection (16 dimensions) and a best-bin-first kd-tree instead of the ANN library; tangent frames oriented by the up axis".into(),
            );
        }
    }
    report.notes.push("colours are processed as sRGB-encoded values".into());
}

/// `guidance.ply`: the target with per-vertex descriptors, guidance and colour,
/// interpolated from the level-0 samples.
fn write_guidance_ply(
    path: &Path,
    mesh: &TriMesh,
    result: &fieldtex_transfer::TransferResult,
) -> Result<()> {
    let nv = mesh.n_vertices();
    let mut corner: Vec<Option<(u32, [f64; 3])>> = vec![None; nv];
    for (f, t) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let v = t[k] as usize;
            if corner[v].is_none() {
                let mut b = [0.0; 3];
                b[k] = 1.0;
                corner[v] = Some((f as u32, b));
            }
        }
    }
    let points: Vec<(u32, [f64; 3])> =
        corner.iter().map(|c| c.unwrap_or((0, [1.0, 0.0, 0.0]))).collect();
    let dim = N_DESCRIPTORS + 6;
    let mut values = Vec::with_capacity(result.target_samples.len() * dim);
    for i in 0..result.target_samples.len() {
        values.extend_from_slice(
            &result.target_descriptors[i * N_DESCRIPTORS..(i + 1) * N_DESCRIPTORS],
        );
        values.extend_from_slice(&result.target_guidance[i * 3..i * 3 + 3]);
        values.extend_from_slice(&result.target_colors[i * 3..i * 3 + 3]);
    }
    let v = values_at_surface_points(mesh, &result.target_samples, &values, dim, &points);
    let mut names: Vec<String> = DESCRIPTOR_NAMES.iter().map(|s| s.to_string()).collect();
    names.extend(
        ["guidance_0", "guidance_1", "guidance_2", "red", "green", "blue"].map(String::from),
    );
    let cols: Vec<Vec<f32>> = (0..dim)
        .map(|k| {
            (0..nv).map(|i| if corner[i].is_some() { v[i * dim + k] as f32 } else { 0.0 }).collect()
        })
        .collect();
    let props: Vec<(&str, &[f32])> =
        names.iter().map(|n| n.as_str()).zip(cols.iter().map(|c| c.as_slice())).collect();
    let plain = TriMesh::new(mesh.positions.clone(), mesh.triangles.clone());
    fieldtex_io::write_ply(path, &plain, &props, true)?;
    Ok(())
}
