//! Helpers shared by the plane tests and the `texopt_plane` example (which includes
//! this file by path): reading an exemplar, carriers laid out as an image, and the
//! dominant line orientation of a result.

#![allow(dead_code)] // each user takes a subset

use fieldtex_core::Image;
use std::path::Path;

/// An RGBA image file as linear `f32` channels in `[0, 1]` (panics naming the path).
pub fn load_image(path: &Path) -> Image {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
        .to_rgba32f();
    let (w, h) = img.dimensions();
    Image { width: w as usize, height: h as usize, pixels: img.pixels().map(|p| p.0).collect() }
}

/// `shared/data/exemplars/<name>` beside the repository.
pub fn load_exemplar(name: &str) -> Image {
    load_image(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/exemplars").join(name),
    )
}

/// Rec. 709 luminance of one colour.
pub fn luma(col: [f32; 4]) -> f32 {
    0.2126 * col[0] + 0.7152 * col[1] + 0.0722 * col[2]
}

/// Luminance of the carriers laid out as an image (vertex (i, j) → pixel (i, size−1−j)).
pub fn luminance(colors: &[[f32; 4]], vertices: &[u32], size: usize) -> Vec<f32> {
    let mut out = vec![0.0; size * size];
    for (c, &v) in vertices.iter().enumerate() {
        let (i, j) = (v as usize % size, v as usize / size);
        out[(size - 1 - j) * size + i] = luma(colors[c]);
    }
    out
}

/// Dominant line orientation (radians in `[0, π)`) and coherence of a luminance image,
/// by fieldtex-eval's structure tensor.
pub fn dominant_orientation(luma: &[f32], w: usize, h: usize) -> Option<(f64, f64)> {
    let view = fieldtex_eval::ImageView::new(luma, w, h, 1).ok()?;
    let (deg, coherence) = fieldtex_eval::dominant_orientation(&view).ok()?;
    Some((deg.to_radians(), coherence))
}

/// Smallest angle between two line orientations (radians, modulo π).
pub fn line_angle_difference(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::PI);
    d.min(std::f64::consts::PI - d)
}
