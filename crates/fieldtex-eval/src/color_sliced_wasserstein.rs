//! Sliced Wasserstein-2 distance between the colour distributions of two images.
//!
//! Rabin, Peyré, Delon & Bernot (2011, "Wasserstein barycenter and its application to
//! texture mixing"): project both pixel sets on random unit directions of colour
//! space, sort, and integrate the squared difference of the two quantile functions;
//! average over directions and take the square root. Unequal pixel counts are handled
//! exactly: the quantile functions are piecewise constant on `[0, 1]` with breaks at
//! `i/n` and `j/m`, and the integral is summed over the merged breaks.
//!
//! Directions are Gaussian vectors normalised, drawn from the seeded stream
//! `(seed, "eval-sliced-wasserstein", ·)`, so results are reproducible. Units are those
//! of the channel values (sRGB in `[0, 1]` for images).

use crate::EvalError;
use crate::image_view::ImageView;
use fieldtex_core::rng::hash_unit;
use rayon::prelude::*;
use serde::Serialize;

/// Options of [`color_sliced_wasserstein`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SlicedWassersteinOptions {
    /// Number of random directions. Default 64.
    pub directions: usize,
    /// Seed of the directions. Default 0.
    pub seed: u64,
}

impl Default for SlicedWassersteinOptions {
    fn default() -> Self {
        Self { directions: 64, seed: 0 }
    }
}

/// Result of [`color_sliced_wasserstein`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SlicedWassersteinReport {
    /// `sqrt(mean over directions of W2²)`, in channel units.
    pub distance: f64,
    /// Largest per-direction W2.
    pub max_direction_distance: f64,
    pub directions: usize,
    pub seed: u64,
}

/// Maps an `f32` to a `u32` whose unsigned order is the float's total order.
#[inline]
fn sort_key(v: f32) -> u32 {
    let b = v.to_bits();
    if b & 0x8000_0000 != 0 { !b } else { b | 0x8000_0000 }
}

#[inline]
fn from_key(k: u32) -> f32 {
    f32::from_bits(if k & 0x8000_0000 != 0 { k & 0x7fff_ffff } else { !k })
}

/// Sorted projections of the pixels of `img` on `dir`.
fn sorted_projection(img: &ImageView, dir: &[f64]) -> Vec<f32> {
    let c = img.channels;
    let mut keys: Vec<u32> = img
        .data
        .chunks_exact(c)
        .map(|p| {
            let mut s = 0f64;
            for k in 0..c {
                s += p[k] as f64 * dir[k];
            }
            sort_key(s as f32)
        })
        .collect();
    keys.sort_unstable();
    keys.into_iter().map(from_key).collect()
}

/// `∫₀¹ (A⁻¹(t) − B⁻¹(t))² dt` for sorted samples `a` (n) and `b` (m).
pub(crate) fn w2_squared_sorted(a: &[f32], b: &[f32]) -> f64 {
    let (n, m) = (a.len() as u64, b.len() as u64);
    if n == 0 || m == 0 {
        return f64::NAN;
    }
    let (mut i, mut j) = (0u64, 0u64);
    let mut t_prev = 0u64; // in units of 1/(n·m)
    let mut acc = 0f64;
    while i < n && j < m {
        // Next break: (i+1)/n = (i+1)·m/(n·m), (j+1)/m = (j+1)·n/(n·m).
        let ta = (i + 1) * m;
        let tb = (j + 1) * n;
        let t = ta.min(tb);
        let d = a[i as usize] as f64 - b[j as usize] as f64;
        acc += (t - t_prev) as f64 * d * d;
        t_prev = t;
        if ta == t {
            i += 1;
        }
        if tb == t {
            j += 1;
        }
    }
    acc / (n * m) as f64
}

/// Sliced Wasserstein-2 distance between the colours of `a` and `b` (same channel
/// count; sizes may differ). Deterministic for a given seed.
pub fn color_sliced_wasserstein(
    a: &ImageView,
    b: &ImageView,
    options: &SlicedWassersteinOptions,
) -> Result<SlicedWassersteinReport, EvalError> {
    if a.channels != b.channels {
        return Err(EvalError::ChannelMismatch {
            what: "sliced Wasserstein",
            a: a.channels,
            b: b.channels,
        });
    }
    for img in [a, b] {
        if img.width == 0 || img.height == 0 {
            return Err(EvalError::TooSmall {
                what: "sliced Wasserstein",
                width: img.width,
                height: img.height,
                min: 1,
            });
        }
    }
    if options.directions == 0 || options.directions > 100_000 {
        return Err(EvalError::InvalidOption {
            name: "directions",
            value: options.directions.to_string(),
            reason: "must be in 1..=100000",
        });
    }
    let c = a.channels;
    let dirs: Vec<Vec<f64>> = (0..options.directions)
        .map(|d| {
            // Box–Muller Gaussians from the seeded hash stream; retry on a zero vector.
            for attempt in 0u64.. {
                let v: Vec<f64> = (0..c)
                    .map(|k| {
                        let idx = ((d as u64 * 64 + attempt) * c as u64 + k as u64) * 2;
                        let u1 =
                            hash_unit(options.seed, "eval-sliced-wasserstein", idx).max(1e-300);
                        let u2 = hash_unit(options.seed, "eval-sliced-wasserstein", idx + 1);
                        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
                    })
                    .collect();
                let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                if n > 1e-9 {
                    return v.iter().map(|x| x / n).collect();
                }
            }
            unreachable!("the attempt loop only ends by returning")
        })
        .collect();
    let per_dir: Vec<f64> = dirs
        .par_iter()
        .map(|dir| w2_squared_sorted(&sorted_projection(a, dir), &sorted_projection(b, dir)))
        .collect();
    let mean = per_dir.iter().sum::<f64>() / per_dir.len() as f64;
    Ok(SlicedWassersteinReport {
        distance: mean.max(0.0).sqrt(),
        max_direction_distance: per_dir.iter().cloned().fold(0.0, f64::max).sqrt(),
        directions: options.directions,
        seed: options.seed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sort_keys_preserve_order() {
        let vals = [-3.5f32, -0.0, 0.0, 1e-30, 2.0, f32::MAX, -f32::MAX];
        for &x in &vals {
            assert_eq!(from_key(sort_key(x)).to_bits(), x.to_bits());
            for &y in &vals {
                if x < y {
                    assert!(sort_key(x) < sort_key(y), "{x} {y}");
                }
            }
        }
    }

    #[test]
    fn w2_of_shifted_and_resampled_sets() {
        let a: Vec<f32> = (0..100).map(|i| i as f32 / 100.0).collect();
        let b: Vec<f32> = a.iter().map(|v| v + 0.25).collect();
        assert!((w2_squared_sorted(&a, &b) - 0.0625).abs() < 1e-9);
        // Same distribution at different counts: [0, 1) uniform in 2 vs 4 atoms.
        let c = [0.25f32, 0.75];
        let d = [0.25f32, 0.25, 0.75, 0.75];
        assert!(w2_squared_sorted(&c, &d).abs() < 1e-12);
    }
}
