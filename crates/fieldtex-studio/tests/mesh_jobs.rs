//! Server tests of the mesh modes and jobs: mesh uploads (good, garbage, bad names,
//! oversized), opening meshes (traversal, links, wrong kinds), field and frame
//! requests with garbage bodies, jobs end to end (SSE events, output listing, files),
//! cancellation, and traversal or link escapes through job listings.

use std::io::{BufRead, BufReader, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::PathBuf;
use std::time::{Duration, Instant};

mod common;
use common::{request, temp_dir, write_inputs};

fn start(tag: &str) -> (SocketAddr, PathBuf) {
    common::start(tag, 256 * 1024)
}

fn open_mesh(addr: SocketAddr, path: &str) -> (serde_json::Value, Vec<f32>, Vec<u32>) {
    let r = request(
        addr,
        "POST",
        "/api/mesh/open",
        format!(r#"{{"root":"workspace","path":"{path}"}}"#).as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    let n = u32::from_le_bytes(r.body[..4].try_into().unwrap()) as usize;
    let json: serde_json::Value = serde_json::from_slice(&r.body[4..4 + n]).unwrap();
    let nv = json["vertices"].as_u64().unwrap() as usize;
    let nt = json["triangles"].as_u64().unwrap() as usize;
    let rest = &r.body[4 + n..];
    assert_eq!(rest.len(), nv * 12 + nt * 12);
    let pos = rest[..nv * 12].chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap()));
    let idx = rest[nv * 12..].chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().unwrap()));
    (json, pos.collect(), idx.collect())
}

