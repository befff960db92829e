//! Exemplar analysis for one patch size: filtered exemplar, patch descriptors, PCA.
//!
//! A `w × w` patch (`w = 8·s`) is described by an `8 × 8` grid of RGB values taken every
//! `s` pixels from the exemplar filtered by a tent of radius `s` (separable weights
//! `1 − |d|/s`; the identity for `s = 1`). The tent matches what the surface side sees:
//! carriers about one pixel apart splatted bilinearly onto a grid of step `s`. This is
//! Kwatra et al. 2005's subsampling of large neighbourhoods; descriptors stay 192-D for
//! every `w`, then [`Pca`] reduces them for exhaustive search.
//!
//! Patch positions are integer *origins* `o` (the pixel of grid point `(0, 0)`); grid
//! point `(i, j)` is pixel `o + (i·s, j·s)`, and the patch centre is `o + 3.5·s`.
//! Origins lie on a lattice of *stride* `t` pixels: `t = max(⌊s/2⌋, t₀, 1)` with `t₀`
//! the smallest stride that keeps the positions of a large exemplar under
//! [`MAX_POSITIONS`]. At `w = 8` on exemplars up to 512² every pixel is an origin; a
//! coarse level is, in effect, a level of the exemplar's pyramid sampled at twice its
//! resolution (Kwatra et al. 2005 search coarse levels on the subsampled exemplar).
//! Matches keep a continuous origin offset of up to `±t/2` (coherence), so copying is
//! not quantised to the lattice. With `toroidal = false` every origin keeps the grid
//! inside the exemplar (`0 ≤ o ≤ W − 1 − 7s`); with `toroidal = true` lookups wrap.
//! Coordinates here are pixel-*index* space (pixel `x` at `x`); the public API adds
//! `0.5` (pixel centres at `x + 0.5`, as `Image::sample_bilinear`).
//!
//! Memory: descriptors are not stored; the exact 192-D distance reads the filtered
//! image (64 pixels), and only the PCA coordinates (`kp` floats) are kept per position.
//! The PCA basis is fitted on at most [`PCA_FIT_SAMPLES`] evenly spread positions.

use crate::TexOptError;
use fieldtex_core::Image;
use fieldtex_linalg::Pca;
use rayon::prelude::*;

/// Descriptor grid points per side.
pub(crate) const GRID: usize = 8;
/// Descriptor length: `GRID² × RGB`.
pub(crate) const DIM: usize = GRID * GRID * 3;
/// Patch coordinate of the grid centre.
pub(crate) const HALF: f64 = (GRID as f64 - 1.0) / 2.0;
/// Most patch positions per level (bounds the PCA coordinates to `2¹⁸ · kp` floats).
pub const MAX_POSITIONS: usize = 1 << 18;
/// Most positions the PCA basis is fitted on.
pub const PCA_FIT_SAMPLES: usize = 16_384;

/// Exemplar data of one patch size.
pub(crate) struct ExemplarLevel {
    pub step: usize,
    /// Lattice spacing of the origins, pixels.
    pub stride: usize,
    pub width: usize,
    pub height: usize,
    pub toroidal: bool,
    /// Filtered exemplar, `width × height` RGBA.
    pub image: Vec<[f32; 4]>,
    /// Origins per axis: `nx × ny` positions, index `oy·nx + ox`.
    pub nx: usize,
    pub ny: usize,
    /// `M × kp` PCA coefficients, zero-padded to `kp` (a multiple of 8) per row.
    pub coords: Vec<f32>,
    /// Padded row length of `coords`.
    pub kp: usize,
    /// `kp × DIM` components (rows past `k` zero) and the `DIM` mean, `f32`.
    basis: Vec<f32>,
    mean: Vec<f32>,
    pub pca: Pca,
    /// Feature distance (exemplar pixels) at each position's centre, `M`.
    pub centre_distance: Option<Vec<f32>>,
    /// Positions grouped by `round(centre_distance)`.
    pub feature_bins: Vec<Vec<u32>>,
}

