//! Steps 1–2 of the exemplar feature-line detector (`exemplar_feature_lines.rs`): the
//! per-pixel line response of the luminance at one scale from sampled Gaussian
//! derivatives (Lindeberg 1998, γ-normalised ridge strength, eq. 41; Steger 1998 §3.1
//! sub-pixel line points) and the selection of the dominant line scale.

use crate::exemplar_feature_lines::{ExemplarFeatureOptions, LinePolarity};
use rayon::prelude::*;

/// Largest sub-pixel offset (per axis) of a line point from its pixel centre. Steger's
/// ½ leaves one-pixel gaps where a slanted line passes between two pixel centres (the
/// extremum, found along the slanted normal, then lies just outside both pixels);
/// 0.6 closes them, and the duplicates it creates are consumed while linking.
const POINT_TOLERANCE: f64 = 0.6;

/// Gaussian smoothing, first and second derivative kernels for correlation
/// (`Σ k[j] f(x + j − r)`), radius `⌈4σ⌉`, normalised to be exact on 1, x and x²/2.
fn gaussian_kernels(sigma: f64) -> [Vec<f64>; 3] {
    let r = (4.0 * sigma).ceil() as i64;
    let offsets: Vec<f64> = (-r..=r).map(|j| j as f64).collect();
    let mut g: Vec<f64> = offsets.iter().map(|j| (-j * j / (2.0 * sigma * sigma)).exp()).collect();
    let sum: f64 = g.iter().sum();
    g.iter_mut().for_each(|v| *v /= sum);
    let mut d1: Vec<f64> = offsets.iter().zip(&g).map(|(j, g)| j * g).collect();
    let m1: f64 = d1.iter().zip(&offsets).map(|(d, j)| d * j).sum();
    d1.iter_mut().for_each(|v| *v /= m1);
    let mut d2: Vec<f64> =
        offsets.iter().zip(&g).map(|(j, g)| (j * j / (sigma * sigma) - 1.0) * g).collect();
    let dc: f64 = d2.iter().sum();
    d2.iter_mut().zip(&g).for_each(|(d, g)| *d -= dc * g);
    let m2: f64 = d2.iter().zip(&offsets).map(|(d, j)| d * j * j).sum();
    d2.iter_mut().for_each(|v| *v *= 2.0 / m2);
    [g, d1, d2]
}

/// Index `i` of a line of `n` samples, wrapped or mirrored (`… 2 1 | 0 1 2 …`).
#[inline]
fn border_index(i: i64, n: usize, wrap: bool) -> usize {
    let n = n as i64;
    if wrap || n == 1 {
        return i.rem_euclid(n) as usize;
    }
    let period = 2 * (n - 1);
    let k = i.rem_euclid(period);
    (if k >= n { period - k } else { k }) as usize
}

/// Correlates every row with `k` (borders wrapped or mirrored through a padded copy).
fn row_pass(data: &[f64], w: usize, h: usize, k: &[f64], wrap: bool) -> Vec<f64> {
    let r = (k.len() / 2) as i64;
    let mut out = vec![0f64; w * h];
    out.par_chunks_mut(w).enumerate().for_each_init(
        || Vec::with_capacity(w + k.len()),
        |padded, (y, out)| {
            let row = &data[y * w..(y + 1) * w];
            padded.clear();
            padded.extend((-r..w as i64 + r).map(|i| row[border_index(i, w, wrap)]));
            for (x, o) in out.iter_mut().enumerate() {
                *o = k.iter().zip(&padded[x..x + k.len()]).map(|(c, v)| c * v).sum();
            }
        },
    );
    out
}

/// Correlates every column with `k`.
fn col_pass(data: &[f64], w: usize, h: usize, k: &[f64], wrap: bool) -> Vec<f64> {
    let r = (k.len() / 2) as i64;
    let mut out = vec![0f64; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        for (j, c) in k.iter().enumerate() {
            let yy = border_index(y as i64 + j as i64 - r, h, wrap);
            for (o, s) in out.iter_mut().zip(&data[yy * w..(yy + 1) * w]) {
                *o += c * s;
            }
        }
    });
    out
}

