//! Feature lines of a texture exemplar and its distance-to-feature map (paper A, Xu et
//! al., §5.2: exemplar patches near feature lines are matched to surface patches near
//! salient curves).
//!
//! Paper A extracts exemplar features "using a heuristic approach [Wu and Yu 2004]";
//! here the strongest **ridge or valley curves of the luminance** are detected instead:
//!
//! 1. **Scale.** Hessian `H` of the luminance by sampled Gaussian derivatives at scales
//!    `σ = 1, √2, 2, …` (up to [`ExemplarFeatureOptions::max_scale`] and a sixth of the
//!    shorter side); at each scale the line strength `σ² |λn − λt|` (λn the eigenvalue
//!    of largest magnitude, of the wanted sign; λt the other one) is Lindeberg's
//!    γ-normalised ridge strength with γ = 1 (Lindeberg 1998, "Edge detection and ridge
//!    detection with automatic scale selection", IJCV 30(2), eq. 41 with `N = (Lpp −
//!    Lqq)²`). The scale whose strongest 2 % of pixels respond most is the exemplar's
//!    dominant line scale (for a sinusoidal stripe pattern of period `P`,
//!    `σ ≈ 0.22 P`).
//! 2. **Line points with non-maximum suppression across the line** (Steger 1998, "An
//!    unbiased detector of curvilinear structures", IEEE PAMI 20(2), §3.1): with the
//!    unit normal `n` (eigenvector of λn), the profile's extremum lies at `p + t n`,
//!    `t = −(∇L·n)/λn`; a pixel is a line point when that extremum falls inside it
//!    (`|t nx|, |t ny| ≤ ½`), which gives sub-pixel positions.
//! 3. **Hysteresis and linking** (Steger 1998, §4, simplified): line points at least
//!    `high` strong seed lines, which grow through line points at least `low` strong;
//!    from each seed (strongest first) the line is followed both ways, each step to the
//!    one of the three neighbours ahead that minimises distance + angle change
//!    (turns over 60° are refused, so lines cross; a one-pixel gap is bridged).
//!    Neighbours across the line that mark the same line are consumed.
//! 4. Lines shorter than [`ExemplarFeatureOptions::min_length_px`] are dropped; the
//!    rest are sorted by total strength (the first one is the principal line of §5.2).
//!
//! The lines (detected or given as polylines) are rasterised and the exact Euclidean
//! distance map computed ([`crate::distance_transform`]), toroidal by default (the
//! synthesis engines treat exemplars as tileable).
//!
//! **Coordinates.** Pixels, x right, y down, pixel `(i, j)` **centred at `(i, j)`** (the
//! index of the pixel; `fieldtex_core::Image::sample_bilinear` puts centres at `i + ½`
//! instead). In toroidal mode the first point of each detected line lies in the image
//! and later points continue across the border (they may lie outside `[0, W) × [0, H)`;
//! wrap them with `rem_euclid`).
//!
//! Files: steps 1–2 (line responses, scale selection) in `line_response.rs`; linking,
//! the entry points and the distance map here.
//!
//! Not implemented: Steger's bias correction for asymmetric line profiles, line width
//! estimation, junction handling (lines simply end at junctions), Wu & Yu's heuristic.

use crate::FeaturesError;
use crate::distance_transform::euclidean_distance_transform;
use crate::error::check_option;
use crate::line_response::{Response, responses, select_scale};
use fieldtex_core::{Image, Warning};
use serde::Serialize;

/// Which luminance extrema count as lines.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum LinePolarity {
    /// Dark lines on a lighter background (valleys of the luminance).
    Dark,
    /// Bright lines on a darker background (ridges).
    Bright,
    /// Both kinds.
    Both,
}

/// Options of [`detect_exemplar_feature_lines`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExemplarFeatureOptions {
    /// Line polarity. Default [`LinePolarity::Dark`] (grooves, grain, seams).
    pub polarity: LinePolarity,
    /// Gaussian scale σ in pixels; `None` selects it automatically (module docs).
    /// Default `None`.
    pub scale: Option<f64>,
    /// Largest σ tried by the automatic selection, pixels. Default 8.
    pub max_scale: f64,
    /// Seed threshold relative to the 99th percentile of line-point strength.
    /// Default 0.5.
    pub high_threshold: f64,
    /// Growth threshold relative to the same percentile (≤ `high_threshold`).
    /// Default 0.25.
    pub low_threshold: f64,
    /// Absolute floor of the seed threshold, in luminance units (a sinusoidal stripe
    /// of peak-to-peak contrast `c` has strength ≈ 0.37 c at its own scale).
    /// Default 0.01 (a flat or noise-only exemplar gives no lines).
    pub min_strength: f64,
    /// Lines shorter than this (pixels of arc length) are dropped. Default 10.
    pub min_length_px: f64,
    /// Treat the exemplar as tileable (filters and distances wrap). Default `true`.
    pub toroidal: bool,
}

