//! `fieldtex orient --mesh PATCH`: orientation-field guided synthesis on a curved,
//! disk-topology patch (Liu et al., paper D, §3 and §4 "curved patches").
//!
//! 1. **Patch.** The mesh is repaired (welding, orientation) and must then be one
//!    component with one boundary loop and Euler characteristic 1 (a disk), else the
//!    run stops with a bad-input error (exit 2).
//! 2. **Parameterisation.** LSCM of the whole patch (Lévy et al. 2002, via
//!    `fieldtex-param`; planar projection if the solve fails). The UV bounding box's
//!    enclosing square, with a 2-texel margin, is the `size × size` texture: texel
//!    `(x, y)` (y down) shows `uv = ((x+½)/size, 1 − (y+½)/size)` as in
//!    [`fieldtex_param::TexelMap`]. LSCM keeps `u × v` along the surface normal, so
//!    image axes (x right, y down) see the surface as a viewer outside it does: the
//!    texture is not mirrored on the surface.
//! 3. **Field on the mesh.** A `[domain] kind = "mesh"` design is built on the patch
//!    as is (singularities by `position = [x, y, z]`). A **plane** design, and every
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
//!    length per texel / `--scale`. So the exemplar's x axis follows the field on the
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

use super::orient::{DesignedSingularity, FieldSource, OrientOptions, kind_index};
use crate::outputs::{prepare_out_dir, write_report};
use crate::pipelines::eval::image_metrics;
use crate::{Error, Progress, Report, Result};
use fieldtex_core::Image;
use fieldtex_core::vec3::{add, cross, dot, norm, normalize, scale, sub};
use fieldtex_fields::design_file::{DomainKind, DomainSpec};
use fieldtex_fields::{DesignFile, FieldDesign, Singularity, SingularityKind, Stroke, Symmetry};
use fieldtex_mesh::{CornerUvs, TriMesh};
use fieldtex_param::TexelMap;
use fieldtex_param::chart_topology::ChartMesh;
use fieldtex_param::face_graph::FaceGraph;
use fieldtex_synth::{ImageDomain, SynthesisOptions, synthesize};
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

/// Texels of margin around the UV bounding box.
const MARGIN_TEXELS: f64 = 2.0;

