//! Texture feature-size variation on a surface (issue 13): the local dominant period of
//! the texture, in surface units, and its area-weighted coefficient of variation.
//!
//! For every triangle, a square texel block of the luminance around its UV centroid
//! gives a period estimate `T = 4√2 · σ / mean|∇I|` (exact for a sinusoid: `σ = A/√2`,
//! `mean|∇I| = 4A/T`), in texels; times the triangle's surface length per texel
//! `√(A_surface / A_texels)` it is a period on the surface. Windows without contrast are
//! skipped. The statistic is a cheap proxy for the dominant period (no spectrum is
//! computed).
//!
//! **Scale-adaptive window.** A window narrower than about two periods cannot see the
//! period: over a window of side `W` much smaller than `T` a sinusoid is a ramp, and the
//! estimate saturates at `4√2 · W/√12 ≈ 1.6 W` whatever `T` is. So the window starts at
//! `window` texels and grows to `2.5 T` of its own estimate until the estimate stays
//! inside it (at most [`MAX_WINDOW_FRACTION`] of the texture's short side; such windows
//! are counted as `saturated`). Windows are shifted to stay inside the texture. Sums
//! over a window come from summed-area tables, so a window of any size costs the same.

use fieldtex_core::{Image, vec3};
use fieldtex_mesh::TriMesh;
use rayon::prelude::*;
use serde::Serialize;

/// Largest window side, as a fraction of the texture's short side.
pub const MAX_WINDOW_FRACTION: f64 = 0.5;

/// See the module docs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FeatureSizeStats {
    /// Area-weighted mean period on the surface (surface units).
    pub mean_period: f64,
    /// Area-weighted coefficient of variation of the period on the surface.
    pub cv: f64,
    /// Area-weighted coefficient of variation of the period in texels (for reference).
    pub cv_texels: f64,
    /// Triangles measured.
    pub triangles: usize,
    /// Triangles whose window reached the largest size before holding two periods.
    pub saturated: usize,
}

/// Summed-area tables of luminance, its square and its gradient magnitude.
struct WindowSums {
    w: usize,
    h: usize,
    /// `(w + 1) × (h + 1)` prefix sums of `[I, I², |∇I|]`.
    sums: Vec<[f64; 3]>,
}

impl WindowSums {
    fn new(lum: &[f32], w: usize, h: usize) -> Self {
        let at = |x: i64, y: i64| {
            lum[(y.clamp(0, h as i64 - 1) as usize) * w + x.clamp(0, w as i64 - 1) as usize] as f64
        };
        let mut sums = vec![[0.0f64; 3]; (w + 1) * (h + 1)];
        for y in 0..h {
            let mut row = [0.0f64; 3];
            for x in 0..w {
                let (xi, yi) = (x as i64, y as i64);
                let v = at(xi, yi);
                let dx = 0.5 * (at(xi + 1, yi) - at(xi - 1, yi));
                let dy = 0.5 * (at(xi, yi + 1) - at(xi, yi - 1));
                row[0] += v;
                row[1] += v * v;
                row[2] += (dx * dx + dy * dy).sqrt();
                let above = sums[y * (w + 1) + x + 1];
                sums[(y + 1) * (w + 1) + x + 1] =
                    [above[0] + row[0], above[1] + row[1], above[2] + row[2]];
            }
        }
        Self { w, h, sums }
    }

    /// `(σ, mean|∇I|)` over the square of half-side `r` around `(cx, cy)`, shifted to
    /// lie inside the texture.
    fn stats(&self, cx: i64, cy: i64, r: i64) -> (f64, f64) {
        let side = |c: i64, len: usize| {
            let len = len as i64;
            let n = (2 * r + 1).min(len);
            let lo = (c - r).clamp(0, len - n);
            (lo as usize, (lo + n) as usize)
        };
        let (x0, x1) = side(cx, self.w);
        let (y0, y1) = side(cy, self.h);
        let s = |x: usize, y: usize| self.sums[y * (self.w + 1) + x];
        let (a, b, c, d) = (s(x1, y1), s(x0, y1), s(x1, y0), s(x0, y0));
        let n = ((x1 - x0) * (y1 - y0)) as f64;
        let m: [f64; 3] = std::array::from_fn(|k| (a[k] - b[k] - c[k] + d[k]) / n);
        ((m[1] - m[0] * m[0]).max(0.0).sqrt(), m[2])
    }
}

