//! Texture atlas generation: segmentation → LSCM per chart (split until flip-free) →
//! uniform texel density → packing → per-corner UVs and quality statistics.
//!
//! UV convention: `[0, 1]²`, `v` **up** — `v = 0` is the bottom row of the texture
//! image, as in [`fieldtex_mesh::CornerUvs`]; the glTF writer flips `v` on output. The
//! atlas is square, `resolution × resolution` texels, and charts keep the gutter
//! described in [`crate::packing`].
//!
//! Every chart's UV area is made proportional to its 3-D area (one texel density for
//! the whole mesh). Charts whose LSCM has flipped or collapsed triangles, or whose
//! boundary crosses itself in UV, are split in two ([`crate::chart_topology::split_in_two`])
//! and flattened again until none is left; single triangles are flattened exactly.

use crate::ParamError;
use crate::chart_segmentation::{SegmentationOptions, segment_charts};
use crate::chart_topology::{ChartMesh, split_in_two};
use crate::distortion::parameterization_distortion;
use crate::face_graph::FaceGraph;
use crate::lscm::{flattening_defects, lscm, planar_projection};
use crate::min_area_rectangle::min_area_rectangle_angle;
use crate::packing::{PackChart, PackingOptions, pack_charts};
use fieldtex_core::{Progress, Warning, Warnings};
use fieldtex_mesh::{CornerUvs, MeshError, TriMesh};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Options of [`build_atlas`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AtlasOptions {
    /// Atlas width and height in texels. Default 1024.
    pub resolution: u32,
    /// Minimum free distance between charts in texels (see [`crate::packing`]). Default 4.
    pub gutter: u32,
    /// Try 90° rotations of charts while packing. Default true.
    pub rotate_charts: bool,
    /// Chart segmentation options.
    pub segmentation: SegmentationOptions,
}

impl Default for AtlasOptions {
    fn default() -> Self {
        Self {
            resolution: 1024,
            gutter: 4,
            rotate_charts: true,
            segmentation: SegmentationOptions::default(),
        }
    }
}

/// Quality of an atlas (DESIGN.md §6). The distortion fields are NaN when no triangle
/// has a non-zero area.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AtlasStats {
    /// Number of charts.
    pub charts: usize,
    /// Area-weighted mean of `σ1/σ2` (see [`crate::distortion`]).
    pub angle_distortion_mean: f64,
    /// Area-weighted 95th percentile of `σ1/σ2`.
    pub angle_distortion_p95: f64,
    /// Area-weighted mean of `max(s, 1/s)`, `s` the normalised UV/3-D area ratio.
    pub area_distortion: f64,
    /// Sum of the charts' UV triangle areas in texels over the atlas area.
    pub packing_efficiency: f64,
    /// Non-degenerate triangles with non-positive UV area.
    pub flipped_triangles: usize,
    /// Triangles with (near-)zero 3-D area (excluded from the measures above).
    pub degenerate_triangles: usize,
    /// Texels per unit of 3-D length.
    pub texels_per_unit: f64,
}

/// A mesh with an atlas parameterisation.
#[derive(Debug, Clone, PartialEq)]
pub struct Atlas {
    /// The input mesh with per-corner UVs (`uvs` replaced; nothing else changed).
    pub mesh: TriMesh,
    /// `#F` chart of each triangle.
    pub chart_of_triangle: Vec<u32>,
    /// Atlas width and height in texels.
    pub resolution: u32,
    /// Gutter in texels.
    pub gutter: u32,
    pub stats: AtlasStats,
    pub warnings: Warnings,
}

/// A flattened chart: local connectivity and one UV per local vertex.
struct FlatChart {
    chart: ChartMesh,
    uv: Vec<[f64; 2]>,
    /// No flipped or collapsed triangle and no boundary crossing in UV.
    clean: bool,
}

enum Flattened {
    Done(FlatChart, bool),
    Split(Vec<Vec<u32>>),
}

