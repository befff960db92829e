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
    ("/page.js", "text/javascript; charset=utf-8", include_str!("../web/page.js")),
    ("/view.js", "text/javascript; charset=utf-8", include_str!("../web/view.js")),
    ("/jobs.js", "text/javascript; charset=utf-8", include_str!("../web/jobs.js")),
    ("/display.js", "text/javascript; charset=utf-8", include_str!("../web/display.js")),
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

mod file_routes;
mod job_routes;
mod mesh_routes;
mod session_routes;
mod solid_routes;
use file_routes::{file, upload};
use job_routes::{job_events, job_files, job_get, job_submit};
use mesh_routes::{mesh_field, mesh_frames, mesh_open, meshes};
use session_routes::{edit, export, get_state, new_session, texture};
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

/// Locks `m`; when a panic poisoned it, `forget` drops the object it guards and the
/// answer is a 500 with `message`.
fn lock_or_forget<'a, T>(
    m: &'a Mutex<T>,
    forget: impl FnOnce(),
    message: &str,
) -> Result<std::sync::MutexGuard<'a, T>, Response> {
    m.lock().map_err(|_| {
        forget();
        Response::error(500, message)
    })
}

/// Locks a session; a session whose lock was poisoned by a panic is dropped.
fn lock<'a>(
    state: &State,
    id: &str,
    s: &'a SessionRef,
) -> Result<std::sync::MutexGuard<'a, Session>, Response> {
    let message = "this design was dropped after an internal error; start a new one";
    lock_or_forget(s, || state.drop_session(id), message)
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

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileRef {
    root: String,
    path: String,
}
