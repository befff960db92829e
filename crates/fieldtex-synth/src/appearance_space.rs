//! Appearance space of one Gaussian-stack level (Lefebvre & Hoppe 2006, §3) with the
//! rotated copy of paper D §4 ("Handling orientation").
//!
//! Each exemplar pixel `u` at stack level `c` is described by its 5×5 neighbourhood of
//! RGB colours sampled `h = 2^c` pixels apart (a 75-D vector, toroidal borders). PCA
//! reduces these vectors to [`APPEARANCE_DIMS`] = 8 dimensions.
//!
//! For 2-RoSy synthesis the same pixel is also described by its neighbourhood rotated
//! by 180°: `N₁(u)[i, j] = N₀(u)[4 − i, 4 − j]`, i.e. the appearance pixel `u` has in
//! the exemplar turned upside down. Following paper D the PCA basis is fitted on the
//! union of both sets, so distances between unrotated and rotated appearance vectors
//! are comparable. Rotated vectors are stored at the *unrotated* coordinate `u` (the
//! synthesis keeps all coordinates in the original exemplar frame and a flip bit).
//!
//! Because the fitted covariance is invariant under the 180° permutation, distances
//! among rotated vectors equal distances among unrotated ones (up to PCA truncation
//! of degenerate eigenvalues), so one k-coherence table serves both copies.
//!
//! Not implemented: the Gaussian weighting of the neighbourhood and the feature-distance
//! channel of the 2006 paper.

use fieldtex_linalg::Pca;
use rayon::prelude::*;

use crate::SynthError;
use crate::exemplar_analysis::APPEARANCE_DIMS;

/// Samples used to fit the PCA basis at most (rows are taken with a fixed stride).
const MAX_PCA_SAMPLES: usize = 8_192;
const NEIGHBOURHOOD_DIMS: usize = 75;

/// Appearance vectors of one stack level: `width × height` entries each, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct AppearanceSpace {
    /// Appearance of each pixel's unrotated neighbourhood (`Ẽ₀`).
    pub unrotated: Vec<[f32; APPEARANCE_DIMS]>,
    /// Appearance of each pixel's 180°-rotated neighbourhood (`Ẽ₁`), stored at the
    /// unrotated coordinate.
    pub rotated: Vec<[f32; APPEARANCE_DIMS]>,
    /// Fraction of the neighbourhood variance the 8 components keep.
    pub explained_variance: f64,
}

/// A stack level: `width × height` RGB pixels sampled `spacing` apart.
#[derive(Clone, Copy)]
struct Level<'a> {
    stack: &'a [[f32; 3]],
    width: usize,
    height: usize,
    spacing: usize,
}

/// The 75-D neighbourhood of pixel `(x, y)` (rotated by 180° when `rotated`) into `out`.
fn neighbourhood(l: Level<'_>, x: usize, y: usize, rotated: bool, out: &mut [f32]) {
    let Level { stack, width, height, spacing } = l;
    let s = spacing as i64;
    let sign = if rotated { -1 } else { 1 };
    let xs: [usize; 5] = std::array::from_fn(|i| {
        (x as i64 + sign * (i as i64 - 2) * s).rem_euclid(width as i64) as usize
    });
    let mut k = 0;
    for j in -2i64..=2 {
        let yy = (y as i64 + sign * j * s).rem_euclid(height as i64) as usize;
        for &xx in &xs {
            out[k..k + 3].copy_from_slice(&stack[yy * width + xx]);
            k += 3;
        }
    }
}

