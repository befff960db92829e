//! Synthesis domains: where the parallel synthesis runs.
//!
//! A domain is a hierarchy of 2-D sample grids, level 0 finest. Each sample has
//! up to 8 grid neighbours at offsets `(dx, dy) ∈ {−1, 0, 1}²`, one parent on the next
//! coarser level, a 2×2 interleaving class for the correction subpasses and a local
//! Jacobian `J` (row-major `[j00, j01, j10, j11]`) mapping a domain offset, in samples
//! of its level, to an exemplar offset in exemplar pixels (the engine multiplies by the
//! level spacing `2^level`). For orientation (2-RoSy) fields `J` is built from one
//! *representative* vector per sample; representatives may jump by 180° between
//! neighbours, which the engine's flip indicator absorbs (paper D §4).
//!
//! [`ImageDomain`] is the plane: a `W × H` output image. Atlas charts (a grid per chart
//! with neighbours across seams) and parameterised patches (the parameterisation's
//! Jacobian composed with the field's) implement the same trait.

use crate::SynthError;

/// A hierarchy of sample grids the synthesis runs over. Implementations must be cheap
/// to query: the engine tabulates everything once per level.
pub trait SynthesisDomain: Sync {
    /// Number of levels available (level 0 finest). The engine uses
    /// `min(analysis levels, level_count − 1)` synthesis levels plus one coarser
    /// initialisation level.
    fn level_count(&self) -> usize;
    /// Samples on `level`.
    fn sample_count(&self, level: usize) -> usize;
    /// The sample at grid offset `offset` (each component in `−1..=1`) from `sample`,
    /// or `None` outside the domain.
    fn neighbor(&self, level: usize, sample: usize, offset: [i32; 2]) -> Option<usize>;
    /// The parent of `sample` on `level + 1` and the sample's offset from the parent's
    /// centre in samples of `level` (`(±½, ±½)` for a regular quadtree).
    fn parent(&self, level: usize, sample: usize) -> (usize, [f32; 2]);
    /// Jacobian of `sample` (row-major 2×2, domain offset → exemplar offset).
    fn jacobian(&self, level: usize, sample: usize) -> [f32; 4];
    /// Interleaving class in `0..4` (samples of one class are never grid neighbours);
    /// for a grid `(x mod 2) + 2 (y mod 2)`.
    fn subpass_class(&self, level: usize, sample: usize) -> usize;
    /// Width and height of the image the finest level's samples form (row-major,
    /// `width · height = sample_count(0)`). Default: one row.
    fn output_size(&self) -> (usize, usize) {
        (self.sample_count(0), 1)
    }
}

/// The plane: a `width × height` output image whose coarser levels halve the size
/// (rounding up) down to 1×1. Sample `(x, y)` has index `y · w + x` on its level.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageDomain {
    pub width: usize,
    pub height: usize,
    /// Finest-level Jacobians, `width × height`, row-major `[j00, j01, j10, j11]`.
    pub jacobian: Vec<[f32; 4]>,
}

/// Levels [`ImageDomain`] reports (levels beyond 1×1 stay 1×1).
const IMAGE_DOMAIN_LEVELS: usize = 24;

impl ImageDomain {
    /// A domain with the given finest-level Jacobians (`width × height` of them).
    pub fn new(width: usize, height: usize, jacobian: Vec<[f32; 4]>) -> Result<Self, SynthError> {
        if width == 0 || height == 0 {
            return Err(SynthError::InvalidDomain {
                reason: format!("image domain is {width}×{height}; both sides must be at least 1"),
            });
        }
        if jacobian.len() != width * height {
            return Err(SynthError::InvalidDomain {
                reason: format!(
                    "{} Jacobians given for a {width}×{height} image domain (need {})",
                    jacobian.len(),
                    width * height
                ),
            });
        }
        for (sample, j) in jacobian.iter().enumerate() {
            check_jacobian(0, sample, j)?;
        }
        Ok(Self { width, height, jacobian })
    }

    /// A domain whose texture follows a direction field: `field` holds `H × W × 2`
    /// values, `[row, col] = (dx, dy)`, x right, y down; the exemplar's x axis follows
    /// `d` and its y axis `d⊥ = (−d.y, d.x)`. The Jacobian (output → exemplar) is
    /// `J = scale · [d; d⊥]` (rows), so `J d = (scale, 0)`; `scale` is exemplar pixels
    /// per output pixel (0.5 shows features twice as large). Vectors are normalised;
    /// zero vectors (e.g. exactly at a singularity) get the direction `(1, 0)`.
    pub fn from_direction_field(
        width: usize,
        height: usize,
        field: &[f32],
        scale: f32,
    ) -> Result<Self, SynthError> {
        if field.len() != width * height * 2 {
            return Err(SynthError::FieldSize {
                width,
                height,
                expected: width * height * 2,
                found: field.len(),
            });
        }
        if !(scale.is_finite() && scale > 0.0) {
            return Err(SynthError::InvalidOption {
                name: "ImageDomain scale",
                value: scale as f64,
                reason: "must be a positive finite number of exemplar pixels per output pixel",
            });
        }
        let mut jac = Vec::with_capacity(width * height);
        for (i, d) in field.chunks_exact(2).enumerate() {
            let (dx, dy) = (d[0], d[1]);
            if !(dx.is_finite() && dy.is_finite()) {
                return Err(SynthError::NonFiniteField { x: i % width, y: i / width, dx, dy });
            }
            let len = (dx * dx + dy * dy).sqrt();
            let (ux, uy) = if len > 1e-12 { (dx / len, dy / len) } else { (1.0, 0.0) };
            jac.push([scale * ux, scale * uy, -scale * uy, scale * ux]);
        }
        Self::new(width, height, jac)
    }

