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
//!
//! **Per-texel surface scale** (`per_texel`, session 13, the default of `conformal`'s
//! report). A window spans many triangles; scaling its period in texels by the centre
//! triangle's `λ` credits a triangle far smaller than the window (a few texels next to
//! a zero point of a conformal map, `λ` 10–20× the mean) with the neighbourhood's
//! texture magnified by its own `λ`: on fertility 0.1 % of the surface gave 60–70 % of
//! the variance that way, whatever the quilting did there. With `per_texel` each texel
//! of the window counts with the `λ` of the triangle its centre lies in: weight `ω = λ²`
//! (the surface area it shows), gradient `|∇I| / λ` (per surface length); texels outside
//! every triangle do not count. The window's period on the surface is then
//! `4√2 σ_ω / mean_ω(|∇I|/λ)` — the statistic of the piece of surface the window shows —
//! and its period in texels (for the window's growth) that over `√mean(ω)`. With one `λ`
//! over the window both forms agree.

use fieldtex_core::{Image, vec3};
use fieldtex_mesh::{CornerUvs, TriMesh};
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

/// Summed-area tables over texels with weights `ω` (surface area per texel, or 1) and
/// gradient scales `g` (1 / surface length per texel, or 1).
struct WindowSums {
    w: usize,
    h: usize,
    /// `(w + 1) × (h + 1)` prefix sums of `[ω, ωI, ωI², ωg|∇I|, counted]`.
    sums: Vec<[f64; 5]>,
}

impl WindowSums {
    /// `weight(i)`: `Some((ω, g))` for a texel that counts, `None` for one that does not.
    fn new(lum: &[f32], w: usize, h: usize, weight: impl Fn(usize) -> Option<(f64, f64)>) -> Self {
        let at = |x: i64, y: i64| {
            lum[(y.clamp(0, h as i64 - 1) as usize) * w + x.clamp(0, w as i64 - 1) as usize] as f64
        };
        let mut sums = vec![[0.0f64; 5]; (w + 1) * (h + 1)];
        for y in 0..h {
            let mut row = [0.0f64; 5];
            for x in 0..w {
                if let Some((om, g)) = weight(y * w + x) {
                    let (xi, yi) = (x as i64, y as i64);
                    let v = at(xi, yi);
                    let dx = 0.5 * (at(xi + 1, yi) - at(xi - 1, yi));
                    let dy = 0.5 * (at(xi, yi + 1) - at(xi, yi - 1));
                    row[0] += om;
                    row[1] += om * v;
                    row[2] += om * v * v;
                    row[3] += om * g * (dx * dx + dy * dy).sqrt();
                    row[4] += 1.0;
                }
                let above = sums[y * (w + 1) + x + 1];
                sums[(y + 1) * (w + 1) + x + 1] = std::array::from_fn(|k| above[k] + row[k]);
            }
        }
        Self { w, h, sums }
    }

    /// `(σ, mean g|∇I|, Σω / counted)`, `ω`-weighted, over the square of half-side `r`
    /// around `(cx, cy)`, shifted to lie inside the texture; `None` when no texel counts.
    fn stats(&self, cx: i64, cy: i64, r: i64) -> Option<(f64, f64, f64)> {
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
        let t: [f64; 5] = std::array::from_fn(|k| a[k] - b[k] - c[k] + d[k]);
        if t[0] <= 0.0 || t[4] <= 0.0 {
            return None;
        }
        let m: [f64; 3] = std::array::from_fn(|k| t[k + 1] / t[0]);
        Some(((m[1] - m[0] * m[0]).max(0.0).sqrt(), m[2], t[0] / t[4]))
    }
}

/// Per texel: the surface length per texel of the triangle whose UV triangle contains
/// its centre (`NaN` where none does; the last triangle in index order wins).
fn texel_lambda(
    mesh: &TriMesh,
    corners: &[[[f64; 2]; 3]],
    lambda: &[f64],
    w: usize,
    h: usize,
) -> Vec<f64> {
    let mut out = vec![f64::NAN; w * h];
    for (f, t) in corners.iter().enumerate() {
        if !lambda[f].is_finite() || f >= mesh.n_triangles() {
            continue;
        }
        let (lo_x, hi_x) = (
            t.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min),
            t.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max),
        );
        let (lo_y, hi_y) = (
            t.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min),
            t.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max),
        );
        let x0 = (lo_x - 0.5).ceil().max(0.0) as usize;
        let y0 = (lo_y - 0.5).ceil().max(0.0) as usize;
        let x1 = ((hi_x - 0.5).floor() as i64).min(w as i64 - 1);
        let y1 = ((hi_y - 0.5).floor() as i64).min(h as i64 - 1);
        let d =
            (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
        if d == 0.0 {
            continue;
        }
        for y in y0 as i64..=y1 {
            for x in x0 as i64..=x1 {
                let p = [x as f64 + 0.5, y as f64 + 0.5];
                let e = |a: [f64; 2], b: [f64; 2]| {
                    ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])) / d
                };
                if e(t[0], t[1]) >= 0.0 && e(t[1], t[2]) >= 0.0 && e(t[2], t[0]) >= 0.0 {
                    out[y as usize * w + x as usize] = lambda[f];
                }
            }
        }
    }
    out
}

