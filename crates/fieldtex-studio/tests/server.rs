//! Server tests: path confinement, limits, malformed requests, concurrency, and the
//! edit → solve → field round trip. Each test starts its own server on a free port
//! with a fresh temporary workspace.

use std::net::SocketAddr;
use std::path::PathBuf;

mod common;
use common::{raw, request, temp_dir, write_stripes};

fn start(tag: &str) -> (SocketAddr, PathBuf) {
    common::start(tag, 64 * 1024)
}

fn new_session(addr: SocketAddr, body: &str) -> (String, serde_json::Value, Vec<f32>) {
    let (json, field) = request(addr, "POST", "/api/session", body.as_bytes()).state();
    (json["session"].as_str().unwrap().to_string(), json, field)
}

#[test]
fn page_and_info_are_served() {
    let (addr, _) = start("page");
    let r = request(addr, "GET", "/", b"");
    assert_eq!(r.status, 200);
    assert!(String::from_utf8_lossy(&r.body).contains("/app.js"));
    let assets = ["/app.js", "/draw.js", "/mesh.js", "/page.js", "/view.js", "/jobs.js"];
    for p in assets.into_iter().chain(["/display.js", "/style.css"]) {
        assert_eq!(request(addr, "GET", p, b"").status, 200, "{p}");
    }
    let info = request(addr, "GET", "/api/info", b"").json();
    assert_eq!(info["presets"].as_array().unwrap().len(), 5);
    assert_eq!(request(addr, "GET", "/nope", b"").status, 404);
    assert_eq!(request(addr, "DELETE", "/api/edit", b"").status, 405);
}

