//! One module per pipeline.
pub mod align;
pub mod atlas;
pub mod conformal;
pub mod crest;
pub mod demo;
pub mod eval;
pub mod field;
pub mod field_texture;
pub mod inspect;
pub mod orient;
pub(crate) mod orient_patch;
pub mod render;
pub(crate) mod repair_stage;
pub mod solid;
pub mod solid_session;
pub(crate) mod synthesis;
pub mod transfer;
pub mod transfer_fidelity;

use crate::Result;
use fieldtex_core::Image;
use fieldtex_mesh::TriMesh;
use std::path::Path;

/// Writes `model.glb` into `dir`.
pub(crate) fn write_model(dir: &Path, mesh: &TriMesh, texture: Option<&Image>) -> Result<()> {
    fieldtex_io::write_glb(
        &dir.join("model.glb"),
        mesh,
        texture,
        &fieldtex_io::GlbOptions::default(),
    )?;
    Ok(())
}

/// Writes `name` (a `.glb`) into `dir` with `texture`.
pub(crate) fn write_model_named(
    dir: &Path,
    name: &str,
    mesh: &TriMesh,
    texture: &Image,
) -> Result<()> {
    fieldtex_io::write_glb(
        &dir.join(name),
        mesh,
        Some(texture),
        &fieldtex_io::GlbOptions::default(),
    )?;
    Ok(())
}

/// Writes a mesh in the format named by the extension of `path`.
pub(crate) fn write_mesh_by_extension(
    path: &Path,
    mesh: &TriMesh,
    texture: Option<&Image>,
) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("glb") => {
            fieldtex_io::write_glb(path, mesh, texture, &fieldtex_io::GlbOptions::default())?
        }
        Some("obj") => fieldtex_io::write_obj(path, mesh, texture)?,
        Some("ply") => fieldtex_io::write_ply(path, mesh, &[], true)?,
        _ => {
            return Err(crate::Error::bad_input(
                Some(path),
                "unknown output format: use a .glb, .obj or .ply extension",
            ));
        }
    }
    Ok(())
}