fn check_mesh(mesh: &TriMesh) -> Result<(), ParamError> {
    if mesh.triangles.is_empty() {
        return Err(MeshError::Empty.into());
    }
    let nv = mesh.n_vertices();
    for (f, t) in mesh.triangles.iter().enumerate() {
        for &i in t {
            let Some(p) = mesh.positions.get(i as usize) else {
                return Err(MeshError::IndexOutOfRange {
                    triangle: f,
                    index: i as u64,
                    n_vertices: nv,
                }
                .into());
            };
            if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
                return Err(MeshError::NonFinitePosition { vertex: i as usize }.into());
            }
        }
    }
    Ok(())
}

/// Flattens one chart or says how to split it. The flag is `true` when a defect could
/// not be removed (a single triangle can always be flattened exactly, so it is `false`
/// in practice).
fn flatten(faces: Vec<u32>, mesh: &TriMesh, graph: &FaceGraph) -> Flattened {
    let chart = ChartMesh::build(faces, graph, &mesh.triangles);
    if !chart.is_disk()
        && let Some(parts) = split_in_two(&chart.faces, graph)
    {
        return Flattened::Split(parts);
    }
    let uv = match lscm(&chart, mesh, graph) {
        Ok(uv) => uv,
        Err(_) => planar_projection(&chart, mesh, graph),
    };
    if flattening_defects(&chart, &uv, graph).is_clean() {
        return Flattened::Done(FlatChart { chart, uv, clean: true }, false);
    }
    match split_in_two(&chart.faces, graph) {
        Some(parts) => Flattened::Split(parts),
        None => Flattened::Done(FlatChart { chart, uv, clean: false }, true),
    }
}

