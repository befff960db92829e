//! Quality metrics of a texture on a surface (issue 4 targets, DESIGN.md §6):
//!
//! - [`surface_orientation_error`]: orientation error of a textured mesh against a
//!   tangent direction field, measured by **tangent-plane resampling**;
//! - [`feature_line_coverage`]: the fraction of salient-curve length on which the
//!   texture shows an exemplar feature line (paper A, Xu et al., §5.2).
//!
//! **Tangent-plane resampling.** At well-spread surface points (Poisson-disk samples,
//! `fieldtex_mesh::poisson_disk_sampling`) a `k × k` image is built in the tangent
//! plane: pixel `(i, j)` is the point `c + (i − (k−1)/2)·s·t + (j − (k−1)/2)·s·(t × n)`
//! (`c` the sample, `n` the interpolated vertex normal, `t` the field projected to the
//! tangent plane, `s` the texel size), moved to the closest surface point (BVH), given
//! the UV of that triangle's corner UVs at its barycentric coordinates, and filled with
//! the texture's luminance sampled bilinearly. The patch's axes are `t` (x, right) and
//! `t × n = −(n × t)` (y, **down**): seen from outside the surface, the patch is laid
//! out like the exemplar with its x axis along the field, exactly as an unmirrored
//! texture maps image x right / y down onto the tangent frame. So the conventions of
//! [`crate::orientation`] carry over: the structure tensor of the patch (Farid–Simoncelli
//! gradients, Gaussian window of σ = k/4; Bigün & Granlund 1987) gives the texture's
//! feature direction in the patch, which should equal `exemplar_angle_deg` (the
//! exemplar's own stripe direction, measured with [`crate::dominant_orientation`]); the
//! error is the difference mod 180°, in `[0°, 90°]`, weighted by the patch coherence.
//!
//! Samples whose patch leaves the surface (more than 10 % of its pixels land farther
//! than [`SurfaceOrientationOptions::max_projection`] patch half-widths from their
//! tangent-plane point: borders, thin parts, strong curvature) or whose field vector
//! vanishes are skipped and counted.
//!
//! UV conventions: `fieldtex_mesh::CornerUvs`, UV (0, 0) at the lower-left of the
//! image; texel `(i, j)` (row `j` from the top) is centred at UV
//! `((i + ½)/W, 1 − (j + ½)/H)`.
//!
//! Not implemented: geodesic (exponential-map) patches; mirrored textures (a texture
//! mapped with flipped handedness shows `−angle`: symmetric exemplars with angle 0° or
//! 90° are unaffected).

use crate::EvalError;
use crate::filters::gradient;
use crate::image_view::ImageView;
use crate::orientation::orientation_difference;
use fieldtex_core::Warning;
use fieldtex_core::vec3::{self, V3};
use fieldtex_mesh::{
    Bvh, CornerUvs, NormalWeighting, PoissonDiskOptions, TriMesh, poisson_disk_sampling,
    vertex_normals,
};
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::PI;

/// Options of [`surface_orientation_error`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SurfaceOrientationOptions {
    /// Approximate number of surface samples (Poisson disk). Default 400.
    pub n_samples: usize,
    /// Side `k` of the square tangent-plane patch, pixels; about two stripe periods or
    /// more. Default 32.
    pub patch_size: usize,
    /// Spacing of patch pixels in mesh units; `None` = the texture's own texel size
    /// on the surface (area-weighted median over triangles of
    /// `√(3-D area / (UV area · W · H))`). Default `None`.
    pub texel_size: Option<f64>,
    /// Stripe direction of the exemplar in its own frame, degrees (x right, y down);
    /// the texture is expected at field angle + this. Default 0.
    pub exemplar_angle_deg: f64,
    /// Wrap UVs outside `[0, 1]` (repeating texture) instead of clamping. Default
    /// `false` (atlases).
    pub uv_wrap: bool,
    /// A patch pixel is off the surface when its closest surface point is farther than
    /// this many patch half-widths away. Default 0.25.
    pub max_projection: f64,
    /// Seed of the sample positions. Default 0.
    pub seed: u64,
}

