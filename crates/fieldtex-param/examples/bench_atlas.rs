//! Atlas benchmark: `cargo run --release -p fieldtex-param --example bench_atlas -- [MESH.obj] [RESOLUTION] [GUTTER] [RUNS] [--atlas-only] [--name NAME]`.
//!
//! Loads an OBJ (a tiny `v`/`f` reader: polygons fanned, `a/b/c` and negative indices
//! accepted), builds the atlas `RUNS` times (default 3) and prints `BENCH` lines: the
//! median wall time, the mean CPU time per run (user + system, all threads, from
//! `/proc/self/stat`; wall times on a loaded machine say little) and the quality of the
//! last run, then (unless `--atlas-only`) the median times of the texel map and of a
//! bake at the atlas resolution. Default mesh: the Stanford bunny of the shared test
//! data; `--name` sets the name in the `BENCH` lines (default: the file stem).

use fieldtex_core::Progress;
use fieldtex_mesh::TriMesh;
use fieldtex_param::{AtlasOptions, bake_surface, build_atlas, build_texel_map};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

/// The mesh's geometry (positions and triangles) through `fieldtex-io`'s reader.
fn load_obj(path: &Path) -> Result<TriMesh, String> {
    let read = fieldtex_io::read_mesh(path).map_err(|e| e.to_string())?.mesh;
    Ok(TriMesh::new(read.positions, read.triangles))
}

/// Records when each stage starts and finishes.
#[derive(Default)]
struct StageTimer {
    marks: Mutex<Vec<(String, Instant)>>,
}

impl Progress for StageTimer {
    fn stage(&self, name: &str, _total: u64) {
        self.marks.lock().expect("no poisoning").push((name.to_string(), Instant::now()));
    }
    fn advance(&self, _n: u64) {}
    fn finish_stage(&self) {
        self.marks.lock().expect("no poisoning").push(("end".to_string(), Instant::now()));
    }
}

/// CPU time (user + system, all threads) of this process in milliseconds, from
/// `/proc/self/stat` (clock ticks of 10 ms); `None` where that file does not exist.
fn cpu_ms() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which is in parentheses and may contain spaces).
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let utime: f64 = f.get(11)?.parse().ok()?;
    let stime: f64 = f.get(12)?.parse().ok()?;
    Some((utime + stime) * 10.0)
}

fn main() {
    let all: Vec<String> = std::env::args().skip(1).collect();
    let atlas_only = all.iter().any(|a| a == "--atlas-only");
    let given_name = all.iter().position(|a| a == "--name").and_then(|k| all.get(k + 1)).cloned();
    let args: Vec<String> = {
        let mut v = Vec::new();
        let mut it = all.iter();
        while let Some(a) = it.next() {
            match a.as_str() {
                "--atlas-only" => {}
                "--name" => {
                    it.next();
                }
                _ => v.push(a.clone()),
            }
        }
        v
    };
    let default = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/meshes/stanford-bunny.obj");
    let path = args.first().filter(|s| !s.is_empty()).map(PathBuf::from).unwrap_or(default);
    let resolution: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1024);
    let gutter: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(4);
    let runs: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(3).max(1);
    let mesh = match load_obj(&path) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    };
    let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh").replace(['-', '.'], "_");
    let name = if name == "stanford_bunny" { "bunny".to_string() } else { name };
    let name = given_name.unwrap_or(name);
    let opts = AtlasOptions { resolution, gutter, ..Default::default() };
    let mut times = Vec::new();
    let mut last = None;
    let mut stages = String::new();
    let cpu0 = cpu_ms();
    for _ in 0..runs {
        let timer = StageTimer::default();
        let t = Instant::now();
        let atlas = match build_atlas(&mesh, &opts, &timer) {
            Ok(a) => a,
            Err(e) => {
                eprintln!("error: {e}");
                std::process::exit(1);
            }
        };
        times.push(t.elapsed().as_secs_f64() * 1e3);
        last = Some(atlas);
        let marks = timer.marks.into_inner().expect("no poisoning");
        stages = marks
            .windows(2)
            .filter(|w| w[0].0 != "end")
            .map(|w| format!("{} {:.0} ms", w[0].0, (w[1].1 - w[0].1).as_secs_f64() * 1e3))
            .collect::<Vec<_>>()
            .join(", ");
    }
    let cpu = cpu0.zip(cpu_ms()).map(|(a, b)| (b - a) / runs as f64);
    times.sort_by(|a, b| a.total_cmp(b));
    let atlas = last.expect("at least one run");
    let s = atlas.stats;
    println!(
        "# {} : {} vertices, {} triangles, resolution {resolution}, gutter {gutter}, {} threads",
        path.display(),
        mesh.n_vertices(),
        mesh.n_triangles(),
        rayon::current_num_threads()
    );
    println!("BENCH atlas_{name} median_ms={:.1}", times[times.len() / 2]);
    if let Some(c) = cpu {
        println!("BENCH atlas_{name}_cpu value={c:.1}");
    }
    println!("BENCH atlas_{name}_charts value={}", s.charts);
    println!("BENCH atlas_{name}_packing value={:.4}", s.packing_efficiency);
    println!("BENCH atlas_{name}_angle_mean value={:.4}", s.angle_distortion_mean);
    println!("BENCH atlas_{name}_angle_p95 value={:.4}", s.angle_distortion_p95);
    println!("BENCH atlas_{name}_area_distortion value={:.4}", s.area_distortion);
    println!("BENCH atlas_{name}_flips value={}", s.flipped_triangles);
    println!("# stages (last run): {stages}");
    for w in &atlas.warnings {
        println!("# warning: {w}");
    }
    if atlas_only {
        return;
    }
    // Texel map and bake at the atlas resolution (median over the same number of runs).
    let res = resolution as usize;
    let mut map_ms = Vec::new();
    let mut bake_ms = Vec::new();
    for _ in 0..runs {
        let t = Instant::now();
        let map = build_texel_map(&atlas.mesh, res, res, gutter).expect("atlas UVs are valid");
        map_ms.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        let img = bake_surface(&atlas.mesh, &map, [0.0; 4], |_, _, p| {
            [p[0] as f32, p[1] as f32, p[2] as f32, 1.0]
        })
        .expect("map matches mesh");
        bake_ms.push(t.elapsed().as_secs_f64() * 1e3);
        assert_eq!(img.pixels.len(), res * res);
    }
    map_ms.sort_by(|a, b| a.total_cmp(b));
    bake_ms.sort_by(|a, b| a.total_cmp(b));
    println!("BENCH texel_map_{name} median_ms={:.1}", map_ms[map_ms.len() / 2]);
    println!("BENCH bake_{name} median_ms={:.1}", bake_ms[bake_ms.len() / 2]);
}
