//! Exemplar analysis for solid synthesis from 2-D exemplars (Kopf et al. 2007; Dong,
//! Lefebvre, Tong & Drettakis 2008; paper E §4).
//!
//! Three exemplars `I_xy`, `I_yz`, `I_zx` (plane `P` = 0, 1, 2) may be the same image.
//! Exemplar `P`'s first pixel coordinate runs along local axis `P` and its second along
//! local axis `(P + 1) % 3` (xy: x, y; yz: y, z; zx: z, x), x right and y down in the
//! image, toroidal borders. For every plane and synthesis level `c` (spacing `h = 2^c`):
//!
//! - the Gaussian stack level `c` ([`crate::gaussian_stack`], the one home of the stack);
//! - a PCA basis ([`fieldtex_linalg::Pca`]) of the `N × N` RGB neighbourhoods sampled
//!   `h` apart, and every pixel's projected neighbourhood (the appearance the correction
//!   compares against; paper E §4.3 "PCA projection … about 20 dimensions per plane",
//!   here [`SolidAnalysisOptions::pca_dims`], default 8);
//! - the candidate triples ([`super::candidate_triples`]).
//!
//! **Feature channel** (paper E §4, for regular exemplars such as bricks, Fig. 16): each
//! plane may carry a feature mask (grey image, high on the feature curves — mortar
//! lines), stacked like the colours and appended, times
//! [`SolidAnalysisOptions::feature_weight`], as a fourth *matched* channel: the PCA
//! neighbourhoods, the crossbar sticks of the triple search and the correction's voxel
//! neighbourhoods all compare RGB + feature ([`PlaneLevel::matched`]); the voxel colour
//! stays the RGB mean (the mask is matched, never shown). Without masks the matched
//! vectors are the three colour channels and every computation is the RGB one.
//!
//! Identical exemplars share one analysis: the triple search is symmetric under the
//! cyclic exchange of the planes, so one table serves all three.

use super::candidate_triples::{CandidateTriples, candidate_triples, wrapped};
use crate::SynthError;
use crate::gaussian_stack::next_stack_level;
use fieldtex_core::{Image, Progress};
use fieldtex_linalg::Pca;
use rayon::prelude::*;
use std::sync::Arc;

/// Options of [`SolidExemplar::new`].
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SolidAnalysisOptions {
    /// Synthesis levels `L` (stack levels `0..L`, coarsest spacing `2^(L−1)`). Default 5.
    pub levels: usize,
    /// Neighbourhood side `N` (odd). Default 5 (the paper uses 7 and 9).
    pub neighbourhood: usize,
    /// PCA dimensions per plane. Default 8.
    pub pca_dims: usize,
    /// Candidate triples kept per pixel, `N_T`. Default 12 (the paper's value).
    pub triples: usize,
    /// Pool pixels the crossbar search examines per query (a regular sub-grid of the
    /// exemplar). Default 1024.
    pub pool: usize,
    /// Largest exemplar side accepted. Default 512.
    pub max_size: usize,
    /// Weight of each plane (xy, yz, zx) in the crossbar error, the correction's
    /// neighbourhood distance and the voxel colour. Default `[1, 1, 1]`; paper E §6.1
    /// suggests dropping or down-weighting the third plane when the exemplars cannot
    /// all hold in one solid (stripes, wood grain).
    pub plane_weights: [f32; 3],
    /// Weight of the feature-mask channel (mask values in `[0, 1]`) against the colour
    /// channels when masks are given ([`SolidExemplar::with_features`]). Default 1.
    pub feature_weight: f32,
}

impl Default for SolidAnalysisOptions {
    fn default() -> Self {
        Self {
            levels: 5,
            neighbourhood: 5,
            pca_dims: 8,
            triples: 12,
            pool: 1024,
            max_size: 512,
            plane_weights: [1.0; 3],
            feature_weight: 1.0,
        }
    }
}

/// One plane's exemplar at one level.
#[derive(Clone, Debug)]
pub struct PlaneLevel {
    /// Stack colours, `W × H` RGB (sRGB-encoded, as stored).
    pub colors: Vec<[f32; 3]>,
    /// The matched values per pixel: RGB and, with a feature mask, the stacked mask
    /// times [`SolidAnalysisOptions::feature_weight`] (else 0); the first
    /// [`Self::channels`] entries are compared.
    pub matched: Vec<[f32; 4]>,
    /// Matched channels: 3 (RGB) or 4 (RGB + feature).
    pub channels: usize,
    /// PCA basis of `N × N × channels` neighbourhoods.
    pub pca: Pca,
    /// Projected neighbourhood per pixel, `W × H × pca_dims`.
    pub appearance: Vec<f32>,
    /// The PCA components as `f32`, `pca_dims × (N² · channels)` row-major, and
    /// `bias[j] = components[j] · mean`: the projection is `basis x − bias`.
    pub basis: Vec<f32>,
    pub bias: Vec<f32>,
}

