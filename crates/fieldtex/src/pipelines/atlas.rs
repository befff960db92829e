//! `fieldtex atlas`: segment, flatten, pack; write the UV-mapped model with a checker
//! texture (so distortion is visible), a preview and the atlas statistics.

use crate::outputs::{begin_command, begin_outputs, commit_outputs};
use crate::{Error, Progress, Report, Result};
use fieldtex_core::Image;
use fieldtex_param::{Atlas, AtlasOptions, build_atlas};
use serde::Serialize;
use std::path::Path;

/// Options of [`atlas_file`].
#[derive(Debug, Clone, Serialize)]
pub struct AtlasCommandOptions {
    /// Atlas resolution in texels (square). Default 1024.
    pub size: usize,
    /// Gutter between charts in texels. Default 4.
    pub gutter: usize,
    pub seed: u64,
}

impl Default for AtlasCommandOptions {
    fn default() -> Self {
        Self { size: 1024, gutter: 4, seed: 1 }
    }
}

/// A checker texture in UV space with `cells` squares per side: equal squares on the
/// surface mean low distortion.
pub(crate) fn uv_checker(size: usize, cells: usize) -> Image {
    let mut im = Image::new(size, size, [1.0; 4]);
    for y in 0..size {
        for x in 0..size {
            let cx = x * cells / size;
            let cy = y * cells / size;
            let c = if (cx + cy).is_multiple_of(2) {
                [0.93, 0.93, 0.9, 1.0]
            } else {
                [0.25, 0.45, 0.7, 1.0]
            };
            im.set(x, y, c);
        }
    }
    im
}

pub(crate) fn atlas_options(size: usize, gutter: usize) -> Result<AtlasOptions> {
    if !(8..=16384).contains(&size) {
        return Err(Error::bad_input(
            None,
            format!("--size must be in 8..=16384 texels, got {size}"),
        ));
    }
    if gutter * 4 >= size {
        return Err(Error::bad_input(
            None,
            format!("--gutter {gutter} is too large for a {size}-texel atlas"),
        ));
    }
    Ok(AtlasOptions { resolution: size as u32, gutter: gutter as u32, ..Default::default() })
}

/// Repairs (when needed) and atlases `mesh`, recording timings and warnings.
pub(crate) fn repaired_atlas(
    mesh: &fieldtex_mesh::TriMesh,
    source: Option<&Path>,
    options: &AtlasOptions,
    report: &mut Report,
    progress: &dyn Progress,
) -> Result<Atlas> {
    let repaired = super::repair_stage::repair_into_report(mesh, source, None, report)?;
    let atlas = report
        .stage(progress, "atlas", || build_atlas(&repaired, options, progress))
        .map_err(|e| {
            let what = source.map(|p| format!("{}: ", p.display())).unwrap_or_default();
            Error::classify(&e, None, &format!("{what}atlas"))
        })?;
    report.warnings.extend(atlas.warnings.iter().cloned());
    Ok(atlas)
}

/// Builds an atlas for the mesh at `mesh_path`; writes `model.glb`, `preview.png` and
/// `report.json` into `out_dir`.
pub fn atlas_file(
    mesh_path: &Path,
    out_dir: &Path,
    options: &AtlasCommandOptions,
    progress: &dyn Progress,
) -> Result<Report> {
    begin_command();
    let aopts = atlas_options(options.size, options.gutter)?;
    let mut report =
        Report::new("atlas", options.seed, serde_json::to_value(options).unwrap_or_default());
    let loaded = report.stage(progress, "read", || fieldtex_io::read_mesh(mesh_path))?;
    report.warnings.extend(loaded.warnings.iter().cloned());
    report.input = serde_json::json!({
        "mesh": mesh_path.display().to_string(),
        "vertices": loaded.mesh.n_vertices(),
        "triangles": loaded.mesh.n_triangles(),
    });
    let out = begin_outputs(out_dir, &["model.glb", "preview.png", "report.json"])?;
    let stage = out.staging();
    let atlas = repaired_atlas(&loaded.mesh, Some(mesh_path), &aopts, &mut report, progress)?;
    let checker = uv_checker(options.size.min(2048), 32);
    report.stage(progress, "write", || super::write_model(stage, &atlas.mesh, Some(&checker)))?;
    let preview = report.stage(progress, "preview", || {
        super::render::preview(&atlas.mesh, Some(&checker), 800, None)
    });
    fieldtex_io::write_png(&stage.join("preview.png"), &preview)?;
    report.metric("atlas", atlas.stats);
    commit_outputs(out, &mut report)?;
    Ok(report)
}
