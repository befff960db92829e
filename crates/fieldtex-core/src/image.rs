//! The image buffer shared by I/O, rendering, metrics and synthesis.
//!
//! Convention: row-major, top row first, `width × height` pixels of RGBA `f32`.
//! Colour channels hold **sRGB-encoded** values in `[0, 1]` (as stored in PNG files);
//! code that needs linear light converts explicitly with [`srgb_to_linear`]. Alpha is
//! linear coverage in `[0, 1]`. Pixel `(x, y)`: x to the right, y downward.

/// An RGBA `f32` image; see the module docs for conventions.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    /// `width * height` pixels, row-major, top row first.
    pub pixels: Vec<[f32; 4]>,
}

impl Image {
    /// A `width × height` image filled with `color`.
    pub fn new(width: usize, height: usize, color: [f32; 4]) -> Self {
        Self { width, height, pixels: vec![color; width * height] }
    }

    /// A `width × height` image whose pixel `(x, y)` is `f(x, y)` (row-major, `y` down).
    pub fn from_fn(width: usize, height: usize, f: impl Fn(usize, usize) -> [f32; 4]) -> Self {
        let pixels = (0..width * height).map(|i| f(i % width, i / width)).collect();
        Self { width, height, pixels }
    }

    #[inline]
    pub fn get(&self, x: usize, y: usize) -> [f32; 4] {
        self.pixels[y * self.width + x]
    }

    #[inline]
    pub fn set(&mut self, x: usize, y: usize, c: [f32; 4]) {
        self.pixels[y * self.width + x] = c;
    }

    /// Pixel with coordinates wrapped toroidally (for tileable exemplars).
    #[inline]
    pub fn get_wrapped(&self, x: i64, y: i64) -> [f32; 4] {
        let w = self.width as i64;
        let h = self.height as i64;
        self.pixels[(y.rem_euclid(h) * w + x.rem_euclid(w)) as usize]
    }

    /// Pixel with coordinates clamped to the image.
    #[inline]
    pub fn get_clamped(&self, x: i64, y: i64) -> [f32; 4] {
        let xi = x.clamp(0, self.width as i64 - 1) as usize;
        let yi = y.clamp(0, self.height as i64 - 1) as usize;
        self.pixels[yi * self.width + xi]
    }

    /// Bilinear sample at continuous pixel coordinates (pixel centres at `i + 0.5`),
    /// clamped at the border.
    pub fn sample_bilinear(&self, x: f64, y: f64) -> [f32; 4] {
        let fx = x - 0.5;
        let fy = y - 0.5;
        let x0 = fx.floor();
        let y0 = fy.floor();
        let tx = (fx - x0) as f32;
        let ty = (fy - y0) as f32;
        let (x0, y0) = (x0 as i64, y0 as i64);
        let a = self.get_clamped(x0, y0);
        let b = self.get_clamped(x0 + 1, y0);
        let c = self.get_clamped(x0, y0 + 1);
        let d = self.get_clamped(x0 + 1, y0 + 1);
        bilerp([a, b, c, d], tx, ty)
    }

    /// Luminance (Rec. 709 weights on the sRGB-encoded values) of every pixel.
    pub fn luminance(&self) -> Vec<f32> {
        self.pixels.iter().map(|p| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]).collect()
    }
}

/// Bilinear blend of four RGBA samples `[top-left, top-right, bottom-left,
/// bottom-right]` at fractions `(tx, ty)` in `[0, 1]`: the one interpolation behind every
/// bilinear image lookup (each caller resolves its own border: clamp, repeat, UV flip).
#[inline]
pub fn bilerp(corners: [[f32; 4]; 4], tx: f32, ty: f32) -> [f32; 4] {
    let [a, b, c, d] = corners;
    let mut out = [0.0f32; 4];
    for k in 0..4 {
        let top = a[k] + (b[k] - a[k]) * tx;
        let bot = c[k] + (d[k] - c[k]) * tx;
        out[k] = top + (bot - top) * ty;
    }
    out
}

/// sRGB transfer function, encoded → linear.
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// sRGB transfer function, linear → encoded.
#[inline]
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip() {
        for i in 0..=100 {
            let c = i as f32 / 100.0;
            assert!((linear_to_srgb(srgb_to_linear(c)) - c).abs() < 1e-5);
        }
    }

    #[test]
    fn bilinear_hits_pixel_centres() {
        let mut im = Image::new(2, 1, [0.0; 4]);
        im.set(1, 0, [1.0; 4]);
        assert_eq!(im.sample_bilinear(0.5, 0.5)[0], 0.0);
        assert_eq!(im.sample_bilinear(1.5, 0.5)[0], 1.0);
        assert!((im.sample_bilinear(1.0, 0.5)[0] - 0.5).abs() < 1e-6);
    }
}
