//! `fieldtex solid`: sketch-guided solid texturing (paper E, Zhang et al. 2010).
//!
//! Steps: read and repair the mesh; read the sketch (`fieldtex_fields::sketch`) and
//! place its curves; the 3-D frame field on a coarse grid over the bounding box
//! ([`fieldtex_fields::FrameField3d`], each curve added as an edit of the kept factor);
//! the exemplar analysis and the lazy solid synthesizer
//! ([`fieldtex_synth::solid`]) over a voxel lattice whose longest side has
//! `resolution` voxels; the surface shell: an atlas of the mesh, each covered texel
//! coloured by trilinear interpolation of the eight voxels around its surface point
//! (only those voxels and their dependency set are synthesised); optional cuts (the
//! mesh part on the negative side, capped, textured from the same solid, and the cap's
//! image), the whole volume as NRRD, and the frame field as PLY.
//!
//! Cut images: for an axis-aligned plane through a plane of voxel centres the image is
//! that slice of the grid, one pixel per voxel (of the two other axes the earlier of
//! x, y, z along columns, the later along rows), alpha 0 where the voxel centre is
//! outside the mesh; other planes are sampled at voxel spacing (nearest voxel) over the
//! mesh's extent in the plane.

use crate::outputs::{begin_command, begin_outputs, commit_outputs};
use crate::pipelines::align::{atlas_carriers, carrier_texture};
use crate::pipelines::atlas::atlas_options;
use crate::{Error, Progress, Report, Result};
use fieldtex_core::Image;
use fieldtex_fields::{FrameField3d, FrameFieldOptions, FrameGrid, Sketch, quaternion};
use fieldtex_mesh::{Bvh, TriMesh};
use fieldtex_render::{Overlay, Polyline3, RenderOptions, Scene, render};
use fieldtex_synth::solid::{
    FrameSource, LevelStats, SolidAnalysisOptions, SolidExemplar, SolidSynthesisOptions,
    SolidSynthesizer, VoxelLattice,
};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[path = "solid_outputs.rs"]
mod extra_outputs;
pub(crate) use extra_outputs::{CutVoxels, cut_voxels, slice_image};
use extra_outputs::{write_cut, write_frames, write_volume};
#[path = "solid_exemplars.rs"]
mod exemplars;
pub(crate) use exemplars::{analyse_exemplars, analyse_interior, read_exemplars};
#[path = "solid_regions.rs"]
mod regions;
use regions::Interior;
pub(crate) use regions::SolidRegions;

/// Options of [`solid`].
#[derive(Debug, Clone, Serialize)]
pub struct SolidOptions {
    pub mesh: PathBuf,
    /// Sketch JSON; `None` = a constant (identity) field, the unguided baseline.
    pub sketch: Option<PathBuf>,
    /// Exemplar for all three planes unless a plane has its own.
    pub exemplar: Option<PathBuf>,
    pub exemplar_xy: Option<PathBuf>,
    pub exemplar_yz: Option<PathBuf>,
    pub exemplar_zx: Option<PathBuf>,
    /// Feature mask (paper E §4, regular exemplars such as bricks): a grey image the
    /// size of the exemplar, high on the feature curves (mortar), matched as a fourth
    /// channel and never shown; transposed for the yz plane like a single `--exemplar`.
    /// `None` = RGB matching only.
    pub feature_mask: Option<PathBuf>,
    /// Voxels along the bounding box's longest side. Default 256.
    pub resolution: usize,
    /// Cut planes `[x, y, z, nx, ny, nz]`.
    pub cuts: Vec<[f64; 6]>,
    /// Write `volume.nrrd` (the whole grid).
    pub volume: bool,
    /// Write `frames.ply`.
    pub keep: bool,
    /// Exemplar of the interior region (all three planes), `None` = one region.
    pub interior: Option<PathBuf>,
    /// Depth below the surface (mesh units) where the interior starts (middle of the
    /// blend band). 0 = default: 15 % of the bounding box's shortest side.
    pub interior_depth: f64,
    /// Width of the blend band (mesh units). 0 = default: three voxels.
    pub interior_band: f64,
    /// Atlas size of `model.glb` and the cut meshes, texels. Default 1024.
    pub atlas_size: usize,
    /// Frame-field cells along the bounding box's shortest side. Default 20 (paper: 20–30).
    pub field_cells: usize,
    pub analysis: SolidAnalysisOptions,
    pub synthesis: SolidSynthesisOptions,
    pub seed: u64,
}