/// The parameterised patch: the mesh with texture UVs and, per triangle, its corners
/// in image coordinates (texels, x right, y down) and the image → surface Jacobian.
struct Patch {
    mesh: TriMesh,
    /// `#F` corners in image coordinates.
    image_corners: Vec<[[f64; 2]; 3]>,
    /// `#F` Jacobian columns `(∂p/∂x, ∂p/∂y)`; `None` for degenerate triangles.
    jacobian: Vec<Option<[[f64; 3]; 2]>>,
    /// `#F` unit normals.
    normals: Vec<[f64; 3]>,
    /// UV bounding box in image coordinates: `[x0, y0, x1, y1]`.
    image_box: [f64; 4],
    /// Mean surface length per texel over the chart.
    length_per_texel: f64,
}

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
    let exemplar = report.time("read", || fieldtex_io::read_image(&options.exemplar))?;
    let loaded = report.time("read_mesh", || fieldtex_io::read_mesh(mesh_path))?;
    report.warnings.extend(loaded.warnings.iter().cloned());
    let repaired = fieldtex_mesh::repair(&loaded.mesh, &fieldtex_mesh::RepairOptions::default());
    report.warnings.extend(repaired.warnings.iter().cloned());
    let mut mesh = repaired.mesh;
    mesh.uvs = None;
    mesh.vertex_colors = None;
    check_disk(&mesh, mesh_path)?;
    report.input = serde_json::json!({
        "exemplar": options.exemplar.display().to_string(),
        "exemplar_size": [exemplar.width, exemplar.height],
        "mesh": mesh_path.display().to_string(),
        "mesh_vertices": mesh.n_vertices(),
        "mesh_triangles": mesh.n_triangles(),
    });
    prepare_out_dir(out_dir)?;
    let mut param_warnings = Vec::new();
    let patch = report.time("parameterize", || parameterize(mesh, n, &mut param_warnings))?;
    report.warnings.extend(param_warnings);
    if let Some(uvs) = &patch.mesh.uvs
        && let Ok(stats) = fieldtex_param::parameterization_distortion(&patch.mesh, uvs)
    {
        report.metric("parameterization", stats);
    }
    let map = report
        .time("texel_map", || fieldtex_param::build_texel_map(&patch.mesh, n, n, 0))
        .map_err(|e| Error::Internal(format!("texel map: {e}")))?;
    let (field, designed) = texel_field(options, &patch, &map, &mut report)?;
    let (jac, field, inside) =
        report.time("jacobians", || jacobians(&patch, &map, &field, options));
    let n_inside = inside.iter().filter(|&&b| b).count();
    if n_inside == 0 {
        return Err(Error::Internal("the patch covers no texel of the texture".into()));
    }
    report.metric("chart_texels", n_inside);
    report.metric("chart_coverage", n_inside as f64 / (n * n) as f64);
    let aopts = fieldtex_synth::AnalysisOptions::default();
    let (analysis, cached) = report
        .time("analysis", || super::synthesis::cached_analysis(&exemplar, &aopts, progress))
        .map_err(|e| Error::bad_input(Some(&options.exemplar), format!("exemplar: {e}")))?;
    report.metric("analysis_cached", cached);
    let domain = ImageDomain::new(n, n, jac)
        .map_err(|e| Error::Internal(format!("synthesis domain: {e}")))?;
    let sopts =
        SynthesisOptions { seed: options.seed, rosy_fix: options.rosy_fix, ..Default::default() };
    let texture = report
        .time("synthesis", || synthesize(&analysis, &domain, &sopts, progress))
        .map_err(|e| Error::Internal(format!("synthesis: {e}")))?
        .colors;
    let flat: Vec<f32> = field.iter().flat_map(|v| [v[0], v[1]]).collect();
    fieldtex_io::write_png(&out_dir.join("texture.png"), &texture)?;
    fieldtex_io::write_npy_f32(&out_dir.join("field.npy"), &[n, n, 2], &flat)?;
    report.time("model", || super::write_model(out_dir, &patch.mesh, Some(&texture)))?;
    let metrics = report
        .time("metrics", || image_metrics(&texture, &exemplar, Some(&flat), None, options.seed))
        .map_err(|e| Error::Internal(format!("metrics: {e}")))?;
    let pts: Vec<[f64; 2]> = designed.iter().map(|s| s.texel).collect();
    if let Some(pd) = &metrics.phase_defects {
        let near = fieldtex_eval::count_defects_near(&pd.defects, &pts, 3.0 * pd.period_px);
        report.metric("phase_defects_near_singularities", near);
    }
    if let Some(e) = chart_orientation_error(&texture, &field, &inside) {
        report.metric("chart_orientation_error", e);
    }
    let marks: Vec<DesignedSingularity> = designed
        .iter()
        .map(|s| DesignedSingularity { x: s.texel[0], y: s.texel[1], index: kind_index(s.kind) })
        .collect();
    report.metric("designed_singularities", &marks);
    report.metric("designed_singularities_on_patch", &designed);
    report.metric("texture", &metrics);
    report.notes.push(
        "curved patch: orientation error, singularities and phase defects are measured in \
         parameter (texture) space against the field pulled back to it (field.npy); \
         chart_orientation_error counts chart texels only; nothing is measured on the surface"
            .into(),
    );
    let preview = report.time("preview", || preview(&patch.mesh, &texture, &designed));
    fieldtex_io::write_png(&out_dir.join("preview.png"), &preview)?;
    write_report(out_dir, &report)?;
    Ok(report)
}

/// Bad input unless `mesh` is one disk: one component, one boundary loop, Euler
/// characteristic 1, no non-manifold edge.
fn check_disk(mesh: &TriMesh, path: &Path) -> Result<()> {
    if mesh.triangles.is_empty() {
        return Err(Error::bad_input(Some(path), "no usable triangle is left after repair"));
    }
    let topo = fieldtex_mesh::Topology::build(mesh.n_vertices(), &mesh.triangles);
    let (_, components) = topo.face_components(&mesh.triangles);
    let loops = topo.boundary_loops(&mesh.triangles).len();
    let nonmanifold = (0..topo.n_edges()).filter(|&e| topo.is_nonmanifold_edge(e)).count();
    let mut used = vec![false; mesh.n_vertices()];
    for t in &mesh.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let nv = used.iter().filter(|&&u| u).count() as i64;
    let euler = nv - topo.n_edges() as i64 + mesh.n_triangles() as i64;
    if components != 1 || loops != 1 || euler != 1 || nonmanifold > 0 {
        return Err(Error::bad_input(
            Some(path),
            format!(
                "--mesh needs a disk-topology patch (1 component, 1 boundary loop, Euler \
                 characteristic 1, manifold); this mesh has {components} component(s), {loops} \
                 boundary loop(s), Euler characteristic {euler} and {nonmanifold} non-manifold \
                 edge(s). Cut a disk-like region out of it (closed meshes and meshes with holes \
                 cannot be flattened into one chart)"
            ),
        ));
    }
    Ok(())
}

