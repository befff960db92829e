//! Contrast and sharpness of a texture against its exemplar: the standard deviation of
//! luminance and the mean luminance-gradient magnitude, over the pixels of a mask (the
//! covered texels of an atlas) and over the whole exemplar, and their ratios.
//!
//! A synthesis that averages overlapping patches washes structure out: its luminance
//! standard deviation drops (a flat grey texture has ratio ≈ 0) and its gradients
//! soften (a blurred copy has gradient ratio < 1). Ratios near 1 mean the output keeps
//! the exemplar's contrast and crispness; they say nothing about *where* the structure
//! is (coherence and orientation error do).
//!
//! Conventions: luminance is [`ImageView::luminance`] (Rec. 709 on the stored, usually
//! sRGB, values). The gradient at pixel `(x, y)` is `sqrt(dx² + dy²)` of forward
//! differences, counted only where the pixel and its right and lower neighbours are all
//! in the mask (differences never cross a chart border). `pixel_ratio` is the size of
//! one exemplar pixel in output pixels (the texture's `--scale`): output gradients are
//! multiplied by it so both are per exemplar pixel.

use crate::{EvalError, ImageView};
use serde::Serialize;

/// Luminance statistics of one image (or its masked part).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LuminanceStatistics {
    /// Pixels counted.
    pub pixels: usize,
    pub mean: f64,
    pub std: f64,
    /// Mean forward-difference gradient magnitude (per pixel of the image).
    pub mean_gradient: f64,
}

/// Output against exemplar.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ContrastSharpnessReport {
    pub output: LuminanceStatistics,
    pub exemplar: LuminanceStatistics,
    /// `output.std / exemplar.std`.
    pub contrast_ratio: f64,
    /// `output.mean_gradient · pixel_ratio / exemplar.mean_gradient`.
    pub gradient_ratio: f64,
}

/// Statistics of `image` over the pixels where `mask` is true (all when `None`; `mask`
/// is `width × height`, row-major).
pub fn luminance_statistics(
    image: &ImageView,
    mask: Option<&[bool]>,
) -> Result<LuminanceStatistics, EvalError> {
    let (w, h) = (image.width, image.height);
    if let Some(m) = mask
        && m.len() != w * h
    {
        return Err(EvalError::BufferSize {
            what: "mask",
            width: w,
            height: h,
            channels: 1,
            expected: w * h,
            found: m.len(),
        });
    }
    let lum = image.luminance();
    let inside = |i: usize| mask.is_none_or(|m| m[i]);
    let (mut n, mut sum, mut sum2) = (0usize, 0.0f64, 0.0f64);
    let (mut ng, mut gsum) = (0usize, 0.0f64);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if !inside(i) {
                continue;
            }
            let l = lum[i] as f64;
            n += 1;
            sum += l;
            sum2 += l * l;
            if x + 1 < w && y + 1 < h && inside(i + 1) && inside(i + w) {
                let dx = lum[i + 1] as f64 - l;
                let dy = lum[i + w] as f64 - l;
                gsum += (dx * dx + dy * dy).sqrt();
                ng += 1;
            }
        }
    }
    let mean = if n > 0 { sum / n as f64 } else { 0.0 };
    let var = if n > 0 { (sum2 / n as f64 - mean * mean).max(0.0) } else { 0.0 };
    Ok(LuminanceStatistics {
        pixels: n,
        mean,
        std: var.sqrt(),
        mean_gradient: if ng > 0 { gsum / ng as f64 } else { 0.0 },
    })
}

/// Contrast and gradient ratios of `output` (over `mask`) against the whole `exemplar`;
/// see the module docs for `pixel_ratio`.
pub fn contrast_sharpness(
    output: &ImageView,
    mask: Option<&[bool]>,
    exemplar: &ImageView,
    pixel_ratio: f64,
) -> Result<ContrastSharpnessReport, EvalError> {
    let o = luminance_statistics(output, mask)?;
    let e = luminance_statistics(exemplar, None)?;
    let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
    Ok(ContrastSharpnessReport {
        output: o,
        exemplar: e,
        contrast_ratio: ratio(o.std, e.std),
        gradient_ratio: ratio(o.mean_gradient * pixel_ratio, e.mean_gradient),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blur_lowers_both_ratios_and_identity_gives_one() {
        let (w, h) = (32, 32);
        // Stripes 4 px wide plus per-pixel grain (blur keeps a lone step's total
        // variation but removes grain).
        let grain = |i: usize| ((i * 2_654_435_761) % 1000) as f32 / 1000.0 * 0.2;
        let img: Vec<f32> =
            (0..w * h).map(|i| if (i % w / 4) % 2 == 0 { 0.2 } else { 0.6 } + grain(i)).collect();
        let v = ImageView::new(&img, w, h, 1).unwrap();
        let same = contrast_sharpness(&v, None, &v, 1.0).unwrap();
        assert!((same.contrast_ratio - 1.0).abs() < 1e-9);
        assert!((same.gradient_ratio - 1.0).abs() < 1e-9);
        let blurred: Vec<f32> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let a = img[y * w + x.saturating_sub(1)];
                let b = img[y * w + (x + 1).min(w - 1)];
                (a + 2.0 * img[i] + b) / 4.0
            })
            .collect();
        let b = ImageView::new(&blurred, w, h, 1).unwrap();
        let r = contrast_sharpness(&b, None, &v, 1.0).unwrap();
        assert!(r.contrast_ratio < 0.95 && r.gradient_ratio < 0.9, "{r:?}");
        // A mask excludes pixels and the differences that cross its border.
        let mask: Vec<bool> = (0..w * h).map(|i| i % w < 4).collect();
        let flat = vec![0.5f32; w * h];
        let f = ImageView::new(&flat, w, h, 1).unwrap();
        let m = luminance_statistics(&f, Some(&mask)).unwrap();
        assert_eq!(m.pixels, 4 * h);
        assert_eq!(m.std, 0.0);
        assert_eq!(m.mean_gradient, 0.0);
    }
}
