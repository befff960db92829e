//! The characteristic scale of an exemplar: the size, in pixels, of its largest
//! repeating structure (a brick with its mortar, a pebble, a stripe period), from the
//! autocorrelation of its luminance.
//!
//! Method (a plain spatial-statistics estimate; no paper prescribes it): the luminance
//! is box-averaged by an integer factor `b` so that the longer side is at most
//! [`ANALYSIS_SIDE`] pixels, its mean removed, and the normalised autocorrelation
//! `R(d) = ⟨l(x) l(x + d·u)⟩ / ⟨l²⟩` evaluated for lags `d = 1 … min(W, H)/2` (in
//! reduced pixels) along four directions `u` (0°, 45°, 90°, 135°; products over the
//! overlapping part only, no wrap). Per direction:
//! - a *period* is the first lag at which `R` has a local maximum above [`PEAK`] that
//!   rises at least [`PROMINENCE`] above the lowest `R` at smaller lags (bricks: the
//!   brick length along rows, the course height across; stripes: their period);
//! - without one, the *correlation length* is the first lag at which `R < 1/e²`, times
//!   two (a blob of diameter `D` decorrelates over about `D/2`); never reached: the
//!   longest lag.
//!
//! The scale is the largest period along the two axes (the diagonals only when neither
//! axis has one: along a diagonal a stripe period appears √2 longer); without any period, the
//! largest correlation length that is not the longest lag (a direction along which the
//! texture never decorrelates, e.g. along stripes, says nothing about its size); times
//! `b`, in exemplar pixels, at least 1.
//! Used to choose the coarsest patch of coarse-to-fine synthesis (`fieldtex align`):
//! the coarsest patches should span one whole structure (Kwatra et al. 2005 §3.1
//! pick the largest patch "comparable to the largest structures").

use fieldtex_core::Image;
use rayon::prelude::*;
use serde::Serialize;

/// Longest side of the reduced luminance image the autocorrelation is computed on.
pub const ANALYSIS_SIDE: usize = 256;
/// How far `R` must rise from its lowest value so far for a maximum to count as a
/// period.
pub const PROMINENCE: f64 = 0.1;
/// Smallest autocorrelation of a period's maximum.
pub const PEAK: f64 = 0.2;

/// The estimate and how it was reached.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CharacteristicScale {
    /// Largest structure size, exemplar pixels.
    pub pixels: f64,
    /// Per direction (0°, 45°, 90°, 135°): size in exemplar pixels and whether it was a
    /// period (`true`) or a correlation length.
    pub directions: [(f64, bool); 4],
    /// Box factor of the reduction.
    pub reduction: usize,
}

/// Estimates the characteristic scale of `exemplar` (module docs). A constant image
/// gives 1 pixel.
pub fn characteristic_scale(exemplar: &Image) -> CharacteristicScale {
    let (w0, h0) = (exemplar.width, exemplar.height);
    let b = w0.max(h0).div_ceil(ANALYSIS_SIDE).max(1);
    let (w, h) = ((w0 / b).max(1), (h0 / b).max(1));
    let lum0 = exemplar.luminance();
    let mut lum = vec![0.0f64; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut s = 0.0;
            for dy in 0..b {
                for dx in 0..b {
                    s += lum0[(y * b + dy) * w0 + x * b + dx] as f64;
                }
            }
            lum[y * w + x] = s / (b * b) as f64;
        }
    }
    let mean = lum.iter().sum::<f64>() / lum.len() as f64;
    lum.iter_mut().for_each(|v| *v -= mean);
    let max_lag = (w.min(h) / 2).max(1);
    let dirs: [(i64, i64); 4] = [(1, 0), (1, 1), (0, 1), (-1, 1)];
    let directions: Vec<(f64, bool)> = dirs
        .par_iter()
        .map(|&(ux, uy)| {
            let step = if ux != 0 && uy != 0 { std::f64::consts::SQRT_2 } else { 1.0 };
            let r: Vec<f64> = (0..=max_lag)
                .map(|d| autocorrelation(&lum, w, h, ux * d as i64, uy * d as i64))
                .collect();
            let r0 = r[0];
            if r0 <= 0.0 {
                return (1.0, false);
            }
            let r: Vec<f64> = r.iter().map(|v| v / r0).collect();
            let (lag, period) = structure_lag(&r);
            (lag as f64 * step * b as f64, period)
        })
        .collect();
    let directions = [directions[0], directions[1], directions[2], directions[3]];
    let longest = max_lag as f64 * b as f64;
    // Axis periods first: along a diagonal a stripe period appears √2 longer.
    let axis_period = directions[0].1 || directions[2].1;
    let periods = directions
        .iter()
        .enumerate()
        .filter(|(k, d)| d.1 && (!axis_period || k % 2 == 0))
        .map(|(_, d)| d.0);
    let lengths = directions.iter().filter(|d| !d.1 && d.0 < longest * 0.999).map(|d| d.0);
    let pixels = if directions.iter().any(|d| d.1) {
        periods.fold(1.0, f64::max)
    } else if directions.iter().any(|d| !d.1 && d.0 < longest * 0.999) {
        lengths.fold(1.0, f64::max)
    } else {
        directions.iter().map(|d| d.0).fold(1.0, f64::max)
    };
    CharacteristicScale { pixels, directions, reduction: b }
}

