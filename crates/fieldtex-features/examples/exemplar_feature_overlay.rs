//! Writes a PNG overlay of an exemplar's detected feature lines for visual checking.
//!
//! `cargo run --release -p fieldtex-features --example exemplar_feature_overlay -- \
//!     EXEMPLAR.png OUT.png [--bright|--both] [--scale SIGMA]`
//!
//! The output is the exemplar enlarged 4× (nearest), its lines drawn in green (the
//! principal line in red), beside the distance map (grey, dark = near a line). Prints
//! one summary line: scale, line count, total length and time.

use fieldtex_core::Image;
use fieldtex_features::{ExemplarFeatureOptions, LinePolarity, detect_exemplar_feature_lines};
use std::path::Path;
use std::time::Instant;

const ZOOM: usize = 4;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        eprintln!(
            "usage: exemplar_feature_overlay EXEMPLAR.png OUT.png [--bright|--both] [--scale S]"
        );
        std::process::exit(2);
    }
    let image = fieldtex_io::read_image(Path::new(&args[0])).expect("read the exemplar");
    let mut options = ExemplarFeatureOptions::default();
    if args.iter().any(|a| a == "--bright") {
        options.polarity = LinePolarity::Bright;
    }
    if args.iter().any(|a| a == "--both") {
        options.polarity = LinePolarity::Both;
    }
    if let Some(i) = args.iter().position(|a| a == "--scale") {
        options.scale = args.get(i + 1).and_then(|s| s.parse().ok());
    }
    let t = Instant::now();
    let f = detect_exemplar_feature_lines(&image, &options).expect("detect feature lines");
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let total: f64 = f
        .lines
        .iter()
        .flat_map(|l| l.windows(2))
        .map(|s| (((s[1][0] - s[0][0]).powi(2) + (s[1][1] - s[0][1]).powi(2)) as f64).sqrt())
        .sum();
    println!(
        "{}: {}×{} scale σ={:.2} lines={} total_length_px={:.0} time_ms={:.1}",
        args[0],
        f.width,
        f.height,
        f.scale,
        f.lines.len(),
        total,
        ms
    );
    for w in &f.warnings {
        println!("warning: {w}");
    }
    let (w, h) = (f.width, f.height);
    let mut out = Image::new(2 * w * ZOOM, h * ZOOM, [0.0, 0.0, 0.0, 1.0]);
    let max_d = f.distance.iter().copied().filter(|d| d.is_finite()).fold(1.0f32, f32::max);
    for y in 0..h * ZOOM {
        for x in 0..w * ZOOM {
            out.set(x, y, image.get(x / ZOOM, y / ZOOM));
            let d = f.distance[(y / ZOOM) * w + x / ZOOM];
            let g = if d.is_finite() { (d / max_d).sqrt() } else { 1.0 };
            out.set(w * ZOOM + x, y, [g, g, g, 1.0]);
        }
    }
    for (k, line) in f.lines.iter().enumerate() {
        let colour = if k == 0 { [1.0, 0.0, 0.0, 1.0] } else { [0.0, 1.0, 0.0, 1.0] };
        for s in line.windows(2) {
            let steps = 4 * ZOOM;
            for i in 0..=steps {
                let t = i as f32 / steps as f32;
                // Pixel (i, j) is centred at (i, j): its zoomed block centre is
                // (i + ½)·ZOOM.
                let x = (s[0][0] + t * (s[1][0] - s[0][0]) + 0.5) * ZOOM as f32;
                let y = (s[0][1] + t * (s[1][1] - s[0][1]) + 0.5) * ZOOM as f32;
                let xi = (x.floor() as i64).rem_euclid((w * ZOOM) as i64) as usize;
                let yi = (y.floor() as i64).rem_euclid((h * ZOOM) as i64) as usize;
                out.set(xi, yi, colour);
            }
        }
    }
    fieldtex_io::write_png(Path::new(&args[1]), &out).expect("write the overlay");
}
