//! Routes of the studio: the embedded page, the design-session JSON API, texture
//! synthesis, export, uploads and workspace files. Every handler returns a
//! [`Response`]; errors are `{"error": "..."}` with a 4xx status for the client's
//! mistakes and 5xx for the server's, and a panic is caught and answered with 500.

use crate::StudioOptions;
use crate::http::{Request, Response, read_request, write_response};
use crate::jobs::Jobs;
use crate::mesh_mode::MeshSession;
use crate::session::{Edit, Session};
use crate::workspace::{Root, check_file_name, is_image_name, is_mesh_name};
use fieldtex_fields::{DesignFile, SingularityKind, Symmetry};
use serde::Deserialize;
use std::collections::{HashMap, VecDeque};
use std::net::TcpStream;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// The embedded pages: URL path, content type, bytes.
const ASSETS: &[(&str, &str, &str)] = &[
    ("/", "text/html; charset=utf-8", include_str!("../web/index.html")),
    ("/index.html", "text/html; charset=utf-8", include_str!("../web/index.html")),
    ("/mesh.html", "text/html; charset=utf-8", include_str!("../web/mesh.html")),
    ("/app.js", "text/javascript; charset=utf-8", include_str!("../web/app.js")),
    ("/draw.js", "text/javascript; charset=utf-8", include_str!("../web/draw.js")),
    ("/mesh.js", "text/javascript; charset=utf-8", include_str!("../web/mesh.js")),
    ("/style.css", "text/css; charset=utf-8", include_str!("../web/style.css")),
];

/// The three.js modules copied by `scripts/setup-studio` (empty before it ran).
mod vendor {
    include!(concat!(env!("OUT_DIR"), "/vendor.rs"));
}

/// Every API route and its method (anything else on these paths is 405).
const ROUTES: &[(&str, &str)] = &[
    ("GET", "/api/info"),
    ("POST", "/api/session"),
    ("GET", "/api/state"),
    ("POST", "/api/edit"),
    ("POST", "/api/texture"),
    ("POST", "/api/export"),
    ("POST", "/api/upload"),
    ("GET", "/api/file"),
    ("GET", "/api/meshes"),
    ("POST", "/api/mesh/open"),
    ("POST", "/api/mesh/field"),
    ("POST", "/api/mesh/frames"),
    ("POST", "/api/solid/open"),
    ("POST", "/api/solid/sketch"),
    ("POST", "/api/solid/cut"),
    ("GET", "/api/jobs"),
    ("POST", "/api/jobs"),
    ("GET", "/api/jobs/get"),
    ("POST", "/api/jobs/cancel"),
    ("GET", "/api/jobs/events"),
    ("GET", "/api/jobs/files"),
];

mod job_routes;
mod mesh_routes;
mod solid_routes;
use job_routes::{job_events, job_files, job_get, job_submit};
use mesh_routes::{mesh_field, mesh_frames, mesh_open, meshes};
use solid_routes::{SolidRef, solid_create, solid_cut, solid_sketch};

/// Most meshes kept open at once (the oldest is dropped beyond).
const MAX_MESH_SESSIONS: usize = 8;

type SessionRef = Arc<Mutex<Session>>;

#[derive(Default)]
struct Sessions {
    map: HashMap<String, SessionRef>,
    order: VecDeque<String>,
    counter: u64,
}

/// Shared server state.
pub struct State {
    workspace: Root,
    exemplars: Option<Root>,
    meshes: Option<Root>,
    mesh_sessions: Mutex<VecDeque<(String, Arc<MeshSession>)>>,
    mesh_counter: std::sync::atomic::AtomicU64,
    /// Open solids (`api/solid_routes.rs`), oldest first.
    solids: Mutex<VecDeque<(String, SolidRef)>>,
    jobs: Arc<Jobs>,
    loopback: bool,
    pub(crate) max_connections: usize,
    max_upload: usize,
    max_json: usize,
    max_sessions: usize,
    seed: u64,
    sessions: Mutex<Sessions>,
    /// One synthesis at a time (they use all cores).
    synth_lock: Mutex<()>,
}

