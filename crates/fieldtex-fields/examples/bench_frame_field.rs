//! Frame-field edit timings (paper E §3; issue 15 target: an edit < 0.1 s).
//!
//! The bunny-sized grid (bounding box of the Stanford bunny, 20 cells on the shortest
//! side: 29 × 29 × 23 nodes) and three curves like `docs/examples/bunny-sketch.json`:
//! the curves are added one by one, then the last one is removed, added again, and
//! moved (remove + add at a shifted place) several times. Prints medians in ms.
//!
//! `cargo run --release -p fieldtex-fields --example bench_frame_field [-- runs]`

use fieldtex_fields::{FrameCurve, FrameField3d, FrameFieldOptions, FrameGrid};
use std::time::Instant;

fn curve(points: Vec<[f64; 3]>, normal: [f64; 3], weight: f64) -> FrameCurve {
    let normals = vec![normal; points.len()];
    FrameCurve { points, normals, axis: 0, weight, refine: false }
}

/// User + system CPU time of this process so far (from /proc, 10 ms ticks), ms.
fn cpu_ms() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = after.split_whitespace().filter_map(|x| x.parse().ok()).collect();
    // Fields after the command name: state is skipped by the parse; utime and stime are
    // the 14th and 15th fields of the line, the 11th and 12th numbers here.
    if f.len() > 12 { (f[10] + f[11]) * 10.0 } else { f64::NAN }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let runs: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(9);
    let grid =
        FrameGrid::over_box([-0.0947, 0.0330, -0.0619], [0.0610, 0.1873, 0.0588], 20).unwrap();
    println!("grid {:?} = {} nodes", grid.dims, grid.len());
    let curves = [
        curve(
            vec![
                [-0.085, 0.110, -0.005],
                [-0.060, 0.150, 0.000],
                [-0.030, 0.165, 0.005],
                [0.000, 0.160, 0.010],
                [0.030, 0.140, 0.010],
                [0.050, 0.110, 0.005],
            ],
            [0.0, 0.0, 1.0],
            1.0,
        ),
        curve(
            vec![[-0.010, 0.050, 0.055], [-0.012, 0.080, 0.060], [-0.014, 0.110, 0.055]],
            [0.0, 0.0, 1.0],
            0.8,
        ),
        curve(
            vec![[-0.060, 0.040, 0.000], [0.000, 0.040, 0.000], [0.040, 0.045, 0.000]],
            [0.0, 1.0, 0.0],
            1.0,
        ),
    ];
    let t = Instant::now();
    let mut field = FrameField3d::new(grid, FrameFieldOptions::default()).unwrap();
    println!("new (assemble + analyse): {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
    let mut ids = Vec::new();
    for (i, c) in curves.iter().enumerate() {
        let t = Instant::now();
        ids.push(field.add_curve(c).unwrap());
        println!("add curve {i}: {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
    }
    let (mut add, mut remove, mut mv) = (Vec::new(), Vec::new(), Vec::new());
    let cpu0 = cpu_ms();
    let mut last = *ids.last().unwrap();
    for r in 0..runs {
        let t = Instant::now();
        field.remove_curve(last).unwrap();
        remove.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        last = field.add_curve(&curves[2]).unwrap();
        add.push(t.elapsed().as_secs_f64() * 1e3);
        // A move: the curve shifted up a little (other nodes), as a drag would.
        let mut moved = curves[2].clone();
        for p in &mut moved.points {
            p[1] += 0.004 * (r % 3 + 1) as f64;
        }
        let t = Instant::now();
        field.replace_curve(last, &moved).unwrap();
        mv.push(t.elapsed().as_secs_f64() * 1e3);
        field.replace_curve(last, &curves[2]).unwrap();
    }
    let cpu_per_edit = (cpu_ms() - cpu0) / (4 * runs) as f64;
    println!(
        "factor entries {:?}, residual {:.1e}, process CPU per edit (mean of {} edits) {cpu_per_edit:.1} ms",
        field.factor_nnz(),
        field.last_residual(),
        4 * runs
    );
    let errs = field.constraint_errors_deg();
    println!(
        "BENCH frame_field_edit remove {:.1} ms, add {:.1} ms, move {:.1} ms (medians of {runs}); max constraint error {:.4}°",
        median(remove),
        median(add),
        median(mv),
        errs.iter().cloned().fold(0.0, f64::max)
    );
}
