//! Procedural exemplars shared by the integration tests.

use std::f32::consts::PI;

use fieldtex_core::Image;

/// Horizontal sinusoidal stripes (they run along x, vary along y), period 8 px, tileable.
pub fn stripes(size: usize) -> Image {
    let mut im = Image::new(size, size, [0.0, 0.0, 0.0, 1.0]);
    for y in 0..size {
        for x in 0..size {
            let v = 0.5 + 0.45 * (2.0 * PI * y as f32 / 8.0).sin();
            // A little x structure so that the exemplar is not degenerate along x.
            let g = 0.5 + 0.1 * (2.0 * PI * x as f32 / size as f32).cos();
            im.set(x, y, [v, g * v, 1.0 - v, 1.0]);
        }
    }
    im
}
