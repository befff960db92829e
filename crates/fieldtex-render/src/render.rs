//! The entry point: [`render`] a [`Scene`] to an [`Image`].

use crate::camera::Camera;
use crate::overlay3d::OverlayPainter;
use crate::rasterize_mesh::{Frame, rasterize_mesh};
use crate::scene::{Overlay, RenderOptions, Scene};
use crate::srgb_lut::to_srgb;
use fieldtex_core::Image;
use fieldtex_core::vec3::{V3, is_finite, norm, sub};
use fieldtex_mesh::Aabb;
use rayon::prelude::*;

/// Bounding sphere (centre of the bounding box, largest distance to it) of the
/// mesh's finite positions, or else of the overlays' points; with the box diagonal.
fn scene_bounds(scene: &Scene) -> Option<(V3, f64, f64)> {
    let finite = |p: &&V3| is_finite(**p);
    if let Some(b) = scene.mesh.bounding_box() {
        let c = b.center();
        let r = scene
            .mesh
            .positions
            .iter()
            .filter(finite)
            .map(|&p| norm(sub(p, c)))
            .fold(0.0, f64::max);
        return Some((c, r, b.diagonal()));
    }
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    let mut any = false;
    let mut add = |p: &[f64; 3]| {
        if p.iter().all(|v| v.is_finite()) {
            any = true;
            for k in 0..3 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        }
    };
    for o in &scene.overlays {
        match o {
            Overlay::Polyline(p) => p.points.iter().for_each(&mut add),
            Overlay::Glyphs(g) => g.positions.iter().for_each(&mut add),
            Overlay::Markers(m) => m.positions.iter().for_each(&mut add),
        }
    }
    if !any {
        return None;
    }
    let b = Aabb { min, max };
    let c = b.center();
    let r = 0.5 * b.diagonal();
    Some((c, r, b.diagonal()))
}

/// The camera [`render`] uses for `scene`, in **output** pixel units (`size × size`),
/// so callers can place labels with [`Camera::project`]. `None` when the scene has no
/// finite point (then `render` returns the background).
pub fn scene_camera(scene: &Scene, options: &RenderOptions) -> Option<Camera> {
    let opts = options.validated();
    scene_bounds(scene).map(|(c, r, _)| Camera::framing(c, r, opts.size, &opts))
}

/// Renders `scene` as seen with `options`: a square sRGB RGBA image of
/// `options.size` pixels, top row first.
///
/// Perspective camera on the bounding sphere of the mesh (or of the overlays when the
/// mesh has no finite vertex), z-buffered triangles shaded two-sided with Lambert plus
/// ambient in linear light, `supersample²` samples per pixel box-filtered down, then
/// overlays drawn in order with a depth test. Never panics on bad meshes: triangles
/// with out-of-range indices or non-finite corners are skipped, and an empty or
/// entirely non-finite scene gives the background. Deterministic for any number of
/// rayon threads.
///
/// Not implemented: texture mip-mapping (minified textures can alias beyond what the
/// supersampling removes), shadows, transparency of the mesh itself.
pub fn render(scene: &Scene, options: &RenderOptions) -> Image {
    let opts = options.validated();
    let size = opts.size;
    let ss = opts.supersample;
    let Some((center, radius, diagonal)) = scene_bounds(scene) else {
        return Image::new(size, size, opts.background);
    };
    let width = size * ss;
    let camera = Camera::framing(center, radius, width, &opts);
    let mut frame = rasterize_mesh(scene, &camera, width, &opts);
    let diagonal = if diagonal > 0.0 { diagonal } else { 2.0 * camera.radius };
    let painter = OverlayPainter {
        camera: &camera,
        ss: ss as f64,
        bias: opts.depth_bias * diagonal,
        diagonal,
    };
    painter.draw(&mut frame, &scene.overlays);
    downsample(&frame, ss)
}

/// Box-filters `ss × ss` linear samples into one sRGB pixel.
fn downsample(frame: &Frame, ss: usize) -> Image {
    let size = frame.width / ss;
    let mut out = Image::new(size, size, [0.0; 4]);
    let norm = 1.0 / (ss * ss) as f32;
    out.pixels.par_chunks_mut(size).enumerate().for_each(|(y, row)| {
        for (x, px) in row.iter_mut().enumerate() {
            let mut acc = [0.0f32; 4];
            for sy in 0..ss {
                let base = (y * ss + sy) * frame.width + x * ss;
                for s in &frame.color[base..base + ss] {
                    for k in 0..4 {
                        acc[k] += s[k];
                    }
                }
            }
            *px = [
                to_srgb(acc[0] * norm),
                to_srgb(acc[1] * norm),
                to_srgb(acc[2] * norm),
                (acc[3] * norm).clamp(0.0, 1.0),
            ];
        }
    });
    out
}
