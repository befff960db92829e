//! `fieldtex orient --mesh PATCH`: orientation-field guided synthesis on a curved,
//! disk-topology patch (Liu et al., paper D, §3 and §4 "curved patches").
//!
//! 1. **Patch.** The mesh is repaired (welding, orientation); with `--patch X,Y,Z,R`
//!    only the connected triangles whose centroids lie within `R` of `(X, Y, Z)` are
//!    kept (ears on the cut rim trimmed), so a disk can be cut out of any mesh. The
//!    patch must then be one component with one boundary loop and Euler
//!    characteristic 1 (a disk), else the run stops with a bad-input error (exit 2).
//! 2. **Parameterisation.** LSCM of the whole patch (Lévy et al. 2002, via
//!    `fieldtex-param`; planar projection if the solve fails). The UV bounding box's
//!    enclosing square, with a 2-texel margin, is the `size × size` texture: texel
//!    `(x, y)` (y down) shows `uv = ((x+½)/size, 1 − (y+½)/size)` as in
//!    [`fieldtex_param::TexelMap`]. LSCM keeps `u × v` along the surface normal, so
//!    image axes (x right, y down) see the surface as a viewer outside it does: the
//!    texture is not mirrored on the surface.
//! 3. **Field on the mesh.** A `[domain] kind = "mesh"` design is built on the patch
//!    as is (singularities by `position = [x, y, z]`); if its matrix cannot be factored
//!    the regularisation is raised (warning `field-regularized`). A **plane** design, and every
//!    `--preset`, is *mapped through the parameterisation*: its `W × H` rectangle
//!    (presets: 512 × 512) is laid on the UV bounding box (x → u, y down → v down, so
//!    the preset appears upright in `texture.png`; a non-square box stretches it), each
//!    singularity goes to the surface point of its UV position with its rotation α
//!    re-expressed in the design's frame of that triangle, and each stroke is densified
//!    in UV, lifted to the surface and split where it leaves the chart. Singularities
//!    outside the chart are dropped with a warning.
//! 4. **Texel field.** The per-triangle field directions are pulled back to image
//!    space (`P⁺ d`, `P` the triangle's image → surface Jacobian), raised to the N-th
//!    power (doubled angles for orientation fields), averaged at vertices, interpolated
//!    barycentrically at each texel and rooted again. This texel field is `field.npy`
//!    (H×W×2 float32 unit `(dx, dy)`, x right, y down) — the field pulled back to
//!    parameter space.
//! 5. **Jacobians.** Per texel `J = (1/s) [dᵀ P; d⊥ᵀ P]` (rows; texel offset → exemplar
//!    offset), `d` the field's unit direction on the surface, `d⊥ = ±n × d` (sign so
//!    that `det J > 0`), `s` the surface length per exemplar pixel = mean surface
//!    length per texel × `--scale` (× the exemplar's reduction factor). So the exemplar's x axis follows the field on the
//!    surface and the pattern has one size on the surface whatever the parameter-space
//!    stretch. Texels outside the chart copy the Jacobian and field of the nearest
//!    chart texel (8-connected breadth-first flood, deterministic order).
//! 6. **Synthesis** over an `ImageDomain` with those Jacobians (`fieldtex-synth`), then
//!    `texture.png`, `field.npy`, `model.glb` (patch, UVs, texture), `preview.png` (the
//!    textured patch rendered face-on with wedges as red discs, trisectors as blue
//!    triangles) and `report.json`.
//!
//! Metrics are measured in **parameter (texture) space** against the pulled-back field
//! (`texture.orientation_error` over the whole image, `chart_orientation_error` over
//! chart texels only); nothing is measured on the surface itself. Not implemented:
//! patches with several boundary loops or handles (no cutting), a field on the surface
//! of a closed mesh, holonomy of the reference frames (see `fieldtex-fields`).

mod patch_parameterization;
mod plane_design_mapping;
mod texel_jacobians;

use super::orient::{DesignedSingularity, FieldSource, OrientOptions, kind_index};
use crate::outputs::{begin_outputs, commit_outputs};
use crate::{Error, Progress, Report, Result};
use fieldtex_core::Image;
use fieldtex_core::vec3::{add, cross, normalize, sub};
use fieldtex_fields::design_file::DomainKind;
use fieldtex_fields::{DesignFile, FieldDesign, SingularityKind};
use fieldtex_mesh::TriMesh;
use fieldtex_param::TexelMap;
use fieldtex_synth::{ImageDomain, synthesize};
use patch_parameterization::{Patch, check_disk, cut_ball, parameterize};
use plane_design_mapping::{build_mesh_design, map_plane_design};
use serde::Serialize;
use std::path::Path;
use texel_jacobians::{jacobians, sample_texels};

