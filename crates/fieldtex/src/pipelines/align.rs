//! `fieldtex align`: feature-aligned shape texturing (paper A, Xu et al. 2009).
//!
//! Steps: read and repair the mesh; salient curves (given OBJ polylines, or crest lines
//! detected with the default options); greedy curve orientation and harmonic penalty
//! diffusion of the field (§4, rank-1 updates, see `field`); an atlas and its texel map;
//! texture optimisation over the atlas texels as colour carriers with oriented
//! tangent-plane patches (§5.1, `fieldtex-texopt`), optionally with feature-to-feature
//! alignment (§5.2: exemplar feature lines and their distance map against the surface
//! geodesic distance to the salient curves); the texture is the carriers' colours with
//! gutters dilated. Writes `model.glb`, `preview.png`, `report.json` and, with `keep`,
//! `curves.obj` and `field.ply`.
//!
//! Where no curve constrains the field (a component without crest lines) it falls back
//! to the smoothest line field, along principal curvature only where the surface is
//! clearly anisotropic (Knöppel et al. 2013, `fieldtex_fields::smoothest_field`), or to
//! a global direction projected onto the surface (`direction`); a warning says so.
//! Users can pass their own curves.
//!
//! Exemplars follow the one policy of `fieldtex_synth::exemplar_policy` (above 2048
//! pixels per side they are reduced, with a warning, and the pattern keeps its size).
//! Synthesis runs coarse to fine over the exemplar's pyramid from a patch that spans its
//! largest structure (`fieldtex_synth::characteristic_scale`,
//! `fieldtex_texopt::pyramid_patch_sizes`), and ends with the crisp pass and the
//! histogram step (`TexOptOptions::histogram_match`).
//!
//! Files: the metrics of a run in `align_metrics.rs`; the stages and the pipeline here.

use crate::outputs::{begin_command, begin_outputs, commit_outputs};
use crate::pipelines::atlas::atlas_options;
use crate::{Error, Progress, Report, Result};
use fieldtex_core::{Image, Warning};
use fieldtex_features::{ExemplarFeatureOptions, ExemplarFeatures};
use fieldtex_fields::{CurveOrientationOptions, OrientationMode, orient_curves_with_geometry};
use fieldtex_mesh::{MeshGeometry, TriMesh};
use fieldtex_render::{Overlay, Polyline3, RenderOptions, Scene, render};
use fieldtex_texopt::{Carrier, FeatureAlignment, SurfaceDomain, TexOptError, TexOptOptions};
use serde::Serialize;
use std::path::{Path, PathBuf};

#[path = "align_metrics.rs"]
mod metrics;
use metrics::{MetricInputs, align_metrics};

/// Options of [`align`].
#[derive(Debug, Clone, Serialize)]
pub struct AlignOptions {
    pub mesh: PathBuf,
    pub exemplar: PathBuf,
    /// OBJ polylines; `None` detects crest lines.
    pub curves: Option<PathBuf>,
    /// Exemplar feature lines as polylines in pixel coordinates (OBJ `l` elements with
    /// `x y 0` vertices); `None` detects them.
    pub exemplar_lines: Option<PathBuf>,
    /// Atlas resolution in texels. Default 1024.
    pub size: usize,
    /// Pattern size: atlas texels per pixel of the exemplar file (2 = the pattern twice
    /// as large on the surface; `orient` uses the same meaning). Default 1.
    pub scale: f64,
    /// Where no curve constrains the field: this global direction projected onto the
    /// surface. Default `None`: the smoothest line field, along principal curvature where
    /// it is clearly anisotropic (Knöppel et al. 2013, `fieldtex_fields::smoothest_field`).
    pub direction: Option<[f64; 3]>,
    /// Feature-to-feature alignment (§5.2). Default on; off is the ablation.
    pub feature_align: bool,
    /// `greedy` (default) or `arbitrary` curve orientation.
    pub greedy: bool,
    /// Also write `curves.obj` and `field.ply`.
    pub keep: bool,
    /// Draw the curves on the preview.
    pub draw_curves: bool,
    pub seed: u64,
}

