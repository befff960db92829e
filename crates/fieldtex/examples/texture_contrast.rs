//! Contrast and gradient ratios of a textured model's base-colour texture against an
//! exemplar (`fieldtex_eval::contrast_sharpness`), for comparing `align` outputs made by
//! different builds (bench/align_quality.sh). Texels that are exactly the empty-texel
//! grey (128, 128, 128) are left out.
//!
//! `cargo run --release -p fieldtex --example texture_contrast -- MODEL.glb EXEMPLAR SCALE`
//! prints `contrast_ratio gradient_ratio`.

use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        eprintln!("usage: texture_contrast MODEL.glb EXEMPLAR SCALE");
        std::process::exit(2);
    }
    let fail = |m: String| -> ! {
        eprintln!("{m}");
        std::process::exit(2)
    };
    let model = fieldtex_io::read_mesh(Path::new(&args[1])).unwrap_or_else(|e| fail(e.to_string()));
    let texture = model.base_color.unwrap_or_else(|| fail(format!("{} has no texture", args[1])));
    let exemplar =
        fieldtex_io::read_image(Path::new(&args[2])).unwrap_or_else(|e| fail(e.to_string()));
    let scale: f64 = args[3].parse().unwrap_or_else(|_| fail(format!("bad SCALE {}", args[3])));
    let grey = 128.0 / 255.0;
    let mask: Vec<bool> =
        texture.pixels.iter().map(|p| (0..3).any(|k| (p[k] - grey).abs() > 1e-4)).collect();
    let tbuf = fieldtex_eval::rgb_buffer(&texture);
    let ebuf = fieldtex_eval::rgb_buffer(&exemplar);
    let tv = fieldtex_eval::ImageView::new(&tbuf, texture.width, texture.height, 3)
        .unwrap_or_else(|e| fail(e.to_string()));
    let ev = fieldtex_eval::ImageView::new(&ebuf, exemplar.width, exemplar.height, 3)
        .unwrap_or_else(|e| fail(e.to_string()));
    let r = fieldtex_eval::contrast_sharpness(&tv, Some(&mask), &ev, scale)
        .unwrap_or_else(|e| fail(e.to_string()));
    println!("{:.4} {:.4}", r.contrast_ratio, r.gradient_ratio);
}
