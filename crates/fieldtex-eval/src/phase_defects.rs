//! Stripe breaks (dislocations) of a striped texture, per 10⁴ pixels.
//!
//! A dislocation is a point around which the stripe phase winds by ±2π: a stripe ends
//! or a new one is inserted. Method (complex demodulation along the local normal, in
//! the spirit of Larkin, Bone & Oldfield 2001 and of Gabor-filter fingerprint analysis,
//! Hong, Wan & Jain 1998):
//! 1. luminance minus its local mean (Gaussian, σ = period);
//! 2. stripe period `T`: given, or [`estimate_stripe_period`];
//! 3. structure-tensor stripe direction (σ = 0.75·T); the normal angle, taken in
//!    `[0°, 180°)`, is quantised into `directions` bins;
//! 4. for each bin, a complex Gabor filter `g(x) e^{−i k n·x}` (`k = 2π/T`, isotropic
//!    Gaussian envelope σ_g = `envelope_periods`·T, separable because the envelope and
//!    the plane wave both factor over x and y) gives at each pixel of that bin the
//!    analytic signal `R = A e^{iφ}` whose phase φ is the local stripe phase (the phase
//!    does not depend on a small mismatch of the filter's direction or frequency, only
//!    the amplitude does);
//! 5. around each 2×2 pixel loop the phase differences are wrapped and summed; the
//!    normal's sign is made consistent inside the loop (a corner whose binned normal is
//!    more than 90° from the first corner's uses `conj R`). A sum of ±2π marks a
//!    dislocation candidate;
//! 6. gating: the amplitude always vanishes *at* a dislocation, so loops are gated on
//!    the amplitude and coherence **smoothed** over one period (≥ `min_amplitude` ×
//!    their median, ≥ `min_coherence`), which rejects flat, noisy or isotropic regions;
//! 7. loops within 1.5·T of a ±1/2 singularity of the orientation (where the normal
//!    turns by 180° around the point and the phase winding is undefined) are skipped:
//!    those are counted by [`crate::singularities()`], not as stripe breaks;
//! 8. candidates closer than `merge_radius_periods`·T are merged (single linkage) and
//!    their charges summed, so dipoles of noise cancel. The count is the sum of the
//!    absolute net charges.
//!
//! The sign of a charge is relative to the normal direction in `[0°, 180°)` and is not
//! meaningful on its own; only counts are. Not implemented: multi-scale periods (one
//! period per image).

use crate::EvalError;
use crate::filters::{gaussian_blur, gaussian_kernel, gradient, mirror, mirrored_row};
use crate::image_view::ImageView;
use crate::orientation::{OrientationOptions, luminance_orientation};
use crate::singularities::loop_winding;
use fieldtex_fields::singularity_index::turns;
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::PI;

/// Options of [`phase_defects`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PhaseDefectOptions {
    /// Stripe period in pixels, in `[2.5, 256]`; `None` = [`estimate_stripe_period`].
    pub period_px: Option<f64>,
    /// Normal-direction bins of the Gabor bank over 180°. Default 16.
    pub directions: usize,
    /// Gabor envelope σ in periods. Default 0.5.
    pub envelope_periods: f64,
    /// Gate: smoothed amplitude ≥ this × its median over the image. Default 0.35.
    pub min_amplitude: f32,
    /// Gate: smoothed structure-tensor coherence ≥ this. Default 0.35.
    pub min_coherence: f32,
    /// Merge distance in periods. Default 0.75.
    pub merge_radius_periods: f64,
    /// Pixels ignored along each border; `None` = `⌈3σ_g⌉ + 2`.
    pub border: Option<usize>,
}

impl Default for PhaseDefectOptions {
    fn default() -> Self {
        Self {
            period_px: None,
            directions: 16,
            envelope_periods: 0.5,
            min_amplitude: 0.35,
            min_coherence: 0.35,
            merge_radius_periods: 0.75,
            border: None,
        }
    }
}

/// One dislocation (merged cluster).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PhaseDefect {
    /// Position, pixel coordinates with pixel `(i, j)` centred at `(i + ½, j + ½)`.
    pub x: f64,
    pub y: f64,
    /// Net winding of the phase in turns (±1 usually; sign relative to the normal).
    pub charge: i32,
}

