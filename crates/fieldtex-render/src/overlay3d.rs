//! Overlays over the shaded mesh: 3-D polylines, field glyphs and markers, drawn in
//! order into the supersampled frame with a depth test against the surface.
//!
//! An overlay fragment at view depth `z` shows where `z ≤ z_surface + bias`, with
//! `bias = depth_bias · diagonal + r_world`, `r_world` being the half-width of the
//! stroke (or marker radius) in world units at that depth: lines lying on a surface
//! seen at up to 45° stay whole. Overlays do not write depth.

use crate::camera::Camera;
use crate::draw2d::{blend, fill_sdf, marker_sdf, segment_distance};
use crate::rasterize_mesh::Frame;
use crate::scene::{FieldGlyphs, GlyphStyle, Markers, Overlay, Polyline3};
use fieldtex_core::image::srgb_to_linear;
use fieldtex_core::vec3::{V3, add, is_finite, lerp, normalize, scale};

/// Context shared by all overlay drawing.
pub(crate) struct OverlayPainter<'a> {
    pub camera: &'a Camera,
    /// Supersampling factor (samples per output pixel along an axis).
    pub ss: f64,
    /// Constant part of the depth bias (world units).
    pub bias: f64,
    /// Diagonal of the framed bounding box (world units).
    pub diagonal: f64,
}

fn to_linear(c: [f32; 4]) -> [f32; 4] {
    let f = |v: f32| srgb_to_linear(if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 });
    [f(c[0]), f(c[1]), f(c[2]), if c[3].is_finite() { c[3].clamp(0.0, 1.0) } else { 1.0 }]
}

