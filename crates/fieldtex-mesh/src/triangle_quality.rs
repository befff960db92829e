//! Shape measures of single triangles used by inspection and repair: area and the
//! smallest interior angle, computed robustly for needles and caps.
//!
//! Angles use `atan2(|a × b|, a · b)`, which stays accurate near 0 and π where
//! `acos` of a normalised dot product loses all digits. A corner with a zero-length
//! edge gets angle 0.

use fieldtex_core::vec3::{cross, dot, norm, sub};

/// Default zero-area tolerance: a triangle is *zero-area* when its area is at most
/// this times the squared bounding-box diagonal. `1e-12` is about a triangle with
/// edges of `1e-6` diagonals, far below any meaningful feature and a few thousand
/// rounding errors above exact zero for coordinates of the size of the box.
pub const DEFAULT_ZERO_AREA_RELATIVE: f64 = 1e-12;

/// Default sliver threshold in degrees: a triangle with a smallest angle below this
/// (and not zero-area) is a *sliver*. 1° corresponds to an aspect ratio of about 57.
pub const DEFAULT_SLIVER_MIN_ANGLE_DEG: f64 = 1.0;

/// Area of a triangle (NaN when a corner is not finite).
#[inline]
pub fn triangle_area(p: &[[f64; 3]; 3]) -> f64 {
    0.5 * norm(cross(sub(p[1], p[0]), sub(p[2], p[0])))
}

/// Smallest interior angle in radians (NaN when a corner is not finite).
#[inline]
pub fn triangle_min_angle(p: &[[f64; 3]; 3]) -> f64 {
    let mut m = f64::INFINITY;
    for i in 0..3 {
        let a = sub(p[(i + 1) % 3], p[i]);
        let b = sub(p[(i + 2) % 3], p[i]);
        let ang = norm(cross(a, b)).atan2(dot(a, b));
        if ang.is_nan() {
            return f64::NAN;
        }
        m = m.min(ang);
    }
    m
}

/// Signed area of a triangle in the plane (positive when counter-clockwise).
#[inline]
pub fn signed_area_2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
}

/// Six times the signed volume of the tetrahedron (origin, a, b, c); summed over a
/// closed, consistently oriented surface it is six times the enclosed volume, positive
/// when the triangles face outward.
#[inline]
pub fn signed_volume6(p: &[[f64; 3]; 3]) -> f64 {
    dot(p[0], cross(p[1], p[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn right_triangle() {
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert!((triangle_area(&p) - 0.5).abs() < 1e-15);
        assert!((triangle_min_angle(&p) - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
        let needle = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1e-12, 0.0]];
        assert!(triangle_min_angle(&needle) > 0.0 && triangle_min_angle(&needle) < 1e-11);
        let collapsed = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        assert_eq!(triangle_area(&collapsed), 0.0);
        assert_eq!(triangle_min_angle(&collapsed), 0.0);
        assert!(signed_area_2d([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]) > 0.0);
    }
}