/// Result of [`phase_defects`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PhaseDefectReport {
    pub defects: Vec<PhaseDefect>,
    /// Sum of `|charge|` over the defects.
    pub count: usize,
    /// `count` per 10⁴ evaluated pixels.
    pub per_10k_px: f64,
    /// Period used, pixels.
    pub period_px: f64,
    /// Pixels inside the border.
    pub evaluated_pixels: usize,
    /// Fraction of the evaluated loops that passed the gates (how much of the image
    /// looks like stripes at all).
    pub striped_fraction: f64,
    /// Reduction of the image the count was made on: 1 = full resolution, 2 = the 2×
    /// reduction of [`crate::coarse_phase_defects()`] (positions and pixel counts are in
    /// full-resolution pixels either way).
    pub reduction: usize,
}

fn check_image(image: &ImageView, min: usize) -> Result<(), EvalError> {
    if image.width < min || image.height < min {
        return Err(EvalError::TooSmall {
            what: "phase defects",
            width: image.width,
            height: image.height,
            min,
        });
    }
    Ok(())
}

/// Luminance minus its Gaussian local mean (σ = `sigma`).
fn detrend(luma: &[f32], w: usize, h: usize, sigma: f64) -> Vec<f32> {
    let mean = gaussian_blur(luma, w, h, sigma);
    luma.iter().zip(&mean).map(|(a, b)| a - b).collect()
}

/// Mean Gabor amplitude at a sparse grid of points, for period `t`, using the local
/// normal angle `normal` per pixel (filters as in [`phase_defects`], evaluated
/// directly at the points).
fn mean_gabor_amplitude(l0: &[f32], w: usize, h: usize, normal: &[f32], t: f64) -> f64 {
    let g = gaussian_kernel(0.5 * t);
    let r = (g.len() / 2) as isize;
    let k = 2.0 * PI / t;
    let n = 24usize;
    let margin = (w.min(h) / 8).max(1);
    let points: Vec<(usize, usize)> = (0..n * n)
        .map(|p| {
            let (i, j) = (p % n, p / n);
            (margin + i * (w - 2 * margin).max(1) / n, margin + j * (h - 2 * margin).max(1) / n)
        })
        .collect();
    let amps: Vec<f64> = points
        .par_iter()
        .map(|&(x, y)| {
            let beta = normal[y * w + x] as f64;
            let (kx, ky) = (k * beta.cos(), k * beta.sin());
            let taps = |kk: f64| -> Vec<(f64, f64)> {
                (-r..=r)
                    .zip(&g)
                    .map(|(d, &gv)| {
                        (gv as f64 * (kk * d as f64).cos(), -(gv as f64) * (kk * d as f64).sin())
                    })
                    .collect()
            };
            let (hx, hy) = (taps(kx), taps(ky));
            // The mirrored columns of the window, once per point (the same indices, so
            // the same sums, as mirroring every tap).
            let cols: Vec<usize> = (-r..=r).map(|dx| mirror(x as isize + dx, w)).collect();
            let (mut re, mut im) = (0f64, 0f64);
            for (dy, &(yr, yi)) in (-r..=r).zip(&hy) {
                let row = &l0[mirror(y as isize + dy, h) * w..][..w];
                let (mut sr, mut si) = (0f64, 0f64);
                for (&c, &(xr, xi)) in cols.iter().zip(&hx) {
                    let v = row[c] as f64;
                    sr += xr * v;
                    si += xi * v;
                }
                re += yr * sr - yi * si;
                im += yr * si + yi * sr;
            }
            (re * re + im * im).sqrt()
        })
        .collect();
    amps.iter().sum::<f64>() / amps.len().max(1) as f64
}

/// The longest stripe period [`estimate_stripe_period`] reports for a `width × height`
/// image (its estimates lie in `[3, this]`): a third of the short side, within
/// `[3, 64]` pixels.
pub fn max_stripe_period(width: usize, height: usize) -> f64 {
    (width.min(height) as f64 / 3.0).clamp(3.0, 64.0)
}

