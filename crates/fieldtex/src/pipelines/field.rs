//! `fieldtex field`: a smooth tangent field that follows oriented feature curves
//! (paper A §4): greedy curve orientation by the score of eq. (1), constrained
//! harmonic diffusion `(L + P) x = P b` with α = 1e8, each step applied by rank-1
//! updates of one factorisation. Writes `field.ply` (`x y z nx ny nz fx fy fz`).

use crate::{Error, Progress, Result};
use fieldtex_fields::{
    CurveOrientationOptions, OrientationMode, orient_curves_with_geometry,
    surface_field_metrics_with,
};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Options of [`field_file`].
#[derive(Debug, Clone, Default)]
pub struct FieldCommandOptions {
    /// OBJ polylines; `None` detects crest lines with the default options.
    pub curves: Option<PathBuf>,
    /// `false`: random orientations from the seed (the ablation of paper A Fig. 4).
    pub greedy: bool,
    pub seed: u64,
}

/// Per-step record of the orientation.
#[derive(Debug, Clone, Serialize)]
pub struct FieldStep {
    pub curve: usize,
    pub sign: i8,
    pub normalized_score: f64,
    pub new_constraints: usize,
    pub update_ms: f64,
    pub factor_ms: f64,
    pub solve_ms: f64,
}

/// What [`field_file`] computed (printed as JSON by the CLI).
#[derive(Debug, Clone, Serialize)]
pub struct FieldSummary {
    pub mesh: String,
    pub output: String,
    pub curves: usize,
    pub curves_source: String,
    pub orientation: String,
    pub singularities: usize,
    /// `(face, index)` of each singular face.
    pub singularity_indices: Vec<(usize, i32)>,
    pub index_sum: i32,
    pub euler_characteristic: i64,
    pub dirichlet_energy: f64,
    pub alignment_mean_deg: f64,
    pub alignment_max_deg: f64,
    pub steps: Vec<FieldStep>,
    pub total_ms: f64,
    pub warnings: Vec<fieldtex_core::Warning>,
}

/// Computes the curve-aligned field of the mesh at `mesh_path` and writes `out`.
pub fn field_file(
    mesh_path: &Path,
    out: &Path,
    options: &FieldCommandOptions,
    progress: &dyn Progress,
) -> Result<FieldSummary> {
    let mut inputs = vec![mesh_path];
    if let Some(c) = &options.curves {
        inputs.push(c);
    }
    crate::outputs::begin_command();
    fieldtex_io::ensure_not_input(out, &inputs)?;
    let loaded = fieldtex_io::read_mesh(mesh_path)?;
    let mut warnings = loaded.warnings.clone();
    let repaired = super::repair_stage::repair_mesh(&loaded.mesh, Some(mesh_path), None)?;
    warnings.extend(repaired.warnings);
    let mesh = repaired.mesh;
    // One geometry object for crest lines, the solver and the metrics (one topology,
    // one set of vertex normals).
    let geometry = fieldtex_mesh::MeshGeometry::new(&mesh);
    let (curves, source) = super::align::salient_curves(
        &geometry,
        mesh_path,
        options.curves.as_deref(),
        &mut warnings,
    )?;
    if curves.is_empty() {
        warnings.push(fieldtex_core::Warning::new(
            "no-curves",
            "no feature curve was found or given: the field falls back to principal curvature directions \
             where it has no constraint (pass --curves C.obj to steer it)",
        ));
    }
    let mode = if options.greedy {
        OrientationMode::Greedy
    } else {
        OrientationMode::Arbitrary { seed: options.seed }
    };
    let copts = CurveOrientationOptions { mode, ..Default::default() };
    let result = orient_curves_with_geometry(&geometry, &curves, &copts, progress)
        .map_err(|e| Error::classify(&e, None, "field"))?;
    warnings.extend(result.warnings.iter().cloned());
    warnings.extend(result.field.warnings.iter().cloned());
    let metrics =
        surface_field_metrics_with(&geometry, &result.field.vectors, &result.solver.constraints())
            .map_err(|e| Error::internal("field metrics", e))?;
    // The metrics' topology gives χ (no second `Topology::build` of the same mesh).
    let chi = metrics.euler_characteristic;
    // field.ply: positions, the solver's normals, the field.
    let mut ply_mesh = fieldtex_mesh::TriMesh::new(mesh.positions.clone(), mesh.triangles.clone());
    ply_mesh.vertex_normals = Some(result.solver.normals().to_vec());
    let comp =
        |k: usize| -> Vec<f32> { result.field.vectors.iter().map(|v| v[k] as f32).collect() };
    let (fx, fy, fz) = (comp(0), comp(1), comp(2));
    fieldtex_io::write_ply(out, &ply_mesh, &[("fx", &fx), ("fy", &fy), ("fz", &fz)], true)?;
    Ok(FieldSummary {
        mesh: mesh_path.display().to_string(),
        output: out.display().to_string(),
        curves: curves.len(),
        curves_source: source,
        orientation: if options.greedy {
            "greedy".into()
        } else {
            format!("arbitrary (seed {})", options.seed)
        },
        singularities: metrics.singularities.len(),
        singularity_indices: metrics.singularities.iter().map(|s| (s.face, s.index)).collect(),
        index_sum: metrics.index_sum,
        euler_characteristic: chi,
        dirichlet_energy: metrics.dirichlet_energy,
        alignment_mean_deg: metrics.alignment.mean_deg,
        alignment_max_deg: metrics.alignment.max_deg,
        steps: result
            .steps
            .iter()
            .map(|s| FieldStep {
                curve: s.curve,
                sign: s.sign,
                normalized_score: s.normalized_score,
                new_constraints: s.new_constraints,
                update_ms: s.update_ms,
                factor_ms: s.factor_ms,
                solve_ms: s.solve_ms,
            })
            .collect(),
        total_ms: result.total_ms,
        warnings,
    })
}
