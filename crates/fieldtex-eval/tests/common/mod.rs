//! Shared inputs of the metric tests: the test exemplars and patchworks of them.

use std::path::Path;

/// The four shared exemplars the approximate metrics are measured on.
#[allow(dead_code)]
pub const TEST_EXEMPLARS: [&str; 4] = [
    "stripes_Fabric071.png",
    "bricks_Bricks012.png",
    "pebbles_Rocks002.png",
    "bands-fingerprint-like_Onyx013.png",
];

/// A shared test exemplar as interleaved RGB in [0, 1], with its width and height.
#[allow(dead_code)]
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
#[allow(dead_code)]
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

/// A `size²` image whose exemplar x axis follows the constant direction `deg`:
/// output pixel `P` copies exemplar pixel `round(Rᵀ (P − centre))` (toroidal), the way
/// a pixel-copying synthesis lays the exemplar out along a field. With `blocks`, the
/// exemplar-space plane is a patchwork of 24×24 blocks each shifted by a random
/// offset (seams like a synthesis output), the same patchwork for every angle.
#[allow(dead_code)]
pub fn rotated_copy(
    ex: &[f32],
    ew: usize,
    eh: usize,
    size: usize,
    deg: f64,
    blocks: bool,
) -> Vec<f32> {
    let (s, c) = deg.to_radians().sin_cos();
    let o = size as f64 / 2.0;
    let mut out = vec![0f32; size * size * 3];
    for y in 0..size {
        for x in 0..size {
            let (px, py) = (x as f64 - o, y as f64 - o);
            let mut ex_x = (c * px + s * py).round() as i64;
            let mut ex_y = (-s * px + c * py).round() as i64;
            if blocks {
                let b = (ex_x.div_euclid(24) * 1000 + ex_y.div_euclid(24)) as u64;
                ex_x += (fieldtex_core::rng::hash_unit(3, "blocks", 2 * b) * 1000.0) as i64;
                ex_y += (fieldtex_core::rng::hash_unit(3, "blocks", 2 * b + 1) * 1000.0) as i64;
            }
            let (ix, iy) =
                (ex_x.rem_euclid(ew as i64) as usize, ex_y.rem_euclid(eh as i64) as usize);
            for ch in 0..3 {
                out[(y * size + x) * 3 + ch] = ex[(iy * ew + ix) * 3 + ch];
            }
        }
    }
    out
}

/// A constant unit field at `deg` degrees (x right, y down), `size²` × 2.
#[allow(dead_code)]
pub fn constant_field(size: usize, deg: f64) -> Vec<f32> {
    let (s, c) = deg.to_radians().sin_cos();
    (0..size * size).flat_map(|_| [c as f32, s as f32]).collect()
}