impl Default for SurfaceOrientationOptions {
    fn default() -> Self {
        Self {
            n_samples: 400,
            patch_size: 32,
            texel_size: None,
            exemplar_angle_deg: 0.0,
            uv_wrap: false,
            max_projection: 0.25,
            seed: 0,
        }
    }
}

impl SurfaceOrientationOptions {
    fn validate(&self) -> Result<(), EvalError> {
        let bad =
            |name, value: String, reason| Err(EvalError::InvalidOption { name, value, reason });
        if !(1..=1_000_000).contains(&self.n_samples) {
            return bad("n_samples", self.n_samples.to_string(), "must be in [1, 1000000]");
        }
        if !(8..=256).contains(&self.patch_size) {
            return bad("patch_size", self.patch_size.to_string(), "must be in [8, 256] pixels");
        }
        if let Some(s) = self.texel_size
            && !(s.is_finite() && s > 0.0)
        {
            return bad("texel_size", s.to_string(), "must be a positive length in mesh units");
        }
        if !self.exemplar_angle_deg.is_finite() {
            let v = self.exemplar_angle_deg.to_string();
            return bad("exemplar_angle_deg", v, "must be finite");
        }
        if !(self.max_projection.is_finite() && self.max_projection > 0.0) {
            let v = self.max_projection.to_string();
            return bad("max_projection", v, "must be a positive number of patch half-widths");
        }
        Ok(())
    }
}

/// Result of [`surface_orientation_error`]; angles in degrees.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SurfaceOrientationReport {
    /// Coherence-weighted mean error, in `[0, 90]` (NaN when nothing was measured).
    pub mean_deg: f64,
    /// Coherence-weighted median error.
    pub median_deg: f64,
    /// Coherence-weighted 90th percentile of the error.
    pub p90_deg: f64,
    /// Plain mean error over the measured samples.
    pub unweighted_mean_deg: f64,
    /// Coherence-weighted circular mean of the texture direction relative to the
    /// field, in `[0, 180)` (compare with `exemplar_angle_deg`).
    pub mean_relative_angle_deg: f64,
    /// Mean patch coherence in `[0, 1]`.
    pub mean_coherence: f64,
    /// Samples measured.
    pub n_samples: usize,
    /// Samples skipped (patch off the surface, no field direction).
    pub n_skipped: usize,
    /// Patch pixel spacing used, mesh units.
    pub texel_size: f64,
    pub patch_size: usize,
    pub warnings: Vec<Warning>,
}

fn invalid(name: &'static str, value: String, reason: &'static str) -> EvalError {
    EvalError::InvalidOption { name, value, reason }
}

/// Checks the mesh, UVs and field against each other.
fn check_inputs(mesh: &TriMesh, uvs: &CornerUvs, field: &[V3]) -> Result<(), EvalError> {
    if mesh.triangles.is_empty() {
        return Err(invalid("mesh", "0 triangles".into(), "must have triangles to texture"));
    }
    mesh.validate().map_err(|e| invalid("mesh", e.to_string(), "must be a valid triangle mesh"))?;
    if uvs.indices.len() != mesh.triangles.len() {
        return Err(invalid(
            "corner_uvs",
            format!("{} index triples for {} triangles", uvs.indices.len(), mesh.triangles.len()),
            "must give one UV index triple per triangle",
        ));
    }
    let n_uv = uvs.values.len();
    if let Some((f, _)) =
        uvs.indices.iter().enumerate().find(|(_, t)| t.iter().any(|&i| i as usize >= n_uv))
    {
        return Err(invalid(
            "corner_uvs",
            format!("triangle {f} indexes past the {n_uv} UV values"),
            "UV indices must be smaller than the number of UV values",
        ));
    }
    if let Some(i) = uvs.values.iter().position(|v| !(v[0].is_finite() && v[1].is_finite())) {
        return Err(invalid("corner_uvs", format!("UV {i} is not finite"), "UVs must be finite"));
    }
    if field.len() != mesh.n_vertices() {
        return Err(invalid(
            "field",
            format!("{} vectors for {} vertices", field.len(), mesh.n_vertices()),
            "must hold one tangent vector per mesh vertex (#V × 3)",
        ));
    }
    Ok(())
}

