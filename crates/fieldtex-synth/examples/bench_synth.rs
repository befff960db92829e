//! Benchmark and visual check of the parallel synthesis engine.
//!
//! `cargo run --release -p fieldtex-synth --example bench_synth -- [EXEMPLAR.png]
//!  [swirl|wedge|trisector|constant|diagonal|flip] [--size N] [--no-rosy-fix] [--seed S] [--runs R]`
//!
//! Prints `BENCH synth_analysis median_ms=…` and `BENCH synth_<size> median_ms=…` and
//! writes `/tmp/synth_<name>_<field>.png` (and `…_coords.png`, the coordinate map as
//! colours: red = x, green = y, blue = flip).

use std::path::{Path, PathBuf};
use std::time::Instant;

use fieldtex_core::{Image, NoProgress};
use fieldtex_synth::{
    AnalysisOptions, ExemplarAnalysis, ImageDomain, SynthesisOptions, synthesize,
};

fn load(path: &Path) -> Image {
    let img = image::open(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let rgba = img.to_rgba32f();
    let (w, h) = rgba.dimensions();
    let pixels = rgba.pixels().map(|p| p.0).collect();
    Image { width: w as usize, height: h as usize, pixels }
}

fn save(im: &Image, path: &Path) {
    let buf: Vec<u8> = im
        .pixels
        .iter()
        .flat_map(|p| [p[0], p[1], p[2]].map(|c| (c.clamp(0.0, 1.0) * 255.0 + 0.5) as u8))
        .collect();
    image::save_buffer(path, &buf, im.width as u32, im.height as u32, image::ColorType::Rgb8)
        .unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
}

/// `H × W × 2` representative direction field.
fn field(kind: &str, n: usize) -> Vec<f32> {
    let c = n as f32 / 2.0;
    let mut out = Vec::with_capacity(n * n * 2);
    for y in 0..n {
        for x in 0..n {
            let (dx, dy) = (x as f32 + 0.5 - c, y as f32 + 0.5 - c);
            let r = (dx * dx + dy * dy).sqrt();
            let phi = dy.atan2(dx);
            let angle = match kind {
                "constant" => 0.0,
                // Constant 45°: every patch rotated, no field variation.
                "diagonal" => std::f32::consts::FRAC_PI_4,
                "flip" => {
                    if x < n / 2 {
                        0.0
                    } else {
                        std::f32::consts::PI
                    }
                }
                // +1/2 wedge: orientation turns by π around the centre; the representative
                // jumps by π across the ray phi = ±π.
                "wedge" => 0.5 * phi,
                "trisector" => -0.5 * phi,
                // Swirl: circles around the centre bending with the radius.
                _ => phi + std::f32::consts::FRAC_PI_2 + 0.6 * (r / n as f32 * 6.0).sin(),
            };
            out.extend_from_slice(&[angle.cos(), angle.sin()]);
        }
    }
    out
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let mut args = std::env::args().skip(1);
    let mut exemplar = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/exemplars/stripes_Fabric071.png");
    let mut kind = "swirl".to_string();
    let (mut size, mut runs, mut seed, mut rosy) = (512usize, 5usize, 1u64, true);
    let mut opts = SynthesisOptions::default();
    let mut aopts = AnalysisOptions::default();
    let mut out_dir = PathBuf::from("/tmp");
    while let Some(a) = args.next() {
        match a.as_str() {
            "--size" => size = args.next().and_then(|v| v.parse().ok()).expect("--size N"),
            "--runs" => runs = args.next().and_then(|v| v.parse().ok()).expect("--runs R"),
            "--seed" => seed = args.next().and_then(|v| v.parse().ok()).expect("--seed S"),
            "--scale" => opts.scale = args.next().and_then(|v| v.parse().ok()).expect("--scale X"),
            "--jitter" => {
                opts.jitter = args.next().and_then(|v| v.parse().ok()).expect("--jitter X")
            }
            "--passes" => {
                opts.correction_passes =
                    args.next().and_then(|v| v.parse().ok()).expect("--passes N")
            }
            "--unjittered" => {
                opts.unjittered_levels =
                    args.next().and_then(|v| v.parse().ok()).expect("--unjittered N")
            }
            "--out" => out_dir = args.next().map(PathBuf::from).expect("--out DIR"),
            "--scan" => {
                aopts.coherence_scan = args.next().and_then(|v| v.parse().ok()).expect("--scan N")
            }
            "--tileable" => aopts.tileable = true,
            "--no-own" => opts.own_candidates = false,
            "--finest-passes" => {
                opts.finest_passes =
                    Some(args.next().and_then(|v| v.parse().ok()).expect("--finest-passes N"))
            }
            "--k" => {
                aopts.k = args.next().and_then(|v| v.parse().ok()).expect("--k N");
                opts.k = aopts.k;
            }
            "--no-rosy-fix" => rosy = false,
            s if s.ends_with(".png") => exemplar = PathBuf::from(s),
            s => kind = s.to_string(),
        }
    }
    std::fs::create_dir_all(&out_dir)
        .unwrap_or_else(|e| panic!("cannot create {}: {e}", out_dir.display()));
    let ex = load(&exemplar);
    let name =
        exemplar.file_stem().unwrap().to_string_lossy().split('_').next().unwrap().to_string();
    let mut times = Vec::new();
    let mut analysis = None;
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        analysis = Some(ExemplarAnalysis::new(&ex, &aopts, &NoProgress).unwrap());
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let analysis = analysis.unwrap();
    println!(
        "BENCH synth_analysis median_ms={:.1} exemplar={}x{} levels={} threads={}",
        median(times),
        ex.width,
        ex.height,
        analysis.level_count(),
        rayon::current_num_threads()
    );
    let ev: Vec<String> = (0..analysis.level_count())
        .map(|c| format!("{:.2}", analysis.level(c).explained_variance))
        .collect();
    println!("explained_variance per level: [{}]", ev.join(","));
    for c in [0usize, 2] {
        let q = &analysis.level(c).appearance_q.data[0];
        let sd: Vec<String> = (0..8)
            .map(|d| {
                let m = q.iter().map(|v| v[d] as f64).sum::<f64>() / q.len() as f64;
                let var = q.iter().map(|v| (v[d] as f64 - m).powi(2)).sum::<f64>() / q.len() as f64;
                format!("{:.1}", var.sqrt())
            })
            .collect();
        println!("level {c} component std in quantisation steps: [{}]", sd.join(","));
    }
    let f = field(&kind, size);
    let domain = ImageDomain::from_direction_field(size, size, &f, 1.0).unwrap();
    let opts = SynthesisOptions { seed, rosy_fix: rosy, ..opts };
    let mut times = Vec::new();
    let mut result = None;
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        result = Some(synthesize(&analysis, &domain, &opts, &NoProgress).unwrap());
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let result = result.unwrap();
    let levels: Vec<String> = result.level_timings_ms.iter().map(|t| format!("{t:.0}")).collect();
    println!(
        "BENCH synth_{size} median_ms={:.1} min_ms={:.1} levels_ms=[{}]",
        median(times.clone()),
        times.iter().cloned().fold(f64::INFINITY, f64::min),
        levels.join(",")
    );
    let tag = if rosy { "" } else { "_norosy" };
    let out = out_dir.join(format!("synth_{name}_{kind}{tag}.png"));
    save(&result.colors, &out);
    let (w, h) = (analysis.width() as f32, analysis.height() as f32);
    let coords = Image {
        width: size,
        height: size,
        pixels: result
            .coords
            .iter()
            .zip(&result.flips)
            .map(|(u, &fl)| [u[0] / w, u[1] / h, if fl { 1.0 } else { 0.0 }, 1.0])
            .collect(),
    };
    save(&coords, &out.with_file_name(format!("synth_{name}_{kind}{tag}_coords.png")));
    println!("wrote {}", out.display());
}
