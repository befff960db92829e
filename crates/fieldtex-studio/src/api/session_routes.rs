//! The design-session routes: a new session from a preset or design file, its state
//! and field, edits, the synthesised texture of the current design, and export.

use super::*;

/// `[u32 LE json length][json][view² × (dx, dy) f32 LE]`: the page's state and field.
fn state_response(id: &str, s: &Session, extra: Option<(&str, serde_json::Value)>) -> Response {
    let mut json = s.state_json(id);
    if let (Some((k, v)), Some(obj)) = (extra, json.as_object_mut()) {
        obj.insert(k.to_string(), v);
    }
    let text = json.to_string();
    let mut body = Vec::with_capacity(4 + text.len() + s.field.len() * 8);
    body.extend_from_slice(&(text.len() as u32).to_le_bytes());
    body.extend_from_slice(text.as_bytes());
    for v in &s.field {
        body.extend_from_slice(&v[0].to_le_bytes());
        body.extend_from_slice(&v[1].to_le_bytes());
    }
    Response::new(200, "application/octet-stream", body)
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct NewSession {
    /// A fingerprint preset name.
    preset: Option<String>,
    /// A design TOML in the workspace.
    design: Option<String>,
    symmetry: Option<Symmetry>,
    grid: Option<usize>,
    /// Side of the square design domain in pixels (default 512).
    size: Option<f64>,
    /// Side of the field grid sent to the page (default 128).
    view: Option<usize>,
}

pub(super) fn new_session(state: &State, req: &Request) -> Result<Response, Response> {
    let o: NewSession = parse_json(&req.body)?;
    let grid = o.grid.unwrap_or(128);
    let size = o.size.unwrap_or(512.0);
    let view = o.view.unwrap_or(128);
    if !(8..=256).contains(&grid) {
        return Err(bad(format!("grid {grid} is outside 8..=256")));
    }
    if !(size.is_finite() && (16.0..=4096.0).contains(&size)) {
        return Err(bad(format!("size {size} is outside 16..=4096")));
    }
    if !(8..=512).contains(&view) {
        return Err(bad(format!("view {view} is outside 8..=512")));
    }
    let base = match (&o.preset, &o.design) {
        (Some(_), Some(_)) => return Err(bad("give a preset or a design, not both")),
        (Some(name), None) => fieldtex_fields::presets::preset(name, size, size, grid)
            .map_err(|e| bad(format!("preset {name:?}: {e}")))?,
        (None, Some(rel)) => {
            let path =
                state.workspace.existing_file(rel).map_err(|(c, m)| Response::error(c, m))?;
            let bytes = std::fs::read(&path).map_err(|e| bad(format!("{rel}: {e}")))?;
            if bytes.len() > state.max_json {
                return Err(Response::error(
                    413,
                    format!("{rel} is over {} bytes", state.max_json),
                ));
            }
            let text =
                String::from_utf8(bytes).map_err(|_| bad(format!("{rel} is not UTF-8 text")))?;
            DesignFile::from_toml_str(&text).map_err(|e| bad(format!("{rel}: {e}")))?
        }
        (None, None) => DesignFile::plane(size, size, grid, o.symmetry.unwrap_or_default()),
    };
    let session = Session::new(base, view).map_err(bad)?;
    let id = state.insert_session(session);
    let (_, s) = state
        .session(&Request { query: vec![("session".into(), id.clone())], ..empty_request() })?;
    let g = lock(state, &id, &s)?;
    Ok(state_response(&id, &g, None))
}

fn empty_request() -> Request {
    Request {
        method: String::new(),
        path: String::new(),
        query: Vec::new(),
        headers: Vec::new(),
        body: Vec::new(),
    }
}

pub(super) fn get_state(state: &State, req: &Request) -> Result<Response, Response> {
    let (id, s) = state.session(req)?;
    let g = lock(state, &id, &s)?;
    Ok(state_response(&id, &g, None))
}

pub(super) fn edit(state: &State, req: &Request) -> Result<Response, Response> {
    let e: Edit = parse_json(&req.body)?;
    let (id, s) = state.session(req)?;
    let mut g = lock(state, &id, &s)?;
    let added = g.apply(e).map_err(bad)?;
    Ok(state_response(&id, &g, Some(("added", serde_json::json!(added)))))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TextureRequest {
    exemplar: FileRef,
    /// Output side in pixels (16..=1024). Default 512.
    size: Option<usize>,
    /// Exemplar pixels per design pixel. Default 1.
    scale: Option<f64>,
    seed: Option<u64>,
    /// The design version the page shows; a newer design answers 409 (stale).
    version: Option<u64>,
}

/// Reads an exemplar image through its confined root.
fn read_exemplar(state: &State, r: &FileRef) -> Result<fieldtex_core::Image, Response> {
    let root = state.root(&r.root)?;
    if !is_image_name(&r.path) {
        return Err(bad(format!("{:?} is not a .png/.jpg exemplar", r.path)));
    }
    let path = root.existing_file(&r.path).map_err(|(c, m)| Response::error(c, m))?;
    let meta = std::fs::metadata(&path).map_err(|e| bad(format!("{}: {e}", r.path)))?;
    if meta.len() as usize > state.max_upload {
        return Err(Response::error(413, format!("{} is over {} bytes", r.path, state.max_upload)));
    }
    fieldtex_io::read_image(&path).map_err(|e| bad(format!("exemplar {}: {e}", r.path)))
}

/// The texture of a session's current design (`size²`) and the milliseconds of the
/// synthesis, or 409 when the design changed meanwhile.
fn synthesize(
    state: &State,
    id: &str,
    s: &SessionRef,
    t: &TextureRequest,
) -> Result<(fieldtex_core::Image, f64, u64), Response> {
    let size = t.size.unwrap_or(512);
    if !(16..=1024).contains(&size) {
        return Err(bad(format!("size {size} is outside 16..=1024")));
    }
    let exemplar = read_exemplar(state, &t.exemplar)?;
    let stale =
        |v: u64| Response::error(409, format!("the design changed (now version {v}); ask again"));
    let (field, version, width) = {
        let mut g = lock(state, id, s)?;
        if let Some(v) = t.version
            && v != g.version
        {
            return Err(stale(g.version));
        }
        (g.sample(size).map_err(|e| Response::error(500, e))?, g.version, g.size().0)
    };
    let scale = t.scale.unwrap_or(1.0) * width / size as f64;
    if !(scale > 0.0 && scale <= 16.0) {
        return Err(bad(format!("scale × design size / size = {scale} is outside (0, 16]")));
    }
    let _one = state.synth_lock.lock().unwrap_or_else(|e| e.into_inner());
    if t.version.is_some() {
        let now = lock(state, id, s)?.version;
        if now != version {
            return Err(stale(now));
        }
    }
    let opts =
        fieldtex::FieldTextureOptions { scale, rosy_fix: true, seed: t.seed.unwrap_or(state.seed) };
    let t0 = Instant::now();
    let (image, _) = fieldtex::synthesize_field_texture(
        &exemplar,
        &field,
        size,
        size,
        &opts,
        &fieldtex::NoProgress,
    )
    .map_err(|e| match e {
        fieldtex::Error::Internal(m) => Response::error(500, m),
        other => bad(other.to_string()),
    })?;
    Ok((image, t0.elapsed().as_secs_f64() * 1e3, version))
}

pub(super) fn texture(state: &State, req: &Request) -> Result<Response, Response> {
    let t: TextureRequest = parse_json(&req.body)?;
    let (id, s) = state.session(req)?;
    let (image, ms, version) = synthesize(state, &id, &s, &t)?;
    let png = fieldtex_io::encode_png(&image).map_err(|e| Response::error(500, e.to_string()))?;
    Ok(Response::new(200, "image/png", png)
        .with_header("X-Synth-Ms", format!("{ms:.1}"))
        .with_header("X-Design-Version", version.to_string()))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ExportRequest {
    /// Output directory inside the workspace (created if missing).
    dir: String,
    /// With an exemplar, `texture.png` is synthesised and written too.
    exemplar: Option<FileRef>,
    /// Side of `field.npy` and `texture.png` (default: the design's width).
    size: Option<usize>,
    scale: Option<f64>,
    seed: Option<u64>,
}

pub(super) fn export(state: &State, req: &Request) -> Result<Response, Response> {
    let x: ExportRequest = parse_json(&req.body)?;
    let (id, s) = state.session(req)?;
    let io_err = |e: fieldtex_io::IoError| Response::error(500, e.to_string());
    let path_err = |(c, m): (u16, String)| Response::error(c, m);
    let (design, field, size) = {
        let mut g = lock(state, &id, &s)?;
        let size = x.size.unwrap_or(g.size().0.round() as usize);
        if !(16..=1024).contains(&size) {
            return Err(bad(format!("size {size} is outside 16..=1024")));
        }
        (g.design_file(), g.sample(size).map_err(|e| Response::error(500, e))?, size)
    };
    let mut files = Vec::new();
    let p = state.workspace.file_for_writing(&x.dir, "design.toml").map_err(path_err)?;
    fieldtex_io::atomic_write(&p, design.to_toml_string().as_bytes()).map_err(io_err)?;
    files.push(format!("{}/design.toml", x.dir));
    let flat: Vec<f32> = field.iter().flat_map(|v| [v[0], v[1]]).collect();
    let p = state.workspace.file_for_writing(&x.dir, "field.npy").map_err(path_err)?;
    fieldtex_io::write_npy_f32(&p, &[size, size, 2], &flat).map_err(io_err)?;
    files.push(format!("{}/field.npy", x.dir));
    if let Some(ex) = x.exemplar {
        let t = TextureRequest {
            exemplar: ex,
            size: Some(size),
            scale: x.scale,
            seed: x.seed,
            version: None,
        };
        let (image, _, _) = synthesize(state, &id, &s, &t)?;
        let p = state.workspace.file_for_writing(&x.dir, "texture.png").map_err(path_err)?;
        fieldtex_io::write_png(&p, &image).map_err(io_err)?;
        files.push(format!("{}/texture.png", x.dir));
    }
    Ok(Response::json(200, &serde_json::json!({ "files": files })))
}
