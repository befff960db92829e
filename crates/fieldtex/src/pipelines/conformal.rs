//! `fieldtex conformal` (paper C: Wang, Gu, Mueller & Yau 2005): uniform texture
//! synthesis on a global conformal parameterisation.
//!
//! Read → repair → global conformal map per component (`fieldtex_param::conformal`) →
//! optional quasi-isometric relaxation → one geometry image per component with its `τ`
//! map → multi-scale quilting with graph-cut seams and periodic margins
//! (`fieldtex_synth::quilt`) → images stacked into one texture → `model.glb`,
//! `preview.png`, `report.json` (+ `--keep` artefacts). Components of genus ≥ 2 (and
//! failed ones) fall back to a chart atlas (LSCM charts) synthesised the same way
//! without partners; the report says so.

use crate::outputs::{begin_command, begin_outputs, commit_outputs};
use crate::{Error, Progress, Report, Result};
use fieldtex_core::{Image, stream_seed};
use fieldtex_mesh::{CornerUvs, TriMesh};
use fieldtex_param::conformal::mass_spring::map_distortion;
use fieldtex_param::conformal::{
    ConformalComponent, ConformalMethod, GeometryImage, MassSpringOptions, global_conformal,
};
use fieldtex_synth::exemplar_scales::{resample, scale_levels};
use fieldtex_synth::{QuiltTarget, QuiltingOptions, quilt};
use serde::Serialize;
use serde_json::json;
use std::path::{Path, PathBuf};