/// Mean area stretch of the flattening above which a warning is given.
const AREA_DISTORTION_WARNING: f64 = 4.0;

/// A designed singularity on the patch.
#[derive(Debug, Clone, Serialize)]
struct PatchSingularity {
    kind: SingularityKind,
    position: [f64; 3],
    /// Texel coordinates in `texture.png`.
    texel: [f64; 2],
    /// Rotation α in the design frame of its triangle, degrees.
    angle_deg: f64,
}

/// Runs the curved-patch orient pipeline into `out_dir` (module docs).
pub(crate) fn orient_patch(
    out_dir: &Path,
    options: &OrientOptions,
    mesh_path: &Path,
    progress: &dyn Progress,
) -> Result<Report> {
    let n = options.size;
    let mut report =
        Report::new("orient", options.seed, serde_json::to_value(options).unwrap_or_default());
    let (fitted, per_texel) = options.read_exemplar(&mut report, progress)?;
    let exemplar = fitted.image;
    let loaded = report.stage(progress, "read_mesh", || fieldtex_io::read_mesh(mesh_path))?;
    report.warnings.extend(loaded.warnings.iter().cloned());
    let repaired = fieldtex_mesh::repair(&loaded.mesh, &fieldtex_mesh::RepairOptions::default());
    report.warnings.extend(repaired.warnings.iter().cloned());
    let mut mesh = repaired.mesh;
    mesh.uvs = None;
    mesh.vertex_colors = None;
    if let Some(cut) = options.patch {
        mesh = report.stage(progress, "cut", || cut_ball(&mesh, cut, mesh_path))?;
    }
    check_disk(&mesh, mesh_path, options.patch.is_some())?;
    report.input = serde_json::json!({
        "exemplar": options.exemplar.display().to_string(),
        "exemplar_size": [exemplar.width, exemplar.height],
        "mesh": mesh_path.display().to_string(),
        "mesh_vertices": mesh.n_vertices(),
        "mesh_triangles": mesh.n_triangles(),
    });
    let out = begin_outputs(
        out_dir,
        &["texture.png", "field.npy", "model.glb", "preview.png", "report.json"],
    )?;
    let stage = out.staging();
    let mut param_warnings = Vec::new();
    let patch =
        report.stage(progress, "parameterize", || parameterize(mesh, n, &mut param_warnings))?;
    report.warnings.extend(param_warnings);
    if let Some(uvs) = &patch.mesh.uvs
        && let Ok(stats) = fieldtex_param::parameterization_distortion(&patch.mesh, uvs)
    {
        if stats.area_distortion > AREA_DISTORTION_WARNING {
            report.warnings.push(fieldtex_core::Warning::new(
                "patch-area-distortion",
                format!(
                    "the flattened patch stretches area by ×{:.1} on average, so texels cover \
                     very different surface areas and the texture is blurred or aliased where \
                     they do; a smaller or flatter patch (--patch) flattens better",
                    stats.area_distortion
                ),
            ));
        }
        report.metric("parameterization", stats);
    }
    let map = report
        .stage(progress, "texel_map", || fieldtex_param::build_texel_map(&patch.mesh, n, n, 0))
        .map_err(|e| Error::internal("texel map", e))?;
    let (field, designed) = texel_field(options, &patch, &map, &mut report)?;
    let (jac, field, inside) =
        report.stage(progress, "jacobians", || jacobians(&patch, &map, &field, per_texel));
    let n_inside = inside.iter().filter(|&&b| b).count();
    if n_inside == 0 {
        return Err(Error::Internal("the patch covers no texel of the texture".into()));
    }
    report.metric("chart_texels", n_inside);
    report.metric("chart_coverage", n_inside as f64 / (n * n) as f64);
    let aopts = fieldtex_synth::AnalysisOptions::default();
    let (analysis, cached) = report
        .stage(progress, "analysis", || {
            super::synthesis::AnalysisCache::process().analysis(&exemplar, &aopts, progress)
        })
        .map_err(|e| Error::classify(&e, Some(&options.exemplar), "exemplar"))?;
    report.metric("analysis_cached", cached);
    let domain = ImageDomain::new(n, n, jac).map_err(|e| Error::internal("synthesis domain", e))?;
    let sopts = options.synthesis_options();
    let texture = report
        .stage(progress, "synthesis", || synthesize(&analysis, &domain, &sopts, progress))
        .map_err(|e| Error::internal("synthesis", e))?
        .colors;
    let flat: Vec<f32> = field.iter().flat_map(|v| [v[0], v[1]]).collect();
    fieldtex_io::write_png(&stage.join("texture.png"), &texture)?;
    fieldtex_io::write_npy_f32(&stage.join("field.npy"), &[n, n, 2], &flat)?;
    report.stage(progress, "model", || super::write_model(stage, &patch.mesh, Some(&texture)))?;
    let marks: Vec<DesignedSingularity> = designed
        .iter()
        .map(|s| DesignedSingularity { x: s.texel[0], y: s.texel[1], index: kind_index(s.kind) })
        .collect();
    report.metric("designed_singularities", &marks);
    report.metric("designed_singularities_on_patch", &designed);
    if options.metrics {
        let pts: Vec<[f64; 2]> = designed.iter().map(|s| s.texel).collect();
        let (metrics, exemplar_angle) = super::orient::texture_metrics(
            &mut report,
            &texture,
            &exemplar,
            &flat,
            None,
            &pts,
            options,
            progress,
        )?;
        if let Some(e) = chart_orientation_error(&texture, &field, &inside, exemplar_angle) {
            report.metric("chart_orientation_error", e);
        }
        report.metric("texture", &metrics);
        report.notes.push(
            "curved patch: orientation error, singularities and phase defects are measured in \
             parameter (texture) space against the field pulled back to it (field.npy); \
             chart_orientation_error counts chart texels only; nothing is measured on the surface"
                .into(),
        );
    } else {
        report.notes.push("image metrics skipped (--no-metrics)".into());
    }
    let preview = report.stage(progress, "preview", || preview(&patch.mesh, &texture, &designed));
    fieldtex_io::write_png(&stage.join("preview.png"), &preview)?;
    commit_outputs(out, &mut report)?;
    Ok(report)
}