impl PlaneLevel {
    /// PCA dimensions.
    pub fn dims(&self) -> usize {
        self.bias.len()
    }
}

/// One exemplar image analysed at every level.
#[derive(Clone, Debug)]
pub struct PlaneExemplar {
    pub width: usize,
    pub height: usize,
    pub levels: Vec<PlaneLevel>,
}

/// The analysis of the three plane exemplars (module docs).
#[derive(Clone, Debug)]
pub struct SolidExemplar {
    pub options: SolidAnalysisOptions,
    /// Plane exemplars (xy, yz, zx); identical images share one `Arc`.
    pub planes: [Arc<PlaneExemplar>; 3],
    /// Candidate triples per level (`triples[c]`), for the three planes.
    pub triples: Vec<[Arc<CandidateTriples>; 3]>,
    /// Wall time, milliseconds.
    pub elapsed_ms: f64,
}

impl SolidExemplar {
    /// Analyses `exemplars` (xy, yz, zx).
    pub fn new(
        exemplars: [&Image; 3],
        options: &SolidAnalysisOptions,
        progress: &dyn Progress,
    ) -> Result<Self, SynthError> {
        Self::with_features(exemplars, [None, None, None], options, progress)
    }

    /// Analyses `exemplars` (xy, yz, zx) with a feature mask per plane (module docs):
    /// all three or none; each the size of its exemplar, its grey value (mean of RGB)
    /// in `[0, 1]`.
    pub fn with_features(
        exemplars: [&Image; 3],
        masks: [Option<&Image>; 3],
        options: &SolidAnalysisOptions,
        progress: &dyn Progress,
    ) -> Result<Self, SynthError> {
        let t0 = std::time::Instant::now();
        let given = masks.iter().filter(|m| m.is_some()).count();
        if given != 0 && given != 3 {
            return Err(SynthError::InvalidOption {
                name: "SolidExemplar::with_features masks",
                value: given as f64,
                reason: "give a feature mask for all three planes or for none",
            });
        }
        let fw = options.feature_weight;
        if !(fw.is_finite() && fw >= 0.0) {
            return Err(SynthError::InvalidOption {
                name: "SolidAnalysisOptions::feature_weight",
                value: fw as f64,
                reason: "must be finite and ≥ 0",
            });
        }
        for p in 0..3 {
            if let Some(m) = masks[p] {
                let e = exemplars[p];
                if m.width != e.width || m.height != e.height || m.pixels.len() != e.pixels.len() {
                    return Err(SynthError::FeatureMaskSize {
                        plane: ["xy", "yz", "zx"][p],
                        mask: (m.width, m.height),
                        exemplar: (e.width, e.height),
                    });
                }
                if let Some((index, v)) =
                    m.pixels.iter().enumerate().find_map(|(i, px)| {
                        px.iter().take(3).find(|v| !v.is_finite()).map(|v| (i, *v))
                    })
                {
                    return Err(SynthError::NonFiniteExemplar {
                        index,
                        x: index % m.width.max(1),
                        y: index / m.width.max(1),
                        value: v,
                    });
                }
            }
        }
        if options.neighbourhood < 3
            || options.neighbourhood.is_multiple_of(2)
            || options.neighbourhood > 15
        {
            return Err(SynthError::InvalidOption {
                name: "SolidAnalysisOptions::neighbourhood",
                value: options.neighbourhood as f64,
                reason: "must be odd, between 3 and 15",
            });
        }
        if !(1..=8).contains(&options.levels) {
            return Err(SynthError::InvalidOption {
                name: "SolidAnalysisOptions::levels",
                value: options.levels as f64,
                reason: "must be between 1 and 8",
            });
        }
        if options.pca_dims == 0
            || options.pca_dims > 32
            || options.triples == 0
            || options.triples > 32
        {
            return Err(SynthError::InvalidOption {
                name: "SolidAnalysisOptions::pca_dims/triples",
                value: options.pca_dims.max(options.triples) as f64,
                reason: "pca_dims and triples must be between 1 and 32",
            });
        }
        let w = options.plane_weights;
        if w.iter().any(|v| !(v.is_finite() && *v >= 0.0)) || w.iter().sum::<f32>() <= 0.0 {
            return Err(SynthError::InvalidOption {
                name: "SolidAnalysisOptions::plane_weights",
                value: w.iter().sum::<f32>() as f64,
                reason: "weights must be finite, ≥ 0, and not all zero",
            });
        }
        let same = |a: &Image, b: &Image| std::ptr::eq(a, b) || a == b;
        let same_mask = |a: Option<&Image>, b: Option<&Image>| match (a, b) {
            (None, None) => true,
            (Some(a), Some(b)) => same(a, b),
            _ => false,
        };
        progress.stage("solid exemplar analysis", 3 * options.levels as u64);
        let mut planes: Vec<Arc<PlaneExemplar>> = Vec::with_capacity(3);
        for p in 0..3 {
            if let Some(q) =
                (0..p).find(|&q| same(exemplars[q], exemplars[p]) && same_mask(masks[q], masks[p]))
            {
                let shared = planes[q].clone();
                planes.push(shared);
                continue;
            }
            planes.push(Arc::new(analyse_plane(exemplars[p], masks[p], options)?));
        }
        let planes: [Arc<PlaneExemplar>; 3] =
            [planes[0].clone(), planes[1].clone(), planes[2].clone()];
        let all_same = Arc::ptr_eq(&planes[0], &planes[1])
            && Arc::ptr_eq(&planes[1], &planes[2])
            && w[0] == w[1]
            && w[1] == w[2];
        let mut triples = Vec::with_capacity(options.levels);
        for c in 0..options.levels {
            let h = 1usize << c;
            let levels: [&PlaneExemplar; 3] = std::array::from_fn(|p| &*planes[p]);
            let t0 = Arc::new(candidate_triples(levels, c, 0, h, options));
            progress.advance(1);
            let row = if all_same {
                // Cyclic symmetry: plane p's table is plane 0's with the coordinates
                // turned by p places.
                let turned = |shift: usize| {
                    let mut t = (*t0).clone();
                    t.plane = shift;
                    for tr in &mut t.triples {
                        let old = *tr;
                        for q in 0..3 {
                            tr[(q + shift) % 3] = old[q];
                        }
                    }
                    Arc::new(t)
                };
                let (t1, t2) = (turned(1), turned(2));
                [t0, t1, t2]
            } else {
                let t1 = Arc::new(candidate_triples(levels, c, 1, h, options));
                let t2 = Arc::new(candidate_triples(levels, c, 2, h, options));
                [t0, t1, t2]
            };
            progress.advance(2);
            triples.push(row);
        }
        progress.finish_stage();
        Ok(Self {
            options: options.clone(),
            planes,
            triples,
            elapsed_ms: t0.elapsed().as_secs_f64() * 1e3,
        })
    }