impl ExemplarLevel {
    /// Analyses `exemplar` for patch size `patch` (a multiple of 8). `distance` is the
    /// optional `W × H` feature-distance map.
    pub fn new(
        exemplar: &Image,
        patch: usize,
        toroidal: bool,
        pca_components: usize,
        distance: Option<&[f32]>,
    ) -> Result<Self, TexOptError> {
        let (w, h) = (exemplar.width, exemplar.height);
        let step = patch / GRID;
        if w < patch || h < patch {
            return Err(TexOptError::ExemplarTooSmall { width: w, height: h, patch, min: patch });
        }
        let image = tent_filter(exemplar, step, toroidal);
        let span = (GRID - 1) * step;
        let base = (w * h).div_ceil(MAX_POSITIONS).isqrt();
        let base = if base * base * MAX_POSITIONS < w * h { base + 1 } else { base };
        let stride = (step / 2).max(base).max(1);
        let (nx, ny) = if toroidal {
            (w.div_ceil(stride), h.div_ceil(stride))
        } else {
            ((w - 1 - span) / stride + 1, (h - 1 - span) / stride + 1)
        };
        let mut level = Self {
            step,
            stride,
            width: w,
            height: h,
            toroidal,
            image,
            nx,
            ny,
            coords: Vec::new(),
            kp: 0,
            basis: Vec::new(),
            mean: Vec::new(),
            pca: Pca { mean: Vec::new(), components: Vec::new(), variances: Vec::new() },
            centre_distance: None,
            feature_bins: Vec::new(),
        };
        let m = nx * ny;
        // PCA on an evenly spread subset of positions (deterministic).
        let fit_step = m.div_ceil(PCA_FIT_SAMPLES).max(1);
        let fit: Vec<u32> = (0..m as u32).step_by(fit_step).collect();
        let mut descriptors = vec![0.0f32; fit.len() * DIM];
        descriptors
            .par_chunks_mut(DIM)
            .zip(fit.par_iter())
            .for_each(|(d, &p)| level.descriptor(p, d));
        let k = pca_components.clamp(1, DIM);
        let pca =
            Pca::fit(&descriptors, DIM, k).map_err(|source| TexOptError::Pca { patch, source })?;
        drop(descriptors);
        let kp = k.div_ceil(8) * 8;
        level.kp = kp;
        level.basis = vec![0.0; kp * DIM];
        for (c, comp) in pca.components.iter().enumerate() {
            for (b, &v) in level.basis[c * DIM..(c + 1) * DIM].iter_mut().zip(comp) {
                *b = v as f32;
            }
        }
        level.mean = pca.mean.iter().map(|&m| m as f32).collect();
        let mut coords = vec![0.0f32; m * kp];
        coords.par_chunks_mut(kp).enumerate().with_min_len(256).for_each(|(p, c)| {
            let mut d = [0.0f32; DIM];
            level.descriptor(p as u32, &mut d);
            level.project(&d, c);
        });
        level.coords = coords;
        level.pca = pca;
        if let Some(dist) = distance {
            let centre: Vec<f32> = (0..m as u32)
                .map(|p| {
                    let [ox, oy] = level.origin(p);
                    let c = HALF * step as f64;
                    let x = ((ox as f64 + c).round() as i64).rem_euclid(w as i64) as usize;
                    let y = ((oy as f64 + c).round() as i64).rem_euclid(h as i64) as usize;
                    dist[y * w + x]
                })
                .collect();
            let max_bin =
                centre.iter().fold(0.0f32, |a, &b| if b.is_finite() { a.max(b) } else { a });
            let mut bins = vec![Vec::new(); max_bin.round() as usize + 1];
            for (p, &d) in centre.iter().enumerate() {
                if d.is_finite() && d >= 0.0 {
                    bins[d.round() as usize].push(p as u32);
                }
            }
            level.centre_distance = Some(centre);
            level.feature_bins = bins;
        }
        Ok(level)
    }

    /// Number of patch positions `M`.
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// Origin pixel of position `p`.
    #[inline]
    pub fn origin(&self, p: u32) -> [i64; 2] {
        let t = self.stride as i64;
        [(p as usize % self.nx) as i64 * t, (p as usize / self.nx) as i64 * t]
    }

    /// The position whose origin is nearest to the continuous origin `(x, y)` (clamped,
    /// or wrapped when toroidal).
    #[inline]
    pub fn position_near(&self, x: f64, y: f64) -> u32 {
        let t = self.stride as f64;
        let (xi, yi) = ((x / t).round() as i64, (y / t).round() as i64);
        let (xi, yi) = if self.toroidal {
            (xi.rem_euclid(self.nx as i64), yi.rem_euclid(self.ny as i64))
        } else {
            (xi.clamp(0, self.nx as i64 - 1), yi.clamp(0, self.ny as i64 - 1))
        };
        (yi as usize * self.nx + xi as usize) as u32
    }

    /// The placement of the continuous origin `(x, y)`: the nearest position and the
    /// remaining offset, clamped to half a stride.
    #[inline]
    pub fn placement_near(&self, x: f64, y: f64) -> crate::patch_search::Placement {
        let position = self.position_near(x, y);
        let [ox, oy] = self.origin(position);
        let lim = 0.5 * self.stride as f64;
        let offset =
            [(x - ox as f64).clamp(-lim, lim) as f32, (y - oy as f64).clamp(-lim, lim) as f32];
        crate::patch_search::Placement { position, offset }
    }

    #[inline]
    fn pixel(&self, x: i64, y: i64) -> [f32; 4] {
        let (w, h) = (self.width as i64, self.height as i64);
        let (x, y) = if self.toroidal {
            (x.rem_euclid(w), y.rem_euclid(h))
        } else {
            (x.clamp(0, w - 1), y.clamp(0, h - 1))
        };
        self.image[(y * w + x) as usize]
    }

    /// Bilinear lookup of the filtered exemplar at pixel-index coordinates.
    #[inline]
    pub fn sample(&self, x: f64, y: f64) -> [f32; 4] {
        let (x0, y0) = (x.floor(), y.floor());
        let (tx, ty) = ((x - x0) as f32, (y - y0) as f32);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let a = self.pixel(x0, y0);
        let b = self.pixel(x0 + 1, y0);
        let c = self.pixel(x0, y0 + 1);
        let d = self.pixel(x0 + 1, y0 + 1);
        fieldtex_core::image::bilerp([a, b, c, d], tx, ty)
    }