impl Default for AlignOptions {
    fn default() -> Self {
        Self {
            mesh: PathBuf::new(),
            exemplar: PathBuf::new(),
            curves: None,
            exemplar_lines: None,
            size: 1024,
            scale: 1.0,
            direction: None,
            feature_align: true,
            greedy: true,
            keep: false,
            draw_curves: false,
            seed: 1,
        }
    }
}

/// The salient curves of the mesh: read from `path`, or crest lines (over the
/// pipeline's geometry object). The caller warns when there are none (what the field
/// then does differs per pipeline).
pub(crate) fn salient_curves(
    geometry: &MeshGeometry,
    mesh_path: &Path,
    path: Option<&Path>,
    warnings: &mut Vec<Warning>,
) -> Result<(Vec<Vec<[f64; 3]>>, String)> {
    let (curves, source) = match path {
        Some(p) => (fieldtex_io::read_obj_polylines(p)?, p.display().to_string()),
        None => {
            let crest = fieldtex_features::crest_lines_with_geometry(
                geometry,
                &fieldtex_features::CrestOptions::default(),
                &fieldtex_core::NoProgress,
            )
            .map_err(|e| Error::classify(&e, Some(mesh_path), ""))?;
            warnings.extend(crest.warnings.iter().cloned());
            (
                crest.lines.into_iter().map(|l| l.points).collect(),
                "crest lines (default options)".to_string(),
            )
        }
    };
    Ok((curves, source))
}

/// An atlas of a repaired mesh, its `size × size` texel map and the covered texels as
/// colour carriers: the stage of every pipeline whose colour lives on atlas texels
/// (align, transfer). Timed as `atlas` and `texel_map`.
pub(crate) struct CarrierAtlas {
    pub atlas: fieldtex_param::Atlas,
    pub map: fieldtex_param::TexelMap,
    /// Row-major indices of the covered texels, parallel to `carriers`.
    pub covered: Vec<usize>,
    pub carriers: Vec<Carrier>,
}

/// Builds the [`CarrierAtlas`] of `mesh`.
pub(crate) fn carrier_atlas(
    mesh: &TriMesh,
    aopts: &fieldtex_param::AtlasOptions,
    size: usize,
    report: &mut Report,
    progress: &dyn Progress,
) -> Result<CarrierAtlas> {
    let atlas = report
        .stage(progress, "atlas", || fieldtex_param::build_atlas(mesh, aopts, progress))
        .map_err(|e| Error::classify(&e, None, "atlas"))?;
    report.warnings.extend(atlas.warnings.iter().cloned());
    let map = report
        .stage(progress, "texel_map", || {
            fieldtex_param::build_texel_map(&atlas.mesh, size, size, atlas.gutter)
        })
        .map_err(|e| Error::internal("texel map", e))?;
    let (covered, carriers) = atlas_carriers(&map);
    Ok(CarrierAtlas { atlas, map, covered, carriers })
}

/// The covered texels of `map` (row-major indices) and their surface points as colour
/// carriers, in the same order.
pub(crate) fn atlas_carriers(map: &fieldtex_param::TexelMap) -> (Vec<usize>, Vec<Carrier>) {
    let covered: Vec<usize> = (0..map.width * map.height)
        .filter(|&i| map.is_covered(i) && map.entries[i].is_some())
        .collect();
    let carriers = covered
        .iter()
        .filter_map(|&i| map.entries[i])
        .map(|e| Carrier {
            triangle: e.triangle,
            barycentric: [e.bary[0] as f64, e.bary[1] as f64, e.bary[2] as f64],
        })
        .collect();
    (covered, carriers)
}