/// Dominant stripe period of an image in pixels: a first guess from the ratio of
/// gradient energy to signal energy (`k² = Σ|∇f|² / Σf²` for a sinusoid), refined by
/// picking, among periods from half to twice the guess, the one whose oriented Gabor
/// filters respond most (harmonics of non-sinusoidal stripes inflate the first guess).
/// Clamped to `[3, min(width, height)/3]` and to at most 64 pixels.
pub fn estimate_stripe_period(image: &ImageView) -> Result<f64, EvalError> {
    check_image(image, 16)?;
    let (w, h) = (image.width, image.height);
    let luma = image.luminance();
    let t_max = max_stripe_period(w, h);
    let ratio_period = |sigma: f64| -> f64 {
        let l0 = detrend(&luma, w, h, sigma);
        let (gx, gy) = gradient(&l0, w, h);
        let (mut num, mut den) = (0f64, 0f64);
        for i in 0..w * h {
            num += (gx[i] as f64).powi(2) + (gy[i] as f64).powi(2);
            den += (l0[i] as f64).powi(2);
        }
        if num > 0.0 && den > 0.0 { 2.0 * PI / (num / den).sqrt() } else { t_max }
    };
    let t0 = ratio_period(8.0).clamp(3.0, t_max);
    let t1 = ratio_period((1.5 * t0).clamp(2.0, t_max)).clamp(3.0, t_max);
    let l0 = detrend(&luma, w, h, t1.max(2.0));
    let map =
        luminance_orientation(&l0, w, h, &OrientationOptions { sigma: (0.75 * t1).max(1.5) })?;
    let normal: Vec<f32> =
        map.angle.iter().map(|a| (*a as f64 + 0.5 * PI).rem_euclid(PI) as f32).collect();
    let mut best = (t1, -1.0);
    for s in -4..=4 {
        let t = (t1 * 2f64.powf(s as f64 / 4.0)).clamp(3.0, t_max);
        let a = mean_gabor_amplitude(&l0, w, h, &normal, t);
        if a > best.1 {
            best = (t, a);
        }
    }
    Ok(best.0)
}

/// Raw windings `(x, y, turns)` of one row of loops, loops passing the gates, loops.
type RowDefects = (Vec<(f64, f64, i32)>, u64, u64);

