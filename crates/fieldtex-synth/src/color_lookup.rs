//! Colour of a synthesised exemplar coordinate: nearest pixel or cubic convolution.
//!
//! The synthesis keeps continuous exemplar coordinates (the upsampling adds `h J o`
//! with a rotating Jacobian), so inside a coherent patch of a rotated region the
//! coordinates are an affine map of the output grid with arbitrary sub-pixel phase.
//! Reading the nearest exemplar pixel resamples the exemplar with a box of one pixel:
//! rotated patches become staircased copies (pixels repeated or skipped along the
//! stripes). [`ColorFilter::Cubic`] reads the exemplar with the cubic convolution
//! kernel of Keys (1981, "Cubic convolution interpolation for digital image
//! processing", IEEE TASSP 29(6), eq. 15 with `a = −½`, i.e. Catmull-Rom): 4 × 4 taps
//! around `u − (½, ½)` (pixel centres at half-integers), toroidal, each channel
//! clamped to the range of its 16 taps so no new extremes appear. At a pixel centre
//! the kernel returns that pixel exactly, so an unrotated, unjittered copy is unchanged.
//!
//! Measured (`examples/orient_probe`, 512² whorl preset, stripes / weave-diagonal /
//! woodgrain / bands exemplars, seed 1, guided coherence at stride 16, load ≈ 2.5):
//! nearest .00183 / .00503 / .000080 / .00058 → cubic .00171 / .00451 / .000075 /
//! .00050; bilinear lowered the weave score more (.0039) but blurred its fine diagonal
//! threads so much that the orientation error rose from 8.9° to 10.7° (cubic 9.0°).
//!
//! The resampling floor (`orient_probe --ideal DEG`: the exemplar itself, exactly
//! rotated to a constant field, scored by `fieldtex_eval::guided_coherence`, stride
//! 16): at 10°/30°/45° nearest gives weave .0043/.0029/.0029, bands .00057/.00047/
//! .00047, woodgrain .000074/.000056/.000057, stripes .00110/.00068/.00046; cubic
//! .0013/.0010/.0011, .00026/.00024/.00023, .000038/.000037/.000037, .00026/.00020/
//! .00018 (0°: exactly 0 with both). A perfect rotated copy of bands or woodgrain
//! therefore already scores about what Embark's *unguided* output scores (.00024,
//! .000039): any rotated synthesis of those two lies above it.

use crate::exemplar_analysis::ExemplarAnalysis;

/// How [`crate::synthesize`] turns exemplar coordinates into colours.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ColorFilter {
    /// The exemplar pixel containing the coordinate.
    Nearest,
    /// Keys cubic convolution (`a = −½`) over 4 × 4 pixels, clamped to their range.
    #[default]
    Cubic,
}

/// Keys (1981) cubic convolution weights (`a = −½`) of the four taps at offsets
/// −1, 0, 1, 2 from the pixel left of a sample at fraction `t ∈ [0, 1)`.
#[inline]
fn keys_weights(t: f32) -> [f32; 4] {
    let (t2, t3) = (t * t, t * t * t);
    [
        -0.5 * t3 + t2 - 0.5 * t,
        1.5 * t3 - 2.5 * t2 + 1.0,
        -1.5 * t3 + 2.0 * t2 + 0.5 * t,
        0.5 * t3 - 0.5 * t2,
    ]
}

/// Colour of exemplar coordinate `u` (pixel units, wrapped toroidally).
pub fn color_lookup(analysis: &ExemplarAnalysis, u: [f32; 2], filter: ColorFilter) -> [f32; 4] {
    match filter {
        ColorFilter::Nearest => analysis.color_at(u),
        ColorFilter::Cubic => cubic(analysis, u),
    }
}