/// Builds a texture atlas for `mesh` (module docs). Errors on an empty mesh, indices
/// out of range, non-finite referenced positions, invalid options, or charts that do
/// not fit (too many charts for the resolution and gutter).
pub fn build_atlas(
    mesh: &TriMesh,
    options: &AtlasOptions,
    progress: &dyn Progress,
) -> Result<Atlas, ParamError> {
    check_mesh(mesh)?;
    let pack_opts = PackingOptions {
        resolution: options.resolution,
        gutter: options.gutter,
        rotate: options.rotate_charts,
        ..Default::default()
    };
    if options.resolution < 8 || options.resolution > 16384 {
        return Err(ParamError::InvalidOption {
            name: "resolution",
            value: options.resolution.to_string(),
            reason: "the atlas resolution must be between 8 and 16384 texels",
        });
    }
    let a = options.segmentation.max_normal_angle_deg;
    if !(a > 0.0 && a < 90.0) {
        return Err(ParamError::InvalidOption {
            name: "max_normal_angle_deg",
            value: a.to_string(),
            reason: "the chart normal cone must be between 0 and 90 degrees (exclusive)",
        });
    }
    let seg = &options.segmentation;
    for (name, value) in
        [("lloyd_iterations", seg.lloyd_iterations), ("smoothing_passes", seg.smoothing_passes)]
    {
        if value > 1000 {
            return Err(ParamError::InvalidOption {
                name,
                value: value.to_string(),
                reason: "at most 1000 rounds are allowed (the defaults are 4 and 2)",
            });
        }
    }
    let mut warnings = Warnings::new();
    progress.stage("atlas: segmenting charts", 0);
    let graph = FaceGraph::build(mesh);
    let seg = segment_charts(&graph, &mesh.triangles, &options.segmentation);
    progress.finish_stage();

    progress.stage("atlas: flattening charts", mesh.n_triangles() as u64);
    let mut work = seg.charts;
    let mut done: Vec<FlatChart> = Vec::new();
    let mut unresolved = 0usize;
    while !work.is_empty() {
        let batch = std::mem::take(&mut work);
        let results: Vec<Flattened> =
            batch.into_par_iter().map(|f| flatten(f, mesh, &graph)).collect();
        for r in results {
            match r {
                Flattened::Done(fc, bad) => {
                    progress.advance(fc.chart.faces.len() as u64);
                    unresolved += bad as usize;
                    done.push(fc);
                }
                Flattened::Split(parts) => work.extend(parts),
            }
        }
    }
    progress.finish_stage();
    if unresolved > 0 {
        warnings.push(Warning::new(
            "atlas-chart-defects",
            format!("{unresolved} single-triangle charts could not be flattened without a flip; their UVs are degenerate"),
        ));
    }
    done.sort_by_key(|c| c.chart.faces[0]);

    progress.stage("atlas: packing charts", 0);
    // Uniform texel density and tight bounding boxes.
    let prepare = |fc: &FlatChart| {
        let a3: f64 = fc.chart.faces.iter().map(|&f| graph.areas[f as usize]).sum();
        let auv: f64 = fc
            .chart
            .corners
            .iter()
            .map(|c| {
                let (p, q, r) = (fc.uv[c[0] as usize], fc.uv[c[1] as usize], fc.uv[c[2] as usize]);
                0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])).abs()
            })
            .sum();
        let s = if auv > 0.0 && a3 > 0.0 { (a3 / auv).sqrt() } else { 1.0 };
        let theta = min_area_rectangle_angle(&fc.uv);
        let (c, sn) = (theta.cos(), theta.sin());
        let points = fc
            .uv
            .iter()
            .map(|p| [s * (c * p[0] + sn * p[1]), s * (-sn * p[0] + c * p[1])])
            .collect();
        PackChart { points, triangles: fc.chart.corners.clone(), simple_outline: fc.clean }
    };
    let pack_charts_in: Vec<PackChart> = done.par_iter().map(prepare).collect();
    let packing = pack_charts(&pack_charts_in, &pack_opts)?;
    progress.finish_stage();

    // Per-corner UVs.
    let nf = mesh.n_triangles();
    let mut chart_of_triangle = vec![0u32; nf];
    let mut values: Vec<[f64; 2]> =
        Vec::with_capacity(done.iter().map(|c| c.chart.n_vertices).sum());
    let mut indices = vec![[0u32; 3]; nf];
    let res = options.resolution as f64;
    let mut uv_area_texels = 0.0;
    for (k, (fc, pc)) in done.iter().zip(&pack_charts_in).enumerate() {
        let base = values.len() as u32;
        values.extend(pc.points.iter().map(|&p| packing.atlas_uv(k, p)));
        for (lf, &f) in fc.chart.faces.iter().enumerate() {
            chart_of_triangle[f as usize] = k as u32;
            let c = fc.chart.corners[lf];
            indices[f as usize] = [base + c[0], base + c[1], base + c[2]];
            let (p, q, r) = (
                values[(base + c[0]) as usize],
                values[(base + c[1]) as usize],
                values[(base + c[2]) as usize],
            );
            uv_area_texels +=
                0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])) * res * res;
        }
    }
    let uvs = CornerUvs { values, indices };
    let dist = parameterization_distortion(mesh, &uvs)?;
    if dist.degenerate_triangles > 0 {
        warnings.push(Warning::new(
            "atlas-degenerate-triangles",
            format!(
                "{} triangles have (near-)zero area; they get collapsed UVs and are left out of the distortion measures (run `fieldtex repair` to drop them)",
                dist.degenerate_triangles
            ),
        ));
    }
    let stats = AtlasStats {
        charts: done.len(),
        angle_distortion_mean: dist.angle_mean,
        angle_distortion_p95: dist.angle_p95,
        area_distortion: dist.area_distortion,
        packing_efficiency: uv_area_texels / (res * res),
        flipped_triangles: dist.flipped_triangles,
        degenerate_triangles: dist.degenerate_triangles,
        texels_per_unit: packing.texels_per_unit,
    };
    let mut out = mesh.clone();
    out.uvs = Some(uvs);
    Ok(Atlas {
        mesh: out,
        chart_of_triangle,
        resolution: options.resolution,
        gutter: options.gutter,
        stats,
        warnings,
    })
}