/// Counts dislocations of the stripes of `image`; see the module docs.
pub fn phase_defects(
    image: &ImageView,
    options: &PhaseDefectOptions,
) -> Result<PhaseDefectReport, EvalError> {
    check_image(image, 16)?;
    if options.directions < 4 || options.directions > 180 {
        return Err(EvalError::InvalidOption {
            name: "directions",
            value: options.directions.to_string(),
            reason: "must be in 4..=180",
        });
    }
    if !(options.envelope_periods.is_finite() && (0.2..=4.0).contains(&options.envelope_periods)) {
        return Err(EvalError::InvalidOption {
            name: "envelope_periods",
            value: options.envelope_periods.to_string(),
            reason: "must be in [0.2, 4]",
        });
    }
    let (w, h) = (image.width, image.height);
    let t = match options.period_px {
        Some(p) if p.is_finite() && (2.5..=256.0).contains(&p) => p,
        Some(p) => {
            return Err(EvalError::InvalidOption {
                name: "period_px",
                value: p.to_string(),
                reason: "must be a period in [2.5, 256] pixels",
            });
        }
        None => estimate_stripe_period(image)?,
    };
    let k = 2.0 * PI / t;
    let sg = options.envelope_periods * t;
    let border = options.border.unwrap_or((3.0 * sg).ceil() as usize + 2);
    let luma = image.luminance();
    let l0 = detrend(&luma, w, h, t);
    let map = luminance_orientation(&l0, w, h, &OrientationOptions { sigma: (0.75 * t).max(1.5) })?;
    let m = options.directions;
    let bin_width = PI / m as f64;
    let bins: Vec<u16> = map
        .angle
        .iter()
        .map(|a| {
            let beta = (*a as f64 + 0.5 * PI).rem_euclid(PI);
            ((beta / bin_width).round() as usize % m) as u16
        })
        .collect();

    // Gabor bank, one separable pass pair per direction bin.
    let g = gaussian_kernel(sg);
    let r = (g.len() / 2) as isize;
    let mut re = vec![0f32; w * h];
    let mut im = vec![0f32; w * h];
    // Start offsets of the (mirrored) rows within the column kernel's reach of each row.
    let taps = g.len();
    let reach_rows: Vec<usize> = (0..h)
        .flat_map(|y| (0..taps).map(move |j| mirror(y as isize + j as isize - r, h) * w))
        .collect();
    for b in 0..m {
        let beta = b as f64 * bin_width;
        let (kx, ky) = (k * beta.cos(), k * beta.sin());
        // h(d) = g(d) e^{−i k d}, as (cos, −sin) parts.
        let hx: Vec<(f32, f32)> = (-r..=r)
            .zip(&g)
            .map(|(d, &gv)| {
                (
                    (gv as f64 * (kx * d as f64).cos()) as f32,
                    (-(gv as f64) * (kx * d as f64).sin()) as f32,
                )
            })
            .collect();
        let hy: Vec<(f32, f32)> = (-r..=r)
            .zip(&g)
            .map(|(d, &gv)| {
                (
                    (gv as f64 * (ky * d as f64).cos()) as f32,
                    (-(gv as f64) * (ky * d as f64).sin()) as f32,
                )
            })
            .collect();
        if !bins.contains(&(b as u16)) {
            continue;
        }
        // Row pass: complex T(x, y) = Σ hx(d) l0(x + d, y), only where the column pass
        // below reads it: at (x, y') with a pixel of this bin in column x within the
        // kernel's reach of row y'.
        let mut needed = vec![false; w * h];
        for y in 0..h {
            let reach = &reach_rows[y * taps..(y + 1) * taps];
            for x in 0..w {
                if bins[y * w + x] as usize == b {
                    for &row in reach {
                        needed[row + x] = true;
                    }
                }
            }
        }
        let mut tre = vec![0f32; w * h];
        let mut tim = vec![0f32; w * h];
        tre.par_chunks_mut(w).zip(tim.par_chunks_mut(w)).enumerate().for_each(|(y, (tr, ti))| {
            let need = &needed[y * w..(y + 1) * w];
            if !need.contains(&true) {
                return;
            }
            let padded = mirrored_row(&l0[y * w..(y + 1) * w], r as usize);
            // Tap by tap over each run of needed pixels (vectorisable; each value sums
            // its taps in kernel order from 0, as a per-pixel loop would, so the values
            // do not depend on the runs).
            let mut x0 = 0;
            while x0 < w {
                if !need[x0] {
                    x0 += 1;
                    continue;
                }
                let x1 = need[x0..].iter().position(|&v| !v).map_or(w, |k| x0 + k);
                for (j, &(hr, hi)) in hx.iter().enumerate() {
                    for ((a, c), &v) in tr[x0..x1]
                        .iter_mut()
                        .zip(ti[x0..x1].iter_mut())
                        .zip(&padded[j + x0..j + x1])
                    {
                        *a += hr * v;
                        *c += hi * v;
                    }
                }
                x0 = x1;
            }
        });
        // Column pass at the pixels of this bin: R = Σ hy(d) T(x, y + d).
        re.par_chunks_mut(w).zip(im.par_chunks_mut(w)).enumerate().for_each(|(y, (rr, ri))| {
            let src_rows = &reach_rows[y * taps..(y + 1) * taps];
            for x in 0..w {
                if bins[y * w + x] as usize != b {
                    continue;
                }
                let (mut a, mut c) = (0f32, 0f32);
                for (&(hr, hi), &row) in hy.iter().zip(src_rows) {
                    let (vr, vi) = (tre[row + x], tim[row + x]);
                    a += hr * vr - hi * vi;
                    c += hr * vi + hi * vr;
                }
                rr[x] = a;
                ri[x] = c;
            }
        });
    }

    // Cores of ±1/2 orientation singularities: there the normal turns by 180° around
    // any loop, so the phase winding is not defined. Loops within `core` pixels of one
    // are not counted (they are reported by `singularities`, not as stripe breaks).
    let core = (1.5 * t).ceil() as isize;
    let mut near_core = vec![false; w * h];
    for y in 0..h - 1 {
        for x in 0..w - 1 {
            if loop_winding(&map, x, y) != 0.0 {
                for yy in (y as isize + 1 - core).max(0)..(y as isize + 1 + core).min(h as isize) {
                    for xx in
                        (x as isize + 1 - core).max(0)..(x as isize + 1 + core).min(w as isize)
                    {
                        near_core[yy as usize * w + xx as usize] = true;
                    }
                }
            }
        }
    }

    // Gates on smoothed amplitude and coherence.
    let amp: Vec<f32> = re.iter().zip(&im).map(|(a, b)| (a * a + b * b).sqrt()).collect();
    let amp_s = gaussian_blur(&amp, w, h, t);
    let coh_s = gaussian_blur(&map.coherence, w, h, t);
    let mut inner: Vec<f32> = Vec::new();
    for y in border..h.saturating_sub(border) {
        for x in border..w.saturating_sub(border) {
            inner.push(amp_s[y * w + x]);
        }
    }
    let evaluated_pixels = inner.len();
    if evaluated_pixels == 0 {
        return Ok(PhaseDefectReport {
            defects: Vec::new(),
            count: 0,
            per_10k_px: f64::NAN,
            period_px: t,
            evaluated_pixels: 0,
            striped_fraction: 0.0,
            reduction: 1,
        });
    }
    let mid = inner.len() / 2;
    inner.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    let amp_threshold = options.min_amplitude * inner[mid];

    let rows: Vec<RowDefects> = (border..h.saturating_sub(border + 1))
        .into_par_iter()
        .map(|y| {
            let mut found = Vec::new();
            let (mut passed, mut total) = (0u64, 0u64);
            for x in border..w.saturating_sub(border + 1) {
                let idx = [y * w + x, y * w + x + 1, (y + 1) * w + x + 1, (y + 1) * w + x];
                total += 1;
                if near_core[idx[0]] {
                    continue;
                }
                if idx.iter().any(|&i| amp_s[i] < amp_threshold || coh_s[i] < options.min_coherence)
                {
                    continue;
                }
                passed += 1;
                let b0 = bins[idx[0]] as usize;
                let z: Vec<(f64, f64)> = idx
                    .iter()
                    .map(|&i| {
                        // Normals are canonical in [0°, 180°): one more than 90° away
                        // from corner 0's is the opposite of a nearby normal.
                        let d = (bins[i] as usize).abs_diff(b0);
                        let flip = 2 * d > m || (2 * d == m && bins[i] as usize > b0);
                        let (a, c) = (re[i] as f64, im[i] as f64);
                        if flip { (a, -c) } else { (a, c) }
                    })
                    .collect();
                if z.iter().any(|&(a, c)| a == 0.0 && c == 0.0) {
                    continue;
                }
                let mut total_phase = 0f64;
                for j in 0..4 {
                    let (a, c) = z[j];
                    let (e, f) = z[(j + 1) % 4];
                    // arg(z_{j+1} · conj(z_j)) ∈ (−π, π].
                    total_phase += (f * a - e * c).atan2(e * a + f * c);
                }
                let winding = turns(total_phase);
                if winding != 0 {
                    found.push((x as f64 + 1.0, y as f64 + 1.0, winding));
                }
            }
            (found, passed, total)
        })
        .collect();
    let mut raw = Vec::new();
    let (mut passed, mut total) = (0u64, 0u64);
    for (f, p, tt) in rows {
        raw.extend(f);
        passed += p;
        total += tt;
    }
    let defects = merge_defects(&raw, options.merge_radius_periods.max(0.0) * t);
    let count: usize = defects.iter().map(|d| d.charge.unsigned_abs() as usize).sum();
    Ok(PhaseDefectReport {
        count,
        per_10k_px: count as f64 * 1e4 / evaluated_pixels as f64,
        defects,
        period_px: t,
        evaluated_pixels,
        striped_fraction: if total > 0 { passed as f64 / total as f64 } else { 0.0 },
        reduction: 1,
    })
}

