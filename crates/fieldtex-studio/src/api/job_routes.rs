//! Routes of the jobs: submit (options checked, inputs the page made written beside the
//! job folder), get, cancel, list a job's files (re-confined) and its server-sent events.

use super::mesh_routes::mesh_file;
use super::*;
use crate::jobs::JobTask;

/// Candidate-triple pool of the studio's solid jobs (module docs of `job_submit`).
const SOLID_PREVIEW_POOL: usize = 256;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JobRequest {
    kind: String,
    /// align, conformal, solid: the mesh; transfer: the target.
    mesh: Option<FileRef>,
    /// transfer: the textured source mesh.
    source: Option<FileRef>,
    exemplar: Option<FileRef>,
    /// align: curves on the surface (written as `curves.obj`); `None` = crest lines.
    curves: Option<Vec<Vec<[f64; 3]>>>,
    /// solid: the sketch JSON (`fieldtex_fields::sketch`), written as `sketch.json`.
    sketch: Option<serde_json::Value>,
    /// solid: cut planes `[x, y, z, nx, ny, nz]`.
    cuts: Option<Vec<[f64; 6]>>,
    /// solid: voxels along the longest side (8..=512, default 96).
    resolution: Option<usize>,
    /// Atlas / texture size (64..=2048, default 512).
    size: Option<usize>,
    seed: Option<u64>,
}

pub(super) fn job_submit(state: &State, req: &Request) -> Result<Response, Response> {
    let j: JobRequest = parse_json(&req.body)?;
    let size = j.size.unwrap_or(512);
    if !(64..=2048).contains(&size) {
        return Err(bad(format!("size {size} is outside 64..=2048")));
    }
    let seed = j.seed.unwrap_or(state.seed);
    let need = |r: &Option<FileRef>, what: &str| -> Result<std::path::PathBuf, Response> {
        let r = r.as_ref().ok_or_else(|| bad(format!("a {} job needs \"{what}\"", j.kind)))?;
        if what == "exemplar" {
            let root = state.root(&r.root)?;
            if !is_image_name(&r.path) {
                return Err(bad(format!("{:?} is not a .png/.jpg exemplar", r.path)));
            }
            root.existing_file(&r.path).map_err(|(c, m)| Response::error(c, m))
        } else {
            mesh_file(state, r)
        }
    };
    if !matches!(j.kind.as_str(), "align" | "conformal" | "transfer" | "solid") {
        return Err(bad(format!(
            "unknown job kind {:?}: use align, conformal, transfer or solid",
            j.kind
        )));
    }
    let (id, dir) = state.jobs.next_id(&j.kind);
    let out_rel = format!("jobs/{dir}");
    let path_err = |(c, m): (u16, String)| Response::error(c, m);
    let inputs_rel = format!("jobs/{dir}-inputs");
    let task = match j.kind.as_str() {
        "align" => {
            let mut o = fieldtex::AlignOptions {
                mesh: need(&j.mesh, "mesh")?,
                exemplar: need(&j.exemplar, "exemplar")?,
                size,
                seed,
                ..Default::default()
            };
            if let Some(c) = &j.curves {
                crate::mesh_mode::check_curves(c).map_err(bad)?;
                let p = state
                    .workspace
                    .file_for_writing(&inputs_rel, "curves.obj")
                    .map_err(path_err)?;
                fieldtex_io::write_obj_polylines(&p, c)
                    .map_err(|e| Response::error(500, e.to_string()))?;
                o.curves = Some(p);
            }
            JobTask::Align(Box::new(o))
        }
        "conformal" => JobTask::Conformal(Box::new(fieldtex::ConformalOptions {
            mesh: need(&j.mesh, "mesh")?,
            exemplar: need(&j.exemplar, "exemplar")?,
            size,
            seed,
            ..Default::default()
        })),
        "transfer" => {
            let mut o = fieldtex::TransferCommandOptions {
                source: need(&j.source, "source")?,
                target: need(&j.mesh, "mesh")?,
                size,
                ..Default::default()
            };
            o.transfer.seed = seed;
            JobTask::Transfer(Box::new(o))
        }
        _ => {
            let resolution = j.resolution.unwrap_or(96);
            if !(8..=512).contains(&resolution) {
                return Err(bad(format!("resolution {resolution} is outside 8..=512")));
            }
            let cuts = j.cuts.clone().unwrap_or_default();
            if cuts.len() > 4 || cuts.iter().flatten().any(|x| !x.is_finite()) {
                return Err(bad("give at most 4 cuts of 6 finite numbers"));
            }
            let mut o = fieldtex::SolidOptions {
                mesh: need(&j.mesh, "mesh")?,
                exemplar: Some(need(&j.exemplar, "exemplar")?),
                resolution,
                cuts,
                atlas_size: size,
                seed,
                ..Default::default()
            };
            // Preview quality for interactive cuts: the candidate-triple search looks at
            // a pool of 256 exemplar pixels instead of 1024 (the analysis dominates a
            // small run); `fieldtex solid` keeps the full default.
            o.analysis.pool = SOLID_PREVIEW_POOL;
            if let Some(sk) = &j.sketch {
                let text = sk.to_string();
                let parsed: fieldtex_fields::Sketch =
                    serde_json::from_value(sk.clone()).map_err(|e| bad(format!("sketch: {e}")))?;
                parsed.validate().map_err(|e| bad(format!("sketch: {e}")))?;
                let p = state
                    .workspace
                    .file_for_writing(&inputs_rel, "sketch.json")
                    .map_err(path_err)?;
                fieldtex_io::atomic_write(&p, text.as_bytes())
                    .map_err(|e| Response::error(500, e.to_string()))?;
                o.sketch = Some(p);
            }
            JobTask::Solid(Box::new(o))
        }
    };
    let out_dir = state.workspace.dir_for_writing(&out_rel).map_err(path_err)?;
    let job = state.jobs.submit(id, out_rel, out_dir, task).map_err(|m| Response::error(503, m))?;
    Ok(Response::json(200, &job.json()))
}