/// The texture's texel size on the surface: area-weighted median over triangles of
/// `√(A_3D / (A_UV · W · H))`; `None` when no triangle has UV area.
fn median_texel_size(mesh: &TriMesh, uvs: &CornerUvs, w: usize, h: usize) -> Option<f64> {
    let mut pairs: Vec<(f64, f64)> = (0..mesh.n_triangles())
        .filter_map(|f| {
            let p = mesh.triangle_positions(f);
            let a3 = 0.5 * vec3::norm(vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0])));
            let [i, j, k] = uvs.indices[f].map(|i| uvs.values[i as usize]);
            let auv = 0.5 * ((j[0] - i[0]) * (k[1] - i[1]) - (k[0] - i[0]) * (j[1] - i[1])).abs();
            let px = auv * (w * h) as f64;
            (a3 > 0.0 && px > 0.0 && a3.is_finite()).then(|| ((a3 / px).sqrt(), a3))
        })
        .collect();
    if pairs.is_empty() {
        return None;
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = pairs.iter().map(|p| p.1).sum();
    let mut acc = 0.0;
    for (size, area) in &pairs {
        acc += area;
        if acc >= 0.5 * total {
            return Some(*size);
        }
    }
    pairs.last().map(|p| p.0)
}

/// Bilinear sample of a `w × h` luminance image at UV `(u, v)` (module conventions).
fn sample_uv(luma: &[f32], w: usize, h: usize, uv: [f64; 2], wrap: bool) -> f32 {
    let x = uv[0] * w as f64 - 0.5;
    let y = (1.0 - uv[1]) * h as f64 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (tx, ty) = ((x - x0) as f32, (y - y0) as f32);
    let index = |i: i64, n: usize| {
        if wrap { i.rem_euclid(n as i64) as usize } else { i.clamp(0, n as i64 - 1) as usize }
    };
    // Far-away UVs (huge or wrapped many times) stay in range through rem/clamp.
    let (x0, y0) = (x0.clamp(-1e15, 1e15) as i64, y0.clamp(-1e15, 1e15) as i64);
    let at = |i: i64, j: i64| luma[index(j, h) * w + index(i, w)];
    let top = at(x0, y0) * (1.0 - tx) + at(x0 + 1, y0) * tx;
    let bottom = at(x0, y0 + 1) * (1.0 - tx) + at(x0 + 1, y0 + 1) * tx;
    top * (1.0 - ty) + bottom * ty
}

