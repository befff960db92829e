//! Structure-tensor orientation of an image and its error against a guidance field.
//!
//! Method (Bigün & Granlund 1987; Kass & Witkin 1987): gradients `g = (∂L/∂x, ∂L/∂y)`
//! of the luminance by the Farid–Simoncelli 5-tap filters, tensor `J = G_σ * (g gᵀ)`
//! smoothed by a Gaussian of standard deviation σ, eigenvalues `λ1 ≥ λ2`.
//!
//! **Convention.** The orientation reported is the **feature (stripe) direction**:
//! the direction along which the image varies least, perpendicular to the dominant
//! gradient. For horizontal stripes (intensity changing with y only) it is 0°. Angles
//! are measured in pixel coordinates, x right and y **down**, as `atan2(dy, dx)` and
//! taken mod 180°: +30° points right and downward on screen. Coherence is
//! `(λ1 − λ2)/(λ1 + λ2)` ∈ [0, 1] (1 for perfect stripes, 0 for flat or isotropic).
//!
//! A guidance field (`field.npy`) gives the direction the exemplar's x axis follows
//! at each pixel, so an exemplar whose stripes run along its x axis should show stripes
//! along the field: texture angle = field angle + `exemplar_angle_deg` (the exemplar's
//! own stripe direction, 0 for stripes along x; measure it with
//! [`dominant_orientation`]).

use crate::EvalError;
use crate::filters::{gaussian_blur, gradient};
use crate::image_view::{FieldView, ImageView};
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::PI;

/// Options of the structure tensor.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrientationOptions {
    /// Standard deviation (pixels) of the Gaussian smoothing the gradient outer
    /// products; about half a stripe period or more. Default 4.
    pub sigma: f64,
}

impl Default for OrientationOptions {
    fn default() -> Self {
        Self { sigma: 4.0 }
    }
}

impl OrientationOptions {
    pub fn with_sigma(mut self, sigma: f64) -> Self {
        self.sigma = sigma;
        self
    }

    pub(crate) fn validate(&self) -> Result<(), EvalError> {
        if !(self.sigma.is_finite() && self.sigma >= 0.0 && self.sigma <= 1000.0) {
            return Err(EvalError::InvalidOption {
                name: "sigma",
                value: self.sigma.to_string(),
                reason: "must be a finite number of pixels in [0, 1000]",
            });
        }
        Ok(())
    }

    /// Pixels near the border whose tensor is affected by mirroring: `⌈2σ⌉ + 2`.
    pub fn default_border(&self) -> usize {
        (2.0 * self.sigma).ceil() as usize + 2
    }
}

/// Per-pixel orientation: `width × height`, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct OrientationMap {
    pub width: usize,
    pub height: usize,
    /// Feature direction in radians, in `[0, π)` (see the module convention).
    pub angle: Vec<f32>,
    /// Coherence in `[0, 1]`; 0 where undefined.
    pub coherence: Vec<f32>,
    /// Smoothing σ used (0 for maps made from a field).
    pub sigma: f64,
}

impl OrientationMap {
    /// Orientation of a direction field (sign ignored): angle of `(dx, dy)` mod π,
    /// coherence 1 where the vector is finite and non-zero, else 0.
    pub fn from_field(field: &FieldView) -> Self {
        let n = field.width * field.height;
        let mut angle = vec![0f32; n];
        let mut coherence = vec![0f32; n];
        for i in 0..n {
            let (dx, dy) = (field.data[2 * i] as f64, field.data[2 * i + 1] as f64);
            if dx.is_finite() && dy.is_finite() && (dx != 0.0 || dy != 0.0) {
                angle[i] = dy.atan2(dx).rem_euclid(PI) as f32;
                coherence[i] = 1.0;
            }
        }
        Self { width: field.width, height: field.height, angle, coherence, sigma: 0.0 }
    }

    /// Orientation of an angle array (radians, `width × height`): coherence 1 where
    /// finite.
    pub fn from_angles(angles: &[f32], width: usize, height: usize) -> Result<Self, EvalError> {
        if angles.len() != width * height {
            return Err(EvalError::BufferSize {
                what: "angle array",
                width,
                height,
                channels: 1,
                expected: width * height,
                found: angles.len(),
            });
        }
        let angle = angles
            .iter()
            .map(|&a| if a.is_finite() { (a as f64).rem_euclid(PI) as f32 } else { 0.0 })
            .collect();
        let coherence = angles.iter().map(|a| if a.is_finite() { 1.0 } else { 0.0 }).collect();
        Ok(Self { width, height, angle, coherence, sigma: 0.0 })
    }
}