impl Default for ExemplarFeatureOptions {
    fn default() -> Self {
        Self {
            polarity: LinePolarity::Dark,
            scale: None,
            max_scale: 8.0,
            high_threshold: 0.5,
            low_threshold: 0.25,
            min_strength: 0.01,
            min_length_px: 10.0,
            toroidal: true,
        }
    }
}

impl ExemplarFeatureOptions {
    pub fn validate(&self) -> Result<(), FeaturesError> {
        if let Some(s) = self.scale {
            check_option("scale", s, (0.3..=256.0).contains(&s), "in [0.3, 256] pixels")?;
        }
        let m = self.max_scale;
        check_option("max_scale", m, (1.0..=256.0).contains(&m), "in [1, 256] pixels")?;
        let h = self.high_threshold;
        check_option("high_threshold", h, h > 0.0 && h <= 1.0, "in (0, 1]")?;
        let l = self.low_threshold;
        check_option("low_threshold", l, l > 0.0 && l <= h, "in (0, high_threshold]")?;
        let s = self.min_strength;
        check_option("min_strength", s, s >= 0.0, "a non-negative strength")?;
        let len = self.min_length_px;
        check_option("min_length_px", len, len >= 0.0, "a non-negative length in pixels")
    }
}

/// Feature lines of an exemplar and its distance-to-feature map.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExemplarFeatures {
    pub width: usize,
    pub height: usize,
    /// Polylines in pixel coordinates (module docs), strongest first.
    pub lines: Vec<Vec<[f32; 2]>>,
    /// Mean line strength of each line (`σ²|λn − λt|`); 0 for given lines.
    pub strengths: Vec<f32>,
    /// `width × height` distance (pixels) from each pixel centre to the nearest
    /// rasterised line pixel, row-major; `+∞` everywhere when there is no line.
    #[serde(skip)]
    pub distance: Vec<f32>,
    /// Detection scale σ in pixels (0 for given lines).
    pub scale: f64,
    /// Whether lines and distances wrap around the borders.
    pub toroidal: bool,
    pub warnings: Vec<Warning>,
}

impl ExemplarFeatures {
    /// The principal feature line (paper A §5.2): the strongest one.
    pub fn principal_line(&self) -> Option<&[[f32; 2]]> {
        self.lines.first().map(|l| l.as_slice())
    }

    /// Distance map bilinearly interpolated at `(x, y)` (pixel centres at integers),
    /// wrapped in toroidal mode, clamped otherwise; `+∞` without lines or for a
    /// non-finite position.
    pub fn distance_at(&self, x: f64, y: f64) -> f32 {
        if !(x.is_finite() && y.is_finite()) || self.distance.is_empty() {
            return f32::INFINITY;
        }
        let (w, h) = (self.width as i64, self.height as i64);
        let index =
            |i: i64, n: i64| if self.toroidal { i.rem_euclid(n) } else { i.clamp(0, n - 1) };
        let (x0, y0) = (x.floor(), y.floor());
        let (tx, ty) = ((x - x0) as f32, (y - y0) as f32);
        let at = |i: i64, j: i64| self.distance[(index(j, h) * w + index(i, w)) as usize];
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = at(x0, y0) * (1.0 - tx) + at(x0 + 1, y0) * tx;
        let bottom = at(x0, y0 + 1) * (1.0 - tx) + at(x0 + 1, y0 + 1) * tx;
        top * (1.0 - ty) + bottom * ty
    }
}

const NEIGHBOURS: [[i64; 2]; 8] =
    [[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1]];

/// Offsets at Chebyshev distance 2.
const RING2: [[i64; 2]; 16] = [
    [2, 0],
    [2, 1],
    [2, 2],
    [1, 2],
    [0, 2],
    [-1, 2],
    [-2, 2],
    [-2, 1],
    [-2, 0],
    [-2, -1],
    [-2, -2],
    [-1, -2],
    [0, -2],
    [1, -2],
    [2, -2],
    [2, -1],
];

