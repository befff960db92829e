//! Workspace files: uploads (exemplars and meshes) and reading a file through its
//! confined root.

use super::*;

pub(super) fn upload(state: &State, req: &Request) -> Result<Response, Response> {
    let name = req.query("name").ok_or_else(|| bad("give ?name=FILE.png"))?;
    check_file_name(name).map_err(|(c, m)| Response::error(c, m))?;
    let mesh = is_mesh_name(name);
    if !is_image_name(name) && !mesh {
        return Err(bad(format!(
            "{name:?}: uploads are .png/.jpg exemplars or .obj/.ply/.stl/.glb meshes"
        )));
    }
    if req.body.is_empty() {
        return Err(bad("empty upload"));
    }
    let path_err = |(c, m): (u16, String)| Response::error(c, m);
    let p = state.workspace.file_for_writing("uploads", name).map_err(path_err)?;
    if mesh {
        // Check the mesh with the same reader the pipelines use, from a hidden file
        // next to the target, before it takes the name.
        let dir = state.workspace.dir_for_writing("uploads").map_err(path_err)?;
        let check = dir.join(format!(".check-{name}"));
        let io500 = |e: fieldtex_io::IoError| Response::error(500, e.to_string());
        fieldtex_io::atomic_write(&check, &req.body).map_err(io500)?;
        let read = fieldtex_io::read_mesh(&check);
        let ok = read.as_ref().is_ok_and(|m| !m.mesh.triangles.is_empty());
        let result = if ok {
            std::fs::rename(&check, &p).map_err(|e| Response::error(500, e.to_string()))
        } else {
            Err(bad(match read {
                Err(e) => format!("{name} is not a readable mesh: {e}"),
                Ok(_) => format!("{name} has no triangles"),
            }))
        };
        let _ = std::fs::remove_file(&check);
        result?;
    } else {
        fieldtex_io::read_image_bytes(&req.body, name)
            .map_err(|e| bad(format!("{name} is not a readable image: {e}")))?;
        fieldtex_io::atomic_write(&p, &req.body)
            .map_err(|e| Response::error(500, e.to_string()))?;
    }
    Ok(Response::json(
        200,
        &serde_json::json!({ "root": "workspace", "path": format!("uploads/{name}") }),
    ))
}

pub(super) fn file(state: &State, req: &Request) -> Result<Response, Response> {
    let rel = req.query("path").ok_or_else(|| bad("give ?path=RELATIVE/PATH"))?;
    let root = state.root(req.query("root").unwrap_or("workspace"))?;
    let path = root.existing_file(rel).map_err(|(c, m)| Response::error(c, m))?;
    let meta = std::fs::metadata(&path).map_err(|e| Response::error(404, e.to_string()))?;
    if meta.len() > 256 << 20 {
        return Err(Response::error(413, format!("{rel} is over 256 MiB")));
    }
    let bytes = std::fs::read(&path).map_err(|e| Response::error(500, format!("{rel}: {e}")))?;
    let lower = rel.to_ascii_lowercase();
    let ct = match lower.rsplit('.').next() {
        Some("png") => "image/png",
        Some("jpg" | "jpeg") => "image/jpeg",
        Some("json") => "application/json",
        Some("toml" | "txt" | "md") => "text/plain; charset=utf-8",
        Some("glb") => "model/gltf-binary",
        _ => "application/octet-stream",
    };
    Ok(Response::new(200, ct, bytes))
}