/// Smoothed structure tensor components `(Jxx, Jxy, Jyy)` of a luminance image.
pub(crate) fn structure_tensor(
    luma: &[f32],
    width: usize,
    height: usize,
    sigma: f64,
) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
    let (gx, gy) = gradient(luma, width, height);
    let xx: Vec<f32> = gx.iter().map(|g| g * g).collect();
    let xy: Vec<f32> = gx.iter().zip(&gy).map(|(a, b)| a * b).collect();
    let yy: Vec<f32> = gy.iter().map(|g| g * g).collect();
    (
        gaussian_blur(&xx, width, height, sigma),
        gaussian_blur(&xy, width, height, sigma),
        gaussian_blur(&yy, width, height, sigma),
    )
}

/// Structure-tensor orientation of a luminance image (`width × height`).
pub fn luminance_orientation(
    luma: &[f32],
    width: usize,
    height: usize,
    options: &OrientationOptions,
) -> Result<OrientationMap, EvalError> {
    options.validate()?;
    ImageView::new(luma, width, height, 1)?;
    if width < 3 || height < 3 {
        return Err(EvalError::TooSmall { what: "orientation", width, height, min: 3 });
    }
    let (jxx, jxy, jyy) = structure_tensor(luma, width, height, options.sigma);
    let n = width * height;
    let mut angle = vec![0f32; n];
    let mut coherence = vec![0f32; n];
    angle.par_iter_mut().zip(coherence.par_iter_mut()).enumerate().for_each(|(i, (a, c))| {
        let (xx, xy, yy) = (jxx[i] as f64, jxy[i] as f64, jyy[i] as f64);
        let trace = xx + yy;
        let diff = ((xx - yy) * (xx - yy) + 4.0 * xy * xy).sqrt();
        // Dominant gradient direction, then the feature direction at +90°.
        let phi = 0.5 * (2.0 * xy).atan2(xx - yy);
        *a = (phi + 0.5 * PI).rem_euclid(PI) as f32;
        // Gradient energies below (1e-5 per pixel)² are rounding noise for images in
        // [0, 1] (an 8-bit step is 4e-3): no orientation there.
        *c = if trace > 1e-10 { (diff / trace).clamp(0.0, 1.0) as f32 } else { 0.0 };
    });
    Ok(OrientationMap { width, height, angle, coherence, sigma: options.sigma })
}

/// Structure-tensor orientation of an image (of its luminance, see
/// [`ImageView::luminance`]).
pub fn image_orientation(
    image: &ImageView,
    options: &OrientationOptions,
) -> Result<OrientationMap, EvalError> {
    luminance_orientation(&image.luminance(), image.width, image.height, options)
}

/// The image's overall feature direction (degrees in `[0, 180)`) and its coherence,
/// from the structure tensor summed over the whole image (no smoothing needed).
pub fn dominant_orientation(image: &ImageView) -> Result<(f64, f64), EvalError> {
    if image.width < 3 || image.height < 3 {
        return Err(EvalError::TooSmall {
            what: "dominant orientation",
            width: image.width,
            height: image.height,
            min: 3,
        });
    }
    let (gx, gy) = gradient(&image.luminance(), image.width, image.height);
    let (mut xx, mut xy, mut yy) = (0f64, 0f64, 0f64);
    for (a, b) in gx.iter().zip(&gy) {
        let (a, b) = (*a as f64, *b as f64);
        xx += a * a;
        xy += a * b;
        yy += b * b;
    }
    let phi = 0.5 * (2.0 * xy).atan2(xx - yy);
    let trace = xx + yy;
    let coh = if trace > 0.0 { ((xx - yy).powi(2) + 4.0 * xy * xy).sqrt() / trace } else { 0.0 };
    let deg = (phi + 0.5 * PI).rem_euclid(PI).to_degrees();
    // rem_euclid of a tiny negative angle rounds up to 180°: report 0 instead.
    Ok((if deg >= 180.0 - 1e-9 { 0.0 } else { deg }, coh))
}

/// The guidance an output is compared with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OrientationReference<'a> {
    /// A per-pixel direction field of the image's size.
    Field(FieldView<'a>),
    /// One direction everywhere, degrees (x right, y down, mod 180°).
    ConstantDeg(f64),
}

/// Options of [`orientation_error`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrientationErrorOptions {
    pub structure: OrientationOptions,
    /// Stripe direction of the exemplar in its own frame, degrees: the texture is
    /// expected at field angle + this. Default 0 (stripes along the exemplar's x).
    pub exemplar_angle_deg: f64,
    /// Pixels ignored along each border; `None` = `⌈2σ⌉ + 2`.
    pub border: Option<usize>,
}

impl Default for OrientationErrorOptions {
    fn default() -> Self {
        Self { structure: OrientationOptions::default(), exemplar_angle_deg: 0.0, border: None }
    }
}