/// LSCM of the whole patch, scaled into the `n × n` texture (module docs).
fn parameterize(
    mut mesh: TriMesh,
    n: usize,
    warnings: &mut Vec<fieldtex_core::Warning>,
) -> Result<Patch> {
    let nf = mesh.n_triangles();
    let graph = FaceGraph::build(&mesh);
    let chart = ChartMesh::build((0..nf as u32).collect(), &graph, &mesh.triangles);
    let uv = match fieldtex_param::lscm::lscm(&chart, &mesh, &graph) {
        Ok(uv) if uv.iter().all(|p| p[0].is_finite() && p[1].is_finite()) => uv,
        other => {
            let why = other.err().map(|e| e.to_string()).unwrap_or_else(|| "non-finite UVs".into());
            warnings.push(fieldtex_core::Warning::new(
                "lscm-failed",
                format!("LSCM failed ({why}); the patch is projected onto its mean plane instead"),
            ));
            fieldtex_param::lscm::planar_projection(&chart, &mesh, &graph)
        }
    };
    let defects = fieldtex_param::lscm::flattening_defects(&chart, &uv, &graph);
    if !defects.is_clean() {
        warnings.push(fieldtex_core::Warning::new(
            "patch-flattening-defects",
            format!(
                "the flattened patch has {} flipped or collapsed triangle(s){}; the texture may \
                 overlap itself there",
                defects.flipped,
                if defects.boundary_crossing { " and its boundary crosses itself" } else { "" }
            ),
        ));
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &uv {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let side = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    if !(side > 0.0 && side.is_finite()) {
        return Err(Error::bad_input(None, "the patch flattens to a point or a line"));
    }
    let nf64 = n as f64;
    // Texture uv = (uv − centre) / span + ½, span leaving MARGIN_TEXELS on each side.
    let span = side * nf64 / (nf64 - 2.0 * MARGIN_TEXELS);
    let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    let values: Vec<[f64; 2]> = uv
        .iter()
        .map(|p| [(p[0] - centre[0]) / span + 0.5, (p[1] - centre[1]) / span + 0.5])
        .collect();
    let to_image = |t: [f64; 2]| [t[0] * nf64, (1.0 - t[1]) * nf64];
    let (bl, tr) = (
        to_image([(lo[0] - centre[0]) / span + 0.5, (lo[1] - centre[1]) / span + 0.5]),
        to_image([(hi[0] - centre[0]) / span + 0.5, (hi[1] - centre[1]) / span + 0.5]),
    );
    let image_box = [bl[0], tr[1], tr[0], bl[1]];
    let mut image_corners = Vec::with_capacity(nf);
    let mut jacobian = Vec::with_capacity(nf);
    let mut normals = Vec::with_capacity(nf);
    let (mut area3, mut area_img) = (0.0, 0.0);
    for f in 0..nf {
        let q: [[f64; 2]; 3] =
            std::array::from_fn(|k| to_image(values[chart.corners[f][k] as usize]));
        let p = mesh.triangle_positions(f);
        let (e1, e2) = (sub(p[1], p[0]), sub(p[2], p[0]));
        let c = cross(e1, e2);
        let a3 = 0.5 * norm(c);
        normals.push(normalize(c).unwrap_or([0.0, 0.0, 1.0]));
        let (a, b) =
            ([q[1][0] - q[0][0], q[1][1] - q[0][1]], [q[2][0] - q[0][0], q[2][1] - q[0][1]]);
        let det = a[0] * b[1] - a[1] * b[0];
        image_corners.push(q);
        if !(det.abs() > 1e-12 && a3 > 0.0) {
            jacobian.push(None);
            continue;
        }
        area3 += a3;
        area_img += 0.5 * det.abs();
        // [∂p/∂x ∂p/∂y] = [e1 e2] · inv([a b]).
        let (i00, i01, i10, i11) = (b[1] / det, -b[0] / det, -a[1] / det, a[0] / det);
        let px = add(scale(e1, i00), scale(e2, i10));
        let py = add(scale(e1, i01), scale(e2, i11));
        jacobian.push(Some([px, py]));
    }
    if !(area3 > 0.0 && area_img > 0.0) {
        return Err(Error::bad_input(None, "the patch has no triangle of positive area"));
    }
    mesh.uvs = Some(CornerUvs { values, indices: chart.corners.clone() });
    Ok(Patch {
        mesh,
        image_corners,
        jacobian,
        normals,
        image_box,
        length_per_texel: (area3 / area_img).sqrt(),
    })
}

impl Patch {
    /// Triangle and barycentric coordinates of image point `q` (texels), starting from
    /// the triangle the texel map shows there; `None` outside the chart.
    fn locate_image(&self, map: &TexelMap, q: [f64; 2]) -> Option<(usize, [f64; 3])> {
        let (x, y) = (q[0].floor(), q[1].floor());
        if !(x >= 0.0 && y >= 0.0 && (x as usize) < map.width && (y as usize) < map.height) {
            return None;
        }
        let i = y as usize * map.width + x as usize;
        let e = map.entries[i].filter(|_| map.is_covered(i))?;
        let f = e.triangle as usize;
        let t = self.image_corners[f];
        let (a, b, p) = (
            [t[1][0] - t[0][0], t[1][1] - t[0][1]],
            [t[2][0] - t[0][0], t[2][1] - t[0][1]],
            [q[0] - t[0][0], q[1] - t[0][1]],
        );
        let det = a[0] * b[1] - a[1] * b[0];
        if det.abs() < 1e-12 {
            return Some((f, e.bary.map(f64::from)));
        }
        // Barycentric coordinates of q, clamped into the triangle (q may lie just
        // outside the triangle nearest its texel's centre).
        let v = ((p[0] * b[1] - p[1] * b[0]) / det).max(0.0);
        let w = ((a[0] * p[1] - a[1] * p[0]) / det).max(0.0);
        let (v, w) = if v + w > 1.0 { (v / (v + w), w / (v + w)) } else { (v, w) };
        Some((f, [1.0 - v - w, v, w]))
    }

    fn surface_point(&self, f: usize, b: [f64; 3]) -> [f64; 3] {
        let p = self.mesh.triangle_positions(f);
        add(add(scale(p[0], b[0]), scale(p[1], b[1])), scale(p[2], b[2]))
    }

    fn image_point(&self, f: usize, b: [f64; 3]) -> [f64; 2] {
        let t = self.image_corners[f];
        std::array::from_fn(|k| b[0] * t[0][k] + b[1] * t[1][k] + b[2] * t[2][k])
    }
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
            let (shape, data) = fieldtex_io::read_npy_f32(p)?;
            if shape != [n, n, 2] {
                return Err(Error::bad_input(
                    Some(p),
                    format!(
                        "the field has shape {shape:?}; --size {n} needs [{n}, {n}, 2] (H×W×2 \
                         float32, the texel field in the patch's parameter space)"
                    ),
                ));
            }
            let field: Vec<[f32; 2]> = data.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
            if let Some(i) = field.iter().position(|v| !(v[0].is_finite() && v[1].is_finite())) {
                return Err(Error::bad_input(Some(p), format!("non-finite vector at texel {i}")));
            }
            return Ok((field, Vec::new()));
        }
        FieldSource::Design(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| {
                Error::bad_input(Some(p), format!("cannot read the design file: {e}"))
            })?;
            let d = DesignFile::from_toml_str(&text)
                .map_err(|e| Error::bad_input(Some(p), e.to_string()))?;
            (d, Some(p.as_path()))
        }
        FieldSource::Preset(name) => {
            let r = fieldtex_fields::presets::REFERENCE_SIZE;
            let d = fieldtex_fields::presets::preset(name, r, r, options.grid)
                .map_err(|e| Error::bad_input(None, format!("--preset {name}: {e}")))?;
            (d, None)
        }
    };
    let bad = |e: fieldtex_fields::FieldsError| Error::bad_input(src, e.to_string());
    let mut designed = Vec::new();
    let mut mapping_warnings = Vec::new();
    let fd = report.time("field_factor", || -> Result<FieldDesign> {
        if file.domain.kind == DomainKind::Mesh {
            return file.build(Some(patch.mesh.clone())).map_err(bad);
        }
        let mut base = file.clone();
        base.domain = DomainSpec { kind: DomainKind::Mesh, width: None, height: None, grid: 128 };
        base.singularities.clear();
        base.strokes.clear();
        let mut fd = base.build(Some(patch.mesh.clone())).map_err(bad)?;
        map_plane_design(&file, patch, map, &mut fd, &mut mapping_warnings).map_err(bad)?;
        Ok(fd)
    })?;
    report.warnings.extend(mapping_warnings);
    if fd.dec().n_faces() != patch.mesh.n_triangles() {
        return Err(Error::Internal("field design changed the patch's triangles".into()));
    }
    let mut fd = fd;
    let solved = report
        .time("field_solve", || fd.solve())
        .map_err(|e| Error::Internal(format!("field solve: {e}")))?;
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