impl State {
    pub fn new(o: &StudioOptions) -> Result<Self, String> {
        let workspace = Root::new(&o.workspace, true)?;
        let exemplars = o.exemplars.as_deref().map(|d| Root::new(d, false)).transpose()?;
        let meshes = o.meshes.as_deref().map(|d| Root::new(d, false)).transpose()?;
        Ok(Self {
            workspace,
            exemplars,
            meshes,
            mesh_sessions: Mutex::new(VecDeque::new()),
            mesh_counter: std::sync::atomic::AtomicU64::new(0),
            solids: Mutex::new(VecDeque::new()),
            jobs: Jobs::start(o.max_jobs, 8),
            loopback: crate::is_loopback_host(&o.host),
            max_connections: o.max_connections.max(1),
            max_upload: o.max_upload_bytes,
            max_json: o.max_json_bytes,
            max_sessions: o.max_sessions.max(1),
            seed: o.seed,
            sessions: Mutex::new(Sessions::default()),
            synth_lock: Mutex::new(()),
        })
    }

    fn root(&self, name: &str) -> Result<&Root, Response> {
        match name {
            "workspace" => Ok(&self.workspace),
            "exemplars" => self.exemplars.as_ref().ok_or_else(|| {
                Response::error(404, "no exemplar directory was given (--exemplars)")
            }),
            "meshes" => self
                .meshes
                .as_ref()
                .ok_or_else(|| Response::error(404, "no meshes directory was given (--meshes)")),
            _ => Err(Response::error(
                400,
                format!("unknown root {name:?}: use \"workspace\", \"exemplars\" or \"meshes\""),
            )),
        }
    }

    fn session(&self, req: &Request) -> Result<(String, SessionRef), Response> {
        let id = req.query("session").ok_or_else(|| Response::error(400, "give ?session=ID"))?;
        let guard = self.sessions.lock().unwrap_or_else(|e| e.into_inner());
        let s = guard.map.get(id).cloned().ok_or_else(|| {
            Response::error(
                404,
                format!(
                    "no design session {id:?} (expired or server restarted): start a new design"
                ),
            )
        })?;
        Ok((id.to_string(), s))
    }

    fn insert_session(&self, session: Session) -> String {
        let mut g = self.sessions.lock().unwrap_or_else(|e| e.into_inner());
        g.counter += 1;
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let id = format!("d{}-{:08x}", g.counter, nanos);
        while g.order.len() >= self.max_sessions {
            if let Some(old) = g.order.pop_front() {
                g.map.remove(&old);
            }
        }
        g.order.push_back(id.clone());
        g.map.insert(id.clone(), Arc::new(Mutex::new(session)));
        id
    }

    fn drop_session(&self, id: &str) {
        let mut g = self.sessions.lock().unwrap_or_else(|e| e.into_inner());
        g.map.remove(id);
        g.order.retain(|s| s != id);
    }
}

/// Locks a session; a session whose lock was poisoned by a panic is dropped.
fn lock<'a>(
    state: &State,
    id: &str,
    s: &'a SessionRef,
) -> Result<std::sync::MutexGuard<'a, Session>, Response> {
    s.lock().map_err(|_| {
        state.drop_session(id);
        Response::error(500, "this design was dropped after an internal error; start a new one")
    })
}