/// Result of [`orientation_error`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrientationErrorReport {
    /// Coherence-weighted mean absolute angle difference, degrees in `[0, 90]`.
    pub mean_error_deg: f64,
    /// Plain mean over the evaluated pixels, degrees.
    pub unweighted_mean_error_deg: f64,
    /// Coherence-weighted circular mean of the texture's feature direction, degrees
    /// in `[0, 180)`.
    pub mean_texture_angle_deg: f64,
    /// Mean coherence of the evaluated pixels.
    pub mean_coherence: f64,
    /// Pixels compared (inside the border, with a defined reference direction).
    pub evaluated_pixels: usize,
    pub sigma: f64,
    pub border: usize,
}

/// Absolute difference of two orientations (radians, mod π) in radians, in `[0, π/2]`.
#[inline]
pub(crate) fn orientation_difference(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(PI);
    d.min(PI - d)
}

/// Coherence-weighted mean absolute difference (mod 180°) between the structure-tensor
/// feature direction of `image` and `reference` (+ `exemplar_angle_deg`). Pixels
/// within `border` of the edge and pixels whose field vector is zero or not finite are
/// skipped. Returns NaN angles (and 0 pixels) when nothing can be compared.
pub fn orientation_error(
    image: &ImageView,
    reference: &OrientationReference,
    options: &OrientationErrorOptions,
) -> Result<OrientationErrorReport, EvalError> {
    check_error_inputs(image.width, image.height, reference, options)?;
    let map = image_orientation(image, &options.structure)?;
    orientation_error_of_map(&map, reference, options)
}

/// The size and angle checks of [`orientation_error`].
fn check_error_inputs(
    width: usize,
    height: usize,
    reference: &OrientationReference,
    options: &OrientationErrorOptions,
) -> Result<(), EvalError> {
    if let OrientationReference::Field(f) = reference
        && (f.width, f.height) != (width, height)
    {
        return Err(EvalError::SizeMismatch {
            what: "orientation field vs image",
            expected_width: width,
            expected_height: height,
            found_width: f.width,
            found_height: f.height,
        });
    }
    if !options.exemplar_angle_deg.is_finite() {
        return Err(EvalError::InvalidOption {
            name: "exemplar_angle_deg",
            value: options.exemplar_angle_deg.to_string(),
            reason: "must be finite",
        });
    }
    Ok(())
}

/// [`orientation_error`] of an image whose structure-tensor orientation `map` is already
/// computed (with `options.structure`; `options.structure.sigma` is reported as given),
/// so that one map serves this and [`crate::singularities()`]. The same values as
/// [`orientation_error`] on the image the map came from.
pub fn orientation_error_of_map(
    map: &OrientationMap,
    reference: &OrientationReference,
    options: &OrientationErrorOptions,
) -> Result<OrientationErrorReport, EvalError> {
    check_error_inputs(map.width, map.height, reference, options)?;
    let border = options.border.unwrap_or_else(|| options.structure.default_border());
    let offset = options.exemplar_angle_deg.to_radians();
    let (w, h) = (map.width, map.height);
    // Per-row partial sums, reduced in row order for determinism.
    let rows: Vec<[f64; 6]> = (0..h)
        .into_par_iter()
        .map(|y| {
            let mut s = [0f64; 6];
            if y < border || y + border >= h {
                return s;
            }
            for x in border..w.saturating_sub(border) {
                let expected = match reference {
                    OrientationReference::ConstantDeg(d) => d.to_radians(),
                    OrientationReference::Field(f) => {
                        let v = f.at(x, y);
                        let (dx, dy) = (v[0] as f64, v[1] as f64);
                        if !(dx.is_finite() && dy.is_finite()) || (dx == 0.0 && dy == 0.0) {
                            continue;
                        }
                        dy.atan2(dx)
                    }
                } + offset;
                let i = y * w + x;
                let a = map.angle[i] as f64;
                let c = map.coherence[i] as f64;
                let e = orientation_difference(a, expected);
                s[0] += c * e;
                s[1] += c;
                s[2] += e;
                s[3] += 1.0;
                s[4] += c * (2.0 * a).cos();
                s[5] += c * (2.0 * a).sin();
            }
            s
        })
        .collect();
    let mut t = [0f64; 6];
    for r in &rows {
        for k in 0..6 {
            t[k] += r[k];
        }
    }
    let n = t[3] as usize;
    let nan_if_zero = |num: f64, den: f64| if den > 0.0 { num / den } else { f64::NAN };
    Ok(OrientationErrorReport {
        mean_error_deg: nan_if_zero(t[0], t[1]).to_degrees(),
        unweighted_mean_error_deg: nan_if_zero(t[2], t[3]).to_degrees(),
        mean_texture_angle_deg: if t[1] > 0.0 {
            (0.5 * t[5].atan2(t[4])).rem_euclid(PI).to_degrees()
        } else {
            f64::NAN
        },
        mean_coherence: nan_if_zero(t[1], t[3]),
        evaluated_pixels: n,
        sigma: options.structure.sigma,
        border,
    })
}
