//! Routes of the solid mode's open solid ([`fieldtex::SolidSession`], paper E): create
//! one from a mesh, an exemplar and the sketch (exemplar analysis, frame field), edit
//! its sketch (curve edits of the factored frame field; answers the frames at surface
//! samples) and cut it (a PNG computed on demand from the kept synthesizer).
//!
//! A solid is held behind its own mutex, so edits and cuts from two tabs run one after
//! the other and each sees a whole sketch; at most [`MAX_SOLIDS`] are open (the oldest
//! is dropped), because each keeps the blocks it computed.

use super::mesh_routes::mesh_file;
use super::*;
use fieldtex::SolidSession;

/// Most open solids.
pub(crate) const MAX_SOLIDS: usize = 2;
/// Voxels along the longest side an open solid may have.
const RESOLUTION_RANGE: std::ops::RangeInclusive<usize> = 16..=256;
/// Candidate-triple pool of the analysis: the studio's preview quality (as its jobs).
const PREVIEW_POOL: usize = 256;

pub(crate) type SolidRef = Arc<Mutex<SolidSession>>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CreateRequest {
    mesh: FileRef,
    exemplar: FileRef,
    sketch: Option<fieldtex_fields::Sketch>,
    /// Voxels along the longest side (16..=256, default 96).
    resolution: Option<usize>,
    seed: Option<u64>,
    /// Synthesis levels (2..=6, default 5) and block side (4..=32, default 12): coarser
    /// previews for small grids (`fieldtex solid --levels / --block`).
    levels: Option<usize>,
    block: Option<usize>,
    /// Frame samples in the answer (default 250).
    samples: Option<usize>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SketchRequest {
    sketch: fieldtex_fields::Sketch,
    samples: Option<usize>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CutRequest {
    /// `[x, y, z, nx, ny, nz]`: the image shows the plane, the mesh part kept is on
    /// the negative side.
    plane: [f64; 6],
}

fn solid_of(state: &State, req: &Request) -> Result<(String, SolidRef), Response> {
    let id = req.query("solid").ok_or_else(|| bad("give ?solid=ID"))?;
    let g = state.solids.lock().unwrap_or_else(|e| e.into_inner());
    g.iter().find(|(k, _)| k == id).map(|(k, s)| (k.clone(), s.clone())).ok_or_else(|| {
        Response::error(
            404,
            format!("no open solid {id:?} (expired or server restarted): open it again"),
        )
    })
}

/// Locks a solid; one whose lock was poisoned by a panic is dropped.
fn lock_solid<'a>(
    state: &State,
    id: &str,
    s: &'a SolidRef,
) -> Result<std::sync::MutexGuard<'a, SolidSession>, Response> {
    let forget = || state.solids.lock().unwrap_or_else(|e| e.into_inner()).retain(|(k, _)| k != id);
    lock_or_forget(s, forget, "this solid was dropped after an internal error; open it again")
}

fn facade_err(e: fieldtex::Error) -> Response {
    match e {
        fieldtex::Error::Internal(m) => Response::error(500, m),
        other => bad(other.to_string()),
    }
}

fn frames_json(s: &SolidSession, samples: usize) -> Result<serde_json::Value, Response> {
    let frames = crate::mesh_mode::frame_samples(s.mesh(), samples, |p| s.frame_at(p))
        .map_err(|(c, m)| Response::error(c, m))?;
    let errs = s.field().map(|f| f.constraint_errors_deg()).unwrap_or_default();
    Ok(serde_json::json!({
        "frames": frames,
        "alignment_error_max_deg": errs.iter().cloned().fold(0.0, f64::max),
    }))
}