/// Options of [`conformal`].
#[derive(Debug, Clone, Serialize)]
pub struct ConformalOptions {
    pub mesh: PathBuf,
    pub exemplar: PathBuf,
    /// Long side `C` of each geometry image in texels (paper: 1024). Default 1024.
    pub size: usize,
    /// Mass-spring relaxation before synthesis (§5). Default false.
    pub quasi_isometric: bool,
    /// Pick the exemplar level per patch from `τ` (§4.2). Default true.
    pub multiscale: bool,
    /// Number of exemplar levels. Default 6.
    pub levels: usize,
    /// Exemplar texels per texture texel where `τ` is at its reference (the 25th
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
struct Block {
    image: Image,
    /// Per global face it textures: canvas texel coordinates of its corners.
    faces: Vec<(u32, [[f64; 2]; 3])>,
    tau: Vec<f32>,
    label: String,
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
    if !(options.scale > 0.0 && options.scale <= 16.0) || options.levels == 0 || options.levels > 16
    {
        return Err(Error::bad_input(None, "--scale must be in (0, 16] and --levels in 1..=16"));
    }
    let mut report =
        Report::new("conformal", options.seed, serde_json::to_value(options).unwrap_or_default());
    begin_command();
    let loaded = report.time("read", || fieldtex_io::read_mesh(&options.mesh))?;
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
        .time("conformal-map", || global_conformal(&mesh, progress))
        .map_err(|e| Error::Internal(format!("conformal map: {e}")))?;
    report.warnings.extend(warnings);
    crate::outputs::check_cancelled(progress)?;
    // 2. Optional quasi-isometric relaxation.
    let mut relax_stats = Vec::new();
    if options.quasi_isometric {
        report.time("mass-spring", || {
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
    let images: Vec<Option<GeometryImage>> = report.time("geometry-images", || {
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
        Some(report.time("fallback-atlas", || {
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
    let tau_ref = weighted_quantile(&mut tau_w.clone(), 0.25).unwrap_or(1.0);
    let q95 = weighted_quantile(&mut tau_w.clone(), 0.95).unwrap_or(1.0);
    let q05 = weighted_quantile(&mut tau_w.clone(), 0.05).unwrap_or(1.0);
    let min_scale =
        ((options.patch_size as f64 + 8.0) / exemplar.width.min(exemplar.height) as f64).max(0.25);
    let (scales, level_names) = if options.multiscale {
        let lo = (q05 / tau_ref).clamp(min_scale, 1.0);
        let hi = (q95 / tau_ref).clamp(1.0, 6.0);
        // At least one level per factor 1.3 of the range (at most 12).
        let n = options.levels.max(((hi / lo).ln() / 1.3f64.ln()).ceil() as usize + 1).min(12);
        let s = scale_levels(lo, hi, n);
        (s.clone(), s)
    } else {
        (vec![1.0], vec![1.0])
    };
    let levels: Vec<Image> = report.time("exemplar-levels", || {
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
        seed: options.seed,
        ..Default::default()
    };
    let mut blocks: Vec<Block> = Vec::new();
    let mut quilt_stats = Vec::new();
    let t_quilt = std::time::Instant::now();
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
        let (image, st) = quilt(&levels, &target, &q, progress);
        quilt_stats.push(json!({"component": c.component, "stats": st}));
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
    report.timings_ms.push(("quilting".into(), t_quilt.elapsed().as_secs_f64() * 1e3));
    crate::outputs::check_cancelled(progress)?;
    // 6. One texture: blocks stacked vertically; per-corner UVs.
    let (texture, out_mesh) = report.time("assemble", || assemble(&mesh, &blocks));
    // 7. Outputs.
    report.time("write", || super::write_model(&stage, &out_mesh, Some(&texture)))?;
    let preview =
        report.time("preview", || super::render::preview(&out_mesh, Some(&texture), 800, None));
    fieldtex_io::write_png(&stage.join("preview.png"), &preview)?;
    // 8. Metrics.
    let comp_json: Vec<serde_json::Value> =
        comps.iter().zip(&images).map(|(c, img)| component_json(c, img.as_ref())).collect();
    report.metric("components", comp_json);
    report.metric("exemplar_levels", json!({"scales": level_names, "tau_reference": tau_ref, "tau_q05": q05, "tau_q95": q95, "multiscale": options.multiscale}));
    report.metric("quilting", quilt_stats);
    if options.quasi_isometric {
        report.metric("mass_spring", relax_stats);
    }
    let seams = report
        .time("eval-seams", || fieldtex_eval::seam_metrics::seam_metrics(&out_mesh, &texture));
    report.metric("seams", seams);
    let feature = report.time("eval-feature-size", || {
        fieldtex_eval::feature_size::feature_size_variation(&out_mesh, &texture, 24)
    });
    report.metric("feature_size", feature);
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
        report.time("keep", || write_keep(&stage, &mesh, &comps, &blocks))?;
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

/// Area-weighted quantile of `(value, weight)` pairs.
fn weighted_quantile(v: &mut [(f64, f64)], q: f64) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = v.iter().map(|x| x.1).sum();
    let mut acc = 0.0;
    for x in v.iter() {
        acc += x.1;
        if acc >= q * total {
            return Some(x.0);
        }
    }
    v.last().map(|x| x.0)
}

#[derive(Serialize)]
struct TexelDensity {
    /// Area-weighted coefficient of variation of texels per surface area (`τ²`).
    density_cv: f64,
    tau_min: f64,
    tau_median: f64,
    tau_max: f64,
}

fn texel_density(tau_w: &[(f64, f64)]) -> TexelDensity {
    let (mut s, mut s2, mut w) = (0.0, 0.0, 0.0);
    for &(t, a) in tau_w {
        let d = t * t;
        s += a * d;
        s2 += a * d * d;
        w += a;
    }
    let mean = s / w.max(f64::MIN_POSITIVE);
    let mut v = tau_w.to_vec();
    TexelDensity {
        density_cv: (s2 / w.max(f64::MIN_POSITIVE) - mean * mean).max(0.0).sqrt()
            / mean.max(f64::MIN_POSITIVE),
        tau_min: tau_w.iter().map(|x| x.0).fold(f64::INFINITY, f64::min),
        tau_median: weighted_quantile(&mut v, 0.5).unwrap_or(f64::NAN),
        tau_max: tau_w.iter().map(|x| x.0).fold(0.0, f64::max),
    }
}

fn component_json(c: &ConformalComponent, img: Option<&GeometryImage>) -> serde_json::Value {
    let mut v = json!({
        "component": c.component,
        "triangles": c.faces.len(),
        "genus": c.genus,
        "boundaries": c.boundaries,
        "method": c.method,
        "harmonic_1_forms": c.harmonic_forms,
        "zero_points": c.zero_points.len(),
        "zero_point_indices": c.zero_points.iter().map(|z| json!({"vertex": z.0, "index": z.1})).collect::<Vec<_>>(),
        "conjugate_residual": c.conjugate_residual,
        "note": c.note,
    });
    if c.has_uv() {
        let near = c.near_singularity.clone();
        let slit = c.slit.clone();
        let all = map_distortion(&c.local_mesh, c.faces.len(), &c.corner_uv, &move |f| slit[f]);
        let away = map_distortion(&c.local_mesh, c.faces.len(), &c.corner_uv, &move |f| near[f]);
        v["patches"] = json!(1);
        v["slit_vertices"] = json!(
            c.map
                .slit_vertices
                .iter()
                .map(|&l| c.local_to_global.get(l as usize).copied().unwrap_or(u32::MAX))
                .collect::<Vec<_>>()
        );
        v["lattice"] = json!({"a": c.lattice.a, "b": c.lattice.b});
        v["distortion"] = json!({"angle_mean_away_from_singularities": away.angle_mean, "angle_mean_non_slit": all.angle_mean, "log_area_std": all.log_area_std, "flipped": all.flipped});
        if let Some(img) = img {
            v["geometry_image"] = json!({"width": img.width, "height": img.height, "margin": img.margin, "period_x": img.period_x, "period_y": img.period_y});
        }
    } else {
        v["patches"] = json!("fallback atlas");
    }
    v
}

fn add_notes(report: &mut Report, comps: &[ConformalComponent], options: &ConformalOptions) {
    let n = &mut report.notes;
    n.push("Open surfaces: holes are capped with fans and the capped closed surface is parameterised (caps dropped afterwards) — a substitute for the paper's double cover; a disk's boundary and an annulus's two boundaries become the ends of the cylinder.".into());
    if comps.iter().any(|c| c.method == ConformalMethod::SlitCylinder) {
        n.push("Genus 0 (the paper is silent): two point slits (vertex stars) at extremal vertices; harmonic u = 0/1 on their rings and its conjugate from the annulus's harmonic 1-form give one cylinder image, periodic across one seam.".into());
    }
    if comps.iter().any(|c| !c.has_uv()) {
        n.push("Genus ≥ 2 (or failed) components: holomorphic basis, conjugates and zero points are computed (zero points reported), but critical-trajectory patches are NOT implemented; these components are textured through a chart atlas (LSCM charts) without boundary consistency across chart seams.".into());
        n.push("The genus ≥ 2 holomorphic form whose zero points are reported is the basis form with the most uniform |φ| — a substitute for the optimisation of Jin et al. 2004.".into());
    }
    n.push("τ per texel: barycentric interpolation of per-vertex τ (substitute for the paper's Gaussian RBF).".into());
    n.push("Quilting: random candidate subset per patch (not exhaustive), old seams not re-cut; colours compared in sRGB.".into());
    if options.quasi_isometric {
        n.push("Mass-spring (eq. 2) in a balanced spring form (rest length = 3-D length / mean conformal factor), stopped when the mean angle distortion would exceed 1.25.".into());
    }
}

/// The fallback texture block: an LSCM chart atlas of the given faces.
struct FallbackAtlas {
    width: usize,
    height: usize,
    tau: Vec<f32>,
    faces: Vec<(u32, [[f64; 2]; 3])>,
    face_lambda: Vec<f64>,
    face_area: Vec<f64>,
}

fn fallback_atlas(
    mesh: &TriMesh,
    faces: &[u32],
    size: usize,
    progress: &dyn Progress,
) -> Result<FallbackAtlas> {
    let sub = TriMesh::new(
        mesh.positions.clone(),
        faces.iter().map(|&f| mesh.triangles[f as usize]).collect(),
    );
    let opts =
        fieldtex_param::AtlasOptions { resolution: size as u32, gutter: 4, ..Default::default() };
    let atlas = fieldtex_param::build_atlas(&sub, &opts, progress)
        .map_err(|e| Error::Internal(format!("fallback atlas: {e}")))?;
    let uvs = atlas
        .mesh
        .uvs
        .as_ref()
        .ok_or_else(|| Error::Internal("fallback atlas has no UVs".into()))?;
    let map = fieldtex_param::build_texel_map(&atlas.mesh, size, size, 4)
        .map_err(|e| Error::Internal(format!("fallback texel map: {e}")))?;
    let s = size as f64;
    let mut out_faces = Vec::with_capacity(faces.len());
    let mut face_lambda = Vec::with_capacity(faces.len());
    let mut face_area = Vec::with_capacity(faces.len());
    for (k, &f) in faces.iter().enumerate() {
        let idx = uvs.indices[k];
        let c = idx.map(|i| {
            let uv = uvs.values[i as usize];
            [uv[0] * s, (1.0 - uv[1]) * s]
        });
        let p = atlas.mesh.triangle_positions(k);
        let a3 = 0.5
            * fieldtex_core::vec3::norm(fieldtex_core::vec3::cross(
                fieldtex_core::vec3::sub(p[1], p[0]),
                fieldtex_core::vec3::sub(p[2], p[0]),
            ));
        let at = 0.5
            * ((c[1][0] - c[0][0]) * (c[2][1] - c[0][1])
                - (c[1][1] - c[0][1]) * (c[2][0] - c[0][0]))
                .abs();
        face_lambda.push(if at > 0.0 { (a3 / at).sqrt() } else { f64::NAN });
        face_area.push(a3);
        out_faces.push((f, c));
    }
    let tau = (0..size * size)
        .map(|t| match map.entries[t] {
            Some(e) => {
                let l = face_lambda[e.triangle as usize];
                if l.is_finite() && l > 0.0 { (1.0 / l) as f32 } else { f32::NAN }
            }
            None => f32::NAN,
        })
        .collect();
    Ok(FallbackAtlas { width: size, height: size, tau, faces: out_faces, face_lambda, face_area })
}

/// Stacks the blocks into one texture (rows follow increasing canvas y, top to bottom)
/// and gives the mesh per-corner UVs (one UV per distinct corner position per vertex).
fn assemble(mesh: &TriMesh, blocks: &[Block]) -> (Image, TriMesh) {
    let width = blocks.iter().map(|b| b.image.width).max().unwrap_or(1);
    let height: usize = blocks.iter().map(|b| b.image.height).sum::<usize>().max(1);
    let mut tex = Image::new(width, height, [0.5, 0.5, 0.5, 1.0]);
    let mut corner: Vec<[[f64; 2]; 3]> = vec![[[0.0; 2]; 3]; mesh.n_triangles()];
    let mut y_off = 0usize;
    for b in blocks {
        for y in 0..b.image.height {
            for x in 0..b.image.width {
                tex.set(x, y + y_off, b.image.get(x, y));
            }
        }
        for &(f, c) in &b.faces {
            corner[f as usize] =
                c.map(|p| [p[0] / width as f64, 1.0 - (p[1] + y_off as f64) / height as f64]);
        }
        y_off += b.image.height;
    }
    // Deduplicate corner UVs per vertex.
    let mut values: Vec<[f64; 2]> = Vec::new();
    let mut per_vertex: Vec<Vec<u32>> = vec![Vec::new(); mesh.n_vertices()];
    let mut indices = Vec::with_capacity(mesh.n_triangles());
    for (f, t) in mesh.triangles.iter().enumerate() {
        let mut idx = [0u32; 3];
        for k in 0..3 {
            let uv = corner[f][k];
            let list = &mut per_vertex[t[k] as usize];
            let found = list.iter().copied().find(|&i| {
                let v = values[i as usize];
                (v[0] - uv[0]).abs() < 1e-9 && (v[1] - uv[1]).abs() < 1e-9
            });
            idx[k] = match found {
                Some(i) => i,
                None => {
                    values.push(uv);
                    list.push((values.len() - 1) as u32);
                    (values.len() - 1) as u32
                }
            };
        }
        indices.push(idx);
    }
    let mut out = TriMesh::new(mesh.positions.clone(), mesh.triangles.clone());
    out.uvs = Some(CornerUvs { values, indices });
    (tex, out)
}

fn write_keep(
    out_dir: &Path,
    mesh: &TriMesh,
    comps: &[ConformalComponent],
    blocks: &[Block],
) -> Result<()> {
    // patches.ply: per-vertex patch id (one patch per component here; fallback = −1).
    let mut patch = vec![-1.0f32; mesh.n_vertices()];
    for c in comps {
        if c.has_uv() {
            for &g in &c.local_to_global {
                patch[g as usize] = c.component as f32;
            }
        }
    }
    let plain = TriMesh::new(mesh.positions.clone(), mesh.triangles.clone());
    fieldtex_io::write_ply(&out_dir.join("patches.ply"), &plain, &[("patch", &patch)], true)?;
    // trajectories.obj: the cut curves = mesh edges where the corner UVs jump.
    let mut lines = Vec::new();
    for c in comps.iter().filter(|c| c.has_uv()) {
        let topo = fieldtex_mesh::Topology::build(
            c.local_mesh.n_vertices(),
            &c.local_mesh.triangles[..c.faces.len()],
        );
        for e in 0..topo.n_edges() {
            let fs = topo.edge_faces(e);
            if fs.len() != 2 {
                continue;
            }
            let [a, b] = topo.edges[e];
            let uv = |f: usize, v: u32| {
                let k = (0..3).find(|&k| c.local_mesh.triangles[f][k] == v).unwrap_or(0);
                c.corner_uv[f][k]
            };
            let (f0, f1) = (fs[0] as usize, fs[1] as usize);
            let d = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).abs() + (p[1] - q[1]).abs();
            if d(uv(f0, a), uv(f1, a)) > 1e-9 || d(uv(f0, b), uv(f1, b)) > 1e-9 {
                lines.push(vec![
                    c.local_mesh.positions[a as usize],
                    c.local_mesh.positions[b as usize],
                ]);
            }
        }
    }
    fieldtex_io::write_obj_polylines(&out_dir.join("trajectories.obj"), &lines)?;
    for b in blocks {
        fieldtex_io::write_png(&out_dir.join(format!("geometry_image_{}.png", b.label)), &b.image)?;
        let (tmin, tmax) = b
            .tau
            .iter()
            .filter(|t| t.is_finite())
            .fold((f32::INFINITY, 0.0f32), |(a, z), &t| (a.min(t), z.max(t)));
        let mut im = Image::new(b.image.width, b.image.height, [0.0, 0.0, 0.0, 1.0]);
        for (i, &t) in b.tau.iter().enumerate() {
            if t.is_finite() && tmax > tmin {
                let v = ((t.ln() - tmin.ln()) / (tmax.ln() - tmin.ln())).clamp(0.0, 1.0);
                im.pixels[i] = [v, v, v, 1.0];
            }
        }
        fieldtex_io::write_png(&out_dir.join(format!("tau_{}.png", b.label)), &im)?;
    }
    Ok(())
}
