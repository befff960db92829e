//! Server-side latency of a singularity drag in `fieldtex studio`: HTTP request →
//! edit → solve (kept factor) → 128² field sample → binary response read by the client,
//! over loopback, as the page does it (one request in flight at a time). Also times a
//! stroke drag and the coarse (128²) and full (512²) texture.
//!
//! `cargo run --release -p fieldtex-studio --example bench_studio_drag -- [EXEMPLAR_DIR]`
//! (or `bench/studio_drag.sh`). Prints medians in milliseconds. Does not include the
//! browser's drawing of the streamlines (the page prints that separately).

use fieldtex_studio::{Studio, StudioOptions};
use std::net::SocketAddr;
use std::time::Instant;

/// The server tests' HTTP helpers (one request per connection, as the page does).
#[path = "../tests/common/mod.rs"]
mod common;

fn request(addr: SocketAddr, method: &str, path: &str, body: &[u8]) -> (u16, Vec<u8>) {
    let r = common::request(addr, method, path, body);
    (r.status, r.body)
}

fn state_json(body: &[u8]) -> serde_json::Value {
    common::Reply { status: 200, head: String::new(), body: body.to_vec() }.state().0
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn main() {
    let exemplars = std::env::args().nth(1).unwrap_or_else(|| "../shared/data/exemplars".into());
    let ws = std::env::temp_dir().join(format!("fieldtex-studio-bench-{}", std::process::id()));
    std::fs::create_dir_all(&ws).unwrap();
    let mut o = StudioOptions::new(ws.clone());
    o.port = 0;
    let have_exemplars = std::path::Path::new(&exemplars).is_dir();
    if have_exemplars {
        o.exemplars = Some(exemplars.clone().into());
    }
    let addr = Studio::bind(o).unwrap().spawn();

    let t = Instant::now();
    let (st, body) = request(addr, "POST", "/api/session", br#"{"preset":"whorl"}"#);
    assert_eq!(st, 200);
    let json = state_json(&body);
    println!(
        "session (whorl preset, 128² grid, factor + first solve): {:.1} ms",
        t.elapsed().as_secs_f64() * 1e3
    );
    let id = json["session"].as_str().unwrap().to_string();
    let sid = json["singularities"][0]["id"].as_u64().unwrap();
    let (x0, y0) = (
        json["singularities"][0]["x"].as_f64().unwrap(),
        json["singularities"][0]["y"].as_f64().unwrap(),
    );
    let path = format!("/api/edit?session={id}");
    let mut round = Vec::new();
    let mut server = Vec::new();
    for i in 0..200 {
        let a = i as f64 * 0.05;
        let body = format!(
            r#"{{"op":"move_singularity","id":{sid},"x":{},"y":{}}}"#,
            x0 + 20.0 * a.cos(),
            y0 + 20.0 * a.sin()
        );
        let t = Instant::now();
        let (st, resp) = request(addr, "POST", &path, body.as_bytes());
        let ms = t.elapsed().as_secs_f64() * 1e3;
        assert_eq!(st, 200);
        if i >= 10 {
            round.push(ms);
            server.push(state_json(&resp)["solve_ms"].as_f64().unwrap());
        }
    }
    println!(
        "singularity drag, {} events: round trip median {:.2} ms (server edit+solve+sample {:.2} ms), p90 {:.2} ms",
        round.len(),
        median(round.clone()),
        median(server),
        {
            let mut r = round.clone();
            r.sort_by(|a, b| a.partial_cmp(b).unwrap());
            r[r.len() * 9 / 10]
        }
    );

    let (st, resp) = request(
        addr,
        "POST",
        &path,
        br#"{"op":"add_stroke","points":[[60,200],[150,170],[250,160],[350,170],[450,200]]}"#,
    );
    assert_eq!(st, 200);
    let stroke = state_json(&resp)["added"].as_u64().unwrap();
    let mut round = Vec::new();
    for i in 0..60 {
        let dy = (i % 20) as f64;
        let body = format!(
            r#"{{"op":"move_stroke","id":{stroke},"points":[[60,{}],[150,{}],[250,{}],[350,{}],[450,{}]]}}"#,
            200.0 + dy,
            170.0 + dy,
            160.0 + dy,
            170.0 + dy,
            200.0 + dy
        );
        let t = Instant::now();
        let (st, _) = request(addr, "POST", &path, body.as_bytes());
        assert_eq!(st, 200);
        if i >= 5 {
            round.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    println!(
        "stroke drag (~400 px stroke), {} events: round trip median {:.2} ms",
        round.len(),
        median(round)
    );

    if have_exemplars {
        let ex = r#"{"root":"exemplars","path":"bands-fingerprint-like_Onyx013.png"}"#;
        for size in [128usize, 512] {
            let mut times = Vec::new();
            for _ in 0..3 {
                let body = format!(r#"{{"exemplar":{ex},"size":{size}}}"#);
                let t = Instant::now();
                let (st, resp) =
                    request(addr, "POST", &format!("/api/texture?session={id}"), body.as_bytes());
                assert_eq!(st, 200, "{}", String::from_utf8_lossy(&resp));
                times.push(t.elapsed().as_secs_f64() * 1e3);
            }
            println!(
                "texture {size}²: runs {times:.0?} ms, median {:.0} ms (the first includes the exemplar analysis)",
                median(times.clone())
            );
        }
    } else {
        println!("(no exemplar directory {exemplars}: texture timings skipped)");
    }
    let _ = std::fs::remove_dir_all(&ws);
}