fn cubic(analysis: &ExemplarAnalysis, u: [f32; 2]) -> [f32; 4] {
    let (w, h) = (analysis.width() as i64, analysis.height() as i64);
    let colors = analysis.colors();
    // Synthesised coordinates are wrapped, so the taps need at most one wrap each; the
    // Euclidean remainder covers any other input.
    let wrap = |v: i64, n: i64| {
        if v < 0 {
            if v >= -n { v + n } else { v.rem_euclid(n) }
        } else if v >= n {
            if v < 2 * n { v - n } else { v.rem_euclid(n) }
        } else {
            v
        }
    };
    // Pixel centres at half-integers: pixel i is centred at i + ½.
    keys_cubic(u[0] as f64 - 0.5, u[1] as f64 - 0.5, |x, y| {
        colors[wrap(y, h) as usize * w as usize + wrap(x, w) as usize]
    })
}

/// Keys (1981) cubic convolution (`a = −½`) at position `(x, y)` in pixel units (pixel
/// `(i, j)` centred at `(i, j)`) over the 4 × 4 pixels around it, read by `tap` (which
/// wraps or reflects as its image needs), each channel clamped to the range of its 16
/// taps so no new extremes appear. Exact at pixel centres. Rows are summed first, in tap
/// order. The one home of the kernel: the 2-D colour lookup here and the solid's
/// sub-pixel reads of its warp.
#[inline]
pub(crate) fn keys_cubic<const C: usize>(
    x: f64,
    y: f64,
    tap: impl Fn(i64, i64) -> [f32; C],
) -> [f32; C] {
    let (x0, y0) = (x.floor(), y.floor());
    let (wx, wy) = (keys_weights((x - x0) as f32), keys_weights((y - y0) as f32));
    let (x0, y0) = (x0 as i64, y0 as i64);
    let mut acc = [0.0f32; C];
    let mut lo = [f32::INFINITY; C];
    let mut hi = [f32::NEG_INFINITY; C];
    for (j, wyj) in wy.iter().enumerate() {
        let mut racc = [0.0f32; C];
        for (i, wxi) in wx.iter().enumerate() {
            let p = tap(x0 - 1 + i as i64, y0 - 1 + j as i64);
            for c in 0..C {
                racc[c] += wxi * p[c];
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        for c in 0..C {
            acc[c] += wyj * racc[c];
        }
    }
    std::array::from_fn(|c| acc[c].clamp(lo[c], hi[c]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::AnalysisOptions;
    use fieldtex_core::{Image, NoProgress};

    #[test]
    fn cubic_is_exact_at_pixel_centres_and_between_neighbours_elsewhere() {
        let (w, h) = (12, 10);
        let ex = Image::from_fn(w, h, |x, y| {
            [x as f32 / 11.0, y as f32 / 9.0, ((x * y) % 3) as f32 / 2.0, 1.0]
        });
        let an = ExemplarAnalysis::new(&ex, &AnalysisOptions::default(), &NoProgress).unwrap();
        for (x, y) in [(0usize, 0usize), (5, 3), (11, 9)] {
            let u = [x as f32 + 0.5, y as f32 + 0.5];
            assert_eq!(color_lookup(&an, u, ColorFilter::Cubic), ex.get(x, y));
            assert_eq!(
                color_lookup(&an, [u[0] + 0.4, u[1] - 0.4], ColorFilter::Nearest),
                ex.get(x, y)
            );
        }
        // Halfway between two pixels of a linear ramp (away from the wrap): the mean.
        let c = color_lookup(&an, [5.0, 3.5], ColorFilter::Cubic);
        assert!((c[0] - 4.5 / 11.0).abs() < 1e-6, "{c:?}");
        assert!((c[1] - 3.0 / 9.0).abs() < 1e-6, "{c:?}");
        // Clamped: never outside the range of the taps.
        for i in 0..50 {
            let u = [i as f32 * 0.37 % 12.0, i as f32 * 0.23 % 10.0];
            let c = color_lookup(&an, u, ColorFilter::Cubic);
            assert!(c.iter().all(|v| (-1e-6..=1.0 + 1e-6).contains(v)), "{u:?}: {c:?}");
        }
    }
}