/// One triangle's measurement (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TriangleFeature {
    /// Period on the surface (surface units).
    pub period: f64,
    /// Period in texels.
    pub period_texels: f64,
    /// Surface length per texel of the triangle.
    pub lambda: f64,
    /// Surface area of the triangle.
    pub area: f64,
    /// Window centre (texel column, row) and final half-side in texels.
    pub centre: [i64; 2],
    pub half_side: i64,
    /// The window reached its largest size before holding 2.5 periods.
    pub saturated: bool,
}

/// Triangle `f` of a mesh with UVs on a `w × h` texture: its corners in texels (row 0 at
/// `v = 1`), its surface area, and its surface length per texel `λ = √(A_surface /
/// A_texels)` (NaN for a triangle degenerate on either side); `uvs` are the mesh's.
pub fn triangle_texel_scale(
    mesh: &TriMesh,
    uvs: &CornerUvs,
    f: usize,
    w: usize,
    h: usize,
) -> ([[f64; 2]; 3], f64, f64) {
    let c = uvs.indices[f].map(|i| uvs.values[i as usize]);
    let t = c.map(|p| [p[0] * w as f64, (1.0 - p[1]) * h as f64]);
    let at = 0.5
        * ((t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]))
            .abs();
    let p = mesh.triangle_positions(f);
    let a3 = 0.5 * vec3::norm(vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0])));
    let lambda = if at > 0.0 && a3 > 0.0 { (a3 / at).sqrt() } else { f64::NAN };
    (t, a3, lambda)
}

/// Per-triangle measurements of `mesh` (per-corner UVs; `None` without) textured by
/// `tex`; a triangle without UV area, outside the texture or whose window has no
/// contrast gives `None`. `window` is the smallest window side in texels; with
/// `adaptive` false every window keeps that side (the measure of sessions 8–9, which
/// saturates on wide features). With `per_texel` every texel of a window counts with
/// its own surface length per texel (see the module docs); without, the window's period
/// in texels is scaled by the centre triangle's (the measure of sessions 8–12).
pub fn feature_size_per_triangle(
    mesh: &TriMesh,
    tex: &Image,
    window: usize,
    adaptive: bool,
    per_texel: bool,
) -> Option<Vec<Option<TriangleFeature>>> {
    let uvs = mesh.uvs.as_ref()?;
    let (w, h) = (tex.width, tex.height);
    if w < 3 || h < 3 {
        return None;
    }
    // Per triangle: corners in texels, surface area, surface length per texel.
    let geo: Vec<([[f64; 2]; 3], f64, f64)> = (0..mesh.n_triangles())
        .into_par_iter()
        .map(|f| triangle_texel_scale(mesh, uvs, f, w, h))
        .collect();
    let lum = tex.luminance();
    let sums = if per_texel {
        let corners: Vec<[[f64; 2]; 3]> = geo.iter().map(|g| g.0).collect();
        let lambdas: Vec<f64> = geo.iter().map(|g| g.2).collect();
        let tl = texel_lambda(mesh, &corners, &lambdas, w, h);
        WindowSums::new(&lum, w, h, |i| tl[i].is_finite().then(|| (tl[i] * tl[i], 1.0 / tl[i])))
    } else {
        WindowSums::new(&lum, w, h, |_| Some((1.0, 1.0)))
    };
    let r0 = (window / 2).max(2) as i64;
    let r_max =
        if adaptive { ((MAX_WINDOW_FRACTION * w.min(h) as f64 / 2.0) as i64).max(r0) } else { r0 };
    let rows = geo
        .par_iter()
        .map(|&(t, a3, lambda)| {
            if !lambda.is_finite() {
                return None;
            }
            let gx = (t[0][0] + t[1][0] + t[2][0]) / 3.0;
            let gy = (t[0][1] + t[1][1] + t[2][1]) / 3.0;
            if !(gx >= 0.0 && gy >= 0.0 && gx < w as f64 && gy < h as f64) {
                return None;
            }
            let (gx, gy) = (gx as i64, gy as i64);
            let mut r = r0;
            loop {
                let (sigma, g, om) = sums.stats(gx, gy, r)?;
                if sigma < 1e-3 || g <= 0.0 {
                    return None;
                }
                // In texels, and on the surface (the window's own surface length per
                // texel: the root mean of ω = λ² over its counted texels).
                let (period_texels, period) = if per_texel {
                    let s = 4.0 * std::f64::consts::SQRT_2 * sigma / g;
                    (s / om.sqrt(), s)
                } else {
                    if g < 1e-4 {
                        return None;
                    }
                    let p = 4.0 * std::f64::consts::SQRT_2 * sigma / g;
                    (p, p * lambda)
                };
                // The window must hold 2.5 periods (side 2r + 1 ≥ 2.5 T).
                let need = (1.25 * period_texels).ceil() as i64;
                if need <= r || r >= r_max {
                    return Some(TriangleFeature {
                        period,
                        period_texels,
                        lambda,
                        area: a3,
                        centre: [gx, gy],
                        half_side: r,
                        saturated: need > r,
                    });
                }
                r = need.min(r_max);
            }
        })
        .collect();
    Some(rows)
}