    /// Level-`c` colour (RGB) of plane `p` at pixel `(x, y)` (wrapped).
    #[inline]
    pub fn color(&self, p: usize, c: usize, x: i32, y: i32) -> [f32; 3] {
        self.planes[p].levels[c].colors[self.wrapped_pixel(p, x, y)]
    }

    /// Level-`c` matched values (RGB + weighted feature, [`PlaneLevel::matched`]) of
    /// plane `p` at pixel `(x, y)` (wrapped).
    #[inline]
    pub fn matched(&self, p: usize, c: usize, x: i32, y: i32) -> [f32; 4] {
        self.planes[p].levels[c].matched[self.wrapped_pixel(p, x, y)]
    }

    /// Index of pixel `(x, y)` of plane `p`, wrapped into the exemplar.
    #[inline]
    fn wrapped_pixel(&self, p: usize, x: i32, y: i32) -> usize {
        let e = &self.planes[p];
        wrapped(y, e.height) * e.width + wrapped(x, e.width)
    }

    /// Asks the CPU to fetch the level-`c` appearance vector of plane `p` at pixel
    /// `xy` ahead of its use (no effect on results).
    #[inline]
    pub(crate) fn prefetch_appearance(&self, p: usize, c: usize, xy: [i32; 2]) {
        let lvl = &self.planes[p].levels[c];
        if let Some(v) = lvl.appearance.get(self.wrapped_pixel(p, xy[0], xy[1]) * lvl.dims()) {
            crate::prefetch::prefetch_read(v);
        }
    }

    /// Matched channels: 4 with feature masks, else 3.
    pub fn channels(&self) -> usize {
        self.planes[0].levels[0].channels
    }
}

