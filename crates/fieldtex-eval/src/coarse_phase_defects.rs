//! [`phase_defects`] on the image reduced 2× (2×2 box means): the default of the fast
//! reports (`fieldtex orient` / `eval` without `--exact-metrics`), a substitute for the
//! full-resolution count with a measured error (`tests/approximate_metrics.rs`,
//! [`COARSE_ERROR_BOUND`]).
//!
//! Why it is sound: a dislocation is a topological point of the stripe phase (its
//! winding is ±2π on any loop around it), and a 2×2 box mean followed by decimation is
//! a low-pass filter with no effect on the phase of stripes much longer than 2 pixels
//! (the 2-tap mean's response at period `T` is `cos(π/T)` per axis, above 0.95 for
//! `T ≥ 10` px in the original pixels), so the phase field, and with it the windings, survive the
//! reduction; every length of the method (period, Gabor envelope, smoothing, merge
//! radius, singular cores) is in periods and halves with the image. The cost of the
//! count after the period estimate falls about 8× (a quarter of the pixels, half the
//! kernel taps).
//!
//! The stripe period is estimated at full resolution ([`estimate_stripe_period`], about
//! half of the full method's cost): estimated on the reduced image it can pick another
//! harmonic of a texture that is not clean stripes (bricks: 14 px reduced against
//! 6.9 px at full resolution, and half the defects). The reduction is used only when
//! that period is at least [`MIN_COARSE_PERIOD_PX`] reduced pixels (the Gabor bank of
//! [`phase_defects`] resolves the phase well above that); otherwise the
//! full-resolution method runs with the period already estimated. Positions, period
//! and pixel counts are reported in the original image's pixels.

use crate::EvalError;
use crate::image_view::ImageView;
use crate::phase_defects::{
    PhaseDefect, PhaseDefectOptions, PhaseDefectReport, estimate_stripe_period, phase_defects,
};

/// Smallest period, in reduced pixels, at which the reduced image is analysed (10 px
/// of the original image).
pub const MIN_COARSE_PERIOD_PX: f64 = 5.0;

/// Stated bound of the reduced count against the full-resolution one on the striped
/// test inputs (at least half the loops pass the stripe gates):
/// `|coarse − exact| ≤ COARSE_ERROR_BOUND.0 + COARSE_ERROR_BOUND.1 · exact` (defects,
/// share of the exact count). Measured values: `docs/perf/orient.md`.
pub const COARSE_ERROR_BOUND: (f64, f64) = (2.0, 0.15);

/// 2×2 box means of `image` (`⌊w/2⌋ × ⌊h/2⌋`; an odd last row or column is dropped).
fn halve(image: &ImageView) -> (Vec<f32>, usize, usize) {
    let (w, h, c) = (image.width / 2, image.height / 2, image.channels);
    let mut out = vec![0f32; w * h * c];
    for y in 0..h {
        for x in 0..w {
            for ch in 0..c {
                let s = image.at(2 * x, 2 * y, ch)
                    + image.at(2 * x + 1, 2 * y, ch)
                    + image.at(2 * x, 2 * y + 1, ch)
                    + image.at(2 * x + 1, 2 * y + 1, ch);
                out[(y * w + x) * c + ch] = 0.25 * s;
            }
        }
    }
    (out, w, h)
}

/// Phase defects of `image` counted on its 2× reduction when the stripes are long
/// enough (module docs), else at full resolution; `options` are those of the
/// full-resolution image (a given `period_px` and `border` in its pixels).
pub fn coarse_phase_defects(
    image: &ImageView,
    options: &PhaseDefectOptions,
) -> Result<PhaseDefectReport, EvalError> {
    // The reduction needs the method's 16-pixel minimum on the reduced image.
    if image.width < 32 || image.height < 32 {
        return phase_defects(image, options);
    }
    let period = match options.period_px {
        Some(p) => p,
        None => estimate_stripe_period(image)?,
    };
    let full = PhaseDefectOptions { period_px: Some(period), ..options.clone() };
    // Invalid periods get the full-resolution method's error.
    if !(period.is_finite() && period / 2.0 >= MIN_COARSE_PERIOD_PX && period <= 256.0) {
        return phase_defects(image, &full);
    }
    let (data, w, h) = halve(image);
    let small = ImageView::new(&data, w, h, image.channels)?;
    let coarse = PhaseDefectOptions {
        period_px: Some(period / 2.0),
        border: options.border.map(|b| b.div_ceil(2)),
        ..options.clone()
    };
    let r = phase_defects(&small, &coarse)?;
    // Reduced pixel (i, j) covers original pixels 2i..2i+2: a reduced coordinate
    // (pixel centres at i + ½) is half the original one.
    let defects: Vec<PhaseDefect> =
        r.defects.iter().map(|d| PhaseDefect { x: 2.0 * d.x, y: 2.0 * d.y, ..*d }).collect();
    let evaluated_pixels = 4 * r.evaluated_pixels;
    Ok(PhaseDefectReport {
        defects,
        count: r.count,
        per_10k_px: if evaluated_pixels > 0 {
            r.count as f64 * 1e4 / evaluated_pixels as f64
        } else {
            f64::NAN
        },
        period_px: 2.0 * r.period_px,
        evaluated_pixels,
        striped_fraction: r.striped_fraction,
        reduction: 2,
    })
}
