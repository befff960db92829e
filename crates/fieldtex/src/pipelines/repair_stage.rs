//! The one repair stage every pipeline runs on a mesh it has read: the default
//! [`fieldtex_mesh::repair`], every change reported the same way (a warning coded
//! `repair:<code>`, or `repair:<which>:<code>` for a named input such as a transfer's
//! `source`, whose message says what changed and how often), and a bad-input error
//! naming the file when no usable triangle is left.

use crate::{Error, Report, Result};
use fieldtex_core::Warning;
use fieldtex_mesh::TriMesh;
use std::path::Path;

/// A repaired mesh and the warnings that describe its repair.
pub(crate) struct RepairedMesh {
    pub mesh: TriMesh,
    pub warnings: Vec<Warning>,
}

/// Repairs `mesh` (read from `source`; `which` names it when a pipeline reads several).
pub(crate) fn repair_mesh(
    mesh: &TriMesh,
    source: Option<&Path>,
    which: Option<&str>,
) -> Result<RepairedMesh> {
    let repaired = fieldtex_mesh::repair(mesh, &fieldtex_mesh::RepairOptions::default());
    let (code_prefix, message_prefix) = match which {
        Some(w) => (format!("repair:{w}:"), format!("{w}: ")),
        None => ("repair:".to_string(), String::new()),
    };
    let mut warnings: Vec<Warning> = repaired
        .changes
        .iter()
        .map(|c| {
            Warning::new(
                format!("{code_prefix}{}", c.code),
                // The message states the count itself.
                format!("{message_prefix}{}", c.message),
            )
        })
        .collect();
    warnings.extend(repaired.warnings.iter().cloned());
    if repaired.mesh.triangles.is_empty() {
        return Err(Error::bad_input(
            source,
            format!(
                "{message_prefix}no usable triangle is left after repair (all were degenerate, \
                 non-finite or invalid); `fieldtex inspect` shows why"
            ),
        ));
    }
    Ok(RepairedMesh { mesh: repaired.mesh, warnings })
}

/// [`repair_mesh`], timed as the report's `repair` stage (`repair_<which>`), with the
/// warnings added to the report.
pub(crate) fn repair_into_report(
    mesh: &TriMesh,
    source: Option<&Path>,
    which: Option<&str>,
    report: &mut Report,
) -> Result<TriMesh> {
    let stage = which.map_or_else(|| "repair".to_string(), |w| format!("repair_{w}"));
    let r = report.time(&stage, || repair_mesh(mesh, source, which))?;
    report.warnings.extend(r.warnings);
    Ok(r.mesh)
}
