//! Golden images: an image a test produced, compared with a checked-in copy under
//! `crates/fieldtex-cli/tests/golden/`. `scripts/update-golden` (which sets
//! `FIELDTEX_UPDATE_GOLDEN=1`) rewrites the copies from the current code; review the
//! changed PNGs before committing them.
//!
//! Images are compared decoded (so a PNG encoder's byte choices do not matter) and with a
//! small tolerance, so that a last-bit difference in a maths library between machines
//! does not fail the suite while a visible change does: the mean absolute difference
//! must stay under 1/255 and at most 1 % of the pixels may differ by more than 8/255 in
//! any channel.

#![allow(dead_code)] // each test file uses a subset

use fieldtex::Image;
use std::path::{Path, PathBuf};

/// The folder of the checked-in golden images.
pub fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

/// Whether this run rewrites the golden images instead of checking them.
pub fn updating() -> bool {
    std::env::var_os("FIELDTEX_UPDATE_GOLDEN").is_some_and(|v| !v.is_empty() && v != "0")
}

/// Checks the PNG at `actual` against golden `name` (a file name under
/// [`golden_dir`]), or writes it there when [`updating`].
pub fn assert_golden_png(name: &str, actual: &Path) {
    let golden = golden_dir().join(name);
    if updating() {
        std::fs::copy(actual, &golden).unwrap_or_else(|e| panic!("{}: {e}", golden.display()));
        return;
    }
    let read = |p: &Path| -> Image {
        fieldtex::crates::io::read_image(p).unwrap_or_else(|e| {
            panic!("{e} (golden images are refreshed by scripts/update-golden)")
        })
    };
    let (want, got) = (read(&golden), read(actual));
    assert_eq!(
        (got.width, got.height),
        (want.width, want.height),
        "{name}: size differs from the golden image (scripts/update-golden refreshes it)"
    );
    let (mut sum, mut far) = (0f64, 0usize);
    for (a, b) in got.pixels.iter().zip(&want.pixels) {
        let d = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0f32, f32::max);
        sum += d as f64;
        far += usize::from(d > 8.0 / 255.0);
    }
    let n = want.pixels.len().max(1);
    let (mean, far_share) = (sum / n as f64, far as f64 / n as f64);
    assert!(
        mean < 1.0 / 255.0 && far_share <= 0.01,
        "{name}: mean difference {:.2}/255, {:.2} % of pixels off by more than 8/255 \
         (output kept at {}; scripts/update-golden refreshes the golden image if the change \
         is intended)",
        mean * 255.0,
        far_share * 100.0,
        actual.display()
    );
}
