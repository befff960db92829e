//! Golden-image tests: previews that must not change unnoticed (see `common/golden.rs`;
//! `scripts/update-golden` refreshes them after an intended change).

mod common;

use common::{code, golden, run_limited, shared, stderr, tmp_in};
use std::time::Duration;

/// The shaded preview of a mesh with sharp creases (the renderer: camera fit, shading,
/// rasterisation, anti-aliasing).
#[test]
fn render_preview_of_fandisk_matches_its_golden_image() {
    let d = tmp_in("fieldtex-golden", "render-fandisk");
    let out = d.join("fandisk.png");
    let mesh = shared().join("meshes/fandisk.obj");
    let args = ["render", mesh.to_str().unwrap(), "--size", "96", "--out", out.to_str().unwrap()];
    let o = run_limited(&args, Duration::from_secs(60));
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    golden::assert_golden_png("render-fandisk-96.png", &out);
}

/// A tampered image fails the comparison: the check can fail.
#[test]
fn a_changed_image_fails_the_golden_comparison() {
    if golden::updating() {
        return;
    }
    let d = tmp_in("fieldtex-golden", "tampered");
    let mut img =
        fieldtex::crates::io::read_image(&golden::golden_dir().join("render-fandisk-96.png"))
            .unwrap();
    // Invert a quarter of the image.
    let (w, h) = (img.width, img.height);
    for y in 0..h / 2 {
        for x in 0..w / 2 {
            let p = &mut img.pixels[y * w + x];
            *p = [1.0 - p[0], 1.0 - p[1], 1.0 - p[2], p[3]];
        }
    }
    let out = d.join("tampered.png");
    fieldtex::crates::io::write_png(&out, &img).unwrap();
    let r = std::panic::catch_unwind(|| golden::assert_golden_png("render-fandisk-96.png", &out));
    assert!(r.is_err(), "an image with an inverted quarter passed the golden comparison");
}
