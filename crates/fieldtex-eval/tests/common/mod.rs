//! Shared inputs of the metric tests: the test exemplars and patchworks of them.

use std::path::Path;

/// The four shared exemplars the approximate metrics are measured on.
pub const TEST_EXEMPLARS: [&str; 4] = [
    "stripes_Fabric071.png",
    "bricks_Bricks012.png",
    "pebbles_Rocks002.png",
    "bands-fingerprint-like_Onyx013.png",
];

/// A shared test exemplar as interleaved RGB in [0, 1], with its width and height.
pub fn load(name: &str) -> (Vec<f32>, usize, usize) {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/exemplars").join(name);
    let im = image::open(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display())).to_rgb32f();
    let (w, h) = (im.width() as usize, im.height() as usize);
    (im.into_raw(), w, h)
}

/// A `size²` patchwork of the exemplar: 16×16 blocks copied (wrapping) from seeded
/// random positions, with a little seeded noise.
#[allow(dead_code)]
pub fn patchwork(ex: &[f32], w: usize, h: usize, size: usize, seed: u64) -> Vec<f32> {
    patchwork_with_coords(ex, w, h, size, seed, 1.0).0
}

/// [`patchwork`] whose blocks start in the left `share` of the exemplar's columns, with
/// the exemplar coordinate `[x, y]` each pixel copies (as `coords.npy` holds them).
pub fn patchwork_with_coords(
    ex: &[f32],
    w: usize,
    h: usize,
    size: usize,
    seed: u64,
    share: f64,
) -> (Vec<f32>, Vec<f32>) {
    let mut out = vec![0f32; size * size * 3];
    let mut coords = vec![0f32; size * size * 2];
    let block = 16;
    for by in (0..size).step_by(block) {
        for bx in (0..size).step_by(block) {
            let k = (by / block * 1000 + bx / block) as u64;
            let sx = (fieldtex_core::rng::hash_unit(seed, "pw-x", k) * w as f64 * share) as usize;
            let sy = (fieldtex_core::rng::hash_unit(seed, "pw-y", k) * h as f64) as usize;
            for y in by..(by + block).min(size) {
                for x in bx..(bx + block).min(size) {
                    let (ex_x, ex_y) = ((sx + x - bx) % w, (sy + y - by) % h);
                    coords[(y * size + x) * 2] = ex_x as f32;
                    coords[(y * size + x) * 2 + 1] = ex_y as f32;
                    for c in 0..3 {
                        let n = 0.02
                            * (fieldtex_core::rng::hash_unit(
                                seed,
                                "pw-n",
                                ((y * size + x) * 3 + c) as u64,
                            ) - 0.5) as f32;
                        out[(y * size + x) * 3 + c] = ex[(ex_y * w + ex_x) * 3 + c] + n;
                    }
                }
            }
        }
    }
    (out, coords)
}