impl Default for SolidOptions {
    fn default() -> Self {
        Self {
            mesh: PathBuf::new(),
            sketch: None,
            exemplar: None,
            exemplar_xy: None,
            exemplar_yz: None,
            exemplar_zx: None,
            feature_mask: None,
            resolution: 256,
            cuts: Vec::new(),
            volume: false,
            keep: false,
            interior: None,
            interior_depth: 0.0,
            interior_band: 0.0,
            atlas_size: 1024,
            field_cells: 20,
            analysis: SolidAnalysisOptions::default(),
            synthesis: SolidSynthesisOptions::default(),
            seed: 1,
        }
    }
}

/// The voxel grid written out: `sizes` voxels from `origin` (centre of voxel 0).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct SolidGrid {
    pub origin: [f64; 3],
    pub spacing: f64,
    pub sizes: [usize; 3],
}

impl SolidGrid {
    pub(crate) fn over_box(min: [f64; 3], max: [f64; 3], resolution: usize) -> Self {
        let ext: [f64; 3] = std::array::from_fn(|a| max[a] - min[a]);
        let longest = ext.iter().cloned().fold(0.0, f64::max).max(1e-12);
        let spacing = longest / resolution as f64;
        let sizes: [usize; 3] =
            std::array::from_fn(|a| ((ext[a] / spacing).ceil() as usize).max(1));
        let origin = std::array::from_fn(|a| {
            0.5 * (min[a] + max[a]) - 0.5 * (sizes[a] - 1) as f64 * spacing
        });
        Self { origin, spacing, sizes }
    }

    fn len(&self) -> usize {
        self.sizes.iter().product()
    }
}

/// The frame field as the synthesis sees it (rotation matrices).
pub(crate) struct FieldFrames<'a>(pub Option<&'a FrameField3d>);

impl FrameSource for FieldFrames<'_> {
    fn frame(&self, p: [f64; 3]) -> [f64; 9] {
        match self.0 {
            Some(f) => quaternion::to_matrix(f.frame_at(p)),
            None => quaternion::to_matrix(quaternion::IDENTITY),
        }
    }
}

/// Quantises an sRGB colour to bytes exactly as the PNG writer does.
fn rgb8(c: [f32; 3]) -> [u8; 3] {
    c.map(|v| if v.is_nan() { 0 } else { (v.clamp(0.0, 1.0) * 255.0).round() as u8 })
}

/// Running totals of the synthesis work, for the report.
#[derive(Default, Serialize)]
pub(crate) struct Work {
    pub(crate) requested: u64,
    computed_finest: u64,
    pub(crate) computed_all_levels: u64,
    corrections: u64,
    seconds: f64,
}

impl Work {
    fn add(&mut self, requested: usize, stats: &[LevelStats], seconds: f64) {
        self.requested += requested as u64;
        self.computed_finest += stats.first().map_or(0, |s| s.voxels);
        self.computed_all_levels += stats.iter().map(|s| s.voxels).sum::<u64>();
        self.corrections += stats.iter().map(|s| s.corrections).sum::<u64>();
        self.seconds += seconds;
    }
}