/// Lays the plane design `file` on the UV bounding box and adds its singularities and
/// strokes to the mesh design `fd` (module docs, step 3).
fn map_plane_design(
    file: &DesignFile,
    patch: &Patch,
    map: &TexelMap,
    fd: &mut FieldDesign,
    warnings: &mut Vec<fieldtex_core::Warning>,
) -> std::result::Result<(), fieldtex_fields::FieldsError> {
    let (w, h) = (file.domain.width.unwrap_or(1.0), file.domain.height.unwrap_or(1.0));
    let [x0, y0, x1, y1] = patch.image_box;
    let (kx, ky) = ((x1 - x0) / w, (y1 - y0) / h);
    let to_image = |x: f64, y: f64| [x0 + x * kx, y0 + y * ky];
    for (i, s) in file.singularity_list()?.into_iter().enumerate() {
        let Some((f, b)) = patch.locate_image(map, to_image(s.position[0], s.position[1])) else {
            warnings.push(fieldtex_core::Warning::new(
                "singularity-outside-patch",
                format!(
                    "singularity {i} ({}) at ({:.1}, {:.1}) of the {w}×{h} design falls outside \
                     the flattened patch; it is left out",
                    s.kind.name(),
                    s.position[0],
                    s.position[1]
                ),
            ));
            continue;
        };
        let p = patch.surface_point(f, b);
        let g = fd.locate(p).map_or(f, |(g, _)| g);
        let angle = match patch.jacobian[g] {
            Some([px, py]) => {
                let (e1, e2) = fd.frames()[g];
                // Plane axes on the surface, in the frame of the singularity's triangle.
                let (ax, ay) = (scale(px, kx), scale(py, ky));
                let m = [[dot(e1, ax), dot(e1, ay)], [dot(e2, ax), dot(e2, ay)]];
                let phi = m[1][0].atan2(m[0][0]);
                let reflect = m[0][0] * m[1][1] - m[0][1] * m[1][0] < 0.0;
                angle_in_frame(s.kind, s.angle, phi, reflect)
            }
            None => s.angle,
        };
        fd.add_singularity(Singularity { position: p, angle, ..s })?;
    }
    // Strokes: samples every 1/256 of the box's longer side, lifted to the surface.
    let step = w.max(h) / 256.0;
    for (i, st) in file.stroke_list().into_iter().enumerate() {
        let mut pieces: Vec<Vec<[f64; 3]>> = vec![Vec::new()];
        let mut push = |q: [f64; 3]| match patch.locate_image(map, to_image(q[0], q[1])) {
            Some((f, b)) => pieces.last_mut().expect("non-empty").push(patch.surface_point(f, b)),
            None => {
                if !pieces.last().expect("non-empty").is_empty() {
                    pieces.push(Vec::new());
                }
            }
        };
        for seg in st.points.windows(2) {
            let d = sub(seg[1], seg[0]);
            let k = ((norm(d) / step).ceil() as usize).clamp(1, 100_000);
            for j in 0..k {
                push(add(seg[0], scale(d, j as f64 / k as f64)));
            }
        }
        if let Some(last) = st.points.last() {
            push(*last);
        }
        let mut added = 0;
        for piece in pieces.into_iter().filter(|p| p.len() >= 2) {
            match fd.add_stroke(Stroke { points: piece, weight: st.weight }) {
                Ok(_) => added += 1,
                Err(fieldtex_fields::FieldsError::StrokeMissesDomain { .. }) => {}
                Err(e) => return Err(e),
            }
        }
        if added == 0 {
            warnings.push(fieldtex_core::Warning::new(
                "stroke-outside-patch",
                format!(
                    "stroke {i} of the design lies outside the flattened patch; it is left out"
                ),
            ));
        }
    }
    Ok(())
}

