//! Routes of the mesh modes: the mesh and GLB lists, opening a mesh (binary answer),
//! the curve-aligned field as surface streamlines and the sketch's frame field.

use super::*;

/// Meshes (workspace and the meshes root) and GLB outputs (workspace) to open.
pub(super) fn meshes(state: &State) -> Response {
    let mut meshes = Vec::new();
    if let Some(r) = &state.meshes {
        for p in r.list_matching(300, is_mesh_name) {
            meshes.push(serde_json::json!({ "root": "meshes", "path": p }));
        }
    }
    for p in state.workspace.list_matching(300, is_mesh_name) {
        meshes.push(serde_json::json!({ "root": "workspace", "path": p }));
    }
    let glbs: Vec<_> = state
        .workspace
        .list_matching(300, |n| n.to_ascii_lowercase().ends_with(".glb"))
        .into_iter()
        .map(|p| serde_json::json!({ "root": "workspace", "path": p }))
        .collect();
    Response::json(200, &serde_json::json!({ "meshes": meshes, "glbs": glbs }))
}

/// A mesh file behind a `{root, path}` reference.
pub(super) fn mesh_file(state: &State, r: &FileRef) -> Result<std::path::PathBuf, Response> {
    let root = state.root(&r.root)?;
    if !is_mesh_name(&r.path) {
        return Err(bad(format!("{:?} is not a .obj/.ply/.stl/.glb mesh", r.path)));
    }
    root.existing_file(&r.path).map_err(|(c, m)| Response::error(c, m))
}

pub(super) fn mesh_open(state: &State, req: &Request) -> Result<Response, Response> {
    let r: FileRef = parse_json(&req.body)?;
    let path = mesh_file(state, &r)?;
    let session =
        MeshSession::open(&path, &r.root, &r.path).map_err(|(c, m)| Response::error(c, m))?;
    let n = state.mesh_counter.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1;
    let id = format!("m{n}");
    let body = session.encode(&id);
    let mut g = state.mesh_sessions.lock().unwrap_or_else(|e| e.into_inner());
    while g.len() >= MAX_MESH_SESSIONS {
        g.pop_front();
    }
    g.push_back((id, Arc::new(session)));
    Ok(Response::new(200, "application/octet-stream", body))
}

pub(super) fn mesh_session(state: &State, req: &Request) -> Result<Arc<MeshSession>, Response> {
    let id = req.query("mesh").ok_or_else(|| bad("give ?mesh=ID"))?;
    let g = state.mesh_sessions.lock().unwrap_or_else(|e| e.into_inner());
    g.iter().find(|(k, _)| k == id).map(|(_, m)| m.clone()).ok_or_else(|| {
        Response::error(
            404,
            format!("no open mesh {id:?} (expired or server restarted): open it again"),
        )
    })
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FieldRequest {
    /// Curves on the surface; `None` = the mesh's crest lines.
    curves: Option<Vec<Vec<[f64; 3]>>>,
    /// Streamline seeds (default 300).
    seeds: Option<usize>,
}

pub(super) fn mesh_field(state: &State, req: &Request) -> Result<Response, Response> {
    let f: FieldRequest = parse_json(&req.body)?;
    let m = mesh_session(state, req)?;
    if let Some(c) = &f.curves {
        crate::mesh_mode::check_curves(c).map_err(bad)?;
    }
    let json = m
        .field_lines(f.curves.as_deref(), f.seeds.unwrap_or(300))
        .map_err(|(c, e)| Response::error(c, e))?;
    Ok(Response::json(200, &json))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FramesRequest {
    sketch: fieldtex_fields::Sketch,
    samples: Option<usize>,
}

pub(super) fn mesh_frames(state: &State, req: &Request) -> Result<Response, Response> {
    let f: FramesRequest = parse_json(&req.body)?;
    let m = mesh_session(state, req)?;
    let json =
        m.frames(&f.sketch, f.samples.unwrap_or(250)).map_err(|(c, e)| Response::error(c, e))?;
    Ok(Response::json(200, &json))
}