fn wait_job(addr: SocketAddr, id: &str, limit: Duration) -> serde_json::Value {
    let t = Instant::now();
    loop {
        let j = request(addr, "GET", &format!("/api/jobs/get?id={id}"), b"").json();
        if matches!(j["state"].as_str(), Some("done" | "failed" | "cancelled")) {
            return j;
        }
        assert!(t.elapsed() < limit, "job {id} still {j}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

#[test]
fn meshes_open_with_crest_lines_and_field_streamlines() {
    let (addr, ws) = start("open");
    write_inputs(&ws);
    let (json, pos, idx) = open_mesh(addr, "torus.obj");
    assert_eq!(json["triangles"], 24 * 12 * 2);
    assert!(pos.iter().all(|x| x.is_finite()));
    assert!(idx.iter().all(|&i| (i as usize) < pos.len() / 3));
    let id = json["id"].as_str().unwrap();
    // The field of one curve around the tube: streamlines on the surface.
    let curve: Vec<[f64; 3]> = (0..=12)
        .map(|k| {
            let a = k as f64 / 12.0 * std::f64::consts::PI;
            [1.4 * a.cos(), 1.4 * a.sin(), 0.0]
        })
        .collect();
    let body = serde_json::json!({ "curves": [curve], "seeds": 60 }).to_string();
    let r = request(addr, "POST", &format!("/api/mesh/field?mesh={id}"), body.as_bytes());
    assert_eq!(r.status, 200, "{}", r.error());
    let lines = r.json()["lines"].as_array().unwrap().clone();
    assert!(lines.len() >= 30, "{} lines", lines.len());
    // Every streamline point lies on the mesh (f32 precision).
    let mesh = fieldtex_mesh::primitives::torus(1.0, 0.4, 24, 12);
    let bvh = fieldtex_mesh::Bvh::build(&mesh).unwrap();
    for l in &lines {
        let l = l.as_array().unwrap();
        assert!(l.len() >= 2);
        for p in l {
            let p: Vec<f64> = p.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            let d = bvh.closest_point([p[0], p[1], p[2]]).unwrap().distance;
            assert!(d < 1e-5, "point {p:?} is {d} off the surface");
        }
    }
    // Frames of a sketch along the same curve.
    let sketch =
        serde_json::json!({ "sketch": { "curves": [{ "points": curve }] }, "samples": 40 });
    let r = request(
        addr,
        "POST",
        &format!("/api/mesh/frames?mesh={id}"),
        sketch.to_string().as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.error());
    let j = r.json();
    assert!(j["frames"].as_array().unwrap().len() >= 20);
    assert!(
        j["alignment_error_max_deg"].as_f64().unwrap() < 5.0,
        "{}",
        j["alignment_error_max_deg"]
    );
    // Garbage: bodies, curves, ids, kinds.
    for (path, body) in [
        (format!("/api/mesh/field?mesh={id}"), "{".to_string()),
        (format!("/api/mesh/field?mesh={id}"), r#"{"curves": [[[0,0,0]]]}"#.to_string()),
        (format!("/api/mesh/field?mesh={id}"), r#"{"curves": [[[0,0,0],[1,"x",0]]]}"#.to_string()),
        (format!("/api/mesh/field?mesh={id}"), r#"{"curvez": []}"#.to_string()),
        (
            format!("/api/mesh/frames?mesh={id}"),
            r#"{"sketch": {"curves": [{"points": [[0,0,0]]}]}}"#.to_string(),
        ),
        ("/api/mesh/field".to_string(), "{}".to_string()),
        ("/api/mesh/open".to_string(), r#"{"root":"workspace","path":"stripes.png"}"#.to_string()),
        ("/api/mesh/open".to_string(), r#"{"root":"nowhere","path":"torus.obj"}"#.to_string()),
    ] {
        let r = request(addr, "POST", &path, body.as_bytes());
        assert!((400..500).contains(&r.status), "{path} {body}: {}", r.status);
        assert!(!r.error().is_empty());
    }
    let r = request(addr, "POST", "/api/mesh/field?mesh=m999", b"{}");
    assert_eq!(r.status, 404);
}

#[test]
fn mesh_paths_and_uploads_stay_confined() {
    let (addr, ws) = start("confine");
    write_inputs(&ws);
    let outside = temp_dir("outside");
    fieldtex_io::write_obj(
        &outside.join("secret.obj"),
        &fieldtex_mesh::primitives::icosphere(1),
        None,
    )
    .unwrap();
    std::os::unix::fs::symlink(outside.join("secret.obj"), ws.join("link.obj")).unwrap();
    for path in ["../secret.obj", "/etc/passwd.obj", "link.obj", "a/../../x.obj", "missing.obj"] {
        let body = format!(r#"{{"root":"workspace","path":"{path}"}}"#);
        let r = request(addr, "POST", "/api/mesh/open", body.as_bytes());
        assert!(matches!(r.status, 403 | 404), "{path}: {}", r.status);
    }
    // Mesh uploads: read back by the mesh reader before they take the name.
    let obj = std::fs::read(ws.join("torus.obj")).unwrap();
    let r = request(addr, "POST", "/api/upload?name=up.obj", &obj);
    assert_eq!(r.status, 200, "{}", r.error());
    assert_eq!(r.json()["path"], "uploads/up.obj");
    let (json, _, _) = open_mesh(addr, "uploads/up.obj");
    assert_eq!(json["triangles"], 24 * 12 * 2);
    for (name, body) in [
        ("bad.obj", b"v 0 0 0\nf 1 2 3\nthis is not obj".to_vec()),
        ("bad.glb", b"glTF garbage".to_vec()),
        ("empty.stl", Vec::new()),
        ("../x.obj", obj.clone()),
        ("x.exe", obj.clone()),
    ] {
        let r = request(addr, "POST", &format!("/api/upload?name={name}"), &body);
        assert!((400..500).contains(&r.status), "{name}: {}", r.status);
        assert!(!ws.join("uploads").join(name).exists(), "{name} was kept");
    }
    let names: Vec<_> = std::fs::read_dir(ws.join("uploads")).unwrap().flatten().collect();
    assert_eq!(names.len(), 1, "only the good upload remains: {names:?}");
    let big = vec![b'v'; 300 * 1024];
    let r = request(addr, "POST", "/api/upload?name=big.obj", &big);
    assert_eq!(r.status, 413);
    // The mesh list names both, and nothing outside.
    let list = request(addr, "GET", "/api/meshes", b"").json();
    let paths: Vec<_> =
        list["meshes"].as_array().unwrap().iter().map(|m| m["path"].as_str().unwrap()).collect();
    assert!(paths.contains(&"torus.obj") && paths.contains(&"uploads/up.obj"), "{paths:?}");
    assert!(outside.join("secret.obj").exists());
}

#[test]
fn jobs_run_stream_list_and_cancel() {
    let (addr, ws) = start("jobs");
    write_inputs(&ws);
    // Bad job requests first.
    for body in [
        r#"{"kind":"rm -rf"}"#,
        r#"{"kind":"align"}"#,
        r#"{"kind":"align","mesh":{"root":"workspace","path":"../x.obj"},"exemplar":{"root":"workspace","path":"stripes.png"}}"#,
        r#"{"kind":"align","mesh":{"root":"workspace","path":"torus.obj"},"exemplar":{"root":"workspace","path":"torus.obj"}}"#,
        r#"{"kind":"align","mesh":{"root":"workspace","path":"torus.obj"},"exemplar":{"root":"workspace","path":"stripes.png"},"size":9}"#,
        r#"{"kind":"solid","mesh":{"root":"workspace","path":"torus.obj"},"exemplar":{"root":"workspace","path":"stripes.png"},"sketch":{"curves":[]},"resolution":4}"#,
        r#"{"kind":"solid","mesh":{"root":"workspace","path":"torus.obj"},"exemplar":{"root":"workspace","path":"stripes.png"},"sketch":{"curvez":1}}"#,
        "not json",
    ] {
        let r = request(addr, "POST", "/api/jobs", body.as_bytes());
        assert!((400..500).contains(&r.status), "{body}: {}", r.status);
    }
    // An align job with one curve; its events arrive over SSE until it ends.
    let body = serde_json::json!({
        "kind": "align",
        "mesh": {"root": "workspace", "path": "torus.obj"},
        "exemplar": {"root": "workspace", "path": "stripes.png"},
        "curves": [[[1.4, 0.0, 0.0], [0.0, 1.4, 0.0], [-1.4, 0.0, 0.0]]],
        "size": 64,
    });
    let r = request(addr, "POST", "/api/jobs", body.to_string().as_bytes());
    assert_eq!(r.status, 200, "{}", r.error());
    let id = r.json()["id"].as_str().unwrap().to_string();
    // A second job waits behind it (one worker) and is cancelled while queued.
    let body2 = serde_json::json!({
        "kind": "conformal",
        "mesh": {"root": "workspace", "path": "torus.obj"},
        "exemplar": {"root": "workspace", "path": "stripes.png"},
        "size": 64,
    });
    let r2 = request(addr, "POST", "/api/jobs", body2.to_string().as_bytes()).json();
    let id2 = r2["id"].as_str().unwrap().to_string();
    let c = request(addr, "POST", &format!("/api/jobs/cancel?id={id2}"), b"").json();
    assert_eq!(c["state"], "cancelled", "{c}");
    let mut s = TcpStream::connect(addr).unwrap();
    write!(s, "GET /api/jobs/events?id={id} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\n\r\n", addr.port())
        .unwrap();
    s.set_read_timeout(Some(Duration::from_secs(120))).unwrap();
    let mut events = Vec::new();
    let mut ended = false;
    for line in BufReader::new(s).lines() {
        let Ok(line) = line else { break };
        if let Some(d) = line.strip_prefix("data: ") {
            events.push(serde_json::from_str::<serde_json::Value>(d).unwrap());
        }
        if line == "event: end" {
            ended = true;
        }
    }
    assert!(ended, "the event stream ended without an end event");
    let last = events.iter().rev().find(|e| e.get("state").is_some()).unwrap();
    assert_eq!(last["state"], "done", "{last}");
    assert!(events.len() >= 2, "{} events", events.len());
    let files: Vec<String> =
        last["files"].as_array().unwrap().iter().map(|f| f.as_str().unwrap().to_string()).collect();
    assert!(files.contains(&"model.glb".to_string()) && files.contains(&"report.json".to_string()));
    let dir = last["dir"].as_str().unwrap();
    let listed = request(addr, "GET", &format!("/api/jobs/files?id={id}"), b"").json();
    assert!(listed["files"].as_array().unwrap().iter().any(|f| f == &format!("{dir}/model.glb")));
    let glb = request(addr, "GET", &format!("/api/file?path={dir}/model.glb"), b"");
    assert_eq!(glb.status, 200);
    assert_eq!(&glb.body[..4], b"glTF");
    // The align job used the given curve file, kept beside its outputs.
    assert!(ws.join(format!("{dir}-inputs/curves.obj")).is_file());
    // The cancelled job never ran and wrote nothing.
    let j2 = wait_job(addr, &id2, Duration::from_secs(5));
    assert_eq!(j2["state"], "cancelled");
    assert!(!ws.join(j2["dir"].as_str().unwrap()).join("report.json").exists());
    // Unknown and traversal job ids.
    for q in ["nope", "../../etc", "%2e%2e"] {
        assert_eq!(request(addr, "GET", &format!("/api/jobs/files?id={q}"), b"").status, 404);
    }
    // A job folder swapped for a link to outside is refused when listed.
    let outside = temp_dir("outside-jobs");
    std::fs::write(outside.join("secret.txt"), b"x").unwrap();
    let job_dir = ws.join(dir);
    std::fs::rename(&job_dir, ws.join("moved")).unwrap();
    std::os::unix::fs::symlink(&outside, &job_dir).unwrap();
    let r = request(addr, "GET", &format!("/api/jobs/files?id={id}"), b"");
    assert_eq!(r.status, 403, "{}", String::from_utf8_lossy(&r.body));
    let r = request(addr, "GET", &format!("/api/file?path={dir}/secret.txt"), b"");
    assert_eq!(r.status, 403);
}

#[test]
fn a_running_job_stops_at_the_next_stage_when_cancelled() {
    let (addr, ws) = start("cancel");
    write_inputs(&ws);
    let body = serde_json::json!({
        "kind": "solid",
        "mesh": {"root": "workspace", "path": "torus.obj"},
        "exemplar": {"root": "workspace", "path": "stripes.png"},
        "resolution": 64,
        "size": 256,
    });
    let j = request(addr, "POST", "/api/jobs", body.to_string().as_bytes()).json();
    let id = j["id"].as_str().unwrap().to_string();
    let t = Instant::now();
    while request(addr, "GET", &format!("/api/jobs/get?id={id}"), b"").json()["state"] == "queued" {
        assert!(t.elapsed() < Duration::from_secs(10));
        std::thread::sleep(Duration::from_millis(5));
    }
    request(addr, "POST", &format!("/api/jobs/cancel?id={id}"), b"");
    let end = wait_job(addr, &id, Duration::from_secs(60));
    // The run stops at its next stage boundary with nothing written.
    assert_eq!(end["state"], "cancelled", "{end}");
    assert!(!ws.join(end["dir"].as_str().unwrap()).join("model.glb").exists());
}
