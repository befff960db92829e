//! Geometry benchmarks (procedural by default; no files needed).
//!
//! `cargo run --release -p fieldtex-mesh --example bench_geometry -- [MESH.obj] [--refine N]
//! [--rays-only] [--threads N] [--reps N]`
//!
//! Without a path the workload is a torus refined once by 1→4 subdivision to
//! 388,128 triangles (the size of the refined horse of the benchmark suite). With a
//! path, the OBJ's `v`/`f` lines are read (polygons fanned) and refined `N` times
//! (default 0). `--rays-only` runs only the BVH entries, `--threads` sets the pool size
//! (default 2), `--reps` the number of timed runs of each ray entry (default 3),
//! `--only build|closest|any` runs just that entry (for profiling; implies `--rays-only`),
//! `--rays N` casts `N` rays instead of 1,000,000. Prints `BENCH name key=value` lines; ray entries also give `cpu_value`,
//! the rate per CPU-second of this process times the thread count (Linux only), which
//! is less sensitive to other processes loading the machine than the wall-clock rate, and
//! `best_value`, the wall-clock rate of the fastest run.

use fieldtex_core::rng::hash_unit;
use fieldtex_core::vec3;
use fieldtex_linalg::SparseMatrix;
use fieldtex_mesh::primitives::{self, subdivide_midpoint, torus};
use fieldtex_mesh::{
    Bvh, CornerUvs, CotanOptions, PoissonDiskOptions, Ray, TriMesh, VertexAreaKind,
    cotan_laplacian_and_mass, poisson_disk_sampling, total_area,
};
use std::time::Instant;

// The crate's test-support OBJ reader; it names `crate::TriMesh`, `crate::CornerUvs` and
// `crate::primitives`, which the imports above provide.
#[path = "../src/test_meshes.rs"]
#[allow(dead_code)]
mod test_meshes;
use test_meshes::parse_obj;

fn median_ms(runs: usize, f: impl FnMut()) -> f64 {
    median_ms_cpu(runs, f).0
}

/// CPU seconds (user + system) used by this process so far; `None` off Linux.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which is in parentheses and may contain spaces).
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0) // USER_HZ is 100 on Linux
}

/// Median wall-clock milliseconds, median CPU milliseconds and least wall-clock
/// milliseconds of `runs` runs.
fn median_ms_cpu(runs: usize, mut f: impl FnMut()) -> (f64, Option<f64>, f64) {
    f(); // warm-up
    let mut t = Vec::with_capacity(runs);
    let mut c = Vec::with_capacity(runs);
    for _ in 0..runs {
        let (s, cs) = (Instant::now(), cpu_seconds());
        f();
        t.push(s.elapsed().as_secs_f64() * 1e3);
        c.push(cpu_seconds().zip(cs).map(|(b, a)| (b - a) * 1e3));
    }
    t.sort_by(f64::total_cmp);
    let mut c: Option<Vec<f64>> = c.into_iter().collect();
    (
        t[runs / 2],
        c.as_mut().map(|c| {
            c.sort_by(f64::total_cmp);
            c[runs / 2]
        }),
        t[0],
    )
}