/// Line linking state over the line points of one scale.
struct Linker<'a> {
    resp: &'a [Response],
    w: usize,
    h: usize,
    wrap: bool,
    low: f64,
    visited: Vec<bool>,
}

impl Linker<'_> {
    /// Pixel index at unwrapped integer coordinates, `None` outside a non-toroidal image.
    fn index(&self, x: i64, y: i64) -> Option<usize> {
        let (w, h) = (self.w as i64, self.h as i64);
        if self.wrap {
            Some((y.rem_euclid(h) * w + x.rem_euclid(w)) as usize)
        } else if (0..w).contains(&x) && (0..h).contains(&y) {
            Some((y * w + x) as usize)
        } else {
            None
        }
    }

    fn candidate(&self, i: usize) -> bool {
        let r = &self.resp[i];
        r.is_point && r.strength >= self.low && !self.visited[i]
    }

    /// Marks pixel `(x, y)` used, with the neighbours whose line point duplicates it
    /// (less than ½ px along the line, 1.5 px across).
    fn consume(&mut self, x: i64, y: i64, dir: [f64; 2]) {
        let i = self.index(x, y).expect("consumed pixels are inside");
        self.visited[i] = true;
        let o = self.resp[i].offset;
        for [dx, dy] in NEIGHBOURS {
            let Some(j) = self.index(x + dx, y + dy) else { continue };
            if !self.candidate(j) {
                continue;
            }
            let q = self.resp[j].offset;
            let d = [dx as f64 + q[0] - o[0], dy as f64 + q[1] - o[1]];
            let along = d[0] * dir[0] + d[1] * dir[1];
            let across = d[0] * dir[1] - d[1] * dir[0];
            if along.abs() < 0.5 && across.abs() < 1.5 {
                self.visited[j] = true;
            }
        }
    }

    /// Follows the line from pixel `(x, y)` in direction `dir`; returns the points
    /// after the start, in unwrapped coordinates.
    fn trace(&mut self, mut x: i64, mut y: i64, mut dir: [f64; 2]) -> Vec<[f64; 2]> {
        let mut out = Vec::new();
        loop {
            let here = self.resp[self.index(x, y).expect("inside")].offset;
            let mut best: Option<(f64, i64, i64, [f64; 2])> = None;
            // The three neighbours ahead; failing those, the pixels two steps ahead
            // within about 30° (bridges a one-pixel gap).
            let ring2 = RING2.iter().filter(|o| {
                let len = ((o[0] * o[0] + o[1] * o[1]) as f64).sqrt();
                (o[0] as f64 * dir[0] + o[1] as f64 * dir[1]) / len >= 0.85
            });
            let ahead = NEIGHBOURS.iter().filter(|o| {
                let len = ((o[0] * o[0] + o[1] * o[1]) as f64).sqrt();
                (o[0] as f64 * dir[0] + o[1] as f64 * dir[1]) / len >= 0.38
            });
            for (ring, &[dx, dy]) in ahead.map(|o| (1, o)).chain(ring2.map(|o| (2, o))) {
                if ring == 2 && best.is_some() {
                    break;
                }
                let Some(j) = self.index(x + dx, y + dy) else { continue };
                if !self.candidate(j) {
                    continue;
                }
                let r = &self.resp[j];
                let d = [dx as f64 + r.offset[0] - here[0], dy as f64 + r.offset[1] - here[1]];
                let mut next = [-r.normal[1], r.normal[0]];
                let cos = next[0] * dir[0] + next[1] * dir[1];
                if cos < 0.0 {
                    next = [-next[0], -next[1]];
                }
                if cos.abs() < 0.5 {
                    continue; // turns by more than 60°: another line crossing this one
                }
                let cost = (d[0] * d[0] + d[1] * d[1]).sqrt() + cos.abs().min(1.0).acos();
                if best.is_none_or(|b| cost < b.0) {
                    best = Some((cost, x + dx, y + dy, next));
                }
            }
            let Some((_, nx, ny, next)) = best else { break };
            x = nx;
            y = ny;
            dir = next;
            self.consume(x, y, dir);
            let o = self.resp[self.index(x, y).expect("inside")].offset;
            out.push([x as f64 + o[0], y as f64 + o[1]]);
        }
        out
    }
}

fn polyline_length(line: &[[f64; 2]]) -> f64 {
    line.windows(2)
        .map(|s| ((s[1][0] - s[0][0]).powi(2) + (s[1][1] - s[0][1]).powi(2)).sqrt())
        .sum()
}

