//! Texel → surface map of an atlas: which triangle, at which barycentric coordinates,
//! each texel of a `W × H` texture shows, with dilation into the gutters.
//!
//! Conventions: texels are stored like [`fieldtex_core::Image`] pixels, row-major with
//! the **top** row first; texel `(x, y)` (y downward) has its centre at
//! `uv = ((x + 0.5) / W, 1 − (y + 0.5) / H)`, i.e. `v = 0` is the bottom row of the image
//! (the glTF writer flips `v` on output, see [`fieldtex_mesh::CornerUvs`]).
//!
//! **Coverage** is conservative: a texel is covered by every UV triangle that meets its
//! square `[x, x+1) × [y, y+1)` in texel units, so texels cut by a chart's boundary are
//! covered too. Among the
//! triangles covering a texel, the one nearest to the texel centre wins (distance 0 when
//! the centre lies inside), ties going to the lower triangle index — a deterministic
//! choice independent of thread count. The barycentric coordinates are those of the
//! point of that triangle nearest to the centre (so they are always in `[0, 1]`).
//!
//! **Dilation**: every uncovered texel within `G` texels (Euclidean, centre to centre)
//! of a covered texel takes the entry of the nearest covered texel (ties: the first in
//! row-major order of the offsets), so bilinear and mip-mapped sampling near chart
//! boundaries reads surface colours rather than background.

use crate::ParamError;
use crate::raster::triangle_row_spans;
use fieldtex_mesh::TriMesh;
use rayon::prelude::*;

/// The surface location a texel shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TexelEntry {
    /// Triangle index in the mesh.
    pub triangle: u32,
    /// Barycentric coordinates in that triangle (corner order of the triangle).
    pub bary: [f32; 3],
}

/// See the module docs.
#[derive(Debug, Clone, PartialEq)]
pub struct TexelMap {
    pub width: usize,
    pub height: usize,
    /// `width × height` entries, top row first; `None` outside charts and gutters.
    pub entries: Vec<Option<TexelEntry>>,
    /// For each texel: its own index when covered by a chart, the index of the covered
    /// texel it copies when it is a dilated gutter texel, `u32::MAX` when empty.
    pub source: Vec<u32>,
}

/// Rows per parallel band.
const BAND: usize = 16;

impl TexelMap {
    /// UV of the centre of texel `(x, y)` (y downward; see the module docs).
    pub fn texel_uv(&self, x: usize, y: usize) -> [f64; 2] {
        [(x as f64 + 0.5) / self.width as f64, 1.0 - (y as f64 + 0.5) / self.height as f64]
    }

    /// `true` when the texel is covered by a chart (not a dilated gutter texel).
    pub fn is_covered(&self, texel: usize) -> bool {
        self.source.get(texel) == Some(&(texel as u32))
    }

    /// The 3-D surface point texel `texel` (row-major index) shows, or `None` for an
    /// empty texel or one whose triangle is not in `mesh`.
    pub fn surface_point(&self, mesh: &TriMesh, texel: usize) -> Option<[f64; 3]> {
        let e = (*self.entries.get(texel)?)?;
        let t = mesh.triangles.get(e.triangle as usize)?;
        let mut p = [0.0; 3];
        for (&v, &b) in t.iter().zip(&e.bary) {
            let q = mesh.positions.get(v as usize)?;
            for (pd, qd) in p.iter_mut().zip(q) {
                *pd += b as f64 * qd;
            }
        }
        Some(p)
    }

    /// The texel (row-major index) that shows the surface point `(triangle, bary)`
    /// through `mesh`'s UVs — the inverse of [`Self::surface_point`] up to the texel
    /// size; `None` without UVs, for a bad triangle index or outside the image.
    pub fn texel_at(&self, mesh: &TriMesh, triangle: u32, bary: [f64; 3]) -> Option<usize> {
        let uv = mesh.uvs.as_ref()?;
        let t = uv.indices.get(triangle as usize)?;
        let (mut u, mut v) = (0.0, 0.0);
        for k in 0..3 {
            let c = uv.values.get(t[k] as usize)?;
            u += bary[k] * c[0];
            v += bary[k] * c[1];
        }
        let x = (u * self.width as f64).floor();
        let y = ((1.0 - v) * self.height as f64).floor();
        if !(x >= 0.0 && y >= 0.0 && x < self.width as f64 && y < self.height as f64) {
            return None;
        }
        Some(y as usize * self.width + x as usize)
    }

    /// Number of texels covered by charts (gutters excluded).
    pub fn n_covered(&self) -> usize {
        (0..self.source.len()).filter(|&i| self.is_covered(i)).count()
    }
}