/// Feature direction (radians in `[0, π)`, patch coordinates x right / y down) and
/// coherence of a `k × k` patch: structure tensor summed under a Gaussian window of
/// σ = k/4, the 2-pixel rim (filter support) left out.
fn patch_orientation(patch: &[f32], k: usize) -> (f64, f64) {
    let (gx, gy) = gradient(patch, k, k);
    let c = (k as f64 - 1.0) / 2.0;
    let sw = k as f64 / 4.0;
    let (mut xx, mut xy, mut yy) = (0f64, 0f64, 0f64);
    for j in 2..k - 2 {
        for i in 2..k - 2 {
            let r2 = (i as f64 - c).powi(2) + (j as f64 - c).powi(2);
            let wgt = (-r2 / (2.0 * sw * sw)).exp();
            let (a, b) = (gx[j * k + i] as f64, gy[j * k + i] as f64);
            xx += wgt * a * a;
            xy += wgt * a * b;
            yy += wgt * b * b;
        }
    }
    let trace = xx + yy;
    let phi = 0.5 * (2.0 * xy).atan2(xx - yy);
    // Same noise floor as the image metric: (1e-5 per pixel)² over the window mass.
    let coherence = if trace > 1e-10 * 2.0 * PI * sw * sw {
        (((xx - yy).powi(2) + 4.0 * xy * xy).sqrt() / trace).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((phi + 0.5 * PI).rem_euclid(PI), coherence)
}

/// Weighted quantile `q` of `(value, weight)` pairs (sorted by value here); NaN when
/// there is no weight.
fn weighted_quantile(pairs: &mut [(f64, f64)], q: f64) -> f64 {
    fieldtex_linalg::stats::weighted_quantile(pairs, q).unwrap_or(f64::NAN)
}

/// Orientation error of a textured mesh against a tangent field, by tangent-plane
/// resampling (module docs). `texture` is the (atlas) image the corner UVs point into;
/// `field` is `#V × 3`, one tangent direction per vertex (sign ignored: a 2-RoSy field
/// may flip between vertices). Errors on inconsistent inputs or options; a mesh or
/// texture on which nothing can be measured gives NaN angles and 0 samples.
pub fn surface_orientation_error(
    mesh: &TriMesh,
    uvs: &CornerUvs,
    texture: &ImageView,
    field: &[V3],
    options: &SurfaceOrientationOptions,
) -> Result<SurfaceOrientationReport, EvalError> {
    options.validate()?;
    check_inputs(mesh, uvs, field)?;
    let (w, h) = (texture.width, texture.height);
    if w < 2 || h < 2 {
        return Err(EvalError::TooSmall {
            what: "surface orientation texture",
            width: w,
            height: h,
            min: 2,
        });
    }
    let luma = texture.luminance();
    let texel = match options.texel_size {
        Some(s) => s,
        None => median_texel_size(mesh, uvs, w, h).ok_or_else(|| {
            invalid(
                "corner_uvs",
                "zero UV area on every triangle".into(),
                "must map some triangle onto a texture area (or give texel_size)",
            )
        })?,
    };
    let bvh = Bvh::build(mesh)
        .map_err(|e| invalid("mesh", e.to_string(), "must be a valid triangle mesh"))?;
    let (normals, _) = vertex_normals(mesh, NormalWeighting::Angle);
    let sampling = PoissonDiskOptions {
        target_count: Some(options.n_samples),
        seed: options.seed,
        ..Default::default()
    };
    let (samples, mut warnings) = poisson_disk_sampling(mesh, &sampling)
        .map_err(|e| invalid("mesh", e.to_string(), "must be a valid triangle mesh"))?;
    let k = options.patch_size;
    let centre = (k as f64 - 1.0) / 2.0;
    let max_dist = options.max_projection * 0.5 * k as f64 * texel;
    let offset = options.exemplar_angle_deg.to_radians();

    // Per sample: (error, coherence, relative angle) or None when skipped.
    let measured: Vec<Option<(f64, f64, f64)>> = samples
        .samples
        .par_iter()
        .map_init(
            || vec![0f32; k * k],
            |patch, s| {
                let tri = mesh.triangles[s.triangle as usize];
                let b = s.barycentric;
                let mut n = [0.0; 3];
                let mut t = [0.0; 3];
                let reference =
                    tri.iter().map(|&v| field[v as usize]).find(|f| vec3::norm2(*f) > 0.0)?;
                for (i, &v) in tri.iter().enumerate() {
                    n = vec3::add(n, vec3::scale(normals[v as usize], b[i]));
                    let f = field[v as usize];
                    let sign = if vec3::dot(f, reference) < 0.0 { -1.0 } else { 1.0 };
                    t = vec3::add(t, vec3::scale(f, sign * b[i]));
                }
                let p = mesh.triangle_positions(s.triangle as usize);
                if vec3::norm2(n) == 0.0 || !vec3::is_finite(n) {
                    n = vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0]));
                }
                let n = vec3::normalize(n)?;
                let t = vec3::sub(t, vec3::scale(n, vec3::dot(t, n)));
                let tn = vec3::norm(t);
                if !(tn > 1e-12 && tn.is_finite()) {
                    return None;
                }
                let ex = vec3::scale(t, 1.0 / tn);
                let ey = vec3::cross(ex, n);
                let mut off = 0usize;
                for j in 0..k {
                    for i in 0..k {
                        let q = vec3::add(
                            s.position,
                            vec3::add(
                                vec3::scale(ex, (i as f64 - centre) * texel),
                                vec3::scale(ey, (j as f64 - centre) * texel),
                            ),
                        );
                        let cp = bvh.closest_point(q)?;
                        if cp.distance > max_dist {
                            off += 1;
                        }
                        let [a, bb, c] =
                            uvs.indices[cp.triangle as usize].map(|i| uvs.values[i as usize]);
                        let l = cp.barycentric;
                        let uv = [
                            l[0] * a[0] + l[1] * bb[0] + l[2] * c[0],
                            l[0] * a[1] + l[1] * bb[1] + l[2] * c[1],
                        ];
                        patch[j * k + i] = sample_uv(&luma, w, h, uv, options.uv_wrap);
                    }
                }
                if off * 10 > k * k {
                    return None;
                }
                let (angle, coherence) = patch_orientation(patch, k);
                Some((orientation_difference(angle, offset), coherence, angle))
            },
        )
        .collect();

    let mut pairs = Vec::new();
    let (mut se, mut sc, mut su, mut cx, mut cy) = (0f64, 0f64, 0f64, 0f64, 0f64);
    for &(e, c, a) in measured.iter().flatten() {
        pairs.push((e, c));
        se += c * e;
        sc += c;
        su += e;
        cx += c * (2.0 * a).cos();
        cy += c * (2.0 * a).sin();
    }
    let n = pairs.len();
    let n_skipped = measured.len() - n;
    if n_skipped * 2 > measured.len() {
        warnings.push(Warning::new(
            "surface-orientation-samples-skipped",
            format!(
                "{n_skipped} of {} surface samples were skipped (patch off the surface or no \
                 field direction); lower patch_size or texel_size for thin or curved parts",
                measured.len()
            ),
        ));
    }
    let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { f64::NAN };
    Ok(SurfaceOrientationReport {
        mean_deg: ratio(se, sc).to_degrees(),
        median_deg: weighted_quantile(&mut pairs, 0.5).to_degrees(),
        p90_deg: weighted_quantile(&mut pairs, 0.9).to_degrees(),
        unweighted_mean_deg: ratio(su, n as f64).to_degrees(),
        mean_relative_angle_deg: if sc > 0.0 {
            let d = (0.5 * cy.atan2(cx)).rem_euclid(PI).to_degrees();
            if d >= 180.0 - 1e-9 { 0.0 } else { d }
        } else {
            f64::NAN
        },
        mean_coherence: ratio(sc, n as f64),
        n_samples: n,
        n_skipped,
        texel_size: texel,
        patch_size: k,
        warnings,
    })
}

