//! Foundation benchmarks on the same inputs the peers use (bench/peers.py):
//! the horse refined once by 1→4 subdivision (~388K triangles) and the Stanford bunny.
//!
//! Prints `BENCH <name> median_ms=<x>` / `value=<x>` lines; `bench/run.sh` pairs them
//! with the peers' lines and prints ratios. `--quick` runs fewer repetitions.

use fieldtex::NoProgress;
use fieldtex::crates::{io, linalg, mesh, param};
use std::path::PathBuf;
use std::time::Instant;

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

fn median_ms(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let t0 = Instant::now();
            f();
            t0.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

fn emit(name: &str, key: &str, v: f64) {
    println!("BENCH {name} {key}={v:.6}");
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let runs = if quick { 3 } else { 5 };

    // --- Refined horse: cotan Laplacian + mass, penalty system, rank-1 updates.
    let horse = io::read_mesh(&data_dir().join("meshes/horse.ply")).expect("horse.ply loads");
    let refined = mesh::primitives::subdivide_midpoint(&horse.mesh);
    println!(
        "# refined horse: {} vertices, {} triangles",
        refined.n_vertices(),
        refined.n_triangles()
    );
    let opts = mesh::CotanOptions::default();
    let ms = median_ms(runs, || {
        let r = mesh::cotan_laplacian_and_mass(&refined, &opts, mesh::VertexAreaKind::MixedVoronoi);
        std::hint::black_box(r.expect("cotan"));
    });
    emit("cotan_mass_388k", "median_ms", ms);

    let (l, _, _) =
        mesh::cotan_laplacian_and_mass(&refined, &opts, mesh::VertexAreaKind::MixedVoronoi)
            .expect("cotan");
    let n = l.nrows();
    // Every 50th vertex constrained (2 %), alpha = 1e8: the same rule as bench/peers.py.
    let mut p = vec![0.0; n];
    for i in (0..n).step_by(50) {
        p[i] = 1e8;
    }
    let a = l.add_diagonal(&p);
    let ms = median_ms(runs, || {
        let sym = linalg::SymbolicCholesky::analyze(&a).expect("analyze");
        std::hint::black_box(linalg::Cholesky::factor_with(&sym, &a).expect("factor"));
    });
    emit("penalty_factor_388k", "median_ms", ms);
    let sym = linalg::SymbolicCholesky::analyze(&a).expect("analyze");
    let ms = median_ms(runs, || {
        std::hint::black_box(linalg::Cholesky::factor_with(&sym, &a).expect("factor"));
    });
    emit("penalty_refactor_388k", "median_ms", ms);

    let mut chol = linalg::Cholesky::factor_with(&sym, &a).expect("factor");
    let updates = if quick { 10 } else { 30 };
    let mut times = Vec::with_capacity(updates);
    for k in 0..updates {
        let i = 25 + 50 * (k * 97 % (n / 50 - 1)); // unconstrained vertices, spread out
        let t0 = Instant::now();
        chol.add_diagonal_penalty(i, 1e8).expect("rank-1 update");
        times.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    emit("rank1_update_388k", "median_ms", times[times.len() / 2]);
    let b: Vec<f64> = (0..n).map(|i| p[i] * ((i % 7) as f64 - 3.0)).collect();
    let (_, res) = chol.solve_with_residual(&b).expect("solve after updates");
    println!("# relative residual after {updates} updates: {res:.3e}");

    // --- Atlas on the bunny (raw file, as xatlas gets it).
    let bunny = io::read_mesh(&data_dir().join("meshes/stanford-bunny.obj")).expect("bunny loads");
    let aopts = param::AtlasOptions::default();
    let mut stats = None;
    let ms = median_ms(if quick { 1 } else { 3 }, || {
        let at = param::build_atlas(&bunny.mesh, &aopts, &NoProgress).expect("atlas");
        stats = Some(at.stats);
    });
    let s = stats.expect("atlas ran");
    emit("atlas_bunny", "median_ms", ms);
    emit("atlas_bunny_packing", "value", s.packing_efficiency);
    emit("atlas_bunny_angle_mean", "value", s.angle_distortion_mean);
    emit("atlas_bunny_angle_p95", "value", s.angle_distortion_p95);
    emit("atlas_bunny_flips", "value", s.flipped_triangles as f64);
    emit("atlas_bunny_charts", "value", s.charts as f64);
}