pub(super) fn solid_create(state: &State, req: &Request) -> Result<Response, Response> {
    let c: CreateRequest = parse_json(&req.body)?;
    let resolution = c.resolution.unwrap_or(96);
    if !RESOLUTION_RANGE.contains(&resolution) {
        return Err(bad(format!("resolution {resolution} is outside 16..=256")));
    }
    let mesh = mesh_file(state, &c.mesh)?;
    let root = state.root(&c.exemplar.root)?;
    if !is_image_name(&c.exemplar.path) {
        return Err(bad(format!("{:?} is not a .png/.jpg exemplar", c.exemplar.path)));
    }
    let exemplar =
        root.existing_file(&c.exemplar.path).map_err(|(code, m)| Response::error(code, m))?;
    // A sketch without curves is no sketch (the constant field).
    if let Some(sk) = c.sketch.as_ref().filter(|s| !s.curves.is_empty()) {
        sk.validate().map_err(|e| bad(format!("sketch: {e}")))?;
    }
    let mut o = fieldtex::SolidOptions {
        mesh,
        exemplar: Some(exemplar),
        resolution,
        seed: c.seed.unwrap_or(state.seed),
        ..Default::default()
    };
    o.analysis.pool = PREVIEW_POOL;
    if let Some(l) = c.levels {
        if !(2..=6).contains(&l) {
            return Err(bad(format!("levels {l} is outside 2..=6")));
        }
        o.analysis.levels = l;
    }
    if let Some(b) = c.block {
        if !(4..=32).contains(&b) {
            return Err(bad(format!("block {b} is outside 4..=32")));
        }
        o.synthesis.block = b;
    }
    let t0 = Instant::now();
    let session =
        SolidSession::new(&o, c.sketch.as_ref(), &fieldtex::NoProgress).map_err(facade_err)?;
    if session.mesh().n_triangles() > crate::mesh_mode::MAX_TRIANGLES {
        return Err(Response::error(
            413,
            format!(
                "{} has {} triangles; the studio opens at most {}",
                c.mesh.path,
                session.mesh().n_triangles(),
                crate::mesh_mode::MAX_TRIANGLES
            ),
        ));
    }
    let build_ms = t0.elapsed().as_secs_f64() * 1e3;
    let mut body = frames_json(&session, c.samples.unwrap_or(250))?;
    let n = state.mesh_counter.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1;
    let id = format!("s{n}");
    body["id"] = serde_json::json!(id);
    body["grid"] = serde_json::json!(session.grid());
    body["build_ms"] = serde_json::json!(build_ms);
    body["warnings"] =
        serde_json::json!(session.warnings.iter().map(|w| w.to_string()).collect::<Vec<_>>());
    let mut g = state.solids.lock().unwrap_or_else(|e| e.into_inner());
    while g.len() >= MAX_SOLIDS {
        g.pop_front();
    }
    g.push_back((id, Arc::new(Mutex::new(session))));
    Ok(Response::json(200, &body))
}

pub(super) fn solid_sketch(state: &State, req: &Request) -> Result<Response, Response> {
    let r: SketchRequest = parse_json(&req.body)?;
    let (id, s) = solid_of(state, req)?;
    let mut g = lock_solid(state, &id, &s)?;
    let edit = g.set_sketch(&r.sketch).map_err(facade_err)?;
    let mut body = frames_json(&g, r.samples.unwrap_or(250))?;
    body["edit"] = serde_json::json!(edit);
    body["edit_ms"] = serde_json::json!(edit.seconds * 1e3);
    Ok(Response::json(200, &body))
}

pub(super) fn solid_cut(state: &State, req: &Request) -> Result<Response, Response> {
    let r: CutRequest = parse_json(&req.body)?;
    let (id, s) = solid_of(state, req)?;
    let mut g = lock_solid(state, &id, &s)?;
    let cut = g.cut(r.plane, &fieldtex::NoProgress).map_err(facade_err)?;
    drop(g);
    let png =
        fieldtex_io::encode_png(&cut.image).map_err(|e| Response::error(500, e.to_string()))?;
    Ok(Response::new(200, "image/png", png)
        .with_header("X-Cut-Ms", format!("{:.1}", cut.seconds * 1e3))
        .with_header("X-Voxels-Requested", cut.voxels_requested.to_string())
        .with_header("X-Voxels-Computed", cut.voxels_computed.to_string())
        .with_header("X-Grid-Slice", cut.grid_slice.to_string())
        .with_header("X-Cut-Placement", serde_json::json!(cut.placement).to_string()))
}
