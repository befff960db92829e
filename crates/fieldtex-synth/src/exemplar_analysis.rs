//! Exemplar analysis for parallel appearance-space synthesis: computed once per
//! exemplar and [`AnalysisOptions`], then shared by every synthesis run.
//!
//! Per Gaussian-stack level `c` (finest `c = 0`, spacing `h = 2^c`, `L = ⌈log₂ max(W,
//! H)⌉` levels; Lefebvre & Hoppe 2005 §3.1): the stack image, the 8-D appearance vectors
//! of the exemplar and of its 180° rotation (Lefebvre & Hoppe 2006 §3; paper D §4, see
//! [`crate::appearance_space`]), 8-bit copies of both for the synthesis, and the
//! k-coherence sets ([`crate::k_coherence`]).

use std::time::Instant;

use fieldtex_core::{Image, Progress};

use crate::SynthError;
use crate::appearance_space::appearance_space;
use crate::gaussian_stack::next_stack_level;
use crate::k_coherence::k_coherence;

/// Dimension of the appearance space (Lefebvre & Hoppe 2006 use 8).
pub const APPEARANCE_DIMS: usize = 8;

/// Smallest exemplar side accepted (a 5×5 neighbourhood plus a k-coherence exclusion
/// zone must fit).
pub const MIN_EXEMPLAR_SIZE: usize = 8;

/// Options of [`ExemplarAnalysis::new`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AnalysisOptions {
    /// k-coherence candidates stored per pixel and level. Default 2 (Lefebvre & Hoppe).
    pub k: usize,
    /// Exclusion radius of the k-coherence search at the finest level, in pixels
    /// (Chebyshev, toroidal); level `c` uses `max(radius, 2^c)` capped at a quarter of
    /// the shorter exemplar side. Default 3.
    pub coherence_radius: usize,
    /// Pixels each k-coherence query examines at most (see [`crate::k_coherence`]);
    /// `usize::MAX` makes the search exact. Default 256.
    pub coherence_scan: usize,
    /// Whether the exemplar tiles seamlessly. When false (the default: most photos do
    /// not tile), level `c` keeps synthesised coordinates at least
    /// `min(2^(c+1), min(W, H) / 8)` pixels from the exemplar border
    /// ([`AnalysisLevel::margin`]), so the exemplar's edges never show as seams.
    /// [`crate::exemplar_tiling`] tells whether an exemplar tiles.
    pub tileable: bool,
    /// The cap of the border margin of a non-tileable exemplar as a divisor of its
    /// shorter side: level `c` keeps `min(2^(c+1), min(W, H) / margin_divisor)` pixels
    /// (at least 1). Default 8. A larger divisor lets the coarse levels use more of a
    /// small exemplar (on a 124² exemplar the default removes up to 43 % of the
    /// positions); measured in docs/real-exemplars.md "session 13" (not adopted).
    #[serde(default = "default_margin_divisor")]
    pub margin_divisor: usize,
    /// Largest accepted exemplar side; larger exemplars are refused with
    /// [`SynthError::ExemplarTooLarge`]. Default
    /// [`MAX_EXEMPLAR_SIDE`](crate::MAX_EXEMPLAR_SIDE) (pipelines reduce larger ones
    /// first, [`crate::exemplar_policy`]).
    pub max_size: usize,
}

fn default_margin_divisor() -> usize {
    8
}

impl Default for AnalysisOptions {
    fn default() -> Self {
        Self {
            k: 2,
            coherence_radius: 3,
            coherence_scan: 256,
            tileable: false,
            margin_divisor: default_margin_divisor(),
            max_size: crate::MAX_EXEMPLAR_SIDE,
        }
    }
}

/// Analysis data of one stack level.
#[derive(Clone, Debug, PartialEq)]
pub struct AnalysisLevel {
    /// Sampling spacing `h = 2^c` of the level, exemplar pixels.
    pub spacing: usize,
    /// Border band (pixels) the synthesis avoids at this level; 0 for tileable exemplars.
    pub margin: usize,
    /// k-coherence sets, `W × H × k` pixel indices, best first (valid for both copies).
    pub coherence: Vec<u32>,
    /// Share of the 5×5-neighbourhood variance kept by the 8 components.
    pub explained_variance: f64,
    /// Appearance of each pixel (`W × H`) for the unrotated exemplar (`Ẽ₀`, `data[0]`)
    /// and for each pixel's 180°-rotated neighbourhood stored at the unrotated
    /// coordinate (`Ẽ₁`, `data[1]`), quantised to 8 bits: 8 bytes per vector keep the
    /// synthesis' random lookups in cache and the analysis of a 1024² exemplar small.
    pub appearance_q: QuantizedVectors,
}

/// Two sets of 8-D vectors quantised with one common scale: `value ≈ q / scale`.
#[derive(Clone, Debug, PartialEq)]
pub struct QuantizedVectors {
    pub scale: f32,
    pub data: [Vec<[i8; APPEARANCE_DIMS]>; 2],
}

impl QuantizedVectors {
    /// Vector `i` of set `set` (0 or 1), de-quantised.
    pub fn get(&self, set: usize, i: usize) -> [f32; APPEARANCE_DIMS] {
        self.data[set][i].map(|q| q as f32 / self.scale)
    }
}

