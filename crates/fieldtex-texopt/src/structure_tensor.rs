//! Dominant orientation of an image by its structure tensor (Bigün & Granlund 1987).
//!
//! The tensor `J = Σ ∇I ∇Iᵀ` of the luminance gradients (central differences over the
//! interior) has its main eigenvector across the structures; the texture's dominant
//! *line* orientation is perpendicular to it. Used to measure that a synthesised
//! texture follows the field, and to find an exemplar's own orientation.

/// Dominant line orientation of a `width × height` row-major scalar image: the angle
/// (radians in `[0, π)`, from `+x` towards `+y`, image axes) along which lines run,
/// and the coherence `(λ₁ − λ₂)/(λ₁ + λ₂)` in `[0, 1]` (0: isotropic). `None` for
/// images smaller than 3 × 3 or without gradient.
pub fn dominant_orientation(values: &[f32], width: usize, height: usize) -> Option<(f64, f64)> {
    if width < 3 || height < 3 || values.len() != width * height {
        return None;
    }
    let (mut jxx, mut jxy, mut jyy) = (0.0f64, 0.0f64, 0.0f64);
    for y in 1..height - 1 {
        for x in 1..width - 1 {
            let at = |x: usize, y: usize| values[y * width + x] as f64;
            let gx = 0.5 * (at(x + 1, y) - at(x - 1, y));
            let gy = 0.5 * (at(x, y + 1) - at(x, y - 1));
            jxx += gx * gx;
            jxy += gx * gy;
            jyy += gy * gy;
        }
    }
    let trace = jxx + jyy;
    if trace.is_nan() || trace <= 0.0 {
        return None;
    }
    // Angle of the gradient direction, then rotate by 90° for the line direction.
    let gradient_angle = 0.5 * (2.0 * jxy).atan2(jxx - jyy);
    let line = (gradient_angle + std::f64::consts::FRAC_PI_2).rem_euclid(std::f64::consts::PI);
    let coherence = ((jxx - jyy).powi(2) + 4.0 * jxy * jxy).sqrt() / trace;
    Some((line, coherence))
}

/// Smallest angle between two line orientations (radians, modulo π), in `[0, π/2]`.
pub fn line_angle_difference(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::PI);
    d.min(std::f64::consts::PI - d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn horizontal_and_diagonal_lines() {
        let (w, h) = (32, 32);
        let horiz: Vec<f32> = (0..w * h).map(|i| ((i / w) as f32 * 0.8).sin()).collect();
        let (a, c) = dominant_orientation(&horiz, w, h).unwrap();
        assert!(line_angle_difference(a, 0.0) < 1e-6, "{a}");
        assert!(c > 0.99);
        let diag: Vec<f32> = (0..w * h).map(|i| (((i % w) + (i / w)) as f32 * 0.7).sin()).collect();
        let (a, _) = dominant_orientation(&diag, w, h).unwrap();
        assert!(line_angle_difference(a, 3.0 * std::f64::consts::FRAC_PI_4) < 1e-6, "{a}");
        assert!(dominant_orientation(&vec![1.0; w * h], w, h).is_none());
    }
}