/// Rotation α of a singularity re-expressed in a frame where the design plane's x axis
/// has angle `phi` (and the plane is mirrored when `reflect`): angles `a` of the plane
/// become `±a + phi` in the frame. Derived from the model fields of
/// [`SingularityKind`] (wedge `θ = ψ/2 + α`, trisector `θ = −(ψ/2 + α)`, vector kinds
/// `u = ψ + arg c`, saddle `u = −ψ − α`).
fn angle_in_frame(kind: SingularityKind, alpha: f64, phi: f64, reflect: bool) -> f64 {
    use std::f64::consts::PI;
    match (kind, reflect) {
        (SingularityKind::Wedge, false) => alpha + 0.5 * phi,
        (SingularityKind::Wedge, true) => 0.5 * phi - alpha,
        (SingularityKind::Trisector, false) => alpha - 1.5 * phi,
        (SingularityKind::Trisector, true) => -alpha - 1.5 * phi,
        (SingularityKind::Saddle, false) => alpha - 2.0 * phi,
        (SingularityKind::Saddle, true) => -alpha - 2.0 * phi,
        (SingularityKind::Vortex, true) => PI - alpha,
        (_, true) => -alpha,
        (_, false) => alpha,
    }
}

/// Complex square (`N = 2`) or identity of an image-space direction.
#[inline]
fn power(w: [f64; 2], symmetry: Symmetry) -> [f64; 2] {
    match symmetry {
        Symmetry::Vector => w,
        Symmetry::Orientation => [w[0] * w[0] - w[1] * w[1], 2.0 * w[0] * w[1]],
    }
}

