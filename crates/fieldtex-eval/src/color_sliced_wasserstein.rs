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
    /// `Some(m)`: an image of more than `n > m` pixels is represented by a seeded
    /// random sample of about `m` of them (each pixel kept with probability `m / n`), a
    /// sampled estimate of its colour distribution (the facade's default reports use
    /// [`SAMPLED_PIXELS`]; the gap to the exact value is pinned by
    /// `tests/approximate_metrics.rs`). `None`: every pixel. Default `None`.
    pub max_pixels: Option<usize>,
}

/// The sample size of the facade's default (approximate) reports.
pub const SAMPLED_PIXELS: usize = 65_536;
/// The stated bound of the sampled distance `s` against the all-pixel value `a`:
/// `|s − a| ≤ SAMPLED_ERROR_BOUND_ABS + SAMPLED_ERROR_BOUND_PERCENT/100 · a` on the test
/// exemplars (`tests/approximate_metrics.rs` fails above). The absolute term matters
/// for near-identical distributions (values of a few 10⁻³, where the sampling noise is
/// of a few 10⁻⁴); the relative one for distinct distributions.
pub const SAMPLED_ERROR_BOUND_PERCENT: f64 = 2.0;
/// See [`SAMPLED_ERROR_BOUND_PERCENT`] (sRGB units).
pub const SAMPLED_ERROR_BOUND_ABS: f64 = 0.001;

impl Default for SlicedWassersteinOptions {
    fn default() -> Self {
        Self { directions: 64, seed: 0, max_pixels: None }
    }
}