/// Builds the texel map of `mesh`'s UVs at `width × height` with a dilation of
/// `dilation` texels (module docs).
pub fn build_texel_map(
    mesh: &TriMesh,
    width: usize,
    height: usize,
    dilation: u32,
) -> Result<TexelMap, ParamError> {
    let uvs = mesh.uvs.as_ref().ok_or(ParamError::MissingUvs { operation: "the texel map" })?;
    let nf = mesh.n_triangles();
    if uvs.indices.len() != nf {
        return Err(ParamError::AttributeLength {
            what: "uv indices",
            expected: nf,
            found: uvs.indices.len(),
        });
    }
    if width == 0 || height == 0 || width > 16384 || height > 16384 {
        return Err(ParamError::InvalidOption {
            name: "texel map size",
            value: format!("{width}×{height}"),
            reason: "width and height must be between 1 and 16384",
        });
    }
    let (w, h) = (width as f64, height as f64);
    // UV triangles in texel units, y up.
    let tris: Vec<Option<[[f64; 2]; 3]>> = uvs
        .indices
        .iter()
        .map(|idx| {
            let mut t = [[0.0; 2]; 3];
            for k in 0..3 {
                let uv = uvs.values.get(idx[k] as usize)?;
                t[k] = [uv[0] * w, uv[1] * h];
            }
            t.iter().all(|p| p[0].is_finite() && p[1].is_finite()).then_some(t)
        })
        .collect();
    // Bin triangles into bands of image rows (y down).
    let nbands = height.div_ceil(BAND);
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); nbands];
    for (f, t) in tris.iter().enumerate() {
        let Some(t) = t else { continue };
        let ymin = t[0][1].min(t[1][1]).min(t[2][1]);
        let ymax = t[0][1].max(t[1][1]).max(t[2][1]);
        // Up-rows floor(ymin)..=floor(ymax) -> image rows h-1-row.
        let r_hi = (height as f64 - 1.0 - ymin.floor()).min(height as f64 - 1.0);
        let r_lo = (height as f64 - 1.0 - ymax.floor()).max(0.0);
        if r_hi < 0.0 || r_lo > height as f64 - 1.0 || r_lo > r_hi {
            continue;
        }
        for bin in &mut bins[r_lo as usize / BAND..=r_hi as usize / BAND] {
            bin.push(f as u32);
        }
    }
    let mut entries: Vec<Option<TexelEntry>> = vec![None; width * height];
    entries.par_chunks_mut(BAND * width).enumerate().for_each(|(b, chunk)| {
        let row0 = b * BAND;
        let nrows = chunk.len() / width;
        let mut best: Vec<f64> = vec![f64::INFINITY; chunk.len()];
        for &f in &bins[b] {
            let t = tris[f as usize].expect("binned triangles are finite");
            triangle_row_spans(t, 0.0, |up_row, c0, c1| {
                let img_row = height as i64 - 1 - up_row;
                if img_row < row0 as i64 || img_row >= (row0 + nrows) as i64 {
                    return;
                }
                let local = (img_row as usize - row0) * width;
                for x in c0.max(0)..=c1.min(width as i64 - 1) {
                    let centre = [x as f64 + 0.5, up_row as f64 + 0.5];
                    let (d, bary) = nearest_on_triangle(&t, centre);
                    let slot = local + x as usize;
                    let better = match chunk[slot] {
                        None => true,
                        Some(e) => d < best[slot] || (d == best[slot] && f < e.triangle),
                    };
                    if better {
                        best[slot] = d;
                        chunk[slot] =
                            Some(TexelEntry { triangle: f, bary: bary.map(|v| v as f32) });
                    }
                }
            });
        }
    });
    let mut source: Vec<u32> = entries
        .iter()
        .enumerate()
        .map(|(i, e)| if e.is_some() { i as u32 } else { u32::MAX })
        .collect();
    dilate(&mut entries, &mut source, width, height, dilation);
    Ok(TexelMap { width, height, entries, source })
}