/// A point of a salient curve on the textured surface, for [`feature_line_coverage`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurveSample {
    /// Exemplar coordinate the texture shows at this point, pixels: x right, y down,
    /// exemplar pixel `(i, j)` centred at `(i, j)` (the distance map's convention).
    pub exemplar_xy: [f64; 2],
    /// Curve length this point stands for (e.g. half of each adjacent segment).
    pub length: f64,
}

/// Options of [`feature_line_coverage`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeatureCoverageOptions {
    /// A point is covered when its exemplar coordinate lies within this many pixels of
    /// an exemplar feature line. Default 1 (one texel).
    pub tolerance_px: f64,
    /// Wrap exemplar coordinates (tileable exemplar). Default `true`; otherwise points
    /// outside the exemplar are skipped.
    pub toroidal: bool,
}

impl Default for FeatureCoverageOptions {
    fn default() -> Self {
        Self { tolerance_px: 1.0, toroidal: true }
    }
}

/// Result of [`feature_line_coverage`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeatureCoverageReport {
    /// `covered_length / total_length` in `[0, 1]` (NaN when no length was measured).
    pub fraction: f64,
    pub covered_length: f64,
    pub total_length: f64,
    /// Points measured.
    pub n_samples: usize,
    /// Points skipped: non-finite coordinate or length, negative length, or outside a
    /// non-toroidal exemplar.
    pub n_skipped: usize,
}

