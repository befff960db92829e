//! Conformal geometry images (Wang et al. 2005 §3–4.1): a component's fundamental domain
//! rasterised into an image whose longer side has `C` texels, with margins where its
//! periodic sides meet, and the inverse conformal factor `τ = 1/λ` per texel.
//!
//! Canvas texel `(i, j)` (column, row; rows go *down* while `y` goes up, so the image
//! keeps the map's orientation) has its centre at `x = x0 + (i − m + ½)/sx`,
//! `y = y1 − (j − m + ½)/sy`, `m` the margin. In a periodic
//! direction the scale is rounded so that the period is a whole number of texels (the
//! x and y scales then differ by less than one texel over the image: a negligible
//! anisotropy); the second period's shift is rounded to whole texels. `λ` is measured
//! in surface length per texel: per triangle `√(A_surface / A_texels)`; per vertex the
//! area-weighted mean of `τ` over its triangles; per texel the barycentric
//! interpolation of the vertex values over the triangle (or its lattice copy) covering
//! it — a substitute for the paper's Gaussian RBF interpolation.

use super::ConformalComponent;
use crate::raster::triangle_row_spans;
use fieldtex_core::vec3;

/// See the module docs.
#[derive(Debug, Clone)]
pub struct GeometryImage {
    pub width: usize,
    pub height: usize,
    pub margin: usize,
    /// Texels per parameter unit in x and y.
    pub scale: [f64; 2],
    pub origin: [f64; 2],
    /// Period in texels along x (`(W, 0)`), when x is periodic.
    pub period_x: Option<i64>,
    /// Second period in canvas texels `(shift, −H)` (rows go down), when y is periodic.
    pub period_y: Option<[i64; 2]>,
    /// `width × height` inverse conformal factors (`NaN` outside the surface).
    pub tau: Vec<f32>,
    /// Per face of the component: corner positions in canvas texel units.
    pub corner_texel: Vec<[[f64; 2]; 3]>,
    /// Per face: `λ` (surface length per texel).
    pub face_lambda: Vec<f64>,
    /// Per face: surface area.
    pub face_area: Vec<f64>,
    /// Texel pairs `(a, b)` (row-major indices, sorted) that show the same surface point
    /// across a cut between patches: margin texels drawn from [`super::Ghost`]s and the
    /// texels they continue (both directions listed).
    pub links: Vec<(u32, u32)>,
    /// `(margin texel, texel it continues, face)` for every ghost-drawn margin texel.
    pub margin_copies: Vec<(u32, u32, u32)>,
    /// `(far texel, near texel)`: real texels on the two sides of a cut that show points
    /// less than a texel apart but that no ghost texel links (the cut passes between
    /// their centres); also in [`Self::links`].
    pub seam_pairs: Vec<(u32, u32)>,
}

