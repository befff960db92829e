//! Binary PLY read benchmark: ~1M triangles (a torus of 250K triangles refined once by
//! `primitives::subdivide_midpoint`), written to a temporary directory, read 5 times.
//! Prints `BENCH ply_read_1m median_ms=<x>` (target: < 500 ms).
//!
//! Run: `cargo run --release -p fieldtex-io --example bench_io`

use fieldtex_io::{read_mesh, write_ply};
use fieldtex_mesh::primitives;
use std::time::Instant;

fn main() {
    let mesh = primitives::subdivide_midpoint(&primitives::torus(1.0, 0.3, 354, 354));
    let dir = std::env::temp_dir().join(format!("fieldtex-bench-io-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("create a temporary directory");
    let path = dir.join("torus-1m.ply");
    let t = Instant::now();
    write_ply(&path, &mesh, &[], true).expect("write the benchmark PLY");
    let write_ms = t.elapsed().as_secs_f64() * 1e3;
    let bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
    let mut times = Vec::new();
    for _ in 0..5 {
        let t = Instant::now();
        let m = read_mesh(&path).expect("read the benchmark PLY");
        times.push(t.elapsed().as_secs_f64() * 1e3);
        assert_eq!(m.mesh.n_triangles(), mesh.n_triangles());
    }
    times.sort_by(f64::total_cmp);
    println!(
        "ply: {} vertices, {} triangles, {:.1} MB, written in {write_ms:.1} ms; reads (ms): {:?}",
        mesh.n_vertices(),
        mesh.n_triangles(),
        bytes as f64 / 1e6,
        times.iter().map(|t| (t * 10.0).round() / 10.0).collect::<Vec<_>>()
    );
    println!("BENCH ply_read_1m median_ms={:.1}", times[2]);
    let _ = std::fs::remove_dir_all(&dir);
}