/// Image-space direction of surface direction `d` on a triangle with Jacobian `[px, py]`
/// (least squares `P w = d`), normalised.
fn pull_back(jac: [[f64; 3]; 2], d: [f64; 3]) -> [f64; 2] {
    let [px, py] = jac;
    let (a, b, c) = (dot(px, px), dot(px, py), dot(py, py));
    let (r0, r1) = (dot(px, d), dot(py, d));
    let det = a * c - b * b;
    let w = if det.abs() > 0.0 {
        [(c * r0 - b * r1) / det, (a * r1 - b * r0) / det]
    } else {
        [1.0, 0.0]
    };
    let l = (w[0] * w[0] + w[1] * w[1]).sqrt();
    if l > 0.0 && l.is_finite() { [w[0] / l, w[1] / l] } else { [1.0, 0.0] }
}

/// Texel field from per-triangle surface directions (module docs, step 4).
fn sample_texels(
    patch: &Patch,
    map: &TexelMap,
    dirs: &[[f64; 3]],
    symmetry: Symmetry,
) -> Vec<[f32; 2]> {
    let mesh = &patch.mesh;
    let z_face: Vec<[f64; 2]> = (0..mesh.n_triangles())
        .map(|f| match patch.jacobian[f] {
            Some(j) => power(pull_back(j, dirs[f]), symmetry),
            None => [0.0, 0.0],
        })
        .collect();
    let mut z_vertex = vec![[0.0f64; 2]; mesh.n_vertices()];
    for (f, t) in mesh.triangles.iter().enumerate() {
        let p = mesh.triangle_positions(f);
        let a = 0.5 * norm(cross(sub(p[1], p[0]), sub(p[2], p[0])));
        for &v in t {
            let z = &mut z_vertex[v as usize];
            z[0] += a * z_face[f][0];
            z[1] += a * z_face[f][1];
        }
    }
    (0..map.width * map.height)
        .into_par_iter()
        .map(|i| {
            let Some(e) = map.entries[i] else { return [1.0, 0.0] };
            let t = mesh.triangles[e.triangle as usize];
            let mut z = [0.0f64; 2];
            for k in 0..3 {
                let zv = z_vertex[t[k] as usize];
                z[0] += e.bary[k] as f64 * zv[0];
                z[1] += e.bary[k] as f64 * zv[1];
            }
            let z = [z[0] as f32, z[1] as f32];
            fieldtex_fields::orientation_field::nrosy_root_f32(z, symmetry)
        })
        .collect()
}