/// Single-linkage merge of raw loop windings (`raw` sorted by y) within `radius`.
fn merge_defects(raw: &[(f64, f64, i32)], radius: f64) -> Vec<PhaseDefect> {
    let points: Vec<[f64; 2]> = raw.iter().map(|d| [d.0, d.1]).collect();
    let (labels, count) = crate::single_linkage::single_linkage_labels(&points, radius);
    let mut acc: Vec<(f64, f64, i32, usize)> = vec![(0.0, 0.0, 0, 0); count];
    for (d, &l) in raw.iter().zip(&labels) {
        acc[l].0 += d.0;
        acc[l].1 += d.1;
        acc[l].2 += d.2;
        acc[l].3 += 1;
    }
    acc.into_iter()
        .filter(|a| a.2 != 0)
        .map(|(sx, sy, c, cnt)| PhaseDefect { x: sx / cnt as f64, y: sy / cnt as f64, charge: c })
        .collect()
}

/// Sum of `|charge|` of the defects within `radius` pixels of any of `points` (e.g.
/// within 3 exemplar periods of each designed singularity).
pub fn count_defects_near(defects: &[PhaseDefect], points: &[[f64; 2]], radius: f64) -> usize {
    defects
        .iter()
        .filter(|d| {
            points.iter().any(|p| (d.x - p[0]).powi(2) + (d.y - p[1]).powi(2) <= radius * radius)
        })
        .map(|d| d.charge.unsigned_abs() as usize)
        .sum()
}