/// The texel field (`n × n` unit image-space directions, chart texels meaningful) and
/// the designed singularities.
fn texel_field(
    options: &OrientOptions,
    patch: &Patch,
    map: &TexelMap,
    report: &mut Report,
) -> Result<(Vec<[f32; 2]>, Vec<PatchSingularity>)> {
    let n = options.size;
    let (file, src) = match &options.source {
        FieldSource::Field(p) => {
            let extra = ", the texel field in the patch's parameter space";
            return Ok((super::orient::read_field_npy(p, n, extra, "texel")?, Vec::new()));
        }
        FieldSource::Design(p) => {
            let text = super::orient::read_design_text(p)?;
            let d =
                DesignFile::from_toml_str(&text).map_err(|e| Error::classify(&e, Some(p), ""))?;
            (d, Some(p.as_path()))
        }
        FieldSource::Preset(name) => {
            let r = fieldtex_fields::presets::REFERENCE_SIZE;
            let d = fieldtex_fields::presets::preset(name, r, r, options.grid)
                .map_err(|e| Error::classify(&e, None, &format!("--preset {name}")))?;
            (d, None)
        }
    };
    let bad = |e: fieldtex_fields::FieldsError| Error::classify(&e, src, "");
    let mut designed = Vec::new();
    let mut mapping_warnings = Vec::new();
    let fd = report.time("field_factor", || -> Result<FieldDesign> {
        let mesh_design = file.domain.kind == DomainKind::Mesh;
        let mut fd = build_mesh_design(&file, &patch.mesh, mesh_design, &mut mapping_warnings)
            .map_err(bad)?;
        if fd.dec().n_faces() != patch.mesh.n_triangles() {
            return Err(Error::Internal("the field design changed the patch's triangles".into()));
        }
        if !mesh_design {
            map_plane_design(&file, patch, map, &mut fd, &mut mapping_warnings).map_err(bad)?;
        }
        Ok(fd)
    })?;
    report.warnings.extend(mapping_warnings);
    let mut fd = fd;
    let solved = report
        .time("field_solve", || fd.solve())
        .map_err(|e| Error::classify(&e, src, "field solve"))?;
    report.metric("field_residual", solved.residual);
    report.warnings.extend(fd.warnings().iter().cloned());
    for (_, s) in fd.singularities() {
        if let Some((f, b)) = fd.locate(s.position) {
            designed.push(PatchSingularity {
                kind: s.kind,
                position: s.position,
                texel: patch.image_point(f, b),
                angle_deg: s.angle.to_degrees(),
            });
        }
    }
    let dirs = fieldtex_fields::orientation_field::face_directions(&fd, &solved);
    let field = report.time("field_sample", || sample_texels(patch, map, &dirs, fd.symmetry()));
    Ok((field, designed))
}