/// Feature-size statistics of `mesh` (per-corner UVs; `None` without) textured by `tex`;
/// `window` is the smallest window side in texels. With `adaptive` false every window
/// keeps that side (the measure of sessions 8–9, which saturates on wide features).
pub fn feature_size_variation(
    mesh: &TriMesh,
    tex: &Image,
    window: usize,
    adaptive: bool,
) -> Option<FeatureSizeStats> {
    let uvs = mesh.uvs.as_ref()?;
    let (w, h) = (tex.width, tex.height);
    if w < 3 || h < 3 {
        return None;
    }
    let sums = WindowSums::new(&tex.luminance(), w, h);
    let r0 = (window / 2).max(2) as i64;
    let r_max =
        if adaptive { ((MAX_WINDOW_FRACTION * w.min(h) as f64 / 2.0) as i64).max(r0) } else { r0 };
    let rows: Vec<Option<(f64, f64, f64, bool)>> = (0..mesh.n_triangles())
        .into_par_iter()
        .map(|f| {
            let c = uvs.indices[f].map(|i| uvs.values[i as usize]);
            let t = c.map(|p| [p[0] * w as f64, (1.0 - p[1]) * h as f64]);
            let at = 0.5
                * ((t[1][0] - t[0][0]) * (t[2][1] - t[0][1])
                    - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]))
                    .abs();
            let p = mesh.triangle_positions(f);
            let a3 = 0.5 * vec3::norm(vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0])));
            if at <= 0.0 || a3 <= 0.0 {
                return None;
            }
            let lambda = (a3 / at).sqrt();
            let gx = (t[0][0] + t[1][0] + t[2][0]) / 3.0;
            let gy = (t[0][1] + t[1][1] + t[2][1]) / 3.0;
            if !(gx >= 0.0 && gy >= 0.0 && gx < w as f64 && gy < h as f64) {
                return None;
            }
            let (gx, gy) = (gx as i64, gy as i64);
            let mut r = r0;
            loop {
                let (sigma, g) = sums.stats(gx, gy, r);
                if sigma < 1e-3 || g < 1e-4 {
                    return None;
                }
                let period = 4.0 * std::f64::consts::SQRT_2 * sigma / g;
                // The window must hold 2.5 periods (side 2r + 1 ≥ 2.5 T).
                let need = (1.25 * period).ceil() as i64;
                if need <= r || r >= r_max {
                    return Some((period * lambda, period, a3, need > r));
                }
                r = need.min(r_max);
            }
        })
        .collect();
    let (mut sw, mut s1, mut s2, mut t1, mut t2, mut n, mut sat) =
        (0.0, 0.0, 0.0, 0.0, 0.0, 0usize, 0usize);
    for (ps, pt, a, saturated) in rows.into_iter().flatten() {
        sw += a;
        s1 += a * ps;
        s2 += a * ps * ps;
        t1 += a * pt;
        t2 += a * pt * pt;
        n += 1;
        sat += saturated as usize;
    }
    if sw <= 0.0 {
        return None;
    }
    let (m, mt) = (s1 / sw, t1 / sw);
    Some(FeatureSizeStats {
        mean_period: m,
        cv: (s2 / sw - m * m).max(0.0).sqrt() / m,
        cv_texels: (t2 / sw - mt * mt).max(0.0).sqrt() / mt,
        triangles: n,
        saturated: sat,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_mesh::CornerUvs;

    /// A unit square over a `side²` texture of vertical stripes of `period` texels.
    fn striped_square(side: usize, period: f32) -> (TriMesh, Image) {
        let mut mesh = fieldtex_mesh::primitives::grid(8, 8, 1.0, 1.0);
        let values: Vec<[f64; 2]> = mesh.positions.iter().map(|p| [p[0], p[1]]).collect();
        mesh.uvs = Some(CornerUvs { values, indices: mesh.triangles.clone() });
        let mut tex = Image::new(side, side, [0.0; 4]);
        for y in 0..side {
            for x in 0..side {
                let v = 0.5 + 0.4 * (x as f32 * std::f32::consts::TAU / period).sin();
                tex.set(x, y, [v, v, v, 1.0]);
            }
        }
        (mesh, tex)
    }

    /// Stripes of period 16 texels over a 256² texture: the estimate is within 20 % of
    /// the true period (1/16 surface units) with a small CV.
    #[test]
    fn stripes_have_their_period() {
        let (mesh, tex) = striped_square(256, 16.0);
        let s = feature_size_variation(&mesh, &tex, 24, true).unwrap();
        assert!(s.triangles > 20);
        assert!((s.mean_period - 1.0 / 16.0).abs() < 0.2 / 16.0, "{s:?}");
        assert!(s.cv < 0.1, "{s:?}");
        assert_eq!(s.saturated, 0);
    }

    /// Stripes of period 80 texels, far wider than the 24-texel starting window (which
    /// alone would saturate near 1.6 × 24 ≈ 39 texels): the window grows and the estimate
    /// is within 20 % of 80 texels.
    #[test]
    fn wide_features_grow_the_window() {
        let (mesh, tex) = striped_square(512, 80.0);
        let s = feature_size_variation(&mesh, &tex, 24, true).unwrap();
        let texels = s.mean_period * 512.0;
        assert!((texels - 80.0).abs() < 16.0, "{texels} texels, {s:?}");
        assert_eq!(s.saturated, 0);
        // A fixed 24-texel window cannot see it.
        let f = feature_size_variation(&mesh, &tex, 24, false).unwrap();
        assert!(f.mean_period * 512.0 < 48.0, "{f:?}");
        assert!(f.saturated > 0);
    }

    /// The window-sum statistics equal a direct computation over a shifted window.
    #[test]
    fn window_sums_match_a_direct_sum() {
        let (w, h) = (37usize, 23usize);
        let lum: Vec<f32> = (0..w * h).map(|i| ((i * 7919) % 101) as f32 / 100.0).collect();
        let sums = WindowSums::new(&lum, w, h);
        let at = |x: i64, y: i64| {
            lum[(y.clamp(0, h as i64 - 1) as usize) * w + x.clamp(0, w as i64 - 1) as usize] as f64
        };
        // Centre (2, 20) with half-side 4 is shifted to x 0..9, y 14..23.
        let (sigma, g) = sums.stats(2, 20, 4);
        let (mut s, mut s2, mut gs) = (0.0, 0.0, 0.0);
        for y in 14..23i64 {
            for x in 0..9i64 {
                let v = at(x, y);
                let dx = 0.5 * (at(x + 1, y) - at(x - 1, y));
                let dy = 0.5 * (at(x, y + 1) - at(x, y - 1));
                s += v;
                s2 += v * v;
                gs += (dx * dx + dy * dy).sqrt();
            }
        }
        let n = 81.0;
        let sd = (s2 / n - (s / n) * (s / n)).sqrt();
        assert!((sigma - sd).abs() < 1e-9 && (g - gs / n).abs() < 1e-9, "{sigma} {sd} {g}");
    }
}