/// Rays from a sphere of 1.5 bounding-box diagonals around the mesh towards random points
/// of the inner 30 % of the box (most hit the surface).
fn random_rays(mesh: &TriMesh, n: u64) -> Vec<Ray> {
    let bb = mesh.bounding_box().unwrap();
    let (c, r) = (bb.center(), bb.diagonal());
    let unit = |stage: &str, i: u64| {
        let z = 2.0 * hash_unit(7, stage, 2 * i) - 1.0;
        let a = std::f64::consts::TAU * hash_unit(7, stage, 2 * i + 1);
        let s = (1.0 - z * z).sqrt();
        [s * a.cos(), s * a.sin(), z]
    };
    (0..n)
        .map(|i| {
            let o = vec3::add(c, vec3::scale(unit("origin", i), 1.5 * r));
            let half = vec3::scale(vec3::sub(bb.max, bb.min), 0.3 * hash_unit(7, "len", i));
            let u = unit("target", i);
            let t = vec3::add(c, [u[0] * half[0], u[1] * half[1], u[2] * half[2]]);
            Ray::new(o, vec3::normalize(vec3::sub(t, o)).unwrap())
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut path = None;
    let mut refine = 0usize;
    let mut threads = 2usize;
    let mut rays_only = false;
    let mut reps = 3usize;
    let mut only: Option<String> = None;
    let mut n_rays = 1_000_000u64;
    let mut i = 0;
    while i < args.len() {
        if args[i] == "--refine" {
            refine = args.get(i + 1).and_then(|s| s.parse().ok()).unwrap_or(1);
            i += 2;
        } else if args[i] == "--threads" {
            threads = args.get(i + 1).and_then(|s| s.parse().ok()).unwrap_or(2);
            i += 2;
        } else if args[i] == "--reps" {
            reps = args.get(i + 1).and_then(|s| s.parse().ok()).unwrap_or(3).max(1);
            i += 2;
        } else if args[i] == "--rays" {
            n_rays = args.get(i + 1).and_then(|s| s.parse().ok()).unwrap_or(n_rays);
            i += 2;
        } else if args[i] == "--only" {
            only = args.get(i + 1).cloned();
            rays_only = true;
            i += 2;
        } else if args[i] == "--rays-only" {
            rays_only = true;
            i += 1;
        } else {
            path = Some(args[i].clone());
            i += 1;
        }
    }
    let mut mesh = match &path {
        Some(p) => parse_obj(&std::fs::read_to_string(p).expect("cannot read the OBJ file")),
        None => subdivide_midpoint(&torus(2.0, 0.7, 311, 156)),
    };
    for _ in 0..refine {
        mesh = subdivide_midpoint(&mesh);
    }
    mesh.validate().expect("invalid mesh");
    println!("mesh: {} vertices, {} triangles", mesh.n_vertices(), mesh.n_triangles());
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let rate = |n: usize, (ms, cpu, best): (f64, Option<f64>, f64)| {
        let wall = n as f64 / (ms * 1e-3);
        let cpu = cpu.map_or(String::new(), |c| {
            format!(" cpu_value={:.0}", n as f64 * threads as f64 / (c.max(1.0) * 1e-3))
        });
        format!("value={wall:.0}{cpu} best_value={:.0}", n as f64 / (best * 1e-3))
    };
    pool.install(|| {
        if !rays_only {
            bench_other(&mesh);
        }
        let run = |name: &str| only.as_deref().is_none_or(|o| o == name);
        if run("build") {
            let ms = median_ms(5, || {
                std::hint::black_box(Bvh::build(&mesh).unwrap());
            });
            println!("BENCH bvh_build median_ms={ms:.2}");
        }
        let bvh = Bvh::build(&mesh).unwrap();
        let rays = random_rays(&mesh, n_rays);
        if run("closest") {
            let mut hits = 0;
            let m = median_ms_cpu(reps, || {
                hits = bvh.intersect_many(&rays).iter().filter(|h| h.is_some()).count();
            });
            println!("hit fraction {:.3}", hits as f64 / rays.len() as f64);
            println!("BENCH rays_per_s {}", rate(rays.len(), m));
        }
        if run("any") {
            let m = median_ms_cpu(reps, || {
                std::hint::black_box(bvh.occluded_many(&rays));
            });
            println!("BENCH any_hit_rays_per_s {}", rate(rays.len(), m));
        }
        if !rays_only {
            bench_poisson(&mesh);
        }
    });
}

fn bench_other(mesh: &TriMesh) {
    let ms = median_ms(11, || {
        let (l, m, _) =
            cotan_laplacian_and_mass(mesh, &CotanOptions::default(), VertexAreaKind::Barycentric)
                .unwrap();
        std::hint::black_box((l, SparseMatrix::from_diagonal(&m)));
    });
    println!("BENCH cotan_mass_388k median_ms={ms:.2}");
}

fn bench_poisson(mesh: &TriMesh) {
    // About 100K samples.
    let r = (0.7 * total_area(mesh) / 100_000.0).sqrt();
    let opts = PoissonDiskOptions { radius: Some(r), seed: 1, ..Default::default() };
    let mut count = 0;
    let ms = median_ms(3, || {
        count = poisson_disk_sampling(mesh, &opts).unwrap().0.samples.len();
    });
    println!("poisson samples {count}");
    println!("BENCH poisson_disk median_ms={ms:.2}");
}