/// Orientation error of the texture against `field` over chart texels only.
#[derive(Debug, Clone, Serialize)]
struct ChartOrientationError {
    /// Coherence-weighted mean absolute angle difference, degrees.
    mean_error_deg: f64,
    unweighted_mean_error_deg: f64,
    evaluated_texels: usize,
}

fn chart_orientation_error(
    texture: &Image,
    field: &[[f32; 2]],
    inside: &[bool],
    exemplar_angle_deg: f64,
) -> Option<ChartOrientationError> {
    let buf = fieldtex_eval::rgb_buffer(texture);
    let view = fieldtex_eval::ImageView::new(&buf, texture.width, texture.height, 3).ok()?;
    let opts = fieldtex_eval::OrientationOptions::default();
    let border = opts.default_border();
    let om = fieldtex_eval::image_orientation(&view, &opts).ok()?;
    let (w, h) = (texture.width, texture.height);
    let (mut s, mut c_sum, mut u, mut count) = (0.0, 0.0, 0.0, 0usize);
    for y in border..h.saturating_sub(border) {
        for x in border..w.saturating_sub(border) {
            let i = y * w + x;
            if !inside[i] {
                continue;
            }
            let expected =
                (field[i][1] as f64).atan2(field[i][0] as f64) + exemplar_angle_deg.to_radians();
            let d = (om.angle[i] as f64 - expected).rem_euclid(std::f64::consts::PI);
            let e = d.min(std::f64::consts::PI - d);
            let c = om.coherence[i] as f64;
            s += c * e;
            c_sum += c;
            u += e;
            count += 1;
        }
    }
    (count > 0 && c_sum > 0.0).then(|| ChartOrientationError {
        mean_error_deg: (s / c_sum).to_degrees(),
        unweighted_mean_error_deg: (u / count as f64).to_degrees(),
        evaluated_texels: count,
    })
}

/// The textured patch seen face-on (along its mean normal, a little from the side),
/// wedges as red discs and trisectors as blue triangles.
fn preview(mesh: &TriMesh, texture: &Image, designed: &[PatchSingularity]) -> Image {
    use fieldtex_render::{MarkerShape, Markers, Overlay, RenderOptions, Scene, render};
    let mut nsum = [0.0; 3];
    for f in 0..mesh.n_triangles() {
        let p = mesh.triangle_positions(f);
        nsum = add(nsum, cross(sub(p[1], p[0]), sub(p[2], p[0])));
    }
    let area2: f64 = (0..mesh.n_triangles())
        .map(|f| {
            let p = mesh.triangle_positions(f);
            fieldtex_core::vec3::norm(cross(sub(p[1], p[0]), sub(p[2], p[0])))
        })
        .sum();
    // Strongly curved patches (mean normal short) get the renderer's default view.
    let (azimuth, elevation) = match normalize(nsum) {
        Some(nrm) if fieldtex_core::vec3::norm(nsum) > 0.35 * area2 => (
            nrm[0].atan2(nrm[2]).to_degrees() + 15.0,
            (nrm[1].clamp(-1.0, 1.0).asin().to_degrees() + 15.0).clamp(-80.0, 80.0),
        ),
        _ => RenderOptions::default().view,
    };
    let mut scene = Scene::new(mesh).with_texture(texture);
    for (kind, shape, color) in [
        (SingularityKind::Wedge, MarkerShape::Disc, [0.9, 0.15, 0.1, 1.0]),
        (SingularityKind::Trisector, MarkerShape::Triangle, [0.1, 0.35, 0.95, 1.0]),
    ] {
        let pos: Vec<[f64; 3]> =
            designed.iter().filter(|s| s.kind == kind).map(|s| s.position).collect();
        if !pos.is_empty() {
            scene = scene.with_overlay(Overlay::Markers(
                Markers::new(pos).with_shape(shape).with_color(color),
            ));
        }
    }
    let others: Vec<[f64; 3]> = designed
        .iter()
        .filter(|s| !matches!(s.kind, SingularityKind::Wedge | SingularityKind::Trisector))
        .map(|s| s.position)
        .collect();
    if !others.is_empty() {
        scene = scene.with_overlay(Overlay::Markers(
            Markers::new(others).with_shape(MarkerShape::Square).with_color([0.95, 0.8, 0.1, 1.0]),
        ));
    }
    render(&scene, &RenderOptions { size: 800, view: (azimuth, elevation), ..Default::default() })
}
