//! Separable filters shared by the metrics: Gaussian smoothing and accurate
//! derivatives. Borders are mirrored (`… 2 1 | 0 1 2 …`); results are deterministic
//! (each output value is computed by one fixed sequence of operations).

use rayon::prelude::*;

/// Mirror an index into `0..n` (`n ≥ 1`).
#[inline]
pub(crate) fn mirror(i: isize, n: usize) -> usize {
    let n = n as isize;
    if n == 1 {
        return 0;
    }
    let period = 2 * (n - 1);
    let mut k = i.rem_euclid(period);
    if k >= n {
        k = period - k;
    }
    k as usize
}

/// `row` extended by `r` mirrored values on each side.
pub(crate) fn mirrored_row(row: &[f32], r: usize) -> Vec<f32> {
    let n = row.len();
    (0..n + 2 * r).map(|i| row[mirror(i as isize - r as isize, n)]).collect()
}

/// Normalised sampled Gaussian of standard deviation `sigma` and radius `⌈3σ⌉`.
pub(crate) fn gaussian_kernel(sigma: f64) -> Vec<f32> {
    if sigma.is_nan() || sigma <= 0.0 {
        return vec![1.0];
    }
    let r = (3.0 * sigma).ceil() as isize;
    let w: Vec<f64> = (-r..=r).map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp()).collect();
    let s: f64 = w.iter().sum();
    w.iter().map(|v| (v / s) as f32).collect()
}

/// Correlates every row with `kx` and then every column with `ky` (odd lengths,
/// centred), mirrored borders.
pub(crate) fn separable(
    data: &[f32],
    width: usize,
    height: usize,
    kx: &[f32],
    ky: &[f32],
) -> Vec<f32> {
    let mut tmp = vec![0f32; data.len()];
    let rx = kx.len() / 2;
    tmp.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        let padded = mirrored_row(&data[y * width..(y + 1) * width], rx);
        // Eight outputs at a time with their sums in registers (vectorisable along x);
        // every output sums its taps in kernel order from 0, so the values are those of
        // a per-pixel loop.
        let mut chunks = row.chunks_exact_mut(8);
        for (c, out) in chunks.by_ref().enumerate() {
            let mut acc = [0f32; 8];
            for (k, &w) in kx.iter().enumerate() {
                let win = &padded[c * 8 + k..c * 8 + k + 8];
                for (a, v) in acc.iter_mut().zip(win) {
                    *a += w * v;
                }
            }
            out.copy_from_slice(&acc);
        }
        let done = width - chunks.into_remainder().len();
        for (x, out) in row.iter_mut().enumerate().skip(done) {
            let mut acc = 0f32;
            for (w, v) in kx.iter().zip(&padded[x..x + kx.len()]) {
                acc += w * v;
            }
            *out = acc;
        }
    });
    let mut out = vec![0f32; data.len()];
    let ry = (ky.len() / 2) as isize;
    out.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (k, &w) in ky.iter().enumerate() {
            let yy = mirror(y as isize + k as isize - ry, height);
            let src = &tmp[yy * width..(yy + 1) * width];
            for (o, s) in row.iter_mut().zip(src) {
                *o += w * s;
            }
        }
    });
    out
}

/// Gaussian smoothing with standard deviation `sigma` pixels (identity for σ ≤ 0).
pub(crate) fn gaussian_blur(data: &[f32], width: usize, height: usize, sigma: f64) -> Vec<f32> {
    let k = gaussian_kernel(sigma);
    separable(data, width, height, &k, &k)
}

/// Farid & Simoncelli (2004, "Differentiation of discrete multidimensional signals",
/// IEEE TIP) 5-tap matched prefilter and derivative. Their ratio of frequency
/// responses follows `iω` closely up to about half the Nyquist frequency, so the
/// gradient direction of an oriented pattern is nearly rotation-invariant (the
/// central difference is biased by more than a degree at an 8-px period).
const FARID_P: [f32; 5] = [0.030320, 0.249724, 0.439911, 0.249724, 0.030320];
/// Derivative taps for correlation: `Σ d[k] f(x + k − 2) ≈ ∂f/∂x`.
const FARID_D: [f32; 5] = [-0.104550, -0.292315, 0.0, 0.292315, 0.104550];

/// Image gradient `(∂/∂x, ∂/∂y)` (x right, y down) with the Farid–Simoncelli filters.
pub(crate) fn gradient(data: &[f32], width: usize, height: usize) -> (Vec<f32>, Vec<f32>) {
    let gx = separable(data, width, height, &FARID_D, &FARID_P);
    let gy = separable(data, width, height, &FARID_P, &FARID_D);
    (gx, gy)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mirror_indices() {
        let m: Vec<usize> = (-3..8).map(|i| mirror(i, 5)).collect();
        assert_eq!(m, vec![3, 2, 1, 0, 1, 2, 3, 4, 3, 2, 1]);
        assert_eq!(mirror(-7, 1), 0);
    }

    #[test]
    fn gradient_of_a_ramp() {
        let (w, h) = (16, 8);
        let data: Vec<f32> =
            (0..w * h).map(|i| 0.5 * (i % w) as f32 - 0.25 * (i / w) as f32).collect();
        let (gx, gy) = gradient(&data, w, h);
        let i = 4 * w + 8;
        // The 5-tap derivative has unit slope to within 0.3 %.
        assert!((gx[i] - 0.5).abs() < 0.005, "{}", gx[i]);
        assert!((gy[i] + 0.25).abs() < 0.0025, "{}", gy[i]);
    }

    #[test]
    fn blur_preserves_constant() {
        let d = vec![0.3f32; 20 * 10];
        let b = gaussian_blur(&d, 20, 10, 2.5);
        assert!(b.iter().all(|v| (v - 0.3).abs() < 1e-5));
    }

    /// The blocked row pass gives each output the bits of a plain per-pixel sum (taps
    /// in kernel order from 0), for widths with and without a remainder of 8.
    #[test]
    fn row_pass_equals_a_per_pixel_sum() {
        let k = gaussian_kernel(1.7);
        for (w, h) in [(21usize, 3usize), (16, 2), (5, 4)] {
            let data: Vec<f32> = (0..w * h).map(|i| ((i * 37 % 11) as f32).sin()).collect();
            let got = separable(&data, w, h, &k, &[1.0]);
            for y in 0..h {
                let padded = mirrored_row(&data[y * w..(y + 1) * w], k.len() / 2);
                for x in 0..w {
                    let mut acc = 0f32;
                    for (t, v) in k.iter().zip(&padded[x..x + k.len()]) {
                        acc += t * v;
                    }
                    assert_eq!(got[y * w + x].to_bits(), acc.to_bits(), "{w}×{h} ({x}, {y})");
                }
            }
        }
    }
}