impl OverlayPainter<'_> {
    pub fn draw(&self, frame: &mut Frame, overlays: &[Overlay]) {
        for o in overlays {
            match o {
                Overlay::Polyline(p) => self.polyline(frame, p),
                Overlay::Glyphs(g) => self.glyphs(frame, g),
                Overlay::Markers(m) => self.markers(frame, m),
            }
        }
    }

    /// World size of one sample at view depth `z`.
    fn world_per_sample(&self, z: f64) -> f64 {
        z / (self.camera.focal * 0.5 * self.camera.width)
    }

    fn polyline(&self, frame: &mut Frame, p: &Polyline3) {
        let radius = 0.5 * p.width.max(0.0) * self.ss;
        if radius.is_nan() || radius <= 0.0 || p.points.len() < 2 {
            return;
        }
        let color = to_linear(p.color);
        let n = p.points.len();
        let n_seg = if p.closed { n } else { n - 1 };
        for i in 0..n_seg {
            let (a, b) = (p.points[i], p.points[(i + 1) % n]);
            self.segment(frame, a, b, radius, color);
        }
    }

    /// A depth-tested capsule of `radius` samples between world points `a` and `b`.
    fn segment(&self, frame: &mut Frame, a: V3, b: V3, radius: f64, color: [f32; 4]) {
        if !is_finite(a) || !is_finite(b) {
            return;
        }
        let cam = self.camera;
        let (mut va, mut vb) = (cam.to_view(a), cam.to_view(b));
        // Clip against the near plane.
        if va[2] < cam.near && vb[2] < cam.near {
            return;
        }
        if va[2] < cam.near {
            va = lerp(va, vb, (cam.near - va[2]) / (vb[2] - va[2]));
        } else if vb[2] < cam.near {
            vb = lerp(vb, va, (cam.near - vb[2]) / (va[2] - vb[2]));
        }
        let (sa, sb) = (cam.view_to_screen(va), cam.view_to_screen(vb));
        let (ia, ib) = (1.0 / va[2], 1.0 / vb[2]);
        let bbox = [
            sa[0].min(sb[0]) - radius,
            sa[1].min(sb[1]) - radius,
            sa[0].max(sb[0]) + radius,
            sa[1].max(sb[1]) + radius,
        ];
        self.fill_depth_tested(
            frame,
            bbox,
            |p| {
                let (d, t) = segment_distance(p, sa, sb);
                (d - radius, 1.0 / ((1.0 - t) * ia + t * ib))
            },
            radius,
            color,
            true,
        );
    }

    /// Fills the shape `f(p) = (signed distance, depth)` with a depth test.
    fn fill_depth_tested(
        &self,
        frame: &mut Frame,
        bbox: [f64; 4],
        f: impl Fn([f64; 2]) -> (f64, f64),
        radius: f64,
        color: [f32; 4],
        depth_test: bool,
    ) {
        let w = frame.width;
        // Refuse absurd boxes (points very close to the near plane) to bound the work.
        let max_extent = 4.0 * w as f64;
        if !(bbox[2] - bbox[0] < max_extent && bbox[3] - bbox[1] < max_extent) {
            return;
        }
        let Frame { color: buf, depth, .. } = frame;
        fill_sdf(
            w,
            w,
            bbox,
            |p| f(p).0,
            |x, y, cov| {
                let i = y * w + x;
                if depth_test {
                    let z = f([x as f64 + 0.5, y as f64 + 0.5]).1;
                    let bias = self.bias + radius * self.world_per_sample(z);
                    if z > depth[i] as f64 + bias {
                        return;
                    }
                }
                blend(&mut buf[i], color, cov);
            },
        );
    }

    fn glyphs(&self, frame: &mut Frame, g: &FieldGlyphs) {
        let radius = 0.5 * g.width.max(0.0) * self.ss;
        if radius.is_nan() || radius <= 0.0 {
            return;
        }
        let len = match g.length {
            Some(l) if l.is_finite() && l > 0.0 => l,
            _ => 0.02 * self.diagonal,
        };
        let color = to_linear(g.color);
        for (&p, &d) in g.positions.iter().zip(&g.directions) {
            let (Some(d), true) = (normalize(d), is_finite(p)) else { continue };
            match g.style {
                GlyphStyle::Segment => {
                    self.segment(
                        frame,
                        add(p, scale(d, -0.5 * len)),
                        add(p, scale(d, 0.5 * len)),
                        radius,
                        color,
                    );
                }
                GlyphStyle::Arrow => {
                    let tip = add(p, scale(d, len));
                    self.segment(frame, p, tip, radius, color);
                    self.arrow_head(frame, p, tip, radius, color);
                }
            }
        }
    }

    /// Two short strokes at `tip`, drawn in screen space at the tip's depth.
    fn arrow_head(&self, frame: &mut Frame, tail: V3, tip: V3, radius: f64, color: [f32; 4]) {
        let (Some((st, _)), Some((sh, zh))) = (self.camera.project(tail), self.camera.project(tip))
        else {
            return;
        };
        let (dx, dy) = (sh[0] - st[0], sh[1] - st[1]);
        let len = (dx * dx + dy * dy).sqrt();
        if len.is_nan() || len <= 2.0 * radius {
            return;
        }
        let (ux, uy) = (dx / len, dy / len);
        let hl = (0.35 * len).max(3.0 * radius);
        let (c, s) = (25f64.to_radians().cos(), 25f64.to_radians().sin());
        for sign in [-1.0, 1.0] {
            let (rx, ry) = (ux * c - sign * uy * s, sign * ux * s + uy * c);
            let end = [sh[0] - hl * rx, sh[1] - hl * ry];
            let bbox = [
                sh[0].min(end[0]) - radius,
                sh[1].min(end[1]) - radius,
                sh[0].max(end[0]) + radius,
                sh[1].max(end[1]) + radius,
            ];
            self.fill_depth_tested(
                frame,
                bbox,
                |p| (segment_distance(p, sh, end).0 - radius, zh),
                radius + hl,
                color,
                true,
            );
        }
    }

    fn markers(&self, frame: &mut Frame, m: &Markers) {
        let r = m.radius.max(0.0) * self.ss;
        if r.is_nan() || r <= 0.0 {
            return;
        }
        let outline_w = self.ss;
        let fill = to_linear(m.color);
        for &p in &m.positions {
            let Some((c, z)) = self.camera.project(p) else { continue };
            let reach = 1.5 * r + outline_w;
            let bbox = [c[0] - reach, c[1] - reach, c[0] + reach, c[1] + reach];
            let sdf = |q: [f64; 2]| marker_sdf(m.shape, r, [q[0] - c[0], q[1] - c[1]]);
            if let Some(o) = m.outline {
                let o = to_linear(o);
                self.fill_depth_tested(
                    frame,
                    bbox,
                    |q| (sdf(q) - outline_w, z),
                    r,
                    o,
                    m.depth_test,
                );
            }
            self.fill_depth_tested(frame, bbox, |q| (sdf(q), z), r, fill, m.depth_test);
        }
    }
}
