//! `fieldtex crest`: crest lines (ridges and valleys) and salient creases as OBJ
//! polylines (paper A §3; Yoshizawa, Belyaev & Seidel 2005), with an optional preview.

use crate::{Error, Result};
use fieldtex_features::{CrestOptions, CrestStats, LineKind, crest_lines};
use fieldtex_render::{Overlay, Polyline3, RenderOptions, Scene, render};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Options of [`crest_file`].
#[derive(Debug, Clone, Default)]
pub struct CrestCommandOptions {
    /// Ascending strength thresholds (`∫|k| ds`); `None` keeps the detector's default.
    pub levels: Option<Vec<f64>>,
    /// Keep lines of this level of detail and above. Default 0 (all kept lines).
    pub min_level: usize,
    /// Also render the mesh with the lines drawn to this PNG.
    pub preview: Option<PathBuf>,
}

/// What [`crest_file`] found.
#[derive(Debug, Clone, Serialize)]
pub struct CrestSummary {
    pub mesh: String,
    pub output: String,
    pub lines_written: usize,
    pub ridges: usize,
    pub valleys: usize,
    pub creases: usize,
    pub total_length: f64,
    pub stats: CrestStats,
    pub warnings: Vec<fieldtex_core::Warning>,
}

/// Detects crest lines on the mesh at `mesh_path` and writes them to `out` (OBJ `l`).
pub fn crest_file(
    mesh_path: &Path,
    out: &Path,
    options: &CrestCommandOptions,
) -> Result<CrestSummary> {
    crate::outputs::begin_command();
    fieldtex_io::ensure_not_input(out, &[mesh_path])?;
    let mut copts = CrestOptions::default();
    if let Some(l) = &options.levels {
        if l.iter().any(|x| !x.is_finite() || *x < 0.0) || l.windows(2).any(|w| w[0] > w[1]) {
            return Err(Error::bad_input(None, "--levels must be ascending non-negative numbers"));
        }
        copts.levels = l.clone();
    }
    let loaded = fieldtex_io::read_mesh(mesh_path)?;
    // Refuse before any work when an output is the mesh or a file it names.
    crate::outputs::guard_output(out)?;
    if let Some(p) = &options.preview {
        crate::outputs::guard_output(p)?;
    }
    let repaired = super::repair_stage::repair_mesh(&loaded.mesh, Some(mesh_path), None)?;
    let crest = crest_lines(&repaired.mesh, &copts)
        .map_err(|e| Error::classify(&e, Some(mesh_path), ""))?;
    let kept: Vec<_> = crest.lines.iter().filter(|l| l.level >= options.min_level).collect();
    let polylines: Vec<Vec<[f64; 3]>> = kept.iter().map(|l| l.points.clone()).collect();
    fieldtex_io::write_obj_polylines(out, &polylines)?;
    if let Some(p) = &options.preview {
        let mut scene = Scene::new(&repaired.mesh);
        for l in &kept {
            let color = match l.kind {
                LineKind::Ridge => [0.85, 0.1, 0.1, 1.0],
                LineKind::Valley => [0.1, 0.3, 0.9, 1.0],
                _ => [0.1, 0.6, 0.2, 1.0],
            };
            scene = scene.with_overlay(Overlay::Polyline(
                Polyline3::new(l.points.clone()).with_color(color),
            ));
        }
        fieldtex_io::write_png(p, &render(&scene, &RenderOptions::default()))?;
    }
    let mut warnings = loaded.warnings;
    warnings.extend(repaired.warnings);
    warnings.extend(crest.warnings.iter().cloned());
    if kept.is_empty() {
        warnings.push(fieldtex_core::Warning::new(
            "no-crest-lines",
            "no crest line passed the thresholds (a smooth or umbilic shape); lower --levels, or pass your own curves to `field`/`align`",
        ));
    }
    Ok(CrestSummary {
        mesh: mesh_path.display().to_string(),
        output: out.display().to_string(),
        lines_written: kept.len(),
        ridges: kept.iter().filter(|l| l.kind == LineKind::Ridge).count(),
        valleys: kept.iter().filter(|l| l.kind == LineKind::Valley).count(),
        creases: kept.iter().filter(|l| l.source == fieldtex_features::LineSource::Crease).count(),
        total_length: kept.iter().map(|l| l.length).sum(),
        stats: crest.stats,
        warnings,
    })
}
