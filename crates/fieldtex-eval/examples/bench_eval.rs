//! Times every metric on a 512² output against a 128² exemplar.
//!
//! `cargo run --release -p fieldtex-eval --example bench_eval [-- [EXEMPLAR.png] [--only coherence,phase_defects]]`
//!
//! The output is a patchwork of 32×32 exemplar blocks copied from seeded random
//! positions (with wrapping): coherent regions and seams, like a synthesis result.
//! `coherence_and_completeness` does both directions in one scan. Prints
//! `BENCH <metric> median_ms=… runs=…` lines and the metric values.

use fieldtex_core::rng::hash_unit;
use fieldtex_eval::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

fn load_rgb(path: &Path) -> (Vec<f32>, usize, usize) {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
        .to_rgb32f();
    let (w, h) = (img.width() as usize, img.height() as usize);
    (img.into_raw(), w, h)
}

fn patchwork(ex: &[f32], ew: usize, eh: usize, size: usize, block: usize) -> Vec<f32> {
    let mut out = vec![0f32; size * size * 3];
    let nb = size.div_ceil(block);
    for by in 0..nb {
        for bx in 0..nb {
            let i = (by * nb + bx) as u64;
            let sx = (hash_unit(1, "bench-patchwork-x", i) * ew as f64) as usize;
            let sy = (hash_unit(1, "bench-patchwork-y", i) * eh as f64) as usize;
            for y in by * block..((by + 1) * block).min(size) {
                for x in bx * block..((bx + 1) * block).min(size) {
                    let (ex_x, ex_y) = ((sx + x - bx * block) % ew, (sy + y - by * block) % eh);
                    let s = (ex_y * ew + ex_x) * 3;
                    out[(y * size + x) * 3..(y * size + x) * 3 + 3].copy_from_slice(&ex[s..s + 3]);
                }
            }
        }
    }
    out
}

/// Metrics to run: all, or those named after `--only` (comma-separated).
fn wanted(name: &str) -> bool {
    let args: Vec<String> = std::env::args().collect();
    match args.iter().position(|a| a == "--only") {
        Some(i) => args.get(i + 1).is_some_and(|list| list.split(',').any(|m| m == name)),
        None => true,
    }
}

fn bench<T>(name: &str, runs: usize, mut f: impl FnMut() -> T) -> Option<T> {
    if !wanted(name) {
        return None;
    }
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..runs {
        let t0 = Instant::now();
        last = Some(f());
        times.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(|a, b| a.total_cmp(b));
    println!("BENCH {name} median_ms={:.1} runs={runs}", times[runs / 2]);
    last
}

fn main() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/exemplars");
    let path = std::env::args()
        .nth(1)
        .filter(|a| !a.starts_with("--"))
        .map(PathBuf::from)
        .unwrap_or_else(|| data.join("stripes_Fabric071.png"));
    // Wrap-extend or crop the exemplar to exactly 128² (the benchmark's contract).
    let (raw, rw, rh) = load_rgb(&path);
    let (ew, eh) = (128usize, 128usize);
    let ex: Vec<f32> = (0..ew * eh)
        .flat_map(|i| {
            let s = ((i / ew % rh) * rw + (i % ew % rw)) * 3;
            [raw[s], raw[s + 1], raw[s + 2]]
        })
        .collect();
    let size = 512;
    let out = patchwork(&ex, ew, eh, size, 32);
    let exv = ImageView::new(&ex, ew, eh, 3).expect("exemplar");
    let ov = ImageView::new(&out, size, size, 3).expect("output");
    println!(
        "exemplar {} ({rw}×{rh} wrapped to {ew}×{eh}), output {size}² patchwork, {} rayon threads",
        path.display(),
        rayon::current_num_threads()
    );

    let popts = PatchDistanceOptions::default();
    if let Some(c) = bench("coherence", 3, || coherence(&ov, &exv, &popts).expect("coherence")) {
        println!(
            "  coherence mean={:.5} rms={:.4} pairs={:.2e}",
            c.mean, c.rms, c.pairs_compared as f64
        );
    }
    if let Some(m) =
        bench("completeness", 3, || completeness(&ov, &exv, &popts).expect("completeness"))
    {
        println!("  completeness mean={:.5} rms={:.4}", m.mean, m.rms);
    }
    if let Some((c, m)) = bench("coherence_and_completeness", 3, || {
        coherence_and_completeness(&ov, &exv, &popts).expect("both")
    }) {
        println!("  both: coherence {:.5}, completeness {:.5}", c.mean, m.mean);
    }
    if let Some(sw) = bench("color_sliced_wasserstein", 5, || {
        color_sliced_wasserstein(&ov, &exv, &Default::default()).expect("sw")
    }) {
        println!("  sliced Wasserstein={:.5}", sw.distance);
    }
    let (dom, coh) = dominant_orientation(&exv).expect("dominant");
    let oe_opts = OrientationErrorOptions { exemplar_angle_deg: dom, ..Default::default() };
    if let Some(oe) = bench("orientation_error", 5, || {
        orientation_error(&ov, &OrientationReference::ConstantDeg(0.0), &oe_opts)
            .expect("orientation")
    }) {
        println!(
            "  exemplar dominant {dom:.1}° (coherence {coh:.2}); orientation error {:.2}°",
            oe.mean_error_deg
        );
    }
    if let Some(sg) = bench("singularities", 5, || {
        let map = image_orientation(&ov, &OrientationOptions::default()).expect("map");
        singularities(&map, &SingularityOptions::default())
    }) {
        println!("  singularities: {} merged ({} raw)", sg.merged.len(), sg.raw.len());
    }
    if let Some(pd) = bench("phase_defects", 5, || {
        phase_defects(&ov, &PhaseDefectOptions::default()).expect("phase")
    }) {
        println!(
            "  phase defects: {} ({:.2} per 10⁴ px), period {:.1} px, striped {:.2}",
            pd.count, pd.per_10k_px, pd.period_px, pd.striped_fraction
        );
    }
}
