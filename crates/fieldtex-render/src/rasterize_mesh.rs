//! Z-buffered triangle rasterisation with deferred shading, parallel over row bands.
//!
//! Triangles are binned by the bands of `BAND` raster rows their screen box touches
//! (in triangle order); each band is then rasterised independently by one rayon task,
//! keeping for every sample the nearest triangle (ties: the lower triangle index) and
//! its perspective-correct barycentric coordinates. Shading runs once per visible
//! sample afterwards. The result does not depend on the number of threads.

use crate::camera::Camera;
use crate::scene::{Light, RenderOptions, Scene, Shading};
use crate::srgb_lut::to_linear;
use fieldtex_core::Image;
use fieldtex_core::vec3::{V3, add, cross, dot, normalize, scale, sub};
use rayon::prelude::*;

/// Raster rows per band.
const BAND: usize = 8;

/// The supersampled frame: linear RGBA colour and view depth per sample.
pub(crate) struct Frame {
    pub width: usize,
    pub color: Vec<[f32; 4]>,
    /// View depth of the visible surface, `f32::INFINITY` where there is none.
    pub depth: Vec<f32>,
}

/// A projected vertex: screen position (samples) and reciprocal depth.
#[derive(Clone, Copy)]
struct Projected {
    s: [f64; 2],
    inv_z: f64,
}

/// Per-triangle data valid for rasterisation.
struct Tri {
    p: [Projected; 3],
}

/// Visible surface at one sample.
#[derive(Clone, Copy)]
struct Hit {
    tri: u32,
    /// Perspective-correct barycentrics of corners 1 and 2.
    b: [f32; 2],
}

const NO_HIT: u32 = u32::MAX;

/// Area-weighted vertex normals; vertices of no valid triangle get `[0, 0, 0]`.
fn vertex_normals(positions: &[V3], triangles: &[[u32; 3]], valid: &[bool]) -> Vec<V3> {
    let mut n = vec![[0.0; 3]; positions.len()];
    for (t, ok) in triangles.iter().zip(valid) {
        if !ok {
            continue;
        }
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let fnrm = cross(sub(b, a), sub(c, a));
        for &i in t {
            n[i as usize] = add(n[i as usize], fnrm);
        }
    }
    for v in &mut n {
        *v = normalize(*v).unwrap_or([0.0; 3]);
    }
    n
}

/// Bilinear texture lookup with repeat wrapping; `uv` with v = 0 at the bottom row.
fn sample_texture(tex: &Image, uv: [f64; 2]) -> [f32; 4] {
    if tex.width == 0 || tex.height == 0 || !(uv[0].is_finite() && uv[1].is_finite()) {
        return [1.0, 0.0, 1.0, 1.0];
    }
    let x = uv[0] * tex.width as f64 - 0.5;
    let y = (1.0 - uv[1]) * tex.height as f64 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (tx, ty) = ((x - x0) as f32, (y - y0) as f32);
    // Reduce first so huge UVs cannot overflow the integer conversion.
    let (w, h) = (tex.width as f64, tex.height as f64);
    let (x0, y0) = (x0.rem_euclid(w) as i64, y0.rem_euclid(h) as i64);
    let a = tex.get_wrapped(x0, y0);
    let b = tex.get_wrapped(x0 + 1, y0);
    let c = tex.get_wrapped(x0, y0 + 1);
    let d = tex.get_wrapped(x0 + 1, y0 + 1);
    fieldtex_core::image::bilerp([a, b, c, d], tx, ty)
}