/// Reads one request, answers it, closes.
pub fn handle_connection(state: &State, mut stream: TcpStream) {
    let response = match read_request(&stream, |path| {
        if path == "/api/upload" { state.max_upload } else { state.max_json }
    }) {
        Err(e) => {
            let r = Response::error(e.status, e.message);
            write_response(&mut stream, &r);
            let _ = stream.shutdown(std::net::Shutdown::Write);
            drain(&mut stream);
            return;
        }
        Ok(req) if req.method == "GET" && req.path == "/api/jobs/events" => {
            match refuse_foreign(state, &req) {
                Some(r) => r,
                None => {
                    job_events(state, &req, &mut stream);
                    return;
                }
            }
        }
        Ok(req) => match catch_unwind(AssertUnwindSafe(|| guarded(state, &req))) {
            Ok(r) => r,
            Err(_) => Response::error(
                500,
                "internal error while handling the request (see the server log)",
            ),
        },
    };
    write_response(&mut stream, &response);
    let _ = stream.shutdown(std::net::Shutdown::Write);
}

/// Reads and drops what the client still sends (at most 64 MiB, 2 s), so that closing
/// with unread data does not reset the connection before the client reads the answer.
fn drain(stream: &mut TcpStream) {
    use std::io::Read;
    let _ = stream.set_read_timeout(Some(std::time::Duration::from_millis(500)));
    let t = Instant::now();
    let mut buf = [0u8; 64 * 1024];
    let mut total = 0usize;
    while t.elapsed().as_secs() < 2 && total < 64 << 20 {
        match stream.read(&mut buf) {
            Ok(0) | Err(_) => break,
            Ok(n) => total += n,
        }
    }
}

fn host_name(host: &str) -> &str {
    if let Some(rest) = host.strip_prefix('[') {
        return rest.split(']').next().unwrap_or("");
    }
    host.rsplit_once(':').map_or(host, |(h, _)| h)
}

/// The DNS-rebinding and cross-site checks: `Some(403)` for a request to refuse.
fn refuse_foreign(state: &State, req: &Request) -> Option<Response> {
    let host = req.header("host").unwrap_or("");
    if state.loopback && !crate::is_loopback_host(host_name(host)) {
        return Some(Response::error(
            403,
            format!("Host {host:?} is not a loopback name; open http://127.0.0.1:PORT/"),
        ));
    }
    if let Some(origin) = req.header("origin")
        && origin != format!("http://{host}")
    {
        return Some(Response::error(403, format!("requests from {origin:?} are refused")));
    }
    None
}

fn guarded(state: &State, req: &Request) -> Response {
    refuse_foreign(state, req).unwrap_or_else(|| route(state, req))
}

fn route(state: &State, req: &Request) -> Response {
    if req.method == "GET" {
        if let Some((_, ct, body)) = ASSETS.iter().find(|(p, _, _)| *p == req.path) {
            return Response::new(200, ct, body.as_bytes().to_vec());
        }
        if let Some((_, body)) = vendor::VENDOR.iter().find(|(p, _)| *p == req.path) {
            return Response::new(200, "text/javascript; charset=utf-8", body.to_vec());
        }
    }
    match (req.method.as_str(), req.path.as_str()) {
        ("GET", "/api/info") => info(state),
        ("POST", "/api/session") => respond(new_session(state, req)),
        ("GET", "/api/state") => respond(get_state(state, req)),
        ("POST", "/api/edit") => respond(edit(state, req)),
        ("POST", "/api/texture") => respond(texture(state, req)),
        ("POST", "/api/export") => respond(export(state, req)),
        ("POST", "/api/upload") => respond(upload(state, req)),
        ("GET", "/api/file") => respond(file(state, req)),
        ("GET", "/api/meshes") => meshes(state),
        ("POST", "/api/mesh/open") => respond(mesh_open(state, req)),
        ("POST", "/api/mesh/field") => respond(mesh_field(state, req)),
        ("POST", "/api/mesh/frames") => respond(mesh_frames(state, req)),
        ("POST", "/api/solid/open") => respond(solid_create(state, req)),
        ("POST", "/api/solid/sketch") => respond(solid_sketch(state, req)),
        ("POST", "/api/solid/cut") => respond(solid_cut(state, req)),
        ("GET", "/api/jobs") => {
            Response::json(200, &serde_json::json!({ "jobs": state.jobs.list() }))
        }
        ("POST", "/api/jobs") => respond(job_submit(state, req)),
        ("GET", "/api/jobs/get") => {
            respond(job_get(state, req).map(|j| Response::json(200, &j.json())))
        }
        ("POST", "/api/jobs/cancel") => respond(job_get(state, req).map(|j| {
            j.request_cancel();
            Response::json(200, &j.json())
        })),
        ("GET", "/api/jobs/files") => respond(job_files(state, req)),
        (m, p) => {
            let known = ASSETS.iter().any(|(a, _, _)| *a == p)
                || vendor::VENDOR.iter().any(|(a, _)| *a == p)
                || ROUTES.iter().any(|(_, r)| *r == p);
            if known {
                Response::error(405, format!("{m} is not allowed on {p}"))
            } else if p.starts_with("/vendor/") {
                Response::error(
                    404,
                    format!(
                        "{p}: three.js is not embedded in this build; run scripts/setup-studio, then rebuild (cargo build --release -p fieldtex-cli)"
                    ),
                )
            } else {
                Response::error(404, format!("no route {p}"))
            }
        }
    }
}