/// Exemplar feature lines and distance map (module docs). Errors on invalid options or
/// an image smaller than 3 × 3; non-finite pixel values are read as 0 with a warning;
/// an exemplar without lines gives no lines, an infinite distance map and a warning.
pub fn detect_exemplar_feature_lines(
    image: &Image,
    options: &ExemplarFeatureOptions,
) -> Result<ExemplarFeatures, FeaturesError> {
    options.validate()?;
    let (w, h) = (image.width, image.height);
    check_option("exemplar width", w as f64, w >= 3, "at least 3 pixels")?;
    check_option("exemplar height", h as f64, h >= 3, "at least 3 pixels")?;
    let n = image.pixels.len() as f64;
    check_option("exemplar pixel count", n, image.pixels.len() == w * h, "width × height")?;
    let mut warnings = Vec::new();
    let mut bad = 0usize;
    let luma: Vec<f64> = image
        .luminance()
        .into_iter()
        .map(|v| {
            if v.is_finite() {
                v as f64
            } else {
                bad += 1;
                0.0
            }
        })
        .collect();
    if bad > 0 {
        warnings.push(Warning::new(
            "exemplar-non-finite-pixels",
            format!("{bad} exemplar pixels have a NaN or infinite value; they were read as 0"),
        ));
    }
    let sigma = options.scale.unwrap_or_else(|| select_scale(&luma, w, h, options));
    let resp = responses(&luma, w, h, sigma, options.polarity, options.toroidal, true);

    // Hysteresis thresholds relative to the 99th percentile of line-point strength.
    let mut point_strengths: Vec<f64> =
        resp.iter().filter(|r| r.is_point && r.strength > 0.0).map(|r| r.strength).collect();
    point_strengths.sort_by(f64::total_cmp);
    let reference = point_strengths
        .get((point_strengths.len() as f64 * 0.99) as usize)
        .or(point_strengths.last())
        .copied()
        .unwrap_or(0.0);
    let high = (options.high_threshold * reference).max(options.min_strength);
    let low = (options.low_threshold * reference).max(0.5 * options.min_strength).min(high);

    let mut seeds: Vec<usize> =
        (0..w * h).filter(|&i| resp[i].is_point && resp[i].strength >= high).collect();
    seeds.sort_by(|&a, &b| resp[b].strength.total_cmp(&resp[a].strength).then(a.cmp(&b)));
    let mut linker =
        Linker { resp: &resp, w, h, wrap: options.toroidal, low, visited: vec![false; w * h] };
    let mut found: Vec<(f64, f64, Vec<[f64; 2]>)> = Vec::new();
    for seed in seeds {
        if linker.visited[seed] {
            continue;
        }
        let (x, y) = ((seed % w) as i64, (seed / w) as i64);
        let r = resp[seed];
        let dir = [-r.normal[1], r.normal[0]];
        linker.consume(x, y, dir);
        let forward = linker.trace(x, y, dir);
        let backward = linker.trace(x, y, [-dir[0], -dir[1]]);
        let mut line: Vec<[f64; 2]> = backward.into_iter().rev().collect();
        line.push([x as f64 + r.offset[0], y as f64 + r.offset[1]]);
        line.extend(forward);
        let length = polyline_length(&line);
        if length < options.min_length_px || line.len() < 2 {
            continue;
        }
        // Strength of each point: that of its (wrapped) pixel.
        let total: f64 = line
            .iter()
            .map(|p| {
                let i = linker.index(p[0].round() as i64, p[1].round() as i64);
                i.map_or(0.0, |i| resp[i].strength)
            })
            .sum();
        found.push((total, total / line.len() as f64, line));
    }
    // Strongest first; ties by the first point (deterministic).
    found.sort_by(|a, b| {
        b.0.total_cmp(&a.0)
            .then(a.2[0][1].total_cmp(&b.2[0][1]))
            .then(a.2[0][0].total_cmp(&b.2[0][0]))
    });
    let strengths: Vec<f32> = found.iter().map(|f| f.1 as f32).collect();
    let lines: Vec<Vec<[f32; 2]>> = found
        .into_iter()
        .map(|(_, _, line)| {
            // Shift a wrapped line so that its first point lies in the image.
            let (sx, sy) = if options.toroidal {
                (
                    (line[0][0].round() as i64).div_euclid(w as i64) as f64 * w as f64,
                    (line[0][1].round() as i64).div_euclid(h as i64) as f64 * h as f64,
                )
            } else {
                (0.0, 0.0)
            };
            line.iter().map(|p| [(p[0] - sx) as f32, (p[1] - sy) as f32]).collect()
        })
        .collect();
    if lines.is_empty() {
        warnings.push(Warning::new(
            "exemplar-no-feature-lines",
            format!(
                "no feature line found in the {w}×{h} exemplar at scale σ = {sigma:.2} px \
                 (strongest line strength {reference:.4} below min_strength {}); \
                 pass feature lines as polylines or lower min_strength",
                options.min_strength
            ),
        ));
    }
    let distance = distance_map(&lines, w, h, options.toroidal);
    Ok(ExemplarFeatures {
        width: w,
        height: h,
        lines,
        strengths,
        distance,
        scale: sigma,
        toroidal: options.toroidal,
        warnings,
    })
}