/// Per-pixel line response at one scale.
#[derive(Clone, Copy, Default)]
pub(crate) struct Response {
    /// `σ²|λn − λt|` when λn has the wanted sign, else 0.
    pub(crate) strength: f64,
    /// Unit normal across the line.
    pub(crate) normal: [f64; 2],
    /// Sub-pixel offset of the profile extremum from the pixel centre.
    pub(crate) offset: [f64; 2],
    /// Whether the extremum lies inside the pixel.
    pub(crate) is_point: bool,
}

pub(crate) fn responses(
    luma: &[f64],
    w: usize,
    h: usize,
    sigma: f64,
    polarity: LinePolarity,
    wrap: bool,
    with_points: bool,
) -> Vec<Response> {
    let [g, d1, d2] = gaussian_kernels(sigma);
    let (rg, rd1, rd2) = (
        row_pass(luma, w, h, &g, wrap),
        row_pass(luma, w, h, &d1, wrap),
        row_pass(luma, w, h, &d2, wrap),
    );
    let lxx = col_pass(&rd2, w, h, &g, wrap);
    let lyy = col_pass(&rg, w, h, &d2, wrap);
    let lxy = col_pass(&rd1, w, h, &d1, wrap);
    let (lx, ly) = if with_points {
        (col_pass(&rd1, w, h, &g, wrap), col_pass(&rg, w, h, &d1, wrap))
    } else {
        (Vec::new(), Vec::new())
    };
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (a, b, c) = (lxx[i], lxy[i], lyy[i]);
            let mean = 0.5 * (a + c);
            let root = (0.25 * (a - c) * (a - c) + b * b).sqrt();
            let (ln, lt) =
                if mean >= 0.0 { (mean + root, mean - root) } else { (mean - root, mean + root) };
            let wanted = match polarity {
                LinePolarity::Dark => ln > 0.0,
                LinePolarity::Bright => ln < 0.0,
                LinePolarity::Both => ln != 0.0,
            };
            if !wanted {
                return Response::default();
            }
            let strength = sigma * sigma * (ln - lt).abs();
            if !with_points {
                return Response { strength, ..Response::default() };
            }
            // Eigenvector of ln: the better conditioned of two equivalent forms.
            let (u, v) = if (ln - a).abs() >= (ln - c).abs() { (b, ln - a) } else { (ln - c, b) };
            let norm = (u * u + v * v).sqrt();
            let normal = if norm > 0.0 { [u / norm, v / norm] } else { [1.0, 0.0] };
            let t = -(lx[i] * normal[0] + ly[i] * normal[1]) / ln;
            let offset = [t * normal[0], t * normal[1]];
            let is_point = t.is_finite()
                && offset[0].abs() <= POINT_TOLERANCE
                && offset[1].abs() <= POINT_TOLERANCE;
            Response { strength, normal, offset, is_point }
        })
        .collect()
}

/// Mean of the strongest 2 % of responses (scale-selection score).
fn top_mean(resp: &[Response]) -> f64 {
    let mut s: Vec<f64> = resp.iter().map(|r| r.strength).collect();
    let k = (s.len() / 50).max(1);
    s.select_nth_unstable_by(k - 1, |a, b| b.total_cmp(a));
    // The k largest, summed in sorted order (deterministic).
    let top = &mut s[..k];
    top.sort_by(f64::total_cmp);
    top.iter().sum::<f64>() / k as f64
}

pub(crate) fn select_scale(luma: &[f64], w: usize, h: usize, o: &ExemplarFeatureOptions) -> f64 {
    let limit = o.max_scale.min(w.min(h) as f64 / 6.0).max(1.0);
    let mut best = (f64::NEG_INFINITY, 1.0);
    let mut sigma = 1.0f64;
    while sigma <= limit + 1e-9 {
        let score = top_mean(&responses(luma, w, h, sigma, o.polarity, o.toroidal, false));
        if score > best.0 {
            best = (score, sigma);
        }
        sigma *= std::f64::consts::SQRT_2;
    }
    best.1
}
