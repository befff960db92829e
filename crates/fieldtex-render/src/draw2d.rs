//! Anti-aliased 2-D primitives by signed distance.
//!
//! Every shape is a signed distance function `d(p)` in pixels (negative inside). The
//! coverage of the pixel whose centre is `p` is `clamp(0.5 − d(p), 0, 1)`: a one-pixel
//! linear ramp across the boundary, which is what a box filter gives for a straight
//! edge. Pixel `(i, j)` has its centre at `(i + 0.5, j + 0.5)`.

use crate::scene::MarkerShape;

/// Distance from `p` to segment `ab` and the parameter `t ∈ [0, 1]` of the nearest
/// point.
#[inline]
pub(crate) fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> (f64, f64) {
    let (abx, aby) = (b[0] - a[0], b[1] - a[1]);
    let (apx, apy) = (p[0] - a[0], p[1] - a[1]);
    let len2 = abx * abx + aby * aby;
    let t = if len2 > 0.0 { ((apx * abx + apy * aby) / len2).clamp(0.0, 1.0) } else { 0.0 };
    let (dx, dy) = (apx - t * abx, apy - t * aby);
    ((dx * dx + dy * dy).sqrt(), t)
}

/// Coverage of a pixel whose centre has signed distance `d` to a shape.
#[inline]
pub(crate) fn coverage(d: f64) -> f32 {
    (0.5 - d).clamp(0.0, 1.0) as f32
}

/// Calls `plot(x, y, coverage)` for every pixel of a `width × height` raster inside
/// the box `[x0, x1] × [y0, y1]` (expanded by one pixel) with positive coverage of
/// the shape `sdf`. Boxes that are not finite are ignored.
pub(crate) fn fill_sdf(
    width: usize,
    height: usize,
    bbox: [f64; 4],
    sdf: impl Fn([f64; 2]) -> f64,
    mut plot: impl FnMut(usize, usize, f32),
) {
    if width == 0 || height == 0 || !bbox.iter().all(|v| v.is_finite()) {
        return;
    }
    let xa = (bbox[0] - 1.0).floor().max(0.0);
    let ya = (bbox[1] - 1.0).floor().max(0.0);
    let xb = (bbox[2] + 1.0).ceil().min(width as f64 - 1.0);
    let yb = (bbox[3] + 1.0).ceil().min(height as f64 - 1.0);
    if xa > xb || ya > yb {
        return;
    }
    for y in ya as usize..=yb as usize {
        for x in xa as usize..=xb as usize {
            let c = coverage(sdf([x as f64 + 0.5, y as f64 + 0.5]));
            if c > 0.0 {
                plot(x, y, c);
            }
        }
    }
}

/// Signed distance of a marker of `shape` and `radius` centred at the origin.
pub(crate) fn marker_sdf(shape: MarkerShape, radius: f64, p: [f64; 2]) -> f64 {
    let r = radius.max(0.5);
    let len = (p[0] * p[0] + p[1] * p[1]).sqrt();
    match shape {
        MarkerShape::Disc => len - r,
        MarkerShape::Ring => {
            let t = (0.3 * r).max(0.75);
            (len - (r - t)).abs() - t
        }
        MarkerShape::Square => p[0].abs().max(p[1].abs()) - 0.85 * r,
        MarkerShape::Triangle | MarkerShape::TriangleDown => {
            // Equilateral triangle with circumradius 1.2 r; y grows downward, so the
            // apex of the upward triangle has negative y.
            let y = if shape == MarkerShape::Triangle { p[1] } else { -p[1] };
            let big_r = 1.2 * r;
            let s3 = 0.5 * 3f64.sqrt();
            let d1 = y; // bottom edge, outward normal (0, 1)
            let d2 = -s3 * p[0] - 0.5 * y; // upper-left edge
            let d3 = s3 * p[0] - 0.5 * y; // upper-right edge
            d1.max(d2).max(d3) - 0.5 * big_r
        }
        MarkerShape::Cross | MarkerShape::Plus => {
            let t = (0.22 * r).max(0.6);
            let (a, b) = if shape == MarkerShape::Plus {
                (([-r, 0.0], [r, 0.0]), ([0.0, -r], [0.0, r]))
            } else {
                let h = r * std::f64::consts::FRAC_1_SQRT_2;
                (([-h, -h], [h, h]), ([-h, h], [h, -h]))
            };
            let d1 = segment_distance(p, a.0, a.1).0;
            let d2 = segment_distance(p, b.0, b.1).0;
            d1.min(d2) - t
        }
    }
}

/// Blends `src` (straight alpha) over `dst` with extra coverage `cov`.
#[inline]
pub(crate) fn blend(dst: &mut [f32; 4], src: [f32; 4], cov: f32) {
    let a = (src[3] * cov).clamp(0.0, 1.0);
    for k in 0..3 {
        dst[k] += (src[k] - dst[k]) * a;
    }
    dst[3] += (1.0 - dst[3]) * a;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disc_coverage_area_matches() {
        let mut area = 0.0f64;
        fill_sdf(
            64,
            64,
            [22.0, 22.0, 42.0, 42.0],
            |p| marker_sdf(MarkerShape::Disc, 10.0, [p[0] - 32.0, p[1] - 32.0]),
            |_, _, c| area += c as f64,
        );
        let expected = std::f64::consts::PI * 100.0;
        assert!((area - expected).abs() / expected < 0.01, "{area} vs {expected}");
    }

    #[test]
    fn segment_distance_endpoints() {
        let (d, t) = segment_distance([5.0, 1.0], [0.0, 0.0], [10.0, 0.0]);
        assert!((d - 1.0).abs() < 1e-12 && (t - 0.5).abs() < 1e-12);
        let (d, t) = segment_distance([-3.0, 4.0], [0.0, 0.0], [10.0, 0.0]);
        assert!((d - 5.0).abs() < 1e-12 && t == 0.0);
    }
}