/// The period or doubled correlation length of a normalised autocorrelation `r`
/// (`r[0] = 1`), in lags, and whether it is a period.
fn structure_lag(r: &[f64]) -> (usize, bool) {
    let n = r.len();
    // First local maximum above PEAK that rises at least PROMINENCE above the minimum
    // before it (bricks along a row: the course's mortar keeps R high, but it dips
    // between vertical joints and peaks again one brick length on).
    let mut lowest = r[0];
    for d in 1..n.saturating_sub(1) {
        lowest = lowest.min(r[d]);
        if r[d] > PEAK && r[d] >= r[d - 1] && r[d] > r[d + 1] && r[d] - lowest >= PROMINENCE {
            return (d, true);
        }
    }
    let threshold = (-2.0f64).exp();
    match (1..n).find(|&d| r[d] < threshold) {
        Some(d) => ((2 * d).min(n - 1).max(1), false),
        None => ((n - 1).max(1), false),
    }
}

/// `⟨l(x) l(x + (dx, dy))⟩` over the overlap of the `w × h` image with its shift.
fn autocorrelation(l: &[f64], w: usize, h: usize, dx: i64, dy: i64) -> f64 {
    let (w, h) = (w as i64, h as i64);
    let (x0, x1) = (0.max(-dx), w.min(w - dx));
    let (y0, y1) = (0.max(-dy), h.min(h - dy));
    if x1 <= x0 || y1 <= y0 {
        return 0.0;
    }
    let mut s = 0.0;
    for y in y0..y1 {
        let a = &l[(y * w) as usize..];
        let b = &l[((y + dy) * w) as usize..];
        for x in x0..x1 {
            s += a[x as usize] * b[(x + dx) as usize];
        }
    }
    s / ((x1 - x0) * (y1 - y0)) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: usize, h: usize, f: impl Fn(usize, usize) -> f32) -> Image {
        Image::from_fn(w, h, |x, y| {
            let v = f(x, y);
            [v, v, v, 1.0]
        })
    }

    #[test]
    fn stripes_give_their_period_at_any_resolution() {
        for (size, period) in [(128usize, 16.0f64), (512, 64.0), (1024, 96.0)] {
            let img = image(size, size, |_, y| {
                (0.5 + 0.5 * (2.0 * std::f64::consts::PI * y as f64 / period).sin()) as f32
            });
            let s = characteristic_scale(&img);
            assert!((s.pixels - period).abs() <= 0.1 * period, "{size}: {s:?}");
            assert!(s.directions[2].1, "vertical lag is a period: {s:?}");
        }
    }

    #[test]
    fn bricks_give_the_brick_length_and_constant_gives_one() {
        // Bricks 48 × 16 px with 2-px mortar, courses offset by half a brick.
        let img = image(384, 384, |x, y| {
            let course = y / 16;
            let xs = (x + course % 2 * 24) % 48;
            if y % 16 < 2 || xs < 2 { 0.9 } else { 0.3 }
        });
        let s = characteristic_scale(&img);
        assert!((40.0..=56.0).contains(&s.pixels), "{s:?}");
        let flat = image(64, 64, |_, _| 0.5);
        assert_eq!(characteristic_scale(&flat).pixels, 1.0);
    }
}