/// Distance from `p` to triangle `t` and the barycentric coordinates of the nearest
/// point (degenerate triangles fall back to their edges).
fn nearest_on_triangle(t: &[[f64; 2]; 3], p: [f64; 2]) -> (f64, [f64; 3]) {
    let cross = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let area = cross(t[0], t[1], t[2]);
    if area != 0.0 {
        let l0 = cross(p, t[1], t[2]) / area;
        let l1 = cross(t[0], p, t[2]) / area;
        let l2 = 1.0 - l0 - l1;
        if l0 >= 0.0 && l1 >= 0.0 && l2 >= 0.0 {
            return (0.0, [l0, l1, l2]);
        }
    }
    let mut best = (f64::INFINITY, [1.0, 0.0, 0.0]);
    for k in 0..3 {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        let d = [b[0] - a[0], b[1] - a[1]];
        let len2 = d[0] * d[0] + d[1] * d[1];
        let s = if len2 > 0.0 {
            (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [a[0] + s * d[0], a[1] + s * d[1]];
        let dist = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
        if dist < best.0 {
            let mut bary = [0.0; 3];
            bary[k] = 1.0 - s;
            bary[(k + 1) % 3] = s;
            best = (dist, bary);
        }
    }
    best
}

/// Fills uncovered texels within `radius` of a covered one (module docs).
fn dilate(
    entries: &mut [Option<TexelEntry>],
    source: &mut [u32],
    width: usize,
    height: usize,
    radius: u32,
) {
    if radius == 0 {
        return;
    }
    let r = radius as i64;
    let mut offsets: Vec<(i64, i64, i64)> = Vec::new();
    for dy in -r..=r {
        for dx in -r..=r {
            let d2 = dx * dx + dy * dy;
            if d2 > 0 && d2 <= r * r {
                offsets.push((d2, dy, dx));
            }
        }
    }
    offsets.sort_unstable();
    let covered: Vec<bool> = entries.iter().map(|e| e.is_some()).collect();
    let src: Vec<u32> = (0..entries.len())
        .into_par_iter()
        .map(|i| {
            if covered[i] {
                return i as u32;
            }
            let (x, y) = ((i % width) as i64, (i / width) as i64);
            for &(_, dy, dx) in &offsets {
                let (xx, yy) = (x + dx, y + dy);
                if xx < 0 || yy < 0 || xx >= width as i64 || yy >= height as i64 {
                    continue;
                }
                let j = yy as usize * width + xx as usize;
                if covered[j] {
                    return j as u32;
                }
            }
            u32::MAX
        })
        .collect();
    for i in 0..entries.len() {
        if !covered[i] && src[i] != u32::MAX {
            entries[i] = entries[src[i] as usize];
        }
    }
    source.copy_from_slice(&src);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_inside_and_outside() {
        let t = [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]];
        let (d, b) = nearest_on_triangle(&t, [0.5, 0.5]);
        assert_eq!(d, 0.0);
        assert!((b[0] - 0.5).abs() < 1e-12 && (b[1] - 0.25).abs() < 1e-12);
        let (d, b) = nearest_on_triangle(&t, [1.0, -1.0]);
        assert!((d - 1.0).abs() < 1e-12);
        assert!((b[0] - 0.5).abs() < 1e-12 && (b[1] - 0.5).abs() < 1e-12 && b[2] == 0.0);
    }

    #[test]
    fn single_triangle_map_with_dilation() {
        let mut mesh =
            TriMesh::new(vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]);
        mesh.uvs = Some(fieldtex_mesh::CornerUvs {
            values: vec![[0.25, 0.25], [0.75, 0.25], [0.25, 0.75]],
            indices: vec![[0, 1, 2]],
        });
        let m = build_texel_map(&mesh, 16, 16, 2).unwrap();
        // The texel at uv (0.3, 0.3) is covered; its surface point matches the uv.
        let (x, y) = ((0.3f64 * 16.0) as usize, ((1.0 - 0.3) * 16.0) as usize);
        let i = y * 16 + x;
        assert!(m.is_covered(i));
        let uv = m.texel_uv(x, y);
        let p = m.surface_point(&mesh, i).unwrap();
        assert!(
            (p[0] - (uv[0] - 0.25) * 2.0).abs() < 1e-6
                && (p[1] - (uv[1] - 0.25) * 2.0).abs() < 1e-6
        );
        // A gutter texel two texels left of the chart copies a covered texel.
        let g = y * 16 + 2;
        assert!(!m.is_covered(g) && m.entries[g].is_some());
        assert!(m.is_covered(m.source[g] as usize));
        // Far corner stays empty.
        assert!(m.entries[15].is_none() && m.source[15] == u32::MAX);
        // Every covered texel whose centre is inside the triangle maps back to itself.
        for t in (0..256).filter(|&t| m.is_covered(t)) {
            let e = m.entries[t].unwrap();
            let b = e.bary.map(f64::from);
            if b.iter().any(|&x| x < 0.01) {
                continue;
            }
            assert_eq!(m.texel_at(&mesh, e.triangle, b), Some(t), "texel {t}");
        }
        assert_eq!(m.texel_at(&mesh, 7, [1.0, 0.0, 0.0]), None);
    }
}