impl QuantizedVectors {
    /// Quantises `a` and `b` with the scale `127 / max |component|` (1 if all zero).
    pub fn new(a: &[[f32; APPEARANCE_DIMS]], b: &[[f32; APPEARANCE_DIMS]]) -> Self {
        let max = a.iter().chain(b).flatten().fold(0.0f32, |m, v| m.max(v.abs()));
        let scale = if max > 0.0 { 127.0 / max } else { 1.0 };
        let q = |v: &[[f32; APPEARANCE_DIMS]]| -> Vec<[i8; APPEARANCE_DIMS]> {
            v.iter().map(|x| x.map(|c| (c * scale).round().clamp(-127.0, 127.0) as i8)).collect()
        };
        Self { scale, data: [q(a), q(b)] }
    }
}

/// The exemplar and its per-level analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct ExemplarAnalysis {
    width: usize,
    height: usize,
    k: usize,
    /// Exemplar pixels (RGBA, sRGB-encoded), `W × H`.
    colors: Vec<[f32; 4]>,
    levels: Vec<AnalysisLevel>,
    /// Wall time of the analysis, milliseconds.
    pub elapsed_ms: f64,
}

impl ExemplarAnalysis {
    /// Analyses `exemplar` (any size from [`MIN_EXEMPLAR_SIZE`] to
    /// `options.max_size` per side, power of two or not). Colours are taken as stored
    /// (sRGB-encoded RGB; alpha is ignored).
    pub fn new(
        exemplar: &Image,
        options: &AnalysisOptions,
        progress: &dyn Progress,
    ) -> Result<Self, SynthError> {
        let start = Instant::now();
        let (width, height) = (exemplar.width, exemplar.height);
        if exemplar.pixels.len() != width * height {
            return Err(SynthError::ExemplarBufferSize {
                width,
                height,
                found: exemplar.pixels.len(),
            });
        }
        if width < MIN_EXEMPLAR_SIZE || height < MIN_EXEMPLAR_SIZE {
            return Err(SynthError::ExemplarTooSmall { width, height, min: MIN_EXEMPLAR_SIZE });
        }
        if width > options.max_size || height > options.max_size {
            return Err(SynthError::ExemplarTooLarge { width, height, max: options.max_size });
        }
        if options.k == 0 || options.k > 16 {
            return Err(SynthError::InvalidOption {
                name: "AnalysisOptions::k",
                value: options.k as f64,
                reason: "must be between 1 and 16",
            });
        }
        for (index, p) in exemplar.pixels.iter().enumerate() {
            if let Some(&value) = p.iter().find(|v| !v.is_finite()) {
                return Err(SynthError::NonFiniteExemplar {
                    index,
                    x: index % width,
                    y: index / width,
                    value,
                });
            }
        }
        let rgb: Vec<[f32; 3]> = exemplar.pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
        let n_levels = (width.max(height) as f64).log2().ceil() as usize;
        progress.stage("exemplar analysis", n_levels as u64);
        let mut levels = Vec::with_capacity(n_levels);
        let mut level_img = rgb;
        for c in 0..n_levels {
            if c > 0 {
                level_img = next_stack_level(&level_img, width, height, c);
            }
            let spacing = 1usize << c;
            let space = appearance_space(&level_img, width, height, spacing, c)?;
            let radius = options.coherence_radius.max(spacing).min(width.min(height) / 4).max(1);
            let cap = width.min(height) / options.margin_divisor.max(1);
            let margin = if options.tileable { 0 } else { (2 * spacing).min(cap).max(1) };
            let coherence = k_coherence(
                &space.unrotated,
                width,
                height,
                options.k,
                radius,
                options.coherence_scan,
                margin,
            );
            let appearance_q = QuantizedVectors::new(&space.unrotated, &space.rotated);
            levels.push(AnalysisLevel {
                spacing,
                margin,
                appearance_q,

                coherence,
                explained_variance: space.explained_variance,
            });
            progress.advance(1);
        }
        progress.finish_stage();
        Ok(Self {
            width,
            height,
            k: options.k,
            colors: exemplar.pixels.clone(),
            levels,
            elapsed_ms: start.elapsed().as_secs_f64() * 1e3,
        })
    }

    /// Exemplar width, pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Exemplar height, pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Number of stack levels `L = ⌈log₂ max(W, H)⌉`.
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// k-coherence candidates stored per pixel.
    pub fn k(&self) -> usize {
        self.k
    }

    /// Level `c` (0 = finest).
    pub fn level(&self, c: usize) -> &AnalysisLevel {
        &self.levels[c]
    }

    /// Exemplar pixels (`W × H`, RGBA).
    pub fn colors(&self) -> &[[f32; 4]] {
        &self.colors
    }

    /// Pixel index shown at continuous exemplar coordinate `u` (wrapped toroidally).
    #[inline]
    pub fn pixel_at(&self, u: [f32; 2]) -> usize {
        let x = (u[0].floor() as i64).rem_euclid(self.width as i64) as usize;
        let y = (u[1].floor() as i64).rem_euclid(self.height as i64) as usize;
        y * self.width + x
    }

    /// Exemplar colour at continuous coordinate `u` (nearest pixel, wrapped).
    pub fn color_at(&self, u: [f32; 2]) -> [f32; 4] {
        self.colors[self.pixel_at(u)]
    }
}