impl GeometryImage {
    /// Builds the image of `component` (which must have UVs) with long side `c` texels
    /// inside the margins.
    pub fn new(component: &ConformalComponent, c: usize) -> Self {
        let [x0, y0, x1, y1] = component.domain;
        let (dx, dy) = ((x1 - x0).max(1e-12), (y1 - y0).max(1e-12));
        let s = c as f64 / dx.max(dy);
        let mut sx = s;
        let mut sy = s;
        let mut period_x = None;
        if let Some(a) = component.lattice.a {
            let w = (a * s).round().max(8.0);
            sx = w / a;
            sy = sx;
            period_x = Some(w as i64);
        }
        let mut period_y = None;
        if let Some(b) = component.lattice.b {
            let h = (b[1] * s).round().max(8.0);
            sy = h / b[1];
            period_y = Some([(b[0] * sx).round() as i64, -(h as i64)]);
        }
        let w_in = (dx * sx).round() as usize;
        let h_in = (dy * sy).round() as usize;
        // Margin: how far corners reach outside the domain, plus filtering slack.
        let mut spill: f64 = 0.0;
        let nf = component.faces.len();
        // Per ghost: face, translation (`None` for a similarity ghost, whose points map
        // to the face's chart by barycentric coordinates) and corners.
        type GhostCorners = (usize, Option<[f64; 2]>, [[f64; 2]; 3]);
        let ghost_corners: Vec<GhostCorners> = component
            .map
            .ghosts
            .iter()
            .filter(|g| (g.face as usize) < nf)
            .map(|g| match g.corners {
                Some(c) => (g.face as usize, None, c),
                None => {
                    let c = component.corner_uv[g.face as usize]
                        .map(|p| [p[0] - g.shift[0], p[1] - g.shift[1]]);
                    (g.face as usize, Some(g.shift), c)
                }
            })
            .collect();
        for cu in component.corner_uv.iter().chain(ghost_corners.iter().map(|g| &g.2)) {
            for p in cu {
                spill = spill
                    .max((x0 - p[0]) * sx)
                    .max((p[0] - x1) * sx)
                    .max((y0 - p[1]) * sy)
                    .max((p[1] - y1) * sy);
            }
        }
        let margin = (spill.ceil() as usize + 3).max(4);
        let (width, height) = (w_in + 2 * margin, h_in + 2 * margin);
        let m = margin as f64;
        let corner_texel: Vec<[[f64; 2]; 3]> = component
            .corner_uv
            .iter()
            .map(|cu| cu.map(|p| [(p[0] - x0) * sx + m, (y1 - p[1]) * sy + m]))
            .collect();
        let mesh = &component.local_mesh;
        let mut face_lambda = vec![f64::NAN; nf];
        let mut face_area = vec![0.0; nf];
        let mut vtau = vec![0.0; mesh.n_vertices()];
        let mut vw = vec![0.0; mesh.n_vertices()];
        for f in 0..nf {
            let p = mesh.triangle_positions(f);
            let a3 = 0.5 * vec3::norm(vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0])));
            let t = corner_texel[f];
            let at = -0.5
                * ((t[1][0] - t[0][0]) * (t[2][1] - t[0][1])
                    - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]));
            face_area[f] = a3;
            if at > 0.0 && a3 > 0.0 && !component.slit[f] {
                face_lambda[f] = (a3 / at).sqrt();
                for &v in &mesh.triangles[f] {
                    vtau[v as usize] += a3 / face_lambda[f];
                    vw[v as usize] += a3;
                }
            }
        }
        let vtau: Vec<f64> =
            vtau.iter().zip(&vw).map(|(t, w)| if *w > 0.0 { t / w } else { f64::NAN }).collect();
        let mut tau = vec![f32::NAN; width * height];
        let mut shifts = vec![[0.0f64, 0.0f64]];
        if let Some(px) = period_x {
            for k in [-1i64, 1] {
                shifts.push([(k * px) as f64, 0.0]);
            }
        }
        if let Some([bx, h]) = period_y {
            let base = shifts.clone();
            for l in [-1i64, 1] {
                for s0 in &base {
                    for extra in [-1i64, 0, 1] {
                        let ex = period_x.map_or(0, |p| extra * p);
                        if extra != 0 && period_x.is_none() {
                            continue;
                        }
                        shifts.push([s0[0] + (l * bx + ex) as f64, s0[1] + (l * h) as f64]);
                    }
                }
            }
            shifts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
            shifts.dedup();
        }
        // Per-corner τ of a face: its vertices' values, or the face's own when a vertex
        // has none; `None` without either.
        let corner_tau = |f: usize| {
            let tv = mesh.triangles[f].map(|v| vtau[v as usize]);
            if !tv.iter().any(|t| t.is_nan()) {
                Some(tv)
            } else {
                (!face_lambda[f].is_nan()).then(|| [1.0 / face_lambda[f]; 3])
            }
        };
        for (f, ct) in corner_texel.iter().enumerate() {
            let Some(tv) = corner_tau(f) else { continue };
            for sh in &shifts {
                let t = ct.map(|p| [p[0] + sh[0], p[1] + sh[1]]);
                let det = doubled_area(&t);
                if det.abs() <= 0.0 {
                    continue;
                }
                for_texels(t, width, height, |i, p| tau[i] = interpolate(&t, det, p, tv));
            }
        }
        // Ghosts fill uncovered margin texels and link them to the texels they continue.
        let mut links: Vec<(u32, u32)> = Vec::new();
        let mut margin_copies: Vec<(u32, u32, u32)> = Vec::new();
        let real: Vec<bool> = tau.iter().map(|t| !t.is_nan()).collect();
        for (f, shift, cu) in &ghost_corners {
            let f = *f;
            let Some(tv) = corner_tau(f) else { continue };
            let t = cu.map(|p| [(p[0] - x0) * sx + m, (y1 - p[1]) * sy + m]);
            let det = doubled_area(&t);
            if det.abs() <= 0.0 {
                continue;
            }
            let real_tri = corner_texel[f];
            let to_real = |p: [f64; 2]| match shift {
                Some(s) => [p[0] + s[0] * sx, p[1] - s[1] * sy],
                None => carry(&t, det, p, &real_tri),
            };
            for_texels(t, width, height, |i, p| {
                if !tau[i].is_nan() {
                    return;
                }
                let Some(j) = texel_at(to_real(p), width, height) else { return };
                if !real[j] {
                    return; // rounding landed off the surface: leave it free
                }
                tau[i] = interpolate(&t, det, p, tv);
                links.push((i as u32, j as u32));
                links.push((j as u32, i as u32));
                margin_copies.push((i as u32, j as u32, f as u32));
            });
        }
        // The far side of each cut: a real texel of a ghost's face whose centre, moved back
        // by the cut's translation, falls in a texel that is *real* on the near side (the
        // cut passes between the two centres) has no ghost texel pointing at it, so it
        // would be synthesised on its own right at the cut. It is paired with that near
        // texel instead (both are real; they show points less than one texel apart). The
        // near texel must lie outside the ghost triangle: one inside it belongs to another
        // chart the ghost overlaps, not to the cut.
        let mut paired = vec![false; width * height];
        for &(a, b) in &links {
            paired[a as usize] = true;
            paired[b as usize] = true;
        }
        let mut seam_pairs: Vec<(u32, u32)> = Vec::new();
        let mut near_of = vec![u32::MAX; width * height];
        for (f, shift, cu) in &ghost_corners {
            let ghost = cu.map(|p| [(p[0] - x0) * sx + m, (y1 - p[1]) * sy + m]);
            let real_tri = corner_texel[*f];
            let det = doubled_area(&real_tri);
            if det.abs() <= 0.0 {
                continue;
            }
            let to_ghost = |p: [f64; 2]| match shift {
                Some(s) => [p[0] - s[0] * sx, p[1] + s[1] * sy],
                None => carry(&real_tri, det, p, &ghost),
            };
            for_texels(corner_texel[*f], width, height, |j, p| {
                if !real[j] || paired[j] {
                    return;
                }
                let Some(i) = texel_at(to_ghost(p), width, height) else { return };
                let centre = [(i % width) as f64 + 0.5, (i / width) as f64 + 0.5];
                if !real[i] || i == j || contains(&ghost, centre) {
                    return;
                }
                // A near texel that is itself the far end of a pair passes on its own near
                // texel, so pairs never chain and one copy pass settles them.
                let i = if near_of[i] != u32::MAX { near_of[i] as usize } else { i };
                if i == j {
                    return;
                }
                near_of[j] = i as u32;
                paired[j] = true;
                paired[i] = true;
                links.push((i as u32, j as u32));
                links.push((j as u32, i as u32));
                seam_pairs.push((j as u32, i as u32));
            });
        }
        links.sort_unstable();
        links.dedup();
        Self {
            width,
            height,
            margin,
            scale: [sx, sy],
            origin: [x0, y0],
            period_x,
            period_y,
            tau,
            corner_texel,
            face_lambda,
            face_area,
            links,
            margin_copies,
            seam_pairs,
        }
    }

    /// Boundary consistency after synthesis (§4.2: "copied to fill P1 of geometry
    /// image 2"): every ghost-drawn margin texel takes the colour of the texel it
    /// continues, so the texture matches across every cut whatever order the synthesis
    /// visited the two sides in. `pixels` is `width × height`, row-major.
    /// [`Self::seam_pairs`] take the near texel's colour too (the quilting makes them
    /// equal unless one patch wrote both).
    pub fn copy_margins<T: Copy>(&self, pixels: &mut [T]) {
        for &(far, near) in &self.seam_pairs {
            pixels[far as usize] = pixels[near as usize];
        }
        for &(g, r, _) in &self.margin_copies {
            pixels[g as usize] = pixels[r as usize];
        }
    }

    /// Seam feathering after [`Self::copy_margins`] (our addition to §4.2): where the
    /// quilting left the two sides of a cut different (it wrote both in one patch, so
    /// the copy overwrote one), the copy leaves a colour step right at the cut. Every
    /// pair of real texels that are neighbours across a cut — a real texel next to a
    /// margin texel, and the texel that margin texel continues; and the
    /// [`Self::seam_pairs`] — meets halfway, and the correction fades into both sides
    /// over `band` texels (Jacobi steps of the correction field over the real texels,
    /// the paired texels held). The margins are copied again afterwards. Colours are
    /// RGB(A) `f32` in `[0, 1]`. Returns the number of texel pairs that met.
    pub fn feather_seams(&self, pixels: &mut [[f32; 4]], band: usize) -> usize {
        let (w, h) = (self.width, self.height);
        let n = w * h;
        let mut margin = vec![false; n];
        for &(g, _, _) in &self.margin_copies {
            margin[g as usize] = true;
        }
        let real = |i: usize| !self.tau[i].is_nan() && !margin[i];
        let mut corr = vec![[0.0f32; 4]; n];
        let mut count = vec![0u32; n];
        let mut pairs = 0usize;
        let mut meet = |a: usize, b: usize, pixels: &[[f32; 4]]| {
            pairs += 1;
            for c in 0..3 {
                let d = 0.5 * (pixels[b][c] - pixels[a][c]);
                corr[a][c] += d;
                corr[b][c] -= d;
            }
            count[a] += 1;
            count[b] += 1;
        };
        for &(g, r, _) in &self.margin_copies {
            let (g, r) = (g as usize, r as usize);
            let (x, y) = (g % w, g / w);
            let nbrs = [
                (x > 0).then(|| g - 1),
                (x + 1 < w).then(|| g + 1),
                (y > 0).then(|| g - w),
                (y + 1 < h).then(|| g + w),
            ];
            for a in nbrs.into_iter().flatten() {
                if real(a) && a != r {
                    meet(a, r, pixels);
                }
            }
        }
        for &(far, near) in &self.seam_pairs {
            meet(far as usize, near as usize, pixels);
        }
        let held: Vec<bool> = count.iter().map(|&k| k > 0).collect();
        for (c, &k) in corr.iter_mut().zip(&count) {
            if k > 0 {
                c.iter_mut().for_each(|v| *v /= k as f32);
            }
        }
        // Fade: Jacobi steps over the real texels, the paired ones held.
        let mut next = corr.clone();
        for _ in 0..band {
            for i in 0..n {
                if held[i] || !real(i) {
                    continue;
                }
                let (x, y) = (i % w, i / w);
                let mut sum = [0.0f32; 4];
                let mut k = 0.0f32;
                for j in [
                    (x > 0).then(|| i - 1),
                    (x + 1 < w).then(|| i + 1),
                    (y > 0).then(|| i - w),
                    (y + 1 < h).then(|| i + w),
                ]
                .into_iter()
                .flatten()
                {
                    if real(j) {
                        for c in 0..3 {
                            sum[c] += corr[j][c];
                        }
                        k += 1.0;
                    }
                }
                if k > 0.0 {
                    // Divided by one more than the neighbours: the correction decays
                    // outwards from the held texels.
                    for c in 0..3 {
                        next[i][c] = sum[c] / (k + 1.0);
                    }
                }
            }
            std::mem::swap(&mut corr, &mut next);
        }
        for i in 0..n {
            if real(i) {
                for c in 0..3 {
                    pixels[i][c] = (pixels[i][c] + corr[i][c]).clamp(0.0, 1.0);
                }
            }
        }
        self.copy_margins(pixels);
        pairs
    }

    /// Texels that show the same surface point as `(i, j)`: its lattice translates that
    /// fall inside the canvas, and its [`Self::links`].
    pub fn partners(&self, i: usize, j: usize, out: &mut Vec<(usize, usize)>) {
        if !self.links.is_empty() {
            let t = (j * self.width + i) as u32;
            let lo = self.links.partition_point(|l| l.0 < t);
            for l in &self.links[lo..] {
                if l.0 != t {
                    break;
                }
                out.push((l.1 as usize % self.width, l.1 as usize / self.width));
            }
        }
        let Some(px) = self.period_x else {
            return;
        };
        let (w, h) = (self.width as i64, self.height as i64);
        let ls: &[i64] = if self.period_y.is_some() { &[-1, 0, 1] } else { &[0] };
        let [bx, bh] = self.period_y.unwrap_or([0, 0]);
        for &l in ls {
            for k in -2i64..=2 {
                if k == 0 && l == 0 {
                    continue;
                }
                let x = i as i64 + k * px + l * bx;
                let y = j as i64 + l * bh;
                if x >= 0 && x < w && y >= 0 && y < h {
                    out.push((x as usize, y as usize));
                }
            }
        }
    }
}