pub(super) fn job_get(state: &State, req: &Request) -> Result<Arc<crate::jobs::Job>, Response> {
    let id = req.query("id").ok_or_else(|| bad("give ?id=JOB"))?;
    state.jobs.get(id).ok_or_else(|| Response::error(404, format!("no job {id:?}")))
}

pub(super) fn job_files(state: &State, req: &Request) -> Result<Response, Response> {
    let job = job_get(state, req)?;
    let files =
        crate::jobs::job_files(&state.workspace, &job).map_err(|(c, m)| Response::error(c, m))?;
    Ok(Response::json(200, &serde_json::json!({ "id": job.id, "files": files })))
}

/// Streams a job's state as server-sent events (`data: {json}`) until it ends or the
/// client goes away: one event per change, checked every 50 ms.
pub(super) fn job_events(state: &State, req: &Request, stream: &mut TcpStream) {
    use std::io::Write;
    let job = match job_get(state, req) {
        Ok(j) => j,
        Err(r) => {
            write_response(stream, &r);
            return;
        }
    };
    let head = "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\nConnection: close\r\nX-Content-Type-Options: nosniff\r\n\r\n";
    if stream.write_all(head.as_bytes()).is_err() {
        return;
    }
    let mut last = String::new();
    let mut quiet = Instant::now();
    loop {
        let finished = job.finished();
        let text = job.json().to_string();
        if text != last {
            if stream.write_all(format!("data: {text}\n\n").as_bytes()).is_err() {
                return;
            }
            let _ = stream.flush();
            last = text;
            quiet = Instant::now();
        } else if quiet.elapsed().as_secs() >= 10 {
            // A comment line: detects clients that went away.
            if stream.write_all(b": alive\n\n").is_err() {
                return;
            }
            quiet = Instant::now();
        }
        if finished {
            let _ = stream.write_all(b"event: end\ndata: {}\n\n");
            let _ = stream.shutdown(std::net::Shutdown::Write);
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
}
