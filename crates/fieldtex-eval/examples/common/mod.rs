//! Readers shared by this crate's examples (not part of the library).

/// An image file as RGB floats in `[0, 1]`, with its width and height.
pub fn rgb(path: &str) -> (Vec<f32>, usize, usize) {
    let img = image::open(path).unwrap_or_else(|e| panic!("{path}: {e}")).to_rgb8();
    let (w, h) = (img.width() as usize, img.height() as usize);
    (img.as_raw().iter().map(|&v| v as f32 / 255.0).collect(), w, h)
}

/// The little-endian float32 payload of a version-1 `.npy` file (e.g. orient's
/// `field.npy`, H×W×2).
pub fn npy(path: &str) -> Vec<f32> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let hl = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    bytes[10 + hl..].chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
}