/// Rasterises and shades the mesh of `scene` into a `width × width` sample frame.
pub(crate) fn rasterize_mesh(
    scene: &Scene,
    camera: &Camera,
    width: usize,
    options: &RenderOptions,
) -> Frame {
    let mesh = scene.mesh;
    let nv = mesh.positions.len();
    let background = {
        let b = options.background;
        [to_linear(b[0]), to_linear(b[1]), to_linear(b[2]), b[3]]
    };
    let mut frame = Frame {
        width,
        color: vec![background; width * width],
        depth: vec![f32::INFINITY; width * width],
    };

    let projected: Vec<Option<Projected>> = mesh
        .positions
        .par_iter()
        .map(|&p| camera.project(p).map(|(s, z)| Projected { s, inv_z: 1.0 / z }))
        .collect();

    // Valid triangles: indices in range, all corners projected, non-zero screen area.
    let tris: Vec<Option<Tri>> = mesh
        .triangles
        .par_iter()
        .map(|t| {
            if t.iter().any(|&i| i as usize >= nv) {
                return None;
            }
            let p =
                [projected[t[0] as usize]?, projected[t[1] as usize]?, projected[t[2] as usize]?];
            let area = edge(p[0].s, p[1].s, p[2].s);
            (area.is_finite() && area.abs() > 1e-12).then_some(Tri { p })
        })
        .collect();
    let valid: Vec<bool> = mesh
        .triangles
        .iter()
        .map(|t| {
            t.iter().all(|&i| {
                (i as usize) < nv && fieldtex_core::vec3::is_finite(mesh.positions[i as usize])
            })
        })
        .collect();
    let normals = match options.shading {
        Shading::Smooth => vertex_normals(&mesh.positions, &mesh.triangles, &valid),
        _ => Vec::new(),
    };

    // Bin triangles into bands, in triangle order.
    let n_bands = width.div_ceil(BAND);
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); n_bands];
    for (f, t) in tris.iter().enumerate() {
        let Some(t) = t else { continue };
        let ymin = t.p.iter().map(|p| p.s[1]).fold(f64::INFINITY, f64::min);
        let ymax = t.p.iter().map(|p| p.s[1]).fold(f64::NEG_INFINITY, f64::max);
        let xmin = t.p.iter().map(|p| p.s[0]).fold(f64::INFINITY, f64::min);
        let xmax = t.p.iter().map(|p| p.s[0]).fold(f64::NEG_INFINITY, f64::max);
        if ymax < 0.0 || xmax < 0.0 || ymin > width as f64 || xmin > width as f64 {
            continue;
        }
        let b0 = (ymin.max(0.0) as usize / BAND).min(n_bands - 1);
        let b1 = (ymax.min(width as f64 - 1.0).max(0.0) as usize / BAND).min(n_bands - 1);
        for bin in &mut bins[b0..=b1] {
            bin.push(f as u32);
        }
    }

    let light = match options.light {
        Light::Headlight => normalize(add(
            add(scale(camera.forward, -1.0), scale(camera.up, 0.6)),
            scale(camera.right, -0.45),
        ))
        .unwrap_or(scale(camera.forward, -1.0)),
        Light::Key { direction } => normalize(direction).unwrap_or(scale(camera.forward, -1.0)),
    };
    let shader = Shader { scene, camera, options, normals: &normals, light };

    frame
        .color
        .par_chunks_mut(BAND * width)
        .zip(frame.depth.par_chunks_mut(BAND * width))
        .enumerate()
        .for_each(|(band, (color, depth))| {
            let y0 = band * BAND;
            let rows = color.len() / width;
            let mut hits = vec![Hit { tri: NO_HIT, b: [0.0; 2] }; rows * width];
            for &f in &bins[band] {
                let t = tris[f as usize].as_ref().expect("binned triangles are valid");
                raster_triangle(t, f, y0, rows, width, depth, &mut hits);
            }
            for (i, h) in hits.iter().enumerate() {
                if h.tri != NO_HIT {
                    color[i] = shader.shade(h.tri as usize, h.b);
                }
            }
        });
    frame
}