fn analyse_plane(
    image: &Image,
    mask: Option<&Image>,
    options: &SolidAnalysisOptions,
) -> Result<PlaneExemplar, SynthError> {
    let (w, h) = (image.width, image.height);
    if image.pixels.len() != w * h {
        return Err(SynthError::ExemplarBufferSize {
            width: w,
            height: h,
            found: image.pixels.len(),
        });
    }
    let min = options.neighbourhood * 2;
    if w < min || h < min {
        return Err(SynthError::ExemplarTooSmall { width: w, height: h, min });
    }
    // Coordinates are kept as `u16` in the correction's candidate table.
    let max = options.max_size.min(1 << 16);
    if w > max || h > max {
        return Err(SynthError::ExemplarTooLarge { width: w, height: h, max });
    }
    for (index, p) in image.pixels.iter().enumerate() {
        if let Some(&value) = p.iter().take(3).find(|v| !v.is_finite()) {
            return Err(SynthError::NonFiniteExemplar { index, x: index % w, y: index / w, value });
        }
    }
    let mut colors: Vec<[f32; 3]> = image.pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
    // The mask's grey value, stacked with the same filter as the colours (in channel 0).
    let mut feature: Option<Vec<[f32; 3]>> = mask.map(|m| {
        m.pixels.iter().map(|p| [((p[0] + p[1] + p[2]) / 3.0).clamp(0.0, 1.0), 0.0, 0.0]).collect()
    });
    let channels = if feature.is_some() { 4 } else { 3 };
    let mut levels = Vec::with_capacity(options.levels);
    for c in 0..options.levels {
        if c > 0 {
            colors = next_stack_level(&colors, w, h, c);
            feature = feature.map(|f| next_stack_level(&f, w, h, c));
        }
        let matched: Vec<[f32; 4]> = match &feature {
            Some(f) => colors
                .iter()
                .zip(f)
                .map(|(col, m)| [col[0], col[1], col[2], options.feature_weight * m[0]])
                .collect(),
            None => colors.iter().map(|col| [col[0], col[1], col[2], 0.0]).collect(),
        };
        let (pca, appearance) = neighbourhood_pca(&matched, channels, w, h, 1 << c, options, c)?;
        let basis: Vec<f32> = pca.components.iter().flatten().map(|&v| v as f32).collect();
        let bias: Vec<f32> = pca
            .components
            .iter()
            .map(|comp| comp.iter().zip(&pca.mean).map(|(a, b)| a * b).sum::<f64>() as f32)
            .collect();
        levels.push(PlaneLevel {
            colors: colors.clone(),
            matched,
            channels,
            pca,
            appearance,
            basis,
            bias,
        });
    }
    Ok(PlaneExemplar { width: w, height: h, levels })
}

/// The `N × N × ch` neighbourhood of `(x, y)` sampled `h` apart into `out` (the first
/// `ch` matched channels); the first pixel coordinate varies fastest
/// (`out[ch (N t + s) + k]` for offsets `(s, t)`).
#[allow(clippy::too_many_arguments)]
pub fn exemplar_neighbourhood(
    colors: &[[f32; 4]],
    ch: usize,
    w: usize,
    hgt: usize,
    h: usize,
    n: usize,
    x: usize,
    y: usize,
    out: &mut [f32],
) {
    let half = (n / 2) as i64;
    let mut k = 0;
    for t in -half..=half {
        let yy = (y as i64 + t * h as i64).rem_euclid(hgt as i64) as usize;
        for s in -half..=half {
            let xx = (x as i64 + s * h as i64).rem_euclid(w as i64) as usize;
            out[k..k + ch].copy_from_slice(&colors[yy * w + xx][..ch]);
            k += ch;
        }
    }
}

fn neighbourhood_pca(
    colors: &[[f32; 4]],
    ch: usize,
    w: usize,
    hgt: usize,
    h: usize,
    options: &SolidAnalysisOptions,
    level: usize,
) -> Result<(Pca, Vec<f32>), SynthError> {
    let n = options.neighbourhood;
    let dim = n * n * ch;
    let count = w * hgt;
    let stride = count.div_ceil(8192).max(1);
    let picks: Vec<usize> = (0..count).step_by(stride).collect();
    let mut samples = vec![0.0f32; picks.len() * dim];
    samples.par_chunks_mut(dim).zip(&picks).for_each(|(row, &p)| {
        exemplar_neighbourhood(colors, ch, w, hgt, h, n, p % w, p / w, row);
    });
    let k = options.pca_dims.min(dim);
    let pca = Pca::fit(&samples, dim, k).map_err(|source| SynthError::Pca { level, source })?;
    let mut appearance = vec![0.0f32; count * k];
    appearance.par_chunks_mut(k).enumerate().for_each(|(p, out)| {
        let mut buf = vec![0.0f32; dim];
        exemplar_neighbourhood(colors, ch, w, hgt, h, n, p % w, p / w, &mut buf);
        pca.project(&buf, out);
    });
    Ok((pca, appearance))
}