    /// A domain with one constant direction (`angle` radians from +x, y down).
    pub fn constant(
        width: usize,
        height: usize,
        angle: f32,
        scale: f32,
    ) -> Result<Self, SynthError> {
        let (s, c) = angle.sin_cos();
        let field: Vec<f32> = (0..width * height).flat_map(|_| [c, s]).collect();
        Self::from_direction_field(width, height, &field, scale)
    }

    /// Size of `level`.
    pub fn level_size(&self, level: usize) -> (usize, usize) {
        let sh = level.min(63) as u32;
        let f = |n: usize| n.div_ceil(1usize.checked_shl(sh).unwrap_or(usize::MAX)).max(1);
        (f(self.width), f(self.height))
    }
}

/// Rejects non-finite and (nearly) singular Jacobians.
pub(crate) fn check_jacobian(level: usize, sample: usize, j: &[f32; 4]) -> Result<(), SynthError> {
    if j.iter().any(|v| !v.is_finite()) {
        return Err(SynthError::InvalidJacobian {
            level,
            sample,
            jacobian: *j,
            reason: "not finite",
        });
    }
    let det = j[0] * j[3] - j[1] * j[2];
    let norm2 = j.iter().map(|v| v * v).sum::<f32>();
    if det.is_nan() || det.abs() <= 1e-6 * norm2.max(1e-30) || norm2 < 1e-12 {
        return Err(SynthError::InvalidJacobian {
            level,
            sample,
            jacobian: *j,
            reason: "singular",
        });
    }
    Ok(())
}

impl SynthesisDomain for ImageDomain {
    fn level_count(&self) -> usize {
        IMAGE_DOMAIN_LEVELS
    }

    fn sample_count(&self, level: usize) -> usize {
        let (w, h) = self.level_size(level);
        w * h
    }

    fn neighbor(&self, level: usize, sample: usize, offset: [i32; 2]) -> Option<usize> {
        let (w, h) = self.level_size(level);
        let x = (sample % w) as i64 + offset[0] as i64;
        let y = (sample / w) as i64 + offset[1] as i64;
        (x >= 0 && y >= 0 && x < w as i64 && y < h as i64).then(|| y as usize * w + x as usize)
    }

    fn parent(&self, level: usize, sample: usize) -> (usize, [f32; 2]) {
        let (w, _) = self.level_size(level);
        let (pw, _) = self.level_size(level + 1);
        let (x, y) = (sample % w, sample / w);
        let off = |v: usize| if v.is_multiple_of(2) { -0.5 } else { 0.5 };
        ((y / 2) * pw + x / 2, [off(x), off(y)])
    }

    fn jacobian(&self, level: usize, sample: usize) -> [f32; 4] {
        let (w, _) = self.level_size(level);
        let (x, y) = (sample % w, sample / w);
        // Point-sample the finest field at the centre of the coarse sample's footprint.
        let half = if level == 0 { 0 } else { 1usize << (level.min(62) - 1) };
        let fx = (x << level.min(62)).saturating_add(half).min(self.width - 1);
        let fy = (y << level.min(62)).saturating_add(half).min(self.height - 1);
        self.jacobian[fy * self.width + fx]
    }

    fn subpass_class(&self, level: usize, sample: usize) -> usize {
        let (w, _) = self.level_size(level);
        (sample % w) % 2 + 2 * ((sample / w) % 2)
    }

    fn output_size(&self) -> (usize, usize) {
        (self.width, self.height)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_frame_maps_direction_to_exemplar_x() {
        let d = [0.6f32, 0.8];
        let field: Vec<f32> = (0..6).flat_map(|_| d).collect();
        let dom = ImageDomain::from_direction_field(3, 2, &field, 2.0).unwrap();
        let j = dom.jacobian(0, 4);
        let jd = [j[0] * d[0] + j[1] * d[1], j[2] * d[0] + j[3] * d[1]];
        assert!((jd[0] - 2.0).abs() < 1e-6 && jd[1].abs() < 1e-6, "{jd:?}");
        assert!(ImageDomain::from_direction_field(3, 2, &field[..10], 1.0).is_err());
        let mut bad = field.clone();
        bad[3] = f32::NAN;
        assert!(matches!(
            ImageDomain::from_direction_field(3, 2, &bad, 1.0),
            Err(SynthError::NonFiniteField { x: 1, y: 0, .. })
        ));
    }

    #[test]
    fn hierarchy_is_consistent() {
        let dom = ImageDomain::constant(5, 3, 0.3, 1.0).unwrap();
        assert_eq!(dom.level_size(1), (3, 2));
        assert_eq!(dom.level_size(5), (1, 1));
        assert_eq!(dom.parent(0, 14), (5, [-0.5, -0.5]));
        assert_eq!(dom.neighbor(0, 4, [1, 0]), None);
        assert_eq!(dom.neighbor(0, 4, [-1, 1]), Some(8));
        assert_eq!(dom.subpass_class(0, 6), 1 + 2);
    }
}
