//! Colours of the source samples, read through the source's per-corner UVs.
//!
//! A sample's UV is the barycentric mix of its triangle's corner UVs; the colour is the
//! bilinear sample of the texture there (`fieldtex_core::Image::sample_bilinear`, UV
//! `(0, 0)` at the image's lower-left corner, coordinates outside `[0, 1]` wrapped as
//! glTF's default `REPEAT`). Values stay sRGB-encoded, as stored: the whole transfer
//! works on sRGB values.
//!
//! Mask (paper B §6.1): an image of the texture's size whose **white** texels (luminance
//! ≥ ½ at the nearest texel) are ignored: their samples carry no colour and are left out
//! of the training set.

use crate::TransferError;
use crate::surface_samples::SampleSet;
use fieldtex_core::Image;
use fieldtex_mesh::TriMesh;
use rayon::prelude::*;

/// RGB of every sample (row-major `#samples × 3`) and whether it is usable (not masked,
/// finite UV).
pub fn source_sample_colors(
    mesh: &TriMesh,
    texture: &Image,
    mask: Option<&Image>,
    samples: &SampleSet,
) -> Result<(Vec<f64>, Vec<bool>), TransferError> {
    surface_colors(mesh, texture, mask, &samples.triangles, &samples.barycentric)
}

/// RGB at surface points `(triangles[i], barycentric[i])` of a textured mesh (module
/// docs), row-major `#points × 3`, and whether each point is usable.
pub fn surface_colors(
    mesh: &TriMesh,
    texture: &Image,
    mask: Option<&Image>,
    triangles: &[u32],
    barycentric: &[[f64; 3]],
) -> Result<(Vec<f64>, Vec<bool>), TransferError> {
    let uvs = mesh.uvs.as_ref().ok_or_else(|| TransferError::SourceNotTextured {
        what: "has no texture coordinates".into(),
    })?;
    if uvs.indices.len() != mesh.n_triangles() {
        return Err(TransferError::SourceNotTextured {
            what: format!(
                "has UV indices for {} of its {} triangles",
                uvs.indices.len(),
                mesh.n_triangles()
            ),
        });
    }
    if texture.width == 0 || texture.height == 0 {
        return Err(TransferError::SourceNotTextured { what: "texture is empty".into() });
    }
    check_mask_size(mask, texture)?;
    let (w, h) = (texture.width as f64, texture.height as f64);
    let rows: Vec<([f64; 3], bool)> = (0..triangles.len().min(barycentric.len()))
        .into_par_iter()
        .map(|i| {
            let f = triangles[i] as usize;
            let b = barycentric[i];
            if f >= uvs.indices.len() {
                return ([0.0; 3], false);
            }
            let mut uv = [0.0; 2];
            for k in 0..3 {
                let Some(c) = uvs.values.get(uvs.indices[f][k] as usize) else {
                    return ([0.0; 3], false);
                };
                uv[0] += b[k] * c[0];
                uv[1] += b[k] * c[1];
            }
            if !(uv[0].is_finite() && uv[1].is_finite()) {
                return ([0.0; 3], false);
            }
            let (u, v) = (uv[0].rem_euclid(1.0), uv[1].rem_euclid(1.0));
            let (x, y) = (u * w, (1.0 - v) * h);
            if let Some(m) = mask {
                let xi = (x as usize).min(m.width - 1);
                let yi = (y as usize).min(m.height - 1);
                let p = m.get(xi, yi);
                if 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] >= 0.5 {
                    return ([0.0; 3], false);
                }
            }
            let c = texture.sample_bilinear(x, y);
            ([c[0] as f64, c[1] as f64, c[2] as f64], true)
        })
        .collect();
    let mut colors = Vec::with_capacity(rows.len() * 3);
    let mut valid = Vec::with_capacity(rows.len());
    for (c, v) in rows {
        colors.extend_from_slice(&c);
        valid.push(v);
    }
    Ok((colors, valid))
}

/// A mask must have the texture's size (one mask texel per texture texel).
pub(crate) fn check_mask_size(mask: Option<&Image>, texture: &Image) -> Result<(), TransferError> {
    match mask {
        Some(m) if m.width != texture.width || m.height != texture.height => {
            Err(TransferError::MaskSize {
                mask_w: m.width,
                mask_h: m.height,
                tex_w: texture.width,
                tex_h: texture.height,
            })
        }
        _ => Ok(()),
    }
}