#[test]
fn edits_resolve_the_field() {
    let (addr, _) = start("edit");
    let (id, json, field0) = new_session(addr, r#"{"grid": 32, "view": 32}"#);
    assert_eq!(field0.len(), 32 * 32 * 2);
    assert_eq!(json["singularities"].as_array().unwrap().len(), 0);
    let path = format!("/api/edit?session={id}");
    let add = r#"{"op":"add_singularity","kind":"wedge","x":256,"y":256,"angle_deg":30}"#;
    let (json, field1) = request(addr, "POST", &path, add.as_bytes()).state();
    let sid = json["added"].as_u64().unwrap();
    assert_eq!(json["singularities"][0]["kind"], "wedge");
    assert!((json["singularities"][0]["angle_deg"].as_f64().unwrap() - 30.0).abs() < 1e-9);
    let moved = format!(r#"{{"op":"move_singularity","id":{sid},"x":100,"y":120}}"#);
    let (json, field2) = request(addr, "POST", &path, moved.as_bytes()).state();
    assert_eq!(json["singularities"][0]["x"], 100.0);
    // The field near the old and new positions changes: pixel (8, 8) ≈ design (72, 72).
    let px = |f: &[f32], x: usize, y: usize| [f[2 * (y * 32 + x)], f[2 * (y * 32 + x) + 1]];
    let a = px(&field1, 8, 8);
    let b = px(&field2, 8, 8);
    assert!((a[0] - b[0]).abs() + (a[1] - b[1]).abs() > 0.05, "{a:?} vs {b:?}");
    for v in field2.chunks_exact(2) {
        assert!(v[0].is_finite() && v[1].is_finite());
    }
    // Vector kinds do not belong to an orientation design: a clear 400.
    let r =
        request(addr, "POST", &path, br#"{"op":"add_singularity","kind":"source","x":1,"y":1}"#);
    assert_eq!(r.status, 400, "{}", r.error());
    // Strokes: add, move, remove.
    let (json, _) = request(
        addr,
        "POST",
        &path,
        br#"{"op":"add_stroke","points":[[20,400],[200,380],[480,400]]}"#,
    )
    .state();
    let st = json["added"].as_u64().unwrap();
    let mv = format!(r#"{{"op":"move_stroke","id":{st},"points":[[20,420],[200,400],[480,420]]}}"#);
    let (json, _) = request(addr, "POST", &path, mv.as_bytes()).state();
    assert_eq!(json["strokes"][0]["points"][0][1], 420.0);
    let rm = format!(r#"{{"op":"remove_stroke","id":{st}}}"#);
    let (json, _) = request(addr, "POST", &path, rm.as_bytes()).state();
    assert_eq!(json["strokes"].as_array().unwrap().len(), 0);
    let rm = format!(r#"{{"op":"remove_singularity","id":{sid}}}"#);
    let (json, _) = request(addr, "POST", &path, rm.as_bytes()).state();
    assert_eq!(json["singularities"].as_array().unwrap().len(), 0);
    assert_eq!(request(addr, "POST", &path, rm.as_bytes()).status, 400);
    // A vector design takes vector kinds.
    let (vid, _, _) = new_session(addr, r#"{"grid": 16, "view": 16, "symmetry": "vector"}"#);
    let r = request(
        addr,
        "POST",
        &format!("/api/edit?session={vid}"),
        br#"{"op":"add_singularity","kind":"vortex","x":100,"y":100}"#,
    );
    assert_eq!(r.state().0["singularities"][0]["kind"], "vortex");
}

#[test]
fn garbage_bodies_and_bad_requests_are_4xx() {
    let (addr, _) = start("garbage");
    let (id, _, _) = new_session(addr, r#"{"grid": 16, "view": 16}"#);
    let path = format!("/api/edit?session={id}");
    for body in [
        &b"not json"[..],
        b"{",
        b"\xff\xfe\x00garbage",
        br#"{"op":"explode"}"#,
        br#"{"op":"add_singularity","kind":"wedge","x":"a","y":1}"#,
        br#"{"op":"add_singularity","kind":"wedge","x":1e400,"y":1}"#,
        br#"{"op":"add_stroke","points":[[1,2]]}"#,
        br#"{"op":"move_singularity","id":99,"x":1,"y":1}"#,
        br#"[1,2,3]"#,
    ] {
        let r = request(addr, "POST", &path, body);
        assert_eq!(r.status, 400, "{:?} → {}", String::from_utf8_lossy(body), r.error());
        assert!(!r.error().is_empty());
    }
    let rm = br#"{"op":"remove_stroke","id":0}"#;
    assert_eq!(request(addr, "POST", "/api/edit?session=nope", rm).status, 404);
    assert_eq!(request(addr, "POST", "/api/session", br#"{"preset":"spiral"}"#).status, 400);
    assert_eq!(request(addr, "POST", "/api/session", br#"{"grid":100000}"#).status, 400);
    assert_eq!(request(addr, "POST", "/api/session", br#"{"bogus":1}"#).status, 400);
    // Malformed HTTP.
    assert_eq!(raw(addr, b"GARBAGE\r\n\r\n").status, 400);
    assert_eq!(
        raw(addr, b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: x\r\n\r\n").status,
        400
    );
    let chunked =
        b"POST /api/edit HTTP/1.1\r\nHost: 127.0.0.1\r\nTransfer-Encoding: chunked\r\n\r\n";
    assert_eq!(raw(addr, chunked).status, 411);
    let mut huge = b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX: ".to_vec();
    huge.extend(std::iter::repeat_n(b'a', 20_000));
    huge.extend_from_slice(b"\r\n\r\n");
    assert_eq!(raw(addr, &huge).status, 431);
    // Foreign Host (DNS rebinding) and foreign Origin are refused.
    assert_eq!(raw(addr, b"GET /api/info HTTP/1.1\r\nHost: evil.example\r\n\r\n").status, 403);
    let cross = format!(
        "POST /api/session HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nOrigin: http://evil.example\r\nContent-Length: 2\r\n\r\n{{}}",
        addr.port()
    );
    assert_eq!(raw(addr, cross.as_bytes()).status, 403);
    // The server still answers.
    assert_eq!(request(addr, "GET", "/api/info", b"").status, 200);
}

#[test]
fn file_access_stays_in_the_workspace() {
    let (addr, ws) = start("paths");
    let outside = temp_dir("outside");
    std::fs::write(outside.join("secret.txt"), b"TOP-SECRET-CONTENT").unwrap();
    std::fs::write(ws.join("inside.txt"), b"inside").unwrap();
    let ok = request(addr, "GET", "/api/file?path=inside.txt", b"");
    assert_eq!((ok.status, ok.body.as_slice()), (200, &b"inside"[..]));
    let secret = outside.join("secret.txt");
    let rel = format!("../{}/secret.txt", outside.file_name().unwrap().to_str().unwrap());
    for p in [
        rel.as_str(),
        "%2e%2e/x",
        "..%2Fx",
        secret.to_str().unwrap(),
        "./inside.txt",
        "a/../../x",
        "..\\x",
        "C:/x",
    ] {
        let r = request(addr, "GET", &format!("/api/file?path={p}"), b"");
        assert!(matches!(r.status, 400 | 403 | 404), "{p} → {}", r.status);
        assert!(!r.body.windows(10).any(|w| w == b"TOP-SECRET"), "{p} leaked");
    }
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&outside, ws.join("link")).unwrap();
        std::os::unix::fs::symlink(&secret, ws.join("file-link.txt")).unwrap();
        for p in ["link/secret.txt", "file-link.txt"] {
            let r = request(addr, "GET", &format!("/api/file?path={p}"), b"");
            assert_eq!(r.status, 403, "{p}: {}", r.error());
        }
        // Writing through the link directory is refused and nothing appears outside.
        let (id, _, _) = new_session(addr, r#"{"grid": 16, "view": 16}"#);
        let r = request(addr, "POST", &format!("/api/export?session={id}"), br#"{"dir":"link"}"#);
        assert_eq!(r.status, 403, "{}", r.error());
        let r = request(addr, "POST", &format!("/api/export?session={id}"), br#"{"dir":"../x"}"#);
        assert_eq!(r.status, 403, "{}", r.error());
        let r = request(addr, "POST", "/api/session", br#"{"design":"file-link.txt"}"#);
        assert_eq!(r.status, 403, "{}", r.error());
    }
    let names: Vec<_> =
        std::fs::read_dir(&outside).unwrap().flatten().map(|e| e.file_name()).collect();
    assert_eq!(names.len(), 1, "only secret.txt outside: {names:?}");
}

#[test]
fn uploads_are_checked_and_limited() {
    let (addr, ws) = start("upload");
    // Over the 64 KiB limit of the test server: refused before the body is read.
    let big = vec![0u8; 100 * 1024];
    let r = request(addr, "POST", "/api/upload?name=big.png", &big);
    assert_eq!(r.status, 413);
    let r = request(addr, "POST", "/api/upload?name=x.png", b"not a png");
    assert_eq!(r.status, 400, "{}", r.error());
    for name in ["../x.png", ".hidden.png", "a/b.png", "x.exe"] {
        let r = request(addr, "POST", &format!("/api/upload?name={name}"), b"abc");
        assert_eq!(r.status, 400, "{name}");
    }
    write_stripes(&ws, "ex.png");
    let png = std::fs::read(ws.join("ex.png")).unwrap();
    let r = request(addr, "POST", "/api/upload?name=stripes.png", &png);
    assert_eq!(r.status, 200, "{}", r.error());
    assert_eq!(r.json()["path"], "uploads/stripes.png");
    assert_eq!(std::fs::read(ws.join("uploads/stripes.png")).unwrap(), png);
    let info = request(addr, "GET", "/api/info", b"").json();
    assert!(
        info["exemplars"].as_array().unwrap().iter().any(|e| e["path"] == "uploads/stripes.png")
    );
}

#[test]
fn texture_and_export() {
    let (addr, ws) = start("texture");
    write_stripes(&ws, "ex.png");
    let (id, json, _) =
        new_session(addr, r#"{"preset":"left-loop","grid": 32, "view": 32, "size": 64}"#);
    assert_eq!(json["singularities"].as_array().unwrap().len(), 2);
    let ex = r#"{"root":"workspace","path":"ex.png"}"#;
    let body = format!(r#"{{"exemplar":{ex},"size":32}}"#);
    let r = request(addr, "POST", &format!("/api/texture?session={id}"), body.as_bytes());
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    let img = fieldtex_io::read_image_bytes(&r.body, "texture.png").unwrap();
    assert_eq!((img.width, img.height), (32, 32));
    // A stale version is answered 409.
    let body = format!(r#"{{"exemplar":{ex},"size":32,"version":99}}"#);
    assert_eq!(
        request(addr, "POST", &format!("/api/texture?session={id}"), body.as_bytes()).status,
        409
    );
    let body = r#"{"exemplar":{"root":"workspace","path":"../ex.png"},"size":32}"#;
    assert_eq!(
        request(addr, "POST", &format!("/api/texture?session={id}"), body.as_bytes()).status,
        403
    );
    let body = format!(r#"{{"dir":"out/a","exemplar":{ex},"size":32}}"#);
    let r = request(addr, "POST", &format!("/api/export?session={id}"), body.as_bytes());
    assert_eq!(r.status, 200, "{}", r.error());
    assert_eq!(r.json()["files"].as_array().unwrap().len(), 3);
    let toml = std::fs::read_to_string(ws.join("out/a/design.toml")).unwrap();
    let d = fieldtex_fields::DesignFile::from_toml_str(&toml).unwrap();
    assert_eq!(d.singularities.len(), 2);
    let (shape, _) = fieldtex_io::read_npy_f32(&ws.join("out/a/field.npy")).unwrap();
    assert_eq!(shape, vec![32, 32, 2]);
    assert!(ws.join("out/a/texture.png").is_file());
    // Same design, exemplar and seed: byte-identical texture.
    let body = format!(r#"{{"dir":"out/b","exemplar":{ex},"size":32}}"#);
    let r = request(addr, "POST", &format!("/api/export?session={id}"), body.as_bytes());
    assert_eq!(r.status, 200, "{}", r.error());
    assert_eq!(
        std::fs::read(ws.join("out/a/texture.png")).unwrap(),
        std::fs::read(ws.join("out/b/texture.png")).unwrap()
    );
    // The exported design loads back as a session.
    let (_, json, _) = new_session(addr, r#"{"design":"out/a/design.toml","view":16}"#);
    assert_eq!(json["singularities"].as_array().unwrap().len(), 2);
}

#[test]
fn concurrent_requests_and_edits() {
    let (addr, _) = start("concurrent");
    let (id, _, _) = new_session(addr, r#"{"grid": 24, "view": 24}"#);
    let threads: Vec<_> = (0..50)
        .map(|i| {
            let id = id.clone();
            std::thread::spawn(move || {
                if i % 2 == 0 {
                    let body = format!(
                        r#"{{"op":"add_singularity","kind":"{}","x":{},"y":{}}}"#,
                        if i % 4 == 0 { "wedge" } else { "trisector" },
                        20 + 9 * i,
                        30 + 7 * i
                    );
                    request(addr, "POST", &format!("/api/edit?session={id}"), body.as_bytes())
                        .status
                } else if i % 3 == 0 {
                    request(addr, "POST", &format!("/api/edit?session={id}"), b"{garbage").status
                } else {
                    request(addr, "GET", &format!("/api/state?session={id}"), b"").status
                }
            })
        })
        .collect();
    let statuses: Vec<u16> = threads.into_iter().map(|t| t.join().unwrap()).collect();
    for (i, s) in statuses.iter().enumerate() {
        let want = if i % 2 == 0 {
            200
        } else if i % 3 == 0 {
            400
        } else {
            200
        };
        assert_eq!(*s, want, "request {i}");
    }
    let (json, field) = request(addr, "GET", &format!("/api/state?session={id}"), b"").state();
    let sings = json["singularities"].as_array().unwrap();
    assert_eq!(sings.len(), 25);
    assert_eq!(json["version"], 25);
    let mut ids: Vec<u64> = sings.iter().map(|s| s["id"].as_u64().unwrap()).collect();
    ids.sort();
    ids.dedup();
    assert_eq!(ids.len(), 25, "distinct ids");
    assert!(field.iter().all(|v| v.is_finite()));
}