/// Runs `fieldtex solid` into `out_dir` (module docs).
pub fn solid(out_dir: &Path, options: &SolidOptions, progress: &dyn Progress) -> Result<Report> {
    let aopts = atlas_options(options.atlas_size, 4)?;
    if !(8..=2048).contains(&options.resolution) {
        return Err(Error::bad_input(
            None,
            format!("--resolution must be in 8..=2048, got {}", options.resolution),
        ));
    }
    let mut report =
        Report::new("solid", options.seed, serde_json::to_value(options).unwrap_or_default());
    begin_command();
    let (mesh, _inputs) = read_inputs(options, &mut report)?;
    let (exemplars, single) = read_exemplars(options)?;
    // The xy exemplar's own stripe direction and its orientation error against it: the
    // floor of a slice's orientation error (as `orient` reports it).
    if let Some(own) = super::orient::exemplar_orientation(&exemplars[0]) {
        report.metric("exemplar_orientation", own);
    }
    if options.synthesis.integrated_init {
        report.warnings.extend(super::orient::integrated_start_warning(&exemplars[0]));
    }
    let mut analysis = options.analysis.clone();
    if single {
        analysis.plane_weights = [1.0, 1.0, 0.0];
    }
    let out = begin_outputs(
        out_dir,
        &["model.glb", "preview.png", "report.json", "volume.nrrd", "frames.ply"],
    )?;
    // Everything below writes into the staging folder, moved into place at the end.
    let stage = out.staging().to_path_buf();
    let out_dir = stage.as_path();
    let bbox = mesh
        .bounding_box()
        .ok_or_else(|| Error::bad_input(Some(&options.mesh), "the mesh has no vertex"))?;
    // 1. Sketch and frame field (§3).
    let (field, curves) = report.stage(progress, "frame_field", || match &options.sketch {
        Some(path) => {
            solid_frame_field(&mesh, path, options.field_cells).map(|(f, c)| (Some(f), c))
        }
        None => Ok((None, Vec::new())),
    })?;
    if let Some(f) = &field {
        let errs = f.constraint_errors_deg();
        let max = errs.iter().cloned().fold(0.0, f64::max);
        let mean = errs.iter().sum::<f64>() / errs.len().max(1) as f64;
        report.metric(
            "frame_field",
            serde_json::json!({
                "grid": f.grid(),
                "curves": curves.len(),
                "constrained_nodes": errs.len(),
                "alignment_error_max_deg": max,
                "alignment_error_mean_deg": mean,
                "factor_entries": f.factor_nnz(),
                "residual": f.last_residual(),
            }),
        );
        let edit_ms = report
            .stage(progress, "frame_field_edit", || edit_timing(f.grid().clone(), &curves))?;
        report.metric("frame_field_edit_ms", edit_ms);
    }
    crate::outputs::check_cancelled(progress)?;
    // 2. Exemplar analysis and the synthesizer.
    let ex = report.stage(progress, "exemplar_analysis", || {
        analyse_exemplars(options, &exemplars, single, &analysis, progress)
    })?;
    let grid = SolidGrid::over_box(bbox.min, bbox.max, options.resolution);
    report.metric("grid", grid);
    let frames = FieldFrames(field.as_ref());
    let lattice = VoxelLattice { origin: grid.origin, spacing: grid.spacing };
    let synth = SolidSynthesizer::new(&ex, lattice, &frames, options.synthesis.clone())
        .map_err(|e| Error::classify(&e, None, "synthesis options"))?
        .with_extent(grid.sizes);
    let bvh = Bvh::build(&mesh).map_err(|e| Error::internal("bvh", e))?;
    // The interior region (paper E Fig. 15): its own analysis, same lattice and field.
    let ex_inner = match &options.interior {
        Some(path) => Some(analyse_interior(path, &options.analysis, &mut report, progress)?),
        None => None,
    };
    let shortest = (0..3).map(|a| bbox.max[a] - bbox.min[a]).fold(f64::INFINITY, f64::min);
    let depth = if options.interior_depth > 0.0 { options.interior_depth } else { 0.15 * shortest };
    let band = if options.interior_band > 0.0 { options.interior_band } else { 3.0 * grid.spacing };
    if !(depth.is_finite() && band.is_finite()) {
        return Err(Error::bad_input(None, "--interior-depth must be a finite number"));
    }
    let inner = match &ex_inner {
        Some(e) => Some(Interior {
            synth: SolidSynthesizer::new(e, lattice, &frames, options.synthesis.clone())
                .map_err(|e| Error::classify(&e, None, "synthesis options"))?
                .with_extent(grid.sizes),
            bvh: &bvh,
            depth,
            band,
            scale: bbox.diagonal(),
        }),
        None => None,
    };
    if inner.is_some() {
        report.metric("interior", serde_json::json!({"depth": depth, "band": band}));
    }
    let mut synth = SolidRegions { outer: synth, inner, grid };
    crate::outputs::check_cancelled(progress)?;
    // 3. Surface shell → atlas texture → model.glb.
    let (atlas_mesh, texture, shell) = report
        .stage(progress, "shell", || textured_atlas(&mesh, &aopts, &grid, &mut synth, progress))?;
    report.metric("shell", &shell);
    report.metric(
        "shell_voxels_per_second",
        shell.computed_all_levels as f64 / shell.seconds.max(1e-9),
    );
    report.metric("shell_share_of_full_volume", shell.computed_finest as f64 / grid.len() as f64);
    report.stage(progress, "write", || super::write_model(out_dir, &atlas_mesh, Some(&texture)))?;
    let preview =
        report.stage(progress, "preview", || preview_with_curves(&atlas_mesh, &texture, &curves));
    fieldtex_io::write_png(&out_dir.join("preview.png"), &preview)?;
    crate::outputs::check_cancelled(progress)?;
    // 4. Cuts.
    let mut cut_reports = Vec::new();
    for (i, cut) in options.cuts.iter().enumerate() {
        let r = report.stage(progress, &format!("cut_{}", i + 1), || {
            let keep_field = options.keep.then_some(&frames);
            write_cut(
                out_dir,
                i + 1,
                *cut,
                &mesh,
                &bvh,
                &aopts,
                &grid,
                &mut synth,
                keep_field,
                progress,
            )
        })?;
        cut_reports.push(r);
    }
    report.metric("cuts", cut_reports);
    // 5. Volume and frames.
    if options.volume {
        let w = report
            .stage(progress, "volume", || write_volume(out_dir, &grid, &mut synth, progress))?;
        report.metric("volume", w);
    }
    if options.keep
        && let Some(f) = &field
    {
        write_frames(&out_dir.join("frames.ply"), f)?;
    }
    report.metric("cached_voxels_per_level", synth.cached_voxels());
    report.notes.extend(notes(options));
    if single {
        report.notes.push(
            "one --exemplar: the xy plane uses it, the yz plane its transpose (they share the local y axis), and the zx plane has weight 0 in matching and colour (paper E §6.1: drop the third plane when the exemplars cannot all hold in one solid); give --exemplar-xy/-yz/-zx for three weighted planes".into(),
        );
    }
    commit_outputs(out, &mut report)?;
    Ok(report)
}