fn respond(r: Result<Response, Response>) -> Response {
    r.unwrap_or_else(|e| e)
}

fn parse_json<'a, T: Deserialize<'a>>(body: &'a [u8]) -> Result<T, Response> {
    let body: &[u8] = if body.iter().all(|b| b.is_ascii_whitespace()) { b"{}" } else { body };
    serde_json::from_slice(body)
        .map_err(|e| Response::error(400, format!("malformed JSON body: {e}")))
}

fn bad(msg: impl Into<String>) -> Response {
    Response::error(400, msg)
}

fn info(state: &State) -> Response {
    let mut exemplars: Vec<serde_json::Value> = Vec::new();
    if let Some(r) = &state.exemplars {
        for p in r.list_images(200) {
            exemplars.push(serde_json::json!({ "root": "exemplars", "path": p }));
        }
    }
    for p in state.workspace.list_images(200) {
        exemplars.push(serde_json::json!({ "root": "workspace", "path": p }));
    }
    let kinds: Vec<_> = SingularityKind::ALL
        .iter()
        .map(|k| serde_json::json!({ "name": k.name(), "symmetry": k.symmetry().name() }))
        .collect();
    Response::json(
        200,
        &serde_json::json!({
            "presets": fieldtex_fields::presets::PRESET_NAMES,
            "kinds": kinds,
            "exemplars": exemplars,
            "workspace": state.workspace.dir.display().to_string(),
            "max_upload_bytes": state.max_upload,
            "seed": state.seed,
            "three": vendor::VENDOR_VERSION,
            "setup_command": "scripts/setup-studio && cargo build --release -p fieldtex-cli",
        }),
    )
}

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

fn new_session(state: &State, req: &Request) -> Result<Response, Response> {
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

fn get_state(state: &State, req: &Request) -> Result<Response, Response> {
    let (id, s) = state.session(req)?;
    let g = lock(state, &id, &s)?;
    Ok(state_response(&id, &g, None))
}

fn edit(state: &State, req: &Request) -> Result<Response, Response> {
    let e: Edit = parse_json(&req.body)?;
    let (id, s) = state.session(req)?;
    let mut g = lock(state, &id, &s)?;
    let added = g.apply(e).map_err(bad)?;
    Ok(state_response(&id, &g, Some(("added", serde_json::json!(added)))))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileRef {
    root: String,
    path: String,
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

fn texture(state: &State, req: &Request) -> Result<Response, Response> {
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

fn export(state: &State, req: &Request) -> Result<Response, Response> {
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

fn upload(state: &State, req: &Request) -> Result<Response, Response> {
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

fn file(state: &State, req: &Request) -> Result<Response, Response> {
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