/// The share of the `n` pixels kept when at most `max` are wanted (1 = all).
fn sample_share(n: usize, max: Option<usize>) -> f64 {
    match max {
        Some(m) if n > m => m.max(1) as f64 / n as f64,
        _ => 1.0,
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

/// The pixels of one image (all, or those whose indices are in a sample) as the list
/// of their distinct colours with multiplicities. Synthesised textures copy exemplar
/// pixels, so a 512² output often holds only the exemplar's few thousand colours:
/// projecting and sorting those instead of every pixel gives the same sorted
/// projection (each value repeated by its count) for a fraction of the work.
struct ColourCounts {
    /// `distinct × channels`, in the order of their bit patterns.
    colours: Vec<f32>,
    counts: Vec<u32>,
}

impl ColourCounts {
    /// `None` when the channels do not fit the packed key (more than 3) or when more
    /// than half the pixels are distinct (then the plain per-pixel path is cheaper).
    fn of(img: &ImageView, keep: Option<&[u32]>) -> Option<Self> {
        let c = img.channels;
        if c > 3 {
            return None;
        }
        let pack = |i: usize| {
            img.data[i * c..(i + 1) * c]
                .iter()
                .fold(0u128, |key, v| key << 32 | v.to_bits() as u128)
        };
        let mut keys: Vec<u128> = match keep {
            Some(k) => k.iter().map(|&i| pack(i as usize)).collect(),
            None => (0..img.data.len() / c).map(pack).collect(),
        };
        keys.sort_unstable();
        let mut colours = Vec::new();
        let mut counts: Vec<u32> = Vec::new();
        let mut previous = None;
        for key in keys.iter().copied() {
            if previous == Some(key) {
                *counts.last_mut().expect("a previous key has a count") += 1;
                continue;
            }
            if counts.len() * 2 >= keys.len() {
                return None;
            }
            previous = Some(key);
            counts.push(1);
            colours.extend((0..c).rev().map(|k| f32::from_bits((key >> (32 * k)) as u32)));
        }
        Some(Self { colours, counts })
    }
}

/// `Σ_k p[k]·dir[k]` in `f64`, rounded to `f32`: the projection of one pixel, the same
/// arithmetic on both paths so they give the same bits.
#[inline]
fn project(p: &[f32], dir: &[f64]) -> f32 {
    let mut s = 0f64;
    for (v, d) in p.iter().zip(dir) {
        s += *v as f64 * d;
    }
    s as f32
}

/// Sorted projections on `dir` of the pixels of `img` whose indices are in `keep`
/// (`None`: all), from `counts` when the image has few distinct colours.
fn sorted_projection(
    img: &ImageView,
    dir: &[f64],
    keep: Option<&[u32]>,
    counts: Option<&ColourCounts>,
) -> Vec<f32> {
    let c = img.channels;
    if let Some(cc) = counts {
        // Key in the high half, the colour's index in the low half: one u64 sort.
        let mut keyed: Vec<u64> = cc
            .colours
            .chunks_exact(c)
            .enumerate()
            .map(|(i, p)| (sort_key(project(p, dir)) as u64) << 32 | i as u64)
            .collect();
        keyed.sort_unstable();
        let total = cc.counts.iter().map(|&n| n as usize).sum();
        let mut out = Vec::with_capacity(total);
        for k in keyed {
            let v = from_key((k >> 32) as u32);
            out.extend(std::iter::repeat_n(v, cc.counts[k as u32 as usize] as usize));
        }
        return out;
    }
    let mut keys: Vec<u32> = match keep {
        Some(k) => {
            k.iter().map(|&i| sort_key(project(&img.data[i as usize * c..][..c], dir))).collect()
        }
        None => img.data.chunks_exact(c).map(|p| sort_key(project(p, dir))).collect(),
    };
    radix_sort_u32(&mut keys);
    keys.into_iter().map(from_key).collect()
}

/// Sorts `keys` ascending with a least-significant-digit radix sort (four passes of
/// 8 bits, one counting pass for all four; a pass whose digit is the same for every
/// key is skipped; the same result as `sort_unstable`). Sequential: the directions
/// are the parallel loop. (`fieldtex_mesh::bvh_ray_order` has a parallel one for its
/// 64-bit index keys.)
fn radix_sort_u32(keys: &mut Vec<u32>) {
    let mut hist = [[0usize; 256]; 4];
    for &k in keys.iter() {
        for (p, h) in hist.iter_mut().enumerate() {
            h[(k >> (8 * p)) as usize & 255] += 1;
        }
    }
    let mut other = vec![0u32; keys.len()];
    for (p, h) in hist.iter_mut().enumerate() {
        if h.contains(&keys.len()) {
            continue;
        }
        let mut sum = 0;
        for s in h.iter_mut() {
            (*s, sum) = (sum, sum + *s);
        }
        for &k in keys.iter() {
            let d = (k >> (8 * p)) as usize & 255;
            other[h[d]] = k;
            h[d] += 1;
        }
        std::mem::swap(keys, &mut other);
    }
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
    // Sampled pixels: each kept independently with the same share, decided by the
    // seeded stream (no aliasing with periodic patterns, unlike a regular sub-grid).
    let sample = |img: &ImageView, which: u64| -> Option<Vec<u32>> {
        let n = img.width * img.height;
        let share = sample_share(n, options.max_pixels);
        (share < 1.0).then(|| {
            (0..n as u32)
                .filter(|&i| {
                    hash_unit(
                        options.seed,
                        "eval-sliced-wasserstein-sample",
                        which << 40 | i as u64,
                    ) < share
                })
                .collect()
        })
    };
    let (ka, kb) = (sample(a, 0), sample(b, 1));
    let (ca, cb) =
        rayon::join(|| ColourCounts::of(a, ka.as_deref()), || ColourCounts::of(b, kb.as_deref()));
    let per_dir: Vec<f64> = dirs
        .par_iter()
        .map(|dir| {
            w2_squared_sorted(
                &sorted_projection(a, dir, ka.as_deref(), ca.as_ref()),
                &sorted_projection(b, dir, kb.as_deref(), cb.as_ref()),
            )
        })
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
    fn radix_sort_matches_the_library_sort() {
        let mut keys: Vec<u32> = (0..5000u64)
            .map(|i| sort_key((hash_unit(3, "radix-test", i) - 0.5) as f32 * 1e3))
            .chain([0, u32::MAX, 7, 7, 1 << 31])
            .collect();
        let mut expected = keys.clone();
        expected.sort_unstable();
        radix_sort_u32(&mut keys);
        assert_eq!(keys, expected);
    }

    /// A 64×64 image of `palette` colours (repeated), plus its pixel values.
    fn palette_image(palette: usize) -> Vec<f32> {
        (0..64 * 64u64)
            .flat_map(|i| {
                let colour = (hash_unit(5, "palette-pick", i) * palette as f64) as u64;
                (0..3).map(move |k| hash_unit(5, "palette-colour", colour * 3 + k) as f32)
            })
            .collect()
    }

    #[test]
    fn colour_counts_give_the_per_pixel_projection_bit_for_bit() {
        let data = palette_image(40);
        let img = ImageView::new(&data, 64, 64, 3).unwrap();
        let keep: Vec<u32> = (0..64 * 64).filter(|i| i % 3 != 1).collect();
        let dir = [0.48, -0.6, 0.64];
        for keep in [None, Some(&keep[..])] {
            let counts = ColourCounts::of(&img, keep).expect("40 colours are few");
            assert!(counts.counts.len() <= 40);
            let fast = sorted_projection(&img, &dir, keep, Some(&counts));
            let plain = sorted_projection(&img, &dir, keep, None);
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&fast), bits(&plain));
            assert_eq!(plain.len(), keep.map_or(64 * 64, <[u32]>::len));
        }
        // Mostly distinct colours take the per-pixel path.
        let many = palette_image(1 << 30);
        assert!(ColourCounts::of(&ImageView::new(&many, 64, 64, 3).unwrap(), None).is_none());
    }

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