/// The atlas texture from the carriers' colours: covered texels get their carrier's
/// colour, dilated gutter texels copy their source texel, empty texels are grey. Also
/// returns, per texel, the carrier index (`u32::MAX` for none).
pub(crate) fn carrier_texture(
    map: &fieldtex_param::TexelMap,
    covered: &[usize],
    colors: &[[f32; 4]],
) -> (Image, Vec<u32>) {
    let n = map.width * map.height;
    let mut texture = Image::new(map.width, map.height, [0.5, 0.5, 0.5, 1.0]);
    let mut carrier_of_texel = vec![u32::MAX; n];
    for (k, &i) in covered.iter().enumerate() {
        texture.pixels[i] = colors[k];
        carrier_of_texel[i] = k as u32;
    }
    for i in 0..n {
        let s = map.source[i];
        if s != u32::MAX && s as usize != i {
            texture.pixels[i] = texture.pixels[s as usize];
        }
    }
    (texture, carrier_of_texel)
}

/// Preview of the textured model, optionally with the curves drawn.
fn preview_with_curves(
    mesh: &TriMesh,
    texture: &Image,
    curves: Option<&[Vec<[f64; 3]>]>,
    size: usize,
) -> Image {
    let mut scene = Scene::new(mesh).with_texture(texture);
    for c in curves.unwrap_or(&[]) {
        scene = scene.with_overlay(Overlay::Polyline(
            Polyline3::new(c.clone()).with_color([0.9, 0.15, 0.1, 1.0]),
        ));
    }
    render(&scene, &RenderOptions { size, ..Default::default() })
}

/// The option checks of [`align`] that do not need the inputs.
fn check_options(options: &AlignOptions) -> Result<()> {
    if !(options.scale.is_finite() && options.scale > 0.0 && options.scale <= 64.0) {
        return Err(Error::bad_input(
            None,
            format!("--scale must be in (0, 64], got {}", options.scale),
        ));
    }
    if let Some(d) = options.direction
        && !(d.iter().all(|v| v.is_finite()) && d.iter().any(|&v| v != 0.0))
    {
        return Err(Error::bad_input(
            None,
            format!("--direction must be three finite numbers, not all zero; got {d:?}"),
        ));
    }
    Ok(())
}

/// The exemplar's feature lines: read from `--exemplar-lines`, or detected.
fn exemplar_feature_lines(
    options: &AlignOptions,
    exemplar: &Image,
    toroidal: bool,
) -> Result<ExemplarFeatures> {
    match &options.exemplar_lines {
        Some(p) => {
            let lines: Vec<Vec<[f32; 2]>> = fieldtex_io::read_obj_polylines(p)?
                .into_iter()
                .map(|l| l.into_iter().map(|q| [q[0] as f32, q[1] as f32]).collect())
                .collect();
            fieldtex_features::exemplar_features_from_polylines(
                exemplar.width,
                exemplar.height,
                &lines,
                toroidal,
            )
            .map_err(|e| Error::classify(&e, Some(p), ""))
        }
        None => fieldtex_features::detect_exemplar_feature_lines(
            exemplar,
            &ExemplarFeatureOptions { toroidal, ..Default::default() },
        )
        .map_err(|e| Error::classify(&e, Some(&options.exemplar), "")),
    }
}

/// `--keep`: the salient curves as OBJ polylines and the field as a PLY with vertex
/// attributes `fx fy fz`.
fn write_curves_and_field(
    stage: &Path,
    mesh: &TriMesh,
    curves: &[Vec<[f64; 3]>],
    normals: Vec<[f64; 3]>,
    field: &[[f64; 3]],
) -> Result<()> {
    fieldtex_io::write_obj_polylines(&stage.join("curves.obj"), curves)?;
    let mut ply_mesh = TriMesh::new(mesh.positions.clone(), mesh.triangles.clone());
    ply_mesh.vertex_normals = Some(normals);
    let comp = |k: usize| -> Vec<f32> { field.iter().map(|v| v[k] as f32).collect() };
    let (fx, fy, fz) = (comp(0), comp(1), comp(2));
    fieldtex_io::write_ply(
        &stage.join("field.ply"),
        &ply_mesh,
        &[("fx", &fx), ("fy", &fy), ("fz", &fz)],
        true,
    )?;
    Ok(())
}