/// Per-texel Jacobians (module docs, step 5), the field with texels outside the chart
/// filled from the nearest chart texel, and the chart mask.
fn jacobians(
    patch: &Patch,
    map: &TexelMap,
    field: &[[f32; 2]],
    options: &OrientOptions,
) -> (Vec<[f32; 4]>, Vec<[f32; 2]>, Vec<bool>) {
    let inv_s = options.scale / patch.length_per_texel;
    let own: Vec<Option<[f32; 4]>> = (0..map.width * map.height)
        .into_par_iter()
        .map(|i| {
            if !map.is_covered(i) {
                return None;
            }
            let e = map.entries[i]?;
            let f = e.triangle as usize;
            let [px, py] = patch.jacobian[f]?;
            let w = [field[i][0] as f64, field[i][1] as f64];
            let d = normalize(add(scale(px, w[0]), scale(py, w[1])))?;
            let dp = cross(patch.normals[f], d);
            let r1 = [dot(d, px) * inv_s, dot(d, py) * inv_s];
            let mut r2 = [dot(dp, px) * inv_s, dot(dp, py) * inv_s];
            let det = r1[0] * r2[1] - r1[1] * r2[0];
            if det < 0.0 {
                r2 = [-r2[0], -r2[1]];
            }
            let j = [r1[0] as f32, r1[1] as f32, r2[0] as f32, r2[1] as f32];
            let (jd, jn) = (j[0] * j[3] - j[1] * j[2], j.iter().map(|v| v * v).sum::<f32>());
            (j.iter().all(|v| v.is_finite()) && jd > 1e-5 * jn && jn > 1e-12).then_some(j)
        })
        .collect();
    let inside: Vec<bool> = own.iter().map(Option::is_some).collect();
    let source = nearest_source(map.width, map.height, &inside);
    let mut jac = Vec::with_capacity(own.len());
    let mut out_field = Vec::with_capacity(own.len());
    let fallback = [options.scale as f32, 0.0, 0.0, options.scale as f32];
    for &s in &source {
        if s == u32::MAX {
            jac.push(fallback);
            out_field.push([1.0, 0.0]);
        } else {
            jac.push(own[s as usize].unwrap_or(fallback));
            out_field.push(field[s as usize]);
        }
    }
    (jac, out_field, inside)
}

/// For each texel, a chart texel near it: itself when inside, else the first one a
/// breadth-first flood (8-neighbours, row-major seeds, fixed neighbour order) reaches.
fn nearest_source(w: usize, h: usize, inside: &[bool]) -> Vec<u32> {
    let mut source = vec![u32::MAX; w * h];
    let mut queue = std::collections::VecDeque::new();
    for (i, &b) in inside.iter().enumerate() {
        if b {
            source[i] = i as u32;
            queue.push_back(i);
        }
    }
    while let Some(i) = queue.pop_front() {
        let (x, y) = ((i % w) as i64, (i / w) as i64);
        for (dx, dy) in [(-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (1, -1), (-1, 1), (1, 1)] {
            let (nx, ny) = (x + dx, y + dy);
            if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                continue;
            }
            let j = ny as usize * w + nx as usize;
            if source[j] == u32::MAX {
                source[j] = source[i];
                queue.push_back(j);
            }
        }
    }
    source
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
            let expected = (field[i][1] as f64).atan2(field[i][0] as f64);
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
    let nrm = normalize(nsum).unwrap_or([0.0, 0.0, 1.0]);
    let azimuth = nrm[0].atan2(nrm[2]).to_degrees() + 15.0;
    let elevation = (nrm[1].clamp(-1.0, 1.0).asin().to_degrees() + 15.0).clamp(-80.0, 80.0);
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
