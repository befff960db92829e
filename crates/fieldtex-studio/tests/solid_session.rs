//! Server tests of the open solid (`/api/solid/open`, `/sketch`, `/cut`): a cut on
//! demand as PNG, the repeated cut from the kept blocks, sketch edits through the
//! factored field, garbage bodies, refused sizes and planes, unknown ids, paths outside
//! the workspace, and concurrent edits and cuts from several clients.

use std::net::SocketAddr;
use std::path::PathBuf;

mod common;
use common::{request, write_inputs};

fn start(tag: &str) -> (SocketAddr, PathBuf) {
    common::start(tag, 256 * 1024)
}

const SURFACE_CURVE: &str = r#"{"points": [[1.4, 0, 0], [0, 1.4, 0], [-1.4, 0, 0]], "axis": "x"}"#;
const PLANE_CURVE: &str = r#"{"points": [[-1, -1, 0.1], [1, 1, 0.1]], "plane": {"point": [0, 0, 0], "normal": [0, 0, 1]}, "axis": "y"}"#;

fn open_solid(addr: SocketAddr, sketch: &str) -> String {
    let body = format!(
        r#"{{"mesh": {{"root": "workspace", "path": "torus.obj"}}, "exemplar": {{"root": "workspace", "path": "stripes.png"}}, "resolution": 24, "levels": 3, "block": 6, "sketch": {sketch}, "samples": 40}}"#
    );
    let r = request(addr, "POST", "/api/solid/open", body.as_bytes());
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    let j = r.json();
    assert!(j["frames"].as_array().unwrap().len() >= 10);
    assert_eq!(j["grid"]["sizes"][0], 24);
    j["id"].as_str().unwrap().to_string()
}

