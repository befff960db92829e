//! Helpers shared by the studio's server tests: a fresh temporary workspace, a server
//! on a free port, raw HTTP requests and their replies, and small inputs (a torus OBJ
//! and a striped exemplar) written into a workspace.
#![allow(dead_code)]

use fieldtex_studio::{Studio, StudioOptions};
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh, empty directory under the system's temp dir.
pub fn temp_dir(tag: &str) -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let d = std::env::temp_dir().join(format!(
        "fieldtex-studio-test-{}-{tag}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::SeqCst)
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A server on a free port over a fresh workspace, uploads limited to `max_upload` bytes.
pub fn start(tag: &str, max_upload: usize) -> (SocketAddr, PathBuf) {
    let ws = temp_dir(tag);
    let mut o = StudioOptions::new(ws.clone());
    o.port = 0;
    o.max_upload_bytes = max_upload;
    let addr = Studio::bind(o).unwrap().spawn();
    (addr, ws)
}

/// A response: status, head (status line and headers) and body.
pub struct Reply {
    pub status: u16,
    pub head: String,
    pub body: Vec<u8>,
}

impl Reply {
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|_| panic!("not JSON: {}", String::from_utf8_lossy(&self.body)))
    }
    pub fn error(&self) -> String {
        self.json()["error"].as_str().unwrap_or("").to_string()
    }
    /// A header's value (names compared without case).
    pub fn header(&self, name: &str) -> Option<String> {
        self.head.lines().skip(1).find_map(|l| {
            let (k, v) = l.split_once(':')?;
            k.trim().eq_ignore_ascii_case(name).then(|| v.trim().to_string())
        })
    }
    /// The binary design state: JSON and the field.
    pub fn state(&self) -> (serde_json::Value, Vec<f32>) {
        assert_eq!(self.status, 200, "{}", String::from_utf8_lossy(&self.body));
        let n = u32::from_le_bytes(self.body[..4].try_into().unwrap()) as usize;
        let json = serde_json::from_slice(&self.body[4..4 + n]).unwrap();
        let field = self.body[4 + n..]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        (json, field)
    }
}

/// Sends `request` as given and reads the whole reply.
pub fn raw(addr: SocketAddr, request: &[u8]) -> Reply {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_nodelay(true).ok();
    let _ = s.write_all(request);
    let mut out = Vec::new();
    let _ = s.read_to_end(&mut out);
    let end = out.windows(4).position(|w| w == b"\r\n\r\n").expect("a response head");
    let head = String::from_utf8_lossy(&out[..end]).to_string();
    let status = head.split(' ').nth(1).unwrap().parse().unwrap();
    Reply { status, head, body: out[end + 4..].to_vec() }
}

/// A well-formed request with a loopback `Host` and a `Content-Length` body.
pub fn request(addr: SocketAddr, method: &str, path: &str, body: &[u8]) -> Reply {
    let mut r = format!(
        "{method} {path} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nContent-Length: {}\r\n\r\n",
        addr.port(),
        body.len()
    )
    .into_bytes();
    r.extend_from_slice(body);
    raw(addr, &r)
}

/// A small torus (`torus.obj`, axis z, radii 1 and 0.4) and a striped exemplar
/// (`stripes.png`, 32²) in the workspace.
pub fn write_inputs(ws: &Path) {
    let mesh = fieldtex_mesh::primitives::torus(1.0, 0.4, 24, 12);
    fieldtex_io::write_obj(&ws.join("torus.obj"), &mesh, None).unwrap();
    write_stripes(ws, "stripes.png");
}

/// A 32² striped exemplar (stripes 4 pixels wide) written into the workspace as `name`.
pub fn write_stripes(ws: &Path, name: &str) {
    let n = 32;
    let mut img = fieldtex_core::Image::new(n, n, [0.0, 0.0, 0.0, 1.0]);
    for y in 0..n {
        for x in 0..n {
            let v = if (x / 4) % 2 == 0 { 0.9 } else { 0.1 };
            img.pixels[y * n + x] = [v, v * 0.8, 0.3, 1.0];
        }
    }
    fieldtex_io::write_png(&ws.join(name), &img).unwrap();
}
