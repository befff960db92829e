//! Drawing markers and lines on a 2-D image (texture previews: singularities marked
//! on a synthesised texture, an orientation field drawn as short segments).
//!
//! Coordinates are continuous pixel coordinates of the image: x to the right, y
//! downward, pixel `(i, j)` covering `[i, i+1) × [j, j+1)` (centre at `i + 0.5`).
//! Blending is done on the sRGB-encoded values (straight alpha), anti-aliased by
//! coverage.

use crate::draw2d::{blend, fill_sdf, marker_sdf, segment_distance};
use crate::scene::{MarkerShape, marker_style_setters};
use fieldtex_core::Image;

/// A 2-D polyline on an image (width in pixels of the output image).
pub type Polyline2 = crate::scene::Polyline<2>;

/// A 2-D marker.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker2 {
    pub position: [f64; 2],
    pub shape: MarkerShape,
    /// Radius in pixels of the output image.
    pub radius: f64,
    pub color: [f32; 4],
    /// 1-px outline colour.
    pub outline: Option<[f32; 4]>,
}

impl Marker2 {
    /// Red disc of radius 5 px with a black outline.
    pub fn new(position: [f64; 2]) -> Self {
        Self {
            position,
            shape: MarkerShape::Disc,
            radius: 5.0,
            color: [0.9, 0.1, 0.1, 1.0],
            outline: Some([0.0, 0.0, 0.0, 1.0]),
        }
    }
    marker_style_setters!();
}

/// What [`render_image_overlay`] draws: polylines first, then markers.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ImageOverlay {
    pub polylines: Vec<Polyline2>,
    pub markers: Vec<Marker2>,
}

/// Options of [`render_image_overlay`].
#[derive(Debug, Clone, PartialEq)]
pub struct ImageOverlayOptions {
    /// Integer enlargement of the image before drawing (so that markers stay crisp on
    /// small textures). Default 1; clamped to 1..=16.
    pub scale: usize,
    /// Enlarge bilinearly instead of by pixel replication. Default false.
    pub smooth: bool,
}

impl Default for ImageOverlayOptions {
    fn default() -> Self {
        Self { scale: 1, smooth: false }
    }
}

/// A copy of `image`, enlarged `options.scale` times, with `overlay` drawn on it.
/// Overlay positions are in the pixel coordinates of the **input** image (they are
/// scaled); widths and radii are in pixels of the **output**.
pub fn render_image_overlay(
    image: &Image,
    overlay: &ImageOverlay,
    options: &ImageOverlayOptions,
) -> Image {
    let s = options.scale.clamp(1, 16);
    let mut out = if s == 1 {
        image.clone()
    } else {
        let (w, h) = (image.width * s, image.height * s);
        let mut o = Image::new(w, h, [0.0; 4]);
        if image.width > 0 && image.height > 0 {
            for y in 0..h {
                for x in 0..w {
                    let c = if options.smooth {
                        image.sample_bilinear(
                            (x as f64 + 0.5) / s as f64,
                            (y as f64 + 0.5) / s as f64,
                        )
                    } else {
                        image.get(x / s, y / s)
                    };
                    o.set(x, y, c);
                }
            }
        }
        o
    };
    let sf = s as f64;
    let scale_pt = |p: [f64; 2]| [p[0] * sf, p[1] * sf];
    for l in &overlay.polylines {
        let pts: Vec<[f64; 2]> = l.points.iter().map(|&p| scale_pt(p)).collect();
        draw_polyline(&mut out, &pts, l.closed, l.color, l.width);
    }
    for m in &overlay.markers {
        draw_marker(&mut out, scale_pt(m.position), m.shape, m.radius, m.color, m.outline);
    }
    out
}

/// Draws a polyline of `width` pixels; non-finite points break it.
pub fn draw_polyline(
    image: &mut Image,
    points: &[[f64; 2]],
    closed: bool,
    color: [f32; 4],
    width: f64,
) {
    let r = 0.5 * width;
    if r.is_nan() || r <= 0.0 || points.len() < 2 {
        return;
    }
    let n = points.len();
    let n_seg = if closed { n } else { n - 1 };
    for i in 0..n_seg {
        draw_segment(image, points[i], points[(i + 1) % n], r, color);
    }
}

fn draw_segment(image: &mut Image, a: [f64; 2], b: [f64; 2], r: f64, color: [f32; 4]) {
    let bbox = [a[0].min(b[0]) - r, a[1].min(b[1]) - r, a[0].max(b[0]) + r, a[1].max(b[1]) + r];
    let (w, h) = (image.width, image.height);
    // Bound the work for absurd coordinates.
    if !(bbox[2] - bbox[0] < 4.0 * (w + h) as f64 && bbox[3] - bbox[1] < 4.0 * (w + h) as f64) {
        return;
    }
    let px = &mut image.pixels;
    fill_sdf(
        w,
        h,
        bbox,
        |p| segment_distance(p, a, b).0 - r,
        |x, y, c| blend(&mut px[y * w + x], color, c),
    );
}

/// Draws one marker centred at `center` with radius `radius` pixels.
pub fn draw_marker(
    image: &mut Image,
    center: [f64; 2],
    shape: MarkerShape,
    radius: f64,
    color: [f32; 4],
    outline: Option<[f32; 4]>,
) {
    if !(radius > 0.0 && radius < 1e4) {
        return;
    }
    let reach = 1.5 * radius + 1.0;
    let bbox = [center[0] - reach, center[1] - reach, center[0] + reach, center[1] + reach];
    let (w, h) = (image.width, image.height);
    let px = &mut image.pixels;
    let sdf = |p: [f64; 2]| marker_sdf(shape, radius, [p[0] - center[0], p[1] - center[1]]);
    if let Some(o) = outline {
        fill_sdf(w, h, bbox, |p| sdf(p) - 1.0, |x, y, c| blend(&mut px[y * w + x], o, c));
    }
    fill_sdf(w, h, bbox, sdf, |x, y, c| blend(&mut px[y * w + x], color, c));
}

/// Short centred segments showing an orientation field `H×W×2` (`[row, col] =
/// (dx, dy)`, pixel coordinates, y down), one every `spacing` pixels, `length` pixels
/// long (input-image units), for [`ImageOverlay::polylines`]. Zero or non-finite
/// vectors are skipped; a field of the wrong length gives no glyphs.
pub fn orientation_glyphs(
    field: &[f32],
    width: usize,
    height: usize,
    spacing: usize,
    length: f64,
    color: [f32; 4],
    line_width: f64,
) -> Vec<Polyline2> {
    let mut out = Vec::new();
    if field.len() != width * height * 2 || spacing == 0 {
        return out;
    }
    let half = spacing / 2;
    for y in (half..height).step_by(spacing) {
        for x in (half..width).step_by(spacing) {
            let i = 2 * (y * width + x);
            let (dx, dy) = (field[i] as f64, field[i + 1] as f64);
            let n = (dx * dx + dy * dy).sqrt();
            if !(n > 0.0 && n.is_finite()) {
                continue;
            }
            let (ux, uy) = (0.5 * length * dx / n, 0.5 * length * dy / n);
            let c = [x as f64 + 0.5, y as f64 + 0.5];
            out.push(Polyline2 {
                points: vec![[c[0] - ux, c[1] - uy], [c[0] + ux, c[1] + uy]],
                closed: false,
                color,
                width: line_width,
            });
        }
    }
    out
}