/// A cut through the torus's middle plane z = 0.05 (normal z): `(status, png, computed)`.
fn cut(addr: SocketAddr, id: &str, z: f64) -> (u16, Vec<u8>, u64) {
    let r = request(
        addr,
        "POST",
        &format!("/api/solid/cut?solid={id}"),
        format!(r#"{{"plane": [0.1, 0, {z}, 0, 0, 1]}}"#).as_bytes(),
    );
    let computed = r.header("x-voxels-computed").and_then(|v| v.parse().ok()).unwrap_or(u64::MAX);
    (r.status, r.body, computed)
}

#[test]
fn open_solid_cuts_on_demand_and_edits_its_sketch() {
    let (addr, ws) = start("solid");
    write_inputs(&ws);
    let id = open_solid(addr, &format!(r#"{{"curves": [{SURFACE_CURVE}]}}"#));
    let (status, png, computed) = cut(addr, &id, 0.05);
    assert_eq!(status, 200);
    assert!(computed > 0);
    let img = fieldtex_io::read_image_bytes(&png, "cut.png").unwrap();
    let opaque = img.pixels.iter().filter(|p| p[3] > 0.5).count();
    assert!(opaque > 50, "{opaque} opaque pixels of {}×{}", img.width, img.height);
    // The same plane again: the kept blocks, the same bytes.
    let (_, png2, computed2) = cut(addr, &id, 0.05);
    assert_eq!(computed2, 0);
    assert_eq!(png, png2);
    // A sketch edit (a reference-plane curve added): frames back, the cut changes.
    let r = request(
        addr,
        "POST",
        &format!("/api/solid/sketch?solid={id}"),
        format!(r#"{{"sketch": {{"curves": [{SURFACE_CURVE}, {PLANE_CURVE}]}}, "samples": 40}}"#)
            .as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    let j = r.json();
    assert_eq!((j["edit"]["kept"].as_u64(), j["edit"]["added"].as_u64()), (Some(1), Some(1)));
    assert!(j["frames"].as_array().unwrap().len() >= 10);
    let (status, png3, computed3) = cut(addr, &id, 0.05);
    assert_eq!(status, 200);
    assert!(computed3 > 0);
    assert_ne!(png, png3, "the edit did not change the cut");
    // Clearing the sketch: the constant field, both curves removed.
    let r = request(
        addr,
        "POST",
        &format!("/api/solid/sketch?solid={id}"),
        br#"{"sketch": {"curves": []}, "samples": 20}"#,
    );
    assert_eq!(r.status, 200, "{}", r.error());
    assert_eq!(r.json()["edit"]["removed"].as_u64(), Some(2));

    // Garbage, refused sizes and planes, unknown ids: clear 4xx, the server lives on.
    let open = |body: &str| request(addr, "POST", "/api/solid/open", body.as_bytes());
    for (body, want) in [
        ("{not json", 400),
        (r#"{"mesh": 3}"#, 400),
        (
            r#"{"mesh": {"root": "workspace", "path": "torus.obj"}, "exemplar": {"root": "workspace", "path": "stripes.png"}, "resolution": 100000}"#,
            400,
        ),
        (
            r#"{"mesh": {"root": "workspace", "path": "torus.obj"}, "exemplar": {"root": "workspace", "path": "stripes.png"}, "bogus": 1}"#,
            400,
        ),
        (
            r#"{"mesh": {"root": "workspace", "path": "torus.obj"}, "exemplar": {"root": "workspace", "path": "stripes.png"}, "levels": 60}"#,
            400,
        ),
        (
            r#"{"mesh": {"root": "workspace", "path": "torus.obj"}, "exemplar": {"root": "workspace", "path": "stripes.png"}, "block": 1000}"#,
            400,
        ),
        (
            r#"{"mesh": {"root": "workspace", "path": "../../etc/passwd.obj"}, "exemplar": {"root": "workspace", "path": "stripes.png"}}"#,
            400,
        ),
        (
            r#"{"mesh": {"root": "workspace", "path": "missing.obj"}, "exemplar": {"root": "workspace", "path": "stripes.png"}}"#,
            404,
        ),
        (
            r#"{"mesh": {"root": "workspace", "path": "torus.obj"}, "exemplar": {"root": "workspace", "path": "torus.obj"}}"#,
            400,
        ),
        (
            r#"{"mesh": {"root": "workspace", "path": "torus.obj"}, "exemplar": {"root": "workspace", "path": "stripes.png"}, "sketch": {"curves": [{"points": [[0, 0, 0]]}]}}"#,
            400,
        ),
    ] {
        let r = open(body);
        assert!((400..500).contains(&r.status), "{body}: {} {}", r.status, r.error());
        if want == 404 {
            assert_eq!(r.status, 404, "{body}: {}", r.error());
        }
        assert!(!r.error().is_empty(), "{body}: no message");
    }
    let post = |path: &str, body: &str| request(addr, "POST", path, body.as_bytes());
    let c = format!("/api/solid/cut?solid={id}");
    for body in [
        "",
        "{}",
        "[1,2]",
        r#"{"plane": [0, 0, 0, 0, 0, 0]}"#,
        r#"{"plane": [0, 0, -99, 0, 0, 1]}"#,
        r#"{"plane": [0, 0, 0]}"#,
        r#"{"plane": [0, 0, 1e400, 0, 0, 1]}"#,
    ] {
        let r = post(&c, body);
        assert!((400..500).contains(&r.status), "{body}: {}", r.status);
    }
    assert_eq!(post("/api/solid/cut?solid=nope", r#"{"plane": [0, 0, 0, 0, 0, 1]}"#).status, 404);
    assert_eq!(post("/api/solid/cut", r#"{"plane": [0, 0, 0, 0, 0, 1]}"#).status, 400);
    assert_eq!(post(&format!("/api/solid/sketch?solid={id}"), r#"{"sketch": 5}"#).status, 400);
    assert_eq!(request(addr, "GET", "/api/solid/cut", b"").status, 405);
    // Still serving, and the solid still answers.
    assert_eq!(cut(addr, &id, 0.05).0, 200);
    // Nothing was written outside the two inputs (the solid keeps no files).
    let mut names: Vec<_> =
        std::fs::read_dir(&ws).unwrap().map(|e| e.unwrap().file_name()).collect();
    names.sort();
    assert_eq!(names, ["stripes.png", "torus.obj"]);
}

#[test]
fn concurrent_edits_and_cuts_on_one_solid() {
    let (addr, ws) = start("solid-concurrent");
    write_inputs(&ws);
    let id = open_solid(addr, &format!(r#"{{"curves": [{SURFACE_CURVE}]}}"#));
    let sketches = [
        format!(r#"{{"curves": [{SURFACE_CURVE}]}}"#),
        format!(r#"{{"curves": [{SURFACE_CURVE}, {PLANE_CURVE}]}}"#),
        format!(r#"{{"curves": [{PLANE_CURVE}]}}"#),
    ];
    let handles: Vec<_> = (0..8)
        .map(|t| {
            let id = id.clone();
            let sketch = sketches[t % 3].clone();
            std::thread::spawn(move || {
                let mut statuses = Vec::new();
                for k in 0..3 {
                    if (t + k) % 2 == 0 {
                        let r = request(
                            addr,
                            "POST",
                            &format!("/api/solid/sketch?solid={id}"),
                            format!(r#"{{"sketch": {sketch}, "samples": 20}}"#).as_bytes(),
                        );
                        statuses.push(r.status);
                    } else {
                        let (s, png, _) = cut(addr, &id, 0.05 + 0.01 * k as f64);
                        if s == 200 {
                            assert!(fieldtex_io::read_image_bytes(&png, "cut.png").is_ok());
                        }
                        statuses.push(s);
                    }
                }
                statuses
            })
        })
        .collect();
    for h in handles {
        for s in h.join().unwrap() {
            assert_eq!(s, 200);
        }
    }
    // A whole sketch afterwards: setting it twice keeps every curve; cuts repeat exactly.
    let set = |s: &str| {
        request(
            addr,
            "POST",
            &format!("/api/solid/sketch?solid={id}"),
            format!(r#"{{"sketch": {s}, "samples": 20}}"#).as_bytes(),
        )
        .json()
    };
    set(&sketches[1]);
    let j = set(&sketches[1]);
    assert_eq!((j["edit"]["kept"].as_u64(), j["edit"]["replaced"].as_u64()), (Some(2), Some(0)));
    let (_, a, _) = cut(addr, &id, 0.05);
    let (_, b, computed) = cut(addr, &id, 0.05);
    assert_eq!(computed, 0);
    assert_eq!(a, b);
}