pub(crate) fn read_inputs(
    options: &SolidOptions,
    report: &mut Report,
) -> Result<(TriMesh, Vec<PathBuf>)> {
    let loaded = report.time("read", || fieldtex_io::read_mesh(&options.mesh))?;
    report.warnings.extend(loaded.warnings.iter().cloned());
    let repaired =
        super::repair_stage::repair_into_report(&loaded.mesh, Some(&options.mesh), None, report)?;
    let mut inputs = vec![options.mesh.clone()];
    inputs.extend(options.sketch.iter().cloned());
    inputs.extend(options.interior.iter().cloned());
    inputs.extend(
        [&options.exemplar, &options.exemplar_xy, &options.exemplar_yz, &options.exemplar_zx]
            .into_iter()
            .flatten()
            .cloned(),
    );
    report.input = serde_json::json!({
        "mesh": options.mesh,
        "vertices": repaired.n_vertices(),
        "triangles": repaired.n_triangles(),
    });
    Ok((repaired, inputs))
}

/// The frame field of the sketch at `sketch` over `mesh`'s bounding box (shortest side
/// `field_cells` cells) and the placed curves, each curve added as an edit of the kept
/// factor. The returned [`FrameField3d`] stays editable (`add_curve`, `remove_curve`,
/// `replace_curve`: one factor update and one solve each), for interactive front ends.
pub fn solid_frame_field(
    mesh: &TriMesh,
    sketch: &Path,
    field_cells: usize,
) -> Result<(FrameField3d, Vec<fieldtex_fields::FrameCurve>)> {
    let path = sketch;
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::bad_input(Some(path), format!("cannot read the sketch: {e}")))?;
    let sketch: Sketch = serde_json::from_str(&text).map_err(|e| {
        Error::bad_input(
            Some(path),
            format!("the sketch is not valid JSON for the schema in docs/solid.md: {e}"),
        )
    })?;
    sketch_frame_field(mesh, &sketch, field_cells, Some(path))
}

/// [`solid_frame_field`] of a sketch already in memory (`path` names it in errors).
pub(crate) fn sketch_frame_field(
    mesh: &TriMesh,
    sketch: &Sketch,
    field_cells: usize,
    path: Option<&Path>,
) -> Result<(FrameField3d, Vec<fieldtex_fields::FrameCurve>)> {
    let bbox =
        mesh.bounding_box().ok_or_else(|| Error::bad_input(None, "the mesh has no vertex"))?;
    let curves = sketch.frame_curves(mesh).map_err(|e| Error::bad_input(path, e.to_string()))?;
    let grid = FrameGrid::over_box(bbox.min, bbox.max, field_cells)
        .map_err(|e| Error::bad_input(None, format!("--field-cells: {e}")))?;
    let mut field = FrameField3d::new(grid, FrameFieldOptions::default())
        .map_err(|e| Error::Internal(e.to_string()))?;
    for (i, c) in curves.iter().enumerate() {
        field.add_curve(c).map_err(|e| Error::classify(&e, path, &format!("curve {i}")))?;
    }
    Ok((field, curves))
}