/// Barycentric coordinates of `p` for corners 1 and 2 of triangle `t` (signed doubled
/// area `det`).
fn barycentric(t: &[[f64; 2]; 3], det: f64, p: [f64; 2]) -> [f64; 2] {
    let l1 =
        ((p[0] - t[0][0]) * (t[2][1] - t[0][1]) - (p[1] - t[0][1]) * (t[2][0] - t[0][0])) / det;
    let l2 =
        ((t[1][0] - t[0][0]) * (p[1] - t[0][1]) - (t[1][1] - t[0][1]) * (p[0] - t[0][0])) / det;
    [l1, l2]
}

/// Barycentric interpolation of the corner values `v` of triangle `t` (signed doubled
/// area `det`) at `p`, with the coordinates clamped to the triangle (texel centres just
/// outside it take the nearest boundary value).
fn interpolate(t: &[[f64; 2]; 3], det: f64, p: [f64; 2], v: [f64; 3]) -> f32 {
    let [l1, l2] = barycentric(t, det, p);
    let (l1, l2) = (l1.clamp(0.0, 1.0), l2.clamp(0.0, 1.0));
    let l0 = (1.0 - l1 - l2).max(0.0);
    ((l0 * v[0] + l1 * v[1] + l2 * v[2]) / (l0 + l1 + l2)) as f32
}

