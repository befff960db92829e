//! A procedural brick exemplar, a stand-in for a 512² brick photo; included by path by
//! texopt's structured-exemplar test and the facade's `align_real_exemplar` test. The
//! including file imports `Image` (`fieldtex_core::Image`).

use super::Image;

/// Integer hash → `[0, 1)`.
fn hash(mut x: u64) -> f32 {
    x ^= x >> 33;
    x = x.wrapping_mul(0xff51_afd7_ed55_8ccd);
    x ^= x >> 33;
    x = x.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    x ^= x >> 33;
    (x >> 40) as f32 / (1u64 << 24) as f32
}

/// Bricks 100 × 42 px with 6-px light mortar, courses offset by half a brick, a shade per
/// brick and a little per-pixel grain (a stand-in for a 512² brick photo).
pub fn bricks(size: usize) -> Image {
    let mut img = Image::new(size, size, [0.0, 0.0, 0.0, 1.0]);
    for y in 0..size {
        for x in 0..size {
            let course = y / 42;
            let xs = x + course % 2 * 50;
            let brick = (course * 64 + xs / 100) as u64;
            let mortar = y % 42 < 6 || xs % 100 < 6;
            let grain = 0.08 * (hash((y * size + x) as u64 + 7) - 0.5);
            let c = if mortar {
                [0.78 + grain, 0.76 + grain, 0.72 + grain]
            } else {
                let s = 0.25 + 0.2 * hash(brick);
                [s + 0.15 + grain, s + grain, s - 0.05 + grain]
            };
            img.set(x, y, [c[0], c[1], c[2], 1.0]);
        }
    }
    img
}
