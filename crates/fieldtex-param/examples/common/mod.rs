//! Shared by the conformal probes: read a mesh and repair it as the pipeline does.

/// The mesh at `path`, repaired with the default options.
pub fn repaired_mesh(path: &str) -> Result<fieldtex_mesh::TriMesh, String> {
    let mesh = fieldtex_io::read_mesh(std::path::Path::new(path)).map_err(|e| e.to_string())?.mesh;
    Ok(fieldtex_mesh::repair(&mesh, &Default::default()).mesh)
}

/// [`repaired_mesh`] and its components from `global_conformal`.
#[allow(dead_code)]
pub fn mapped(
    path: &str,
) -> Result<(fieldtex_mesh::TriMesh, Vec<fieldtex_param::conformal::ConformalComponent>), String> {
    let mesh = repaired_mesh(path)?;
    let (comps, _) = fieldtex_param::conformal::global_conformal(&mesh, &fieldtex_core::NoProgress)
        .map_err(|e| e.to_string())?;
    Ok((mesh, comps))
}