/// Marks the pixels under `lines` (segments sampled every ≤ ½ px, nearest pixel) and
/// returns the distance map; points outside a non-toroidal image are skipped.
fn distance_map(lines: &[Vec<[f32; 2]>], w: usize, h: usize, wrap: bool) -> Vec<f32> {
    let mut mask = vec![false; w * h];
    let mut mark = |x: f64, y: f64| {
        let (xi, yi) = (x.round() as i64, y.round() as i64);
        let (wi, hi) = (w as i64, h as i64);
        if wrap {
            mask[(yi.rem_euclid(hi) * wi + xi.rem_euclid(wi)) as usize] = true;
        } else if (0..wi).contains(&xi) && (0..hi).contains(&yi) {
            mask[(yi * wi + xi) as usize] = true;
        }
    };
    for line in lines {
        if let [p] = line.as_slice() {
            mark(p[0] as f64, p[1] as f64);
        }
        for s in line.windows(2) {
            let (a, b) = ([s[0][0] as f64, s[0][1] as f64], [s[1][0] as f64, s[1][1] as f64]);
            let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            // Bounded: a segment longer than the image is sampled over 4 image sizes.
            let steps = (2.0 * len).ceil().clamp(1.0, 8.0 * (w + h) as f64) as usize;
            for k in 0..=steps {
                let t = k as f64 / steps as f64;
                mark(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
            }
        }
    }
    euclidean_distance_transform(&mask, w, h, wrap)
}

/// Exemplar features from user lines: polylines in pixel coordinates (module docs) on
/// a `width × height` exemplar. Lines with fewer than two points are kept as dots.
/// Errors on a non-finite coordinate or an empty image size; a line entirely outside a
/// non-toroidal image gives a warning.
pub fn exemplar_features_from_polylines(
    width: usize,
    height: usize,
    lines: &[Vec<[f32; 2]>],
    toroidal: bool,
) -> Result<ExemplarFeatures, FeaturesError> {
    check_option("exemplar width", width as f64, width >= 1, "at least 1 pixel")?;
    check_option("exemplar height", height as f64, height >= 1, "at least 1 pixel")?;
    for (curve, line) in lines.iter().enumerate() {
        if let Some(point) = line.iter().position(|p| !(p[0].is_finite() && p[1].is_finite())) {
            return Err(FeaturesError::NonFiniteCurvePoint { curve, point });
        }
    }
    let mut warnings = Vec::new();
    let lines: Vec<Vec<[f32; 2]>> = lines.iter().filter(|l| !l.is_empty()).cloned().collect();
    let outside = |p: &[f32; 2]| {
        let (x, y) = (p[0].round(), p[1].round());
        x < 0.0 || y < 0.0 || x >= width as f32 || y >= height as f32
    };
    let n_outside = lines.iter().filter(|l| l.iter().all(outside)).count();
    if !toroidal && n_outside > 0 {
        warnings.push(Warning::new(
            "exemplar-lines-outside",
            format!(
                "{n_outside} of {} feature lines lie entirely outside the {width}×{height} \
                 exemplar and were ignored; give coordinates in pixels (x right, y down)",
                lines.len()
            ),
        ));
    }
    if lines.is_empty() {
        warnings.push(Warning::new(
            "exemplar-no-feature-lines",
            "no feature line was given; the distance map is infinite everywhere",
        ));
    }
    let distance = distance_map(&lines, width, height, toroidal);
    Ok(ExemplarFeatures {
        width,
        height,
        strengths: vec![0.0; lines.len()],
        lines,
        distance,
        scale: 0.0,
        toroidal,
        warnings,
    })
}