/// Feature-size statistics of `mesh` (per-corner UVs; `None` without) textured by `tex`:
/// the area-weighted aggregate of [`feature_size_per_triangle`].
pub fn feature_size_variation(
    mesh: &TriMesh,
    tex: &Image,
    window: usize,
    adaptive: bool,
    per_texel: bool,
) -> Option<FeatureSizeStats> {
    let rows = feature_size_per_triangle(mesh, tex, window, adaptive, per_texel)?;
    let (mut sw, mut s1, mut s2, mut t1, mut t2, mut n, mut sat) =
        (0.0, 0.0, 0.0, 0.0, 0.0, 0usize, 0usize);
    for r in rows.into_iter().flatten() {
        let (ps, pt, a) = (r.period, r.period_texels, r.area);
        sw += a;
        s1 += a * ps;
        s2 += a * ps * ps;
        t1 += a * pt;
        t2 += a * pt * pt;
        n += 1;
        sat += r.saturated as usize;
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
        let s = feature_size_variation(&mesh, &tex, 24, true, false).unwrap();
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
        let s = feature_size_variation(&mesh, &tex, 24, true, false).unwrap();
        let texels = s.mean_period * 512.0;
        assert!((texels - 80.0).abs() < 16.0, "{texels} texels, {s:?}");
        assert_eq!(s.saturated, 0);
        // A fixed 24-texel window cannot see it.
        let f = feature_size_variation(&mesh, &tex, 24, false, false).unwrap();
        assert!(f.mean_period * 512.0 < 48.0, "{f:?}");
        assert!(f.saturated > 0);
    }

    /// With one `λ` everywhere the per-texel form reads the same period as the centre
    /// form.
    #[test]
    fn per_texel_scale_agrees_on_a_uniform_map() {
        let (mesh, tex) = striped_square(256, 16.0);
        let a = feature_size_variation(&mesh, &tex, 24, true, false).unwrap();
        let b = feature_size_variation(&mesh, &tex, 24, true, true).unwrap();
        assert!((a.mean_period - b.mean_period).abs() < 1e-6 * a.mean_period, "{a:?} {b:?}");
        assert!((a.cv - b.cv).abs() < 1e-6, "{a:?} {b:?}");
    }

    /// A grid over stripes plus one extra triangle of a fifth of the surface area whose
    /// UV triangle is a sliver inside the texture (surface length per texel ~400× the
    /// grid's; it covers no texel centre). The centre form multiplies the stripes' period
    /// around it by its own `λ` and reads a large CV; the per-texel form measures the
    /// texels its window shows, all of the grid, and reads the stripes' period.
    #[test]
    fn a_tiny_uv_triangle_does_not_magnify_its_neighbourhood() {
        let (mut mesh, tex) = striped_square(256, 16.0);
        let base = mesh.positions.len() as u32;
        mesh.positions.extend([[2.0, 0.0, 0.0], [2.7, 0.0, 0.0], [2.0, 0.7, 0.0]]);
        mesh.triangles.push([base, base + 1, base + 2]);
        let uvs = mesh.uvs.as_mut().unwrap();
        let k = uvs.values.len() as u32;
        uvs.values.extend([[0.5, 0.5], [0.5 + 0.0017, 0.5], [0.5, 0.5 + 0.0017]]);
        uvs.indices.push([k, k + 1, k + 2]);
        let centre = feature_size_variation(&mesh, &tex, 24, true, false).unwrap();
        let texel = feature_size_variation(&mesh, &tex, 24, true, true).unwrap();
        assert!(centre.cv > 1.0, "{centre:?}");
        assert!(texel.cv < 0.1, "{texel:?}");
        assert!((texel.mean_period - 1.0 / 16.0).abs() < 0.2 / 16.0, "{texel:?}");
    }

    /// The window-sum statistics equal a direct computation over a shifted window.
    #[test]
    fn window_sums_match_a_direct_sum() {
        let (w, h) = (37usize, 23usize);
        let lum: Vec<f32> = (0..w * h).map(|i| ((i * 7919) % 101) as f32 / 100.0).collect();
        let sums = WindowSums::new(&lum, w, h, |_| Some((1.0, 1.0)));
        let at = |x: i64, y: i64| {
            lum[(y.clamp(0, h as i64 - 1) as usize) * w + x.clamp(0, w as i64 - 1) as usize] as f64
        };
        // Centre (2, 20) with half-side 4 is shifted to x 0..9, y 14..23.
        let (sigma, g, _) = sums.stats(2, 20, 4).unwrap();
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