/// Builds the appearance space of stack level `level` (`stack`: `width × height` RGB,
/// sampled with spacing `spacing`).
pub fn appearance_space(
    stack: &[[f32; 3]],
    width: usize,
    height: usize,
    spacing: usize,
    level: usize,
) -> Result<AppearanceSpace, SynthError> {
    let lv = Level { stack, width, height, spacing };
    let n = width * height;
    // Both orientations of every picked pixel, so the sample set (and the covariance)
    // is closed under the 180° permutation.
    let stride = (2 * n).div_ceil(MAX_PCA_SAMPLES).max(1);
    let picks: Vec<usize> = (0..n).step_by(stride).collect();
    let mut samples = vec![0.0f32; 2 * picks.len() * NEIGHBOURHOOD_DIMS];
    samples.par_chunks_mut(2 * NEIGHBOURHOOD_DIMS).zip(&picks).for_each(|(rows, &p)| {
        let (a, b) = rows.split_at_mut(NEIGHBOURHOOD_DIMS);
        neighbourhood(lv, p % width, p / width, false, a);
        neighbourhood(lv, p % width, p / width, true, b);
    });
    let pca = Pca::fit(&samples, NEIGHBOURHOOD_DIMS, APPEARANCE_DIMS)
        .map_err(|source| SynthError::Pca { level, source })?;
    let count = samples.len() / NEIGHBOURHOOD_DIMS;
    let total: f64 = samples
        .chunks_exact(NEIGHBOURHOOD_DIMS)
        .map(|row| row.iter().zip(&pca.mean).map(|(&v, &m)| (v as f64 - m).powi(2)).sum::<f64>())
        .sum::<f64>()
        / (count.max(2) - 1) as f64;
    drop(samples);
    let kept: f64 = pca.variances.iter().sum();
    let explained_variance = if total > 0.0 { (kept / total).min(1.0) } else { 1.0 };

    // Projection in f32 with the mean folded into an offset per component.
    // Transposed: `comps[i][c]` = weight of input dimension i in component c.
    let comps: Vec<[f32; APPEARANCE_DIMS]> = (0..NEIGHBOURHOOD_DIMS)
        .map(|i| std::array::from_fn(|c| pca.components[c][i] as f32))
        .collect();
    let offsets: Vec<f32> = pca
        .components
        .iter()
        .map(|c| c.iter().zip(&pca.mean).map(|(a, m)| a * m).sum::<f64>() as f32)
        .collect();
    let project_all = |rotated: bool| -> Vec<[f32; APPEARANCE_DIMS]> {
        let mut out = vec![[0.0f32; APPEARANCE_DIMS]; n];
        out.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
            let mut buf = [0.0f32; NEIGHBOURHOOD_DIMS];
            for (x, o) in row.iter_mut().enumerate() {
                neighbourhood(lv, x, y, rotated, &mut buf);
                let mut acc = [0.0f32; APPEARANCE_DIMS];
                for (a, row) in buf.iter().zip(&comps) {
                    for (oc, w) in acc.iter_mut().zip(row) {
                        *oc += a * w;
                    }
                }
                for ((oc, a), off) in o.iter_mut().zip(&acc).zip(&offsets) {
                    *oc = a - off;
                }
            }
        });
        out
    };
    Ok(AppearanceSpace {
        unrotated: project_all(false),
        rotated: project_all(true),
        explained_variance,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotated_appearance_matches_rotated_exemplar() {
        // Appearance of pixel u in the rotated space equals the unrotated appearance of
        // the corresponding pixel of the exemplar turned by 180° (same PCA basis).
        let (w, h) = (9, 7);
        let img: Vec<[f32; 3]> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32, (i / w) as f32);
                [(x * 0.7 + y * 0.3).sin(), (x * y * 0.1).cos(), (x - 2.0 * y).sin() * 0.5]
            })
            .collect();
        let a = appearance_space(&img, w, h, 1, 0).unwrap();
        // Distances are preserved between the two copies (invariance of the fitted
        // covariance under the 180° permutation).
        let d =
            |p: &[f32; 8], q: &[f32; 8]| p.iter().zip(q).map(|(a, b)| (a - b).powi(2)).sum::<f32>();
        for (i, j) in [(0usize, 5usize), (3, 40), (17, 62)] {
            let d0 = d(&a.unrotated[i], &a.unrotated[j]);
            let d1 = d(&a.rotated[i], &a.rotated[j]);
            assert!((d0 - d1).abs() <= 1e-3 * d0.max(1e-3), "{d0} vs {d1}");
        }
        assert!(a.explained_variance > 0.3 && a.explained_variance <= 1.0);
    }
}
