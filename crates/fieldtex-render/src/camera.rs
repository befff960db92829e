//! A perspective camera orbiting the scene's bounding sphere.

use crate::scene::{RenderOptions, UpAxis};
use fieldtex_core::vec3::{V3, add, cross, dot, normalize, scale, sub};

/// A pinhole camera looking at the centre of a bounding sphere.
///
/// Screen coordinates are continuous pixel coordinates of a `width × width` raster:
/// x to the right, y downward, pixel `(i, j)` covering `[i, i+1) × [j, j+1)`.
/// Depth is the distance along the viewing axis (positive in front of the camera).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Eye position (world).
    pub eye: V3,
    /// Unit right, up and forward vectors of the view (world).
    pub right: V3,
    pub up: V3,
    pub forward: V3,
    /// `1 / tan(fov / 2)`.
    pub focal: f64,
    /// Raster width = height in pixels.
    pub width: f64,
    /// Points nearer than this are clipped.
    pub near: f64,
    /// Radius of the framed bounding sphere.
    pub radius: f64,
}

/// Unit vector from the target towards the eye for `(azimuth°, elevation°)`, and the
/// world up vector.
fn view_direction(azimuth_deg: f64, elevation_deg: f64, up: UpAxis) -> (V3, V3) {
    let (a, e) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
    match up {
        UpAxis::Y => ([a.sin() * e.cos(), e.sin(), a.cos() * e.cos()], [0.0, 1.0, 0.0]),
        UpAxis::Z => ([a.sin() * e.cos(), -a.cos() * e.cos(), e.sin()], [0.0, 0.0, 1.0]),
    }
}

impl Camera {
    /// Frames the sphere (`center`, `radius`) for a square raster of `width` pixels,
    /// using the view, up axis, field of view and margin of `options` (already
    /// validated). A zero or non-finite radius is replaced by 1.
    pub fn framing(center: V3, radius: f64, width: usize, options: &RenderOptions) -> Self {
        let mut radius = radius;
        if !(radius > 1e-300 && radius.is_finite()) {
            radius = 1.0;
        }
        let half_fov = 0.5 * options.fov_deg.to_radians();
        let dist = options.margin * radius / half_fov.sin();
        let (to_eye, world_up) = view_direction(options.view.0, options.view.1, options.up);
        let eye = add(center, scale(to_eye, dist));
        let forward = scale(to_eye, -1.0);
        let right = normalize(cross(forward, world_up)).unwrap_or([1.0, 0.0, 0.0]);
        let up = cross(right, forward);
        Self {
            eye,
            right,
            up,
            forward,
            focal: 1.0 / half_fov.tan(),
            width: width as f64,
            near: (dist - radius * options.margin.max(1.0)).max(dist * 1e-3),
            radius,
        }
    }

    /// View-space coordinates `(x right, y up, depth)` of a world point.
    #[inline]
    pub fn to_view(&self, p: V3) -> V3 {
        let v = sub(p, self.eye);
        [dot(v, self.right), dot(v, self.up), dot(v, self.forward)]
    }

    /// Screen position of a view-space point (depth must be positive).
    #[inline]
    pub fn view_to_screen(&self, v: V3) -> [f64; 2] {
        let h = 0.5 * self.width;
        [h + v[0] / v[2] * self.focal * h, h - v[1] / v[2] * self.focal * h]
    }

    /// Screen position and depth of a world point, or `None` when it is behind the
    /// near plane or not finite.
    pub fn project(&self, p: V3) -> Option<([f64; 2], f64)> {
        let v = self.to_view(p);
        if v[2].is_nan() || v[2] < self.near || !v[0].is_finite() || !v[1].is_finite() {
            return None;
        }
        Some((self.view_to_screen(v), v[2]))
    }
}
