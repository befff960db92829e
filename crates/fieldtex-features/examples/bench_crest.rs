//! Benchmark of crest-line detection on fandisk, the bunny and the horse refined once
//! (~388K triangles), plus the sharp-edge coverage target on fandisk.
//!
//! `cargo run --release -p fieldtex-features --example bench_crest [-- --runs N]`
//! prints `BENCH crest_<mesh> median_ms=..` lines and
//! `BENCH crest_fandisk_sharp_coverage value=..`, `BENCH crest_fandisk_precision value=..`.

use fieldtex_features::{CrestOptions, crest_lines, sharp_edge_coverage};
use fieldtex_mesh::{RepairOptions, TriMesh, primitives::subdivide_midpoint, repair};
use std::path::Path;
use std::time::Instant;

fn load(name: &str) -> TriMesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/meshes").join(name);
    let loaded = fieldtex_io::read_mesh(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    repair(&loaded.mesh, &RepairOptions::default()).mesh
}

fn median_ms(mesh: &TriMesh, options: &CrestOptions, runs: usize) -> (f64, usize) {
    let mut times = Vec::with_capacity(runs);
    let mut n = 0;
    for _ in 0..runs {
        let t = Instant::now();
        let c = crest_lines(mesh, options).expect("crest lines");
        times.push(t.elapsed().as_secs_f64() * 1e3);
        n = c.lines.len();
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], n)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = args
        .iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(5usize)
        .max(1);
    let options = CrestOptions::default();
    let fandisk = load("fandisk.obj");
    let bunny = load("stanford-bunny.obj");
    let horse = subdivide_midpoint(&load("horse.ply"));
    for (name, mesh) in [("fandisk", &fandisk), ("bunny", &bunny), ("horse_refined", &horse)] {
        let (ms, lines) = median_ms(mesh, &options, runs);
        println!(
            "BENCH crest_{name} median_ms={ms:.1} triangles={} lines={lines} runs={runs}",
            mesh.n_triangles()
        );
    }
    let crest = crest_lines(&fandisk, &options).expect("crest lines");
    let cov = sharp_edge_coverage(&fandisk, &crest.polylines(), 30.0, 2.0).expect("coverage");
    println!("BENCH crest_fandisk_sharp_coverage value={:.4}", cov.sharp_covered);
    println!("BENCH crest_fandisk_precision value={:.4}", cov.lines_on_sharp);
}