    /// Writes the descriptor of position `p` into `out` (`DIM`).
    fn descriptor(&self, p: u32, out: &mut [f32]) {
        let [ox, oy] = self.origin(p);
        let s = self.step as i64;
        for j in 0..GRID {
            for i in 0..GRID {
                let c = self.pixel(ox + i as i64 * s, oy + j as i64 * s);
                let o = (j * GRID + i) * 3;
                out[o..o + 3].copy_from_slice(&c[..3]);
            }
        }
    }

    /// Squared distance between a descriptor and the descriptor of `p` (read from the
    /// filtered image).
    #[inline]
    pub fn distance2(&self, x: &[f32; DIM], p: u32) -> f32 {
        let [ox, oy] = self.origin(p);
        let s = self.step as i64;
        let inside =
            !self.toroidal || (ox + 7 * s < self.width as i64 && oy + 7 * s < self.height as i64);
        let mut acc = [0.0f32; 3];
        for j in 0..GRID {
            let y = oy + j as i64 * s;
            for i in 0..GRID {
                let c = if inside {
                    self.image[y as usize * self.width + (ox + i as i64 * s) as usize]
                } else {
                    self.pixel(ox + i as i64 * s, y)
                };
                let o = (j * GRID + i) * 3;
                for k in 0..3 {
                    let e = x[o + k] - c[k];
                    acc[k] += e * e;
                }
            }
        }
        acc[0] + acc[1] + acc[2]
    }

    /// Projects a descriptor onto the padded PCA basis: `out[..kp]`.
    #[inline]
    pub fn project(&self, x: &[f32; DIM], out: &mut [f32]) {
        let mut centred = [0.0f32; DIM];
        for ((c, &v), &m) in centred.iter_mut().zip(x).zip(&self.mean) {
            *c = v - m;
        }
        for (o, row) in out[..self.kp].iter_mut().zip(self.basis.chunks_exact(DIM)) {
            let mut s = [0.0f32; 8];
            for (a, b) in centred.chunks_exact(8).zip(row.chunks_exact(8)) {
                for k in 0..8 {
                    s[k] += a[k] * b[k];
                }
            }
            *o = (s[0] + s[1]) + (s[2] + s[3]) + ((s[4] + s[5]) + (s[6] + s[7]));
        }
    }

    /// Squared distance in PCA space between the padded projection `q` (`kp`) and
    /// position `p`, or any value `≥ bound` once the partial sum exceeds `bound`
    /// (components come by decreasing variance, so the early exit is effective).
    #[inline]
    pub fn coord_distance2(&self, q: &[f32], p: u32, bound: f32) -> f32 {
        let kp = self.kp;
        let c = &self.coords[p as usize * kp..(p as usize + 1) * kp];
        let mut total = 0.0f32;
        for (a, b) in q.chunks_exact(8).zip(c.chunks_exact(8)) {
            let mut s = [0.0f32; 8];
            for k in 0..8 {
                let e = a[k] - b[k];
                s[k] = e * e;
            }
            total += (s[0] + s[1]) + (s[2] + s[3]) + ((s[4] + s[5]) + (s[6] + s[7]));
            if total >= bound {
                return total;
            }
        }
        total
    }
}

/// Separable tent filter of radius `s` (weights `1 − |d|/s`), clamped or wrapped.
fn tent_filter(img: &Image, s: usize, toroidal: bool) -> Vec<[f32; 4]> {
    if s <= 1 {
        return img.pixels.clone();
    }
    let (w, h) = (img.width as i64, img.height as i64);
    let weights: Vec<(i64, f32)> =
        (-(s as i64) + 1..s as i64).map(|d| (d, 1.0 - d.abs() as f32 / s as f32)).collect();
    let norm: f32 = weights.iter().map(|x| x.1).sum();
    let fetch = |v: i64, n: i64| if toroidal { v.rem_euclid(n) } else { v.clamp(0, n - 1) };
    let pass = |src: &[[f32; 4]], horizontal: bool| -> Vec<[f32; 4]> {
        let mut out = vec![[0.0f32; 4]; src.len()];
        out.par_chunks_mut(w as usize).enumerate().for_each(|(y, row)| {
            for (x, o) in row.iter_mut().enumerate() {
                let mut acc = [0.0f32; 4];
                for &(d, wt) in &weights {
                    let (sx, sy) = if horizontal {
                        (fetch(x as i64 + d, w), y as i64)
                    } else {
                        (x as i64, fetch(y as i64 + d, h))
                    };
                    let c = src[(sy * w + sx) as usize];
                    for k in 0..4 {
                        acc[k] += wt * c[k];
                    }
                }
                for k in 0..4 {
                    o[k] = acc[k] / norm;
                }
            }
        });
        out
    };
    let tmp = pass(&img.pixels, true);
    pass(&tmp, false)
}