/// Twice the signed area of the screen triangle `abc`.
#[inline]
fn edge(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Rasterises triangle `f` into the band starting at raster row `y0`.
fn raster_triangle(
    t: &Tri,
    f: u32,
    y0: usize,
    rows: usize,
    width: usize,
    depth: &mut [f32],
    hits: &mut [Hit],
) {
    let [p0, p1, p2] = t.p;
    let area = edge(p0.s, p1.s, p2.s);
    let inv_area = 1.0 / area;
    let xmin = p0.s[0].min(p1.s[0]).min(p2.s[0]);
    let xmax = p0.s[0].max(p1.s[0]).max(p2.s[0]);
    let ymin = p0.s[1].min(p1.s[1]).min(p2.s[1]);
    let ymax = p0.s[1].max(p1.s[1]).max(p2.s[1]);
    // Samples at centres c = i + 0.5 with xmin <= c <= xmax.
    let xa = (xmin - 0.5).ceil().max(0.0) as usize;
    let xb = ((xmax - 0.5).floor().min(width as f64 - 1.0)).max(-1.0);
    let ya = ((ymin - 0.5).ceil().max(y0 as f64)) as usize;
    let yb = (ymax - 0.5).floor().min((y0 + rows) as f64 - 1.0);
    if xb < 0.0 || yb < ya as f64 {
        return;
    }
    let (xb, yb) = (xb as usize, yb as usize);
    for y in ya..=yb {
        let sy = y as f64 + 0.5;
        let row = (y - y0) * width;
        for x in xa..=xb {
            let s = [x as f64 + 0.5, sy];
            let l0 = edge(p1.s, p2.s, s) * inv_area;
            let l1 = edge(p2.s, p0.s, s) * inv_area;
            let l2 = edge(p0.s, p1.s, s) * inv_area;
            if l0 < 0.0 || l1 < 0.0 || l2 < 0.0 {
                continue;
            }
            let q0 = l0 * p0.inv_z;
            let q1 = l1 * p1.inv_z;
            let q2 = l2 * p2.inv_z;
            let sum = q0 + q1 + q2;
            let z = (1.0 / sum) as f32;
            let i = row + x;
            if z < depth[i] {
                depth[i] = z;
                hits[i] = Hit { tri: f, b: [(q1 / sum) as f32, (q2 / sum) as f32] };
            }
        }
    }
}

/// Everything shading needs, shared read-only by the band tasks.
struct Shader<'a> {
    scene: &'a Scene<'a>,
    camera: &'a Camera,
    options: &'a RenderOptions,
    normals: &'a [V3],
    light: V3,
}

impl Shader<'_> {
    /// Linear RGBA colour of triangle `f` at perspective-correct barycentrics
    /// `(1 − b1 − b2, b1, b2)`.
    fn shade(&self, f: usize, b: [f32; 2]) -> [f32; 4] {
        let mesh = self.scene.mesh;
        let t = mesh.triangles[f];
        let w = [1.0 - b[0] as f64 - b[1] as f64, b[0] as f64, b[1] as f64];
        let [a, bb, c] = t.map(|i| mesh.positions[i as usize]);
        let p = add(add(scale(a, w[0]), scale(bb, w[1])), scale(c, w[2]));

        // Albedo, sRGB.
        let mut albedo = self.scene.base_color;
        if let (Some(tex), Some(uvs)) = (self.scene.texture, mesh.uvs.as_ref()) {
            if let Some(ti) = uvs.indices.get(f) {
                let uv = ti.map(|i| uvs.values.get(i as usize).copied());
                if let [Some(u0), Some(u1), Some(u2)] = uv {
                    let u = w[0] * u0[0] + w[1] * u1[0] + w[2] * u2[0];
                    let v = w[0] * u0[1] + w[1] * u1[1] + w[2] * u2[1];
                    albedo = sample_texture(tex, [u, v]);
                }
            }
        } else if let Some(vc) = mesh
            .vertex_colors
            .as_ref()
            .filter(|vc| self.scene.use_vertex_colors && vc.len() == mesh.positions.len())
        {
            let cs = t.map(|i| vc[i as usize]);
            for k in 0..4 {
                albedo[k] =
                    (w[0] as f32) * cs[0][k] + (w[1] as f32) * cs[1][k] + (w[2] as f32) * cs[2][k];
            }
        }
        let mut lin = [to_linear(albedo[0]), to_linear(albedo[1]), to_linear(albedo[2])];
        if self.options.shading == Shading::Unlit {
            return [lin[0], lin[1], lin[2], 1.0];
        }

        let face_n = normalize(cross(sub(bb, a), sub(c, a))).unwrap_or(self.camera.forward);
        let to_eye = sub(self.camera.eye, p);
        let front = dot(face_n, to_eye) >= 0.0;
        let mut n = match self.options.shading {
            Shading::Smooth if !self.normals.is_empty() => {
                let ns = t.map(|i| self.normals[i as usize]);
                let s = add(add(scale(ns[0], w[0]), scale(ns[1], w[1])), scale(ns[2], w[2]));
                normalize(s).unwrap_or(face_n)
            }
            _ => face_n,
        };
        if !front {
            n = scale(n, -1.0);
            for c in &mut lin {
                *c *= self.options.backface_factor;
            }
        }
        let ambient = self.options.ambient;
        let k = ambient + (1.0 - ambient) * (dot(n, self.light).max(0.0) as f32);
        [lin[0] * k, lin[1] * k, lin[2] * k, 1.0]
    }
}