/// Reads the mesh and the exemplar (or takes the in-memory ones) and fits the exemplar
/// to the size policy; returns the mesh as loaded, the exemplar used and its reduction.
fn load_inputs(
    options: &AlignOptions,
    given: Option<(&TriMesh, &Image)>,
    report: &mut Report,
) -> Result<(fieldtex_io::LoadedMesh, Image, usize)> {
    let (loaded, exemplar) = match given {
        None => {
            let loaded = report.time("read", || fieldtex_io::read_mesh(&options.mesh))?;
            (loaded, fieldtex_io::read_image(&options.exemplar)?)
        }
        Some((mesh, exemplar)) => (
            fieldtex_io::LoadedMesh {
                mesh: mesh.clone(),
                base_color: None,
                warnings: Vec::new(),
                format: fieldtex_io::MeshFormat::Obj,
            },
            exemplar.clone(),
        ),
    };
    report.warnings.extend(loaded.warnings.iter().cloned());
    // One exemplar policy for every pipeline: reduce above the size limit, with a warning.
    let fitted = fieldtex_synth::fit_exemplar(exemplar, fieldtex_synth::MAX_EXEMPLAR_SIDE);
    report.warnings.extend(fitted.warning.clone());
    let (exemplar, reduction) = (fitted.image, fitted.factor);
    let min_side = TexOptOptions::default().patch_sizes.into_iter().max().unwrap_or(8);
    if exemplar.width < min_side || exemplar.height < min_side {
        return Err(Error::bad_input(
            Some(&options.exemplar),
            format!(
                "the exemplar is {}×{} pixels; align needs at least {min_side}×{min_side} (its largest patch)",
                exemplar.width, exemplar.height
            ),
        ));
    }
    Ok((loaded, exemplar, reduction))
}

/// `#V` vectors, one per mesh vertex.
type VertexVectors = Vec<[f64; 3]>;

/// The curve-aligned field of paper A §4 (greedy or arbitrary orientation) with its
/// metrics in `report`; returns the per-vertex field and the normals it was projected on.
fn oriented_field(
    geometry: &MeshGeometry,
    curves: &[Vec<[f64; 3]>],
    curves_source: &str,
    options: &AlignOptions,
    report: &mut Report,
    progress: &dyn Progress,
) -> Result<(VertexVectors, VertexVectors)> {
    let mode = if options.greedy {
        OrientationMode::Greedy
    } else {
        OrientationMode::Arbitrary { seed: options.seed }
    };
    let mut copts = CurveOrientationOptions { mode, ..Default::default() };
    if let Some(d) = options.direction {
        copts.field.fallback = fieldtex_fields::UnconstrainedFallback::Direction(d);
    }
    let oriented = report
        .stage(progress, "field", || {
            orient_curves_with_geometry(geometry, curves, &copts, progress)
        })
        .map_err(|e| Error::classify(&e, None, "field"))?;
    report.warnings.extend(oriented.warnings.iter().cloned());
    report.warnings.extend(oriented.field.warnings.iter().cloned());
    let field_metrics = fieldtex_fields::surface_field_metrics_with(
        geometry,
        &oriented.field.vectors,
        &oriented.solver.constraints(),
    )
    .map_err(|e| Error::internal("field metrics", e))?;
    report.metric(
        "field",
        serde_json::json!({
            "curves": curves.len(),
            "curves_source": curves_source,
            "orientation": if options.greedy { "greedy" } else { "arbitrary" },
            "singularities": field_metrics.singularities.len(),
            "index_sum": field_metrics.index_sum,
            "dirichlet_energy": field_metrics.dirichlet_energy,
            "alignment_mean_deg": field_metrics.alignment.mean_deg,
        }),
    );
    let field = oriented.field.vectors.clone();
    let normals = oriented.solver.normals().to_vec();
    Ok((field, normals))
}

/// A texture-optimisation error as bad input (the exemplar's fault) or internal.
fn texopt_error(e: TexOptError, exemplar: &Path) -> Error {
    match e {
        TexOptError::ExemplarTooSmall { .. }
        | TexOptError::ExemplarBufferSize { .. }
        | TexOptError::NonFiniteExemplar { .. } => Error::classify(&e, Some(exemplar), ""),
        e => Error::classify(&e, None, "texture optimisation"),
    }
}

