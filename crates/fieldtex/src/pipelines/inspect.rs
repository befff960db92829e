//! `fieldtex inspect` and `fieldtex repair`.

use crate::{Error, Result};
use fieldtex_core::Warning;
use fieldtex_mesh::inspect::{InspectOptions, InspectReport, inspect};
use fieldtex_mesh::repair::{RepairChange, RepairOptions, repair};
use serde::Serialize;
use std::path::Path;

/// Reads `path` and inspects it; the warnings are those of the reader.
pub fn inspect_file(path: &Path) -> Result<(InspectReport, Vec<Warning>)> {
    crate::outputs::begin_command();
    let loaded = fieldtex_io::read_mesh(path)?;
    let report = inspect(&loaded.mesh, &InspectOptions::default());
    Ok((report, loaded.warnings))
}

/// Options of [`repair_file`].
#[derive(Debug, Clone, Default)]
pub struct RepairCommandOptions {
    /// Weld distance relative to the bounding-box diagonal (0 = identical positions).
    pub weld_epsilon: f64,
}

/// What [`repair_file`] did.
#[derive(Debug, Clone, Serialize)]
pub struct RepairSummary {
    pub input: String,
    pub output: String,
    pub vertices_before: usize,
    pub triangles_before: usize,
    pub vertices_after: usize,
    pub triangles_after: usize,
    pub changes: Vec<RepairChange>,
    pub warnings: Vec<Warning>,
}

impl RepairSummary {
    /// Human-readable lines: one per change and warning.
    pub fn lines(&self) -> Vec<String> {
        let mut out = vec![format!(
            "{}: {} vertices, {} triangles -> {}: {} vertices, {} triangles",
            self.input,
            self.vertices_before,
            self.triangles_before,
            self.output,
            self.vertices_after,
            self.triangles_after
        )];
        if self.changes.is_empty() {
            out.push("no changes were needed".to_string());
        }
        for c in &self.changes {
            out.push(format!("  {} ({}): {}", c.code, c.count, c.message));
        }
        for w in &self.warnings {
            out.push(format!("  warning: {w}"));
        }
        out
    }
}

/// Reads `input`, repairs it and writes the result to `output` (format by extension:
/// `.obj`, `.ply` or `.glb`). Refuses to overwrite the input.
pub fn repair_file(
    input: &Path,
    output: &Path,
    options: &RepairCommandOptions,
) -> Result<RepairSummary> {
    if !(options.weld_epsilon >= 0.0 && options.weld_epsilon < 1.0) {
        return Err(Error::bad_input(
            None,
            format!("--weld-epsilon must be in [0, 1), got {}", options.weld_epsilon),
        ));
    }
    crate::outputs::begin_command();
    fieldtex_io::ensure_not_input(output, &[input])?;
    let loaded = fieldtex_io::read_mesh(input)?;
    let opts = RepairOptions { weld_epsilon_relative: options.weld_epsilon, ..Default::default() };
    let result = repair(&loaded.mesh, &opts);
    if result.mesh.triangles.is_empty() {
        return Err(Error::bad_input(
            Some(input),
            "no usable triangle is left after repair (every triangle was degenerate or invalid)",
        ));
    }
    super::write_mesh_by_extension(output, &result.mesh, loaded.base_color.as_ref())?;
    let mut warnings = loaded.warnings;
    warnings.extend(result.warnings.iter().cloned());
    Ok(RepairSummary {
        input: input.display().to_string(),
        output: output.display().to_string(),
        vertices_before: loaded.mesh.n_vertices(),
        triangles_before: loaded.mesh.n_triangles(),
        vertices_after: result.mesh.n_vertices(),
        triangles_after: result.mesh.n_triangles(),
        changes: result.changes,
        warnings,
    })
}
