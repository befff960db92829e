//! Resizes an exemplar to `SIZE × SIZE` (Catmull–Rom), for probing synthesis on photo-size
//! exemplars whose structures span many pixels (bench/align_quality.sh).
//!
//! `cargo run --release -p fieldtex-texopt --example resize_exemplar -- IN.png SIZE OUT.png`

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        eprintln!("usage: resize_exemplar IN.png SIZE OUT.png");
        std::process::exit(2);
    }
    let size: u32 = args[2].parse().unwrap_or_else(|_| {
        eprintln!("SIZE must be a positive integer, got {}", args[2]);
        std::process::exit(2)
    });
    let img = image::open(&args[1]).unwrap_or_else(|e| {
        eprintln!("cannot read {}: {e}", args[1]);
        std::process::exit(2)
    });
    let out = img.resize_exact(size, size, image::imageops::FilterType::CatmullRom).to_rgb8();
    out.save(&args[3]).unwrap_or_else(|e| {
        eprintln!("cannot write {}: {e}", args[3]);
        std::process::exit(1)
    });
}
