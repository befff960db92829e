//! Baking surface colours into an atlas texture through a [`TexelMap`].
//!
//! Colours are evaluated once per *covered* texel (in parallel over texel rows; each
//! texel's value depends only on its own entry, so the image is identical for any
//! thread count) and copied into the dilated gutter texels from the covered texel each
//! one maps to. Empty texels get the background colour. The result follows the
//! [`fieldtex_core::Image`] conventions (top row first, sRGB-encoded RGBA `f32`);
//! vertex colours are interpolated as given (no colour-space conversion).

use crate::ParamError;
use crate::texel_map::TexelMap;
use fieldtex_core::Image;
use fieldtex_mesh::TriMesh;
use rayon::prelude::*;

/// Bakes `color(triangle, barycentric, position)` for every covered texel (module docs).
/// `position` is the 3-D surface point of the texel.
pub fn bake_surface<F>(
    mesh: &TriMesh,
    map: &TexelMap,
    background: [f32; 4],
    color: F,
) -> Result<Image, ParamError>
where
    F: Fn(u32, [f32; 3], [f64; 3]) -> [f32; 4] + Sync,
{
    let n = map.width * map.height;
    if map.entries.len() != n || map.source.len() != n {
        return Err(ParamError::AttributeLength {
            what: "texel map entries",
            expected: n,
            found: map.entries.len(),
        });
    }
    let nf = mesh.n_triangles();
    for (i, e) in map.entries.iter().enumerate() {
        if let Some(e) = e
            && e.triangle as usize >= nf
        {
            return Err(ParamError::TriangleOutOfRange {
                texel: i,
                triangle: e.triangle,
                n_triangles: nf,
            });
        }
    }
    if n == 0 {
        return Ok(Image { width: map.width, height: map.height, pixels: Vec::new() });
    }
    let mut pixels = vec![background; n];
    pixels.par_chunks_mut(map.width).enumerate().for_each(|(y, row)| {
        for (x, px) in row.iter_mut().enumerate() {
            let i = y * map.width + x;
            if !map.is_covered(i) {
                continue;
            }
            let Some(e) = map.entries[i] else { continue };
            let p = map.surface_point(mesh, i).unwrap_or([0.0; 3]);
            *px = color(e.triangle, e.bary, p);
        }
    });
    for i in 0..n {
        let s = map.source[i];
        if s != u32::MAX && s as usize != i {
            pixels[i] = pixels[s as usize];
        }
    }
    Ok(Image { width: map.width, height: map.height, pixels })
}

/// Bakes per-vertex colours (`#V` RGBA), interpolated with barycentric coordinates.
pub fn bake_vertex_colors(
    mesh: &TriMesh,
    map: &TexelMap,
    colors: &[[f32; 4]],
    background: [f32; 4],
) -> Result<Image, ParamError> {
    if colors.len() != mesh.n_vertices() {
        return Err(ParamError::AttributeLength {
            what: "vertex colours",
            expected: mesh.n_vertices(),
            found: colors.len(),
        });
    }
    bake_surface(mesh, map, background, |f, b, _| {
        let t = mesh.triangles[f as usize];
        let mut c = [0.0f32; 4];
        for k in 0..3 {
            let v = colors.get(t[k] as usize).copied().unwrap_or([0.0; 4]);
            for ch in 0..4 {
                c[ch] += b[k] * v[ch];
            }
        }
        c
    })
}