/// Interactive edit timings: the curves added one by one into a fresh field (the first
/// factors), then the last curve removed and added again, and replaced by itself (a
/// redraw: downdate + update + one solve).
fn edit_timing(
    grid: FrameGrid,
    curves: &[fieldtex_fields::FrameCurve],
) -> Result<serde_json::Value> {
    let mut field = FrameField3d::new(grid, FrameFieldOptions::default())
        .map_err(|e| Error::Internal(e.to_string()))?;
    let mut add_ms = Vec::new();
    let mut last = 0;
    for c in curves {
        let t = Instant::now();
        last = field.add_curve(c).map_err(|e| Error::Internal(e.to_string()))?;
        add_ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let t = Instant::now();
    field.remove_curve(last).map_err(|e| Error::Internal(e.to_string()))?;
    let remove_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    if let Some(c) = curves.last() {
        field.add_curve(c).map_err(|e| Error::Internal(e.to_string()))?;
    }
    let readd_ms = t.elapsed().as_secs_f64() * 1e3;
    let ids = field.curve_ids();
    let t = Instant::now();
    if let (Some(&id), Some(c)) = (ids.last(), curves.last()) {
        field.replace_curve(id, c).map_err(|e| Error::Internal(e.to_string()))?;
    }
    let replace_ms = t.elapsed().as_secs_f64() * 1e3;
    Ok(serde_json::json!({
        "add_ms": add_ms,
        "remove_ms": remove_ms,
        "re_add_ms": readd_ms,
        "replace_ms": replace_ms,
    }))
}

/// Eight voxels and trilinear weights around world point `p`.
fn trilinear(grid: &SolidGrid, p: [f64; 3]) -> [([i32; 3], f32); 8] {
    let t: [f64; 3] = std::array::from_fn(|a| (p[a] - grid.origin[a]) / grid.spacing);
    let b: [i32; 3] = t.map(|x| x.floor() as i32);
    let f: [f64; 3] = std::array::from_fn(|a| t[a] - b[a] as f64);
    std::array::from_fn(|c| {
        let d = [c & 1, (c >> 1) & 1, (c >> 2) & 1];
        let w: f64 = (0..3).map(|a| if d[a] == 1 { f[a] } else { 1.0 - f[a] }).product();
        ([b[0] + d[0] as i32, b[1] + d[1] as i32, b[2] + d[2] as i32], w as f32)
    })
}

/// Colours of surface points by trilinear interpolation of the solid.
fn surface_colors(
    points: &[[f64; 3]],
    grid: &SolidGrid,
    synth: &mut SolidRegions<'_>,
    progress: &dyn Progress,
    work: &mut Work,
) -> Vec<[f32; 4]> {
    let corners: Vec<[([i32; 3], f32); 8]> = points.iter().map(|&p| trilinear(grid, p)).collect();
    let mut voxels: Vec<[i32; 3]> =
        corners.iter().flat_map(|c| c.iter().map(|(v, _)| *v)).collect();
    voxels.sort_unstable();
    voxels.dedup();
    let t = Instant::now();
    let (rgb, stats) = synth.colors(&voxels, progress);
    work.add(voxels.len(), &stats, t.elapsed().as_secs_f64());
    corners
        .iter()
        .map(|c| {
            let mut acc = [0.0f32; 3];
            for (v, w) in c {
                let i = voxels.binary_search(v).expect("requested above");
                for ch in 0..3 {
                    acc[ch] += w * rgb[i][ch];
                }
            }
            [acc[0], acc[1], acc[2], 1.0]
        })
        .collect()
}

/// An atlas of `mesh` whose texels carry the solid's colour at their surface points.
fn textured_atlas(
    mesh: &TriMesh,
    aopts: &fieldtex_param::AtlasOptions,
    grid: &SolidGrid,
    synth: &mut SolidRegions<'_>,
    progress: &dyn Progress,
) -> Result<(TriMesh, Image, Work)> {
    let atlas = fieldtex_param::build_atlas(mesh, aopts, progress)
        .map_err(|e| Error::classify(&e, None, "atlas"))?;
    let size = aopts.resolution as usize;
    let map = fieldtex_param::build_texel_map(&atlas.mesh, size, size, atlas.gutter)
        .map_err(|e| Error::internal("texel map", e))?;
    let (covered, _) = atlas_carriers(&map);
    let points: Vec<[f64; 3]> =
        covered.iter().filter_map(|&i| map.surface_point(&atlas.mesh, i)).collect();
    if points.len() != covered.len() {
        return Err(Error::Internal("a covered texel has no surface point".into()));
    }
    let mut work = Work::default();
    let colors = surface_colors(&points, grid, synth, progress, &mut work);
    let (texture, _) = carrier_texture(&map, &covered, &colors);
    Ok((atlas.mesh, texture, work))
}

fn preview_with_curves(
    mesh: &TriMesh,
    texture: &Image,
    curves: &[fieldtex_fields::FrameCurve],
) -> Image {
    let mut scene = Scene::new(mesh).with_texture(texture);
    for c in curves {
        scene = scene.with_overlay(Overlay::Polyline(
            Polyline3::new(c.points.clone()).with_color([0.9, 0.15, 0.1, 1.0]),
        ));
    }
    render(&scene, &RenderOptions { size: 800, ..Default::default() })
}

fn notes(options: &SolidOptions) -> Vec<String> {
    let mut n = vec![
        "candidate triples: the partners of each pixel are searched coarse to fine (brute force over a regular sub-grid pool of the other exemplars, SolidAnalysisOptions::pool, then every pixel of the pool cells around the best hits; for exemplars above about 128² pixels a kd-tree over every pixel's stick, best-bin-first with 128 points examined, instead), not Dong 2008's exhaustive search; Dong's neighbour-consistency test is not applied".to_string(),
        format!(
            "correction neighbourhoods are sampled by trilinear interpolation on the {} coarsest levels and at the nearest voxel below them, as the paper; on the {} coarsest levels the sample positions are integrated along the field (unit Euler steps), below them the centre voxel's frame spans the neighbourhood",
            options.synthesis.trilinear_levels, options.synthesis.integrate_levels
        ),
        format!(
            "neighbourhood N = {} on every level and {} PCA dimensions per plane (the paper: N = 7 coarse / 9 fine, about 20 dimensions)",
            options.analysis.neighbourhood, options.analysis.pca_dims
        ),
        "the coarsest level uses the same block (dual-grid) scheme as the others, with more passes, so that every level is lazy; the paper corrects the whole coarsest level without barriers".to_string(),
        if options.synthesis.integrated_init {
            "--integrated-init (a substitute start, not paper E's): the exemplar planes are carried along the least-squares integral of the frames and, unless --level-passes asks for corrections, left uncorrected; a voxel's colour is then the plane-weighted mean of the exemplar colours read by cubic convolution at its coordinate triple moved by the warp's sub-pixel part (with corrections, at the whole-pixel triple)".to_string()
        } else {
            "a voxel's colour is the plane-weighted mean of the exemplar colours at its coordinate triple".to_string()
        },
        if options.feature_mask.is_some() {
            "--feature-mask: the mask (grey value, stacked like the colours, times --feature-weight) is matched as a fourth channel in the PCA neighbourhoods, the crossbar sticks of the triple search and the correction's voxel neighbourhoods, and never shown (paper E §4); the same mask serves every plane, transposed for yz with one --exemplar; a detected mask is not implemented (give it)".to_string()
        } else {
            "no feature mask: matching is RGB only (--feature-mask adds the paper's fourth channel for regular exemplars such as bricks)".to_string()
        },
        "the surface texture interpolates the eight voxels around each texel's surface point (trilinear)".to_string(),
    ];
    if options.interior.is_some() {
        n.push("--interior: voxels deeper than the interior depth below the surface (closest-point distance, ray-parity inside test) come from a second synthesizer with the interior exemplar (same lattice and field), blended by a smoothstep across the band; the interior exemplar feeds xy and transposed yz with zx weight 0, as a single --exemplar does".into());
    }
    if options.sketch.is_none() {
        n.push("no sketch: a constant (identity) frame field, the unguided baseline".into());
    }
    n
}