/// Distance map value at `(x, y)`: bilinear between pixel centres, the nearest pixel's
/// value where a neighbour is infinite (no line anywhere).
fn distance_at(distance: &[f32], w: usize, h: usize, x: f64, y: f64, wrap: bool) -> f32 {
    let index = |i: i64, n: usize| {
        if wrap { i.rem_euclid(n as i64) as usize } else { i.clamp(0, n as i64 - 1) as usize }
    };
    let (x0, y0) = (x.floor(), y.floor());
    let (tx, ty) = ((x - x0) as f32, (y - y0) as f32);
    let (x0, y0) = (x0.clamp(-1e15, 1e15) as i64, y0.clamp(-1e15, 1e15) as i64);
    let at = |i: i64, j: i64| distance[index(j, h) * w + index(i, w)];
    let v = [at(x0, y0), at(x0 + 1, y0), at(x0, y0 + 1), at(x0 + 1, y0 + 1)];
    if v.iter().all(|d| d.is_finite()) {
        let top = v[0] * (1.0 - tx) + v[1] * tx;
        let bottom = v[2] * (1.0 - tx) + v[3] * tx;
        top * (1.0 - ty) + bottom * ty
    } else {
        at(x.round().clamp(-1e15, 1e15) as i64, y.round().clamp(-1e15, 1e15) as i64)
    }
}

/// Fraction of salient-curve length whose exemplar coordinate lies within
/// `tolerance_px` of an exemplar feature line (paper A §5.2; DESIGN.md §6 "feature
/// alignment"). `distance` is the exemplar's `width × height` distance-to-feature map
/// in pixels (row-major, top row first, `+∞` allowed where there is no line), e.g.
/// `fieldtex_features::ExemplarFeatures::distance`; `samples` come from any engine.
pub fn feature_line_coverage(
    samples: &[CurveSample],
    distance: &[f32],
    width: usize,
    height: usize,
    options: &FeatureCoverageOptions,
) -> Result<FeatureCoverageReport, EvalError> {
    if width == 0 || height == 0 || width.checked_mul(height) != Some(distance.len()) {
        return Err(EvalError::BufferSize {
            what: "exemplar distance map",
            width,
            height,
            channels: 1,
            expected: width.saturating_mul(height),
            found: distance.len(),
        });
    }
    if let Some((index, &value)) =
        distance.iter().enumerate().find(|(_, d)| d.is_nan() || **d < 0.0)
    {
        return Err(EvalError::NonFinite {
            what: "exemplar distance map (NaN or negative)",
            index,
            value,
        });
    }
    let tol = options.tolerance_px;
    if !(tol.is_finite() && tol >= 0.0) {
        return Err(invalid(
            "tolerance_px",
            tol.to_string(),
            "must be a non-negative number of pixels",
        ));
    }
    let (mut covered, mut total, mut n, mut skipped) = (0f64, 0f64, 0usize, 0usize);
    for s in samples {
        let [x, y] = s.exemplar_xy;
        let inside =
            (-0.5..width as f64 - 0.5).contains(&x) && (-0.5..height as f64 - 0.5).contains(&y);
        if !(x.is_finite() && y.is_finite() && s.length.is_finite() && s.length >= 0.0)
            || (!options.toroidal && !inside)
        {
            skipped += 1;
            continue;
        }
        n += 1;
        total += s.length;
        if distance_at(distance, width, height, x, y, options.toroidal) as f64 <= tol {
            covered += s.length;
        }
    }
    Ok(FeatureCoverageReport {
        fraction: if total > 0.0 { covered / total } else { f64::NAN },
        covered_length: covered,
        total_length: total,
        n_samples: n,
        n_skipped: skipped,
    })
}