/// The point of triangle `to` with the barycentric coordinates that `p` has in `from`
/// (signed doubled area `det`).
fn carry(from: &[[f64; 2]; 3], det: f64, p: [f64; 2], to: &[[f64; 2]; 3]) -> [f64; 2] {
    let [l1, l2] = barycentric(from, det, p);
    let l0 = 1.0 - l1 - l2;
    [l0 * to[0][0] + l1 * to[1][0] + l2 * to[2][0], l0 * to[0][1] + l1 * to[1][1] + l2 * to[2][1]]
}

/// Whether `p` lies in triangle `t` (either orientation, boundary included).
fn contains(t: &[[f64; 2]; 3], p: [f64; 2]) -> bool {
    let side =
        |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
    let s = [side(t[0], t[1]), side(t[1], t[2]), side(t[2], t[0])];
    s.iter().all(|&v| v >= 0.0) || s.iter().all(|&v| v <= 0.0)
}

/// Twice the signed area of `t` (negative for the clockwise canvas triangles).
fn doubled_area(t: &[[f64; 2]; 3]) -> f64 {
    (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0])
}

/// Calls `visit(index, centre)` for every canvas texel whose centre `t` covers.
fn for_texels(
    t: [[f64; 2]; 3],
    width: usize,
    height: usize,
    mut visit: impl FnMut(usize, [f64; 2]),
) {
    triangle_row_spans(t, 0.0, |row, c0, c1| {
        if row < 0 || row >= height as i64 {
            return;
        }
        for col in c0.max(0)..=c1.min(width as i64 - 1) {
            visit(row as usize * width + col as usize, [col as f64 + 0.5, row as f64 + 0.5]);
        }
    });
}

/// Row-major index of the canvas texel containing `p`, if inside the canvas.
fn texel_at(p: [f64; 2], width: usize, height: usize) -> Option<usize> {
    let (x, y) = (p[0].floor(), p[1].floor());
    (x >= 0.0 && y >= 0.0 && x < width as f64 && y < height as f64)
        .then(|| y as usize * width + x as usize)
}