/// Runs `fieldtex align` into `out_dir` (module docs).
pub fn align(out_dir: &Path, options: &AlignOptions, progress: &dyn Progress) -> Result<Report> {
    begin_command();
    align_impl(out_dir, options, None, None, progress)
}

/// [`align`] on a mesh and an exemplar already in memory (the demo's procedural inputs);
/// `options.mesh` and `options.exemplar` only name them in the report and in messages.
/// Same algorithm, outputs and report as [`align`].
pub fn align_in_memory(
    out_dir: &Path,
    options: &AlignOptions,
    mesh: &TriMesh,
    exemplar: &Image,
    progress: &dyn Progress,
) -> Result<Report> {
    begin_command();
    align_impl(out_dir, options, Some((mesh, exemplar)), None, progress)
}

/// Called with the staging folder and the report just before the outputs are moved into
/// place: a caller (the demo) adds files and report entries to the same output set.
pub(crate) type ExtraOutputs<'a> = &'a mut dyn FnMut(&Path, &mut Report) -> Result<()>;

/// The align pipeline on files (`given` = `None`) or in-memory inputs.
pub(crate) fn align_impl(
    out_dir: &Path,
    options: &AlignOptions,
    given: Option<(&TriMesh, &Image)>,
    extra: Option<ExtraOutputs<'_>>,
    progress: &dyn Progress,
) -> Result<Report> {
    let aopts = atlas_options(options.size, 4)?;
    check_options(options)?;
    let mut inputs = vec![options.mesh.as_path(), options.exemplar.as_path()];
    if let Some(c) = &options.curves {
        inputs.push(c);
    }
    let mut report =
        Report::new("align", options.seed, serde_json::to_value(options).unwrap_or_default());
    let (loaded, exemplar, reduction) = load_inputs(options, given, &mut report)?;
    for name in ["model.glb", "preview.png", "report.json", "curves.obj", "field.ply"] {
        fieldtex_io::ensure_not_input(&out_dir.join(name), &inputs)?;
    }
    let out = begin_outputs(
        out_dir,
        &["model.glb", "preview.png", "report.json", "curves.obj", "field.ply"],
    )?;
    let stage = out.staging();
    // 1. Repair once; everything below uses this mesh (the atlas keeps its triangles).
    let mesh = super::repair_stage::repair_into_report(
        &loaded.mesh,
        Some(&options.mesh),
        None,
        &mut report,
    )?;
    report.input = serde_json::json!({
        "mesh": options.mesh.display().to_string(),
        "vertices": mesh.n_vertices(),
        "triangles": mesh.n_triangles(),
        "exemplar": options.exemplar.display().to_string(),
        "exemplar_size": [exemplar.width * reduction, exemplar.height * reduction],
        "exemplar_reduction": reduction,
    });
    crate::outputs::check_cancelled(progress)?;
    // 2. Salient curves and the oriented field (paper A §3–4).
    // One geometry object for crest lines, the field solver and its metrics.
    let geometry = MeshGeometry::new(&mesh);
    let mut warnings = Vec::new();
    let (curves, curves_source) = report.stage(progress, "curves", || {
        salient_curves(&geometry, &options.mesh, options.curves.as_deref(), &mut warnings)
    })?;
    if curves.is_empty() {
        warnings.push(Warning::new(
            "no-curves",
            "no feature curve was found or given: the field is the smoothest field (along \
             curvature where it is clearly anisotropic) or --direction where no curve \
             constrains it (pass --curves C.obj to steer it)",
        ));
    }
    report.warnings.extend(warnings);
    let (field, normals) =
        oriented_field(&geometry, &curves, &curves_source, options, &mut report, progress)?;
    crate::outputs::check_cancelled(progress)?;
    // 3. Atlas and colour carriers (covered texels).
    let size = options.size;
    let CarrierAtlas { atlas, map, covered, carriers } =
        carrier_atlas(&mesh, &aopts, size, &mut report, progress)?;
    let (domain, dwarn) = report
        .stage(progress, "domain", || SurfaceDomain::new(&atlas.mesh, &field, &carriers))
        .map_err(|e| Error::internal("surface domain", e))?;
    report.warnings.extend(dwarn);
    // Coarse to fine over the exemplar's pyramid: the coarsest patch spans its largest
    // structure (autocorrelation estimate).
    let structure = report
        .stage(progress, "exemplar_scale", || fieldtex_synth::characteristic_scale(&exemplar));
    let patch_sizes =
        fieldtex_texopt::pyramid_patch_sizes(structure.pixels, exemplar.width.min(exemplar.height));
    report.metric("exemplar_scale", &structure);
    // `--scale` counts texels per pixel of the exemplar file; a reduced exemplar's
    // pixel is `reduction` file pixels.
    let texels_per_pixel = options.scale * reduction as f64;
    let topts = TexOptOptions {
        patch_sizes,
        pixel_size: Some(domain.carrier_spacing() * texels_per_pixel),
        feature_align: options.feature_align,
        seed: options.seed,
        ..Default::default()
    };
    // 4. Feature alignment inputs (§5.2).
    let bvh = fieldtex_mesh::Bvh::build(&atlas.mesh).map_err(|e| Error::internal("bvh", e))?;
    let h = topts.pixel_size.unwrap_or(1.0);
    let curve_points = fieldtex_features::curve_surface_points(&bvh, &curves, h);
    let exemplar_features = report.stage(progress, "exemplar_features", || {
        exemplar_feature_lines(options, &exemplar, topts.toroidal)
    })?;
    report.warnings.extend(exemplar_features.warnings.iter().cloned());
    let features = if options.feature_align && !curve_points.is_empty() {
        // Paper A constrains samples within half a patch of a curve; coarse levels
        // (w > 32) span whole structures, so the band is half a 32-px patch plus 2 px.
        let w = topts.patch_sizes.iter().copied().max().unwrap_or(8).min(32) as f64;
        let band = (0.5 * w + 2.0) * h;
        let carrier_curve_distance = report.stage(progress, "curve_distance", || {
            fieldtex_features::distance_to_curves(domain.positions(), &curves, 0.25 * h, band)
        });
        Some(FeatureAlignment {
            exemplar_distance: exemplar_features.distance.clone(),
            carrier_curve_distance,
        })
    } else {
        None
    };
    // 5. Texture optimisation (§5.1).
    let result = report
        .stage(progress, "synthesis", || {
            fieldtex_texopt::optimise(&domain, &exemplar, &topts, features.as_ref(), progress)
        })
        .map_err(|e| texopt_error(e, &options.exemplar))?;
    report.warnings.extend(result.warnings.iter().cloned());
    crate::outputs::check_cancelled(progress)?;
    let (texture, carrier_of_texel) = carrier_texture(&map, &covered, &result.colors);
    // 6. Metrics.
    let inputs = MetricInputs {
        atlas_mesh: &atlas.mesh,
        map: &map,
        covered: &covered,
        carrier_of_texel: &carrier_of_texel,
        curve_points: &curve_points,
        exemplar: &exemplar,
        exemplar_features: &exemplar_features,
        texture: &texture,
        field: &field,
        texels_per_pixel,
        seed: options.seed,
    };
    align_metrics(&inputs, &result, features.is_some(), carriers.len(), &mut report)?;
    // 7. Outputs.
    report.stage(progress, "write", || super::write_model(stage, &atlas.mesh, Some(&texture)))?;
    let preview = report.stage(progress, "preview", || {
        preview_with_curves(&atlas.mesh, &texture, options.draw_curves.then_some(&curves[..]), 800)
    });
    fieldtex_io::write_png(&stage.join("preview.png"), &preview)?;
    if options.keep {
        write_curves_and_field(stage, &mesh, &curves, normals, &field)?;
    }
    if let Some(extra) = extra {
        extra(stage, &mut report)?;
    }
    commit_outputs(out, &mut report)?;
    Ok(report)
}
