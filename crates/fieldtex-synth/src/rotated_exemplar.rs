//! Synthesis against a pre-rotated copy of the exemplar, so that a rotated design copies
//! whole pixels.
//!
//! The anisometric synthesis (Lefebvre & Hoppe 2006 §6; paper D §4) keeps continuous
//! exemplar coordinates: in a region whose frame `J` is a rotation by `θ ∉ {0°, 90°, …}`
//! every coordinate has its own sub-pixel phase, the appearance vectors it is compared
//! with are those of the pixel containing it, and its colour is resampled
//! ([`crate::color_lookup`]). Lefebvre & Hoppe 2006 §6 and paper D note that the
//! exemplar can instead be stored at a few orientations; this module is that idea for
//! one angle: the exemplar is resampled *once* into a copy `E_θ` turned by `θ`
//! (`E_θ(v) = E(R v)`, `R` the frame of a unit field at `θ`, cubic colours), the copy is
//! analysed like any exemplar, and the synthesis runs on the residual frames `R⁻¹ J(p)`
//! (the identity where the field is at `θ`). Inside a coherent patch the output then
//! repeats pixels of `E_θ` exactly, with the snapped coordinates of the unrotated case
//! ([`crate::SynthesisOptions::snap_coordinates`]); the synthesised coordinates are
//! mapped back through `R` so they stay coordinates of the original exemplar.
//!
//! One copy per synthesis (the angle given, e.g. a constant design's angle), not the
//! per-angle-bin copies a curved field would need: a sample whose frame is far from
//! `θ` gets a large residual rotation and is resampled as before. The copy wraps the
//! exemplar toroidally, as the engine's coordinates do: a non-tileable exemplar's
//! wrap seams show inside the copy (the synthesis avoids only the copy's own border).
//!
//! Not used by the pipelines: on the real exemplars (bands, stripes, a constant design
//! at 30°) it scored the same as the plain engine within seed noise, so resampling is
//! not what keeps rotated designs above the rotated-copy floor (measurements:
//! `docs/real-exemplars.md`, session 12). On a synthetic tileable stripe exemplar it
//! halves the guided coherence (`tests/rotated_exemplar.rs`).

use fieldtex_core::{Image, Progress};

use crate::SynthError;
use crate::color_lookup::{ColorFilter, color_lookup};
use crate::domain::ImageDomain;
use crate::exemplar_analysis::{AnalysisOptions, ExemplarAnalysis};
use crate::parallel_synthesis::{SynthesisOptions, SynthesisResult, synthesize};

/// The exemplar turned by an angle: pixel `(x, y)` of [`Self::image`] shows the
/// original exemplar at `R (x + ½, y + ½)` (wrapped).
#[derive(Clone, Debug, PartialEq)]
pub struct RotatedExemplar {
    /// The copy (the exemplar's size unless [`Self::with_size`] says otherwise).
    pub image: Image,
    /// `R = [c, s; −s, c]` (row-major), the frame of a unit field at the angle.
    frame: [f32; 4],
    /// The original exemplar's size.
    source: (f32, f32),
}

impl RotatedExemplar {
    /// The copy of the analysed exemplar for a field at `angle` radians (from +x, y
    /// down), colours read with `filter`, the exemplar's size.
    pub fn new(analysis: &ExemplarAnalysis, angle: f32, filter: ColorFilter) -> Self {
        Self::with_size(analysis, angle, filter, analysis.width(), analysis.height())
    }

    /// [`Self::new`] with a copy of `w × h` pixels (a larger copy holds more of the
    /// turned exemplar's periods, so its border band and wrap are a smaller share).
    pub fn with_size(
        analysis: &ExemplarAnalysis,
        angle: f32,
        filter: ColorFilter,
        w: usize,
        h: usize,
    ) -> Self {
        let (s, c) = angle.sin_cos();
        let source = (analysis.width() as f32, analysis.height() as f32);
        let mut this = Self {
            image: Image { width: w, height: h, pixels: Vec::with_capacity(w * h) },
            frame: [c, s, -s, c],
            source,
        };
        for y in 0..h {
            for x in 0..w {
                let u = this.to_exemplar([x as f32 + 0.5, y as f32 + 0.5]);
                this.image.pixels.push(color_lookup(analysis, u, filter));
            }
        }
        this
    }

    /// The original exemplar coordinate of copy coordinate `v`: `R v`, wrapped into
    /// `[0, W) × [0, H)`.
    pub fn to_exemplar(&self, v: [f32; 2]) -> [f32; 2] {
        let r = &self.frame;
        let u = [r[0] * v[0] + r[1] * v[1], r[2] * v[0] + r[3] * v[1]];
        let (w, h) = self.source;
        [wrap(u[0], w), wrap(u[1], h)]
    }

    /// The residual frame `R⁻¹ J = Rᵀ J` of a domain Jacobian `J` (row-major). Entries
    /// within 1e-5 of an integer are rounded to it, so a field at the copy's angle gets
    /// exactly the identity (and whole-pixel offsets) despite the rounding of `R`.
    pub fn residual(&self, j: [f32; 4]) -> [f32; 4] {
        let r = &self.frame;
        [
            r[0] * j[0] + r[2] * j[2],
            r[0] * j[1] + r[2] * j[3],
            r[1] * j[0] + r[3] * j[2],
            r[1] * j[1] + r[3] * j[3],
        ]
        .map(|x| if (x - x.round()).abs() < 1e-5 { x.round() } else { x })
    }
}

/// `x` wrapped into `[0, n)`.
fn wrap(x: f32, n: f32) -> f32 {
    let r = x.rem_euclid(n);
    if r >= n { 0.0 } else { r }
}

/// [`synthesize`] over `domain` against the exemplar pre-rotated by `angle`
/// ([`RotatedExemplar`], `copy_scale` × the exemplar's size): analyses the copy with `analysis_options`, runs the engine on
/// the residual frames and returns the result with coordinates of the original
/// exemplar (the colours and flips are the copy's, i.e. the same exemplar turned).
pub fn synthesize_rotated(
    analysis: &ExemplarAnalysis,
    analysis_options: &AnalysisOptions,
    domain: &ImageDomain,
    angle: f32,
    copy_scale: f32,
    options: &SynthesisOptions,
    progress: &dyn Progress,
) -> Result<SynthesisResult, SynthError> {
    let side = |n: usize| ((n as f32 * copy_scale).round() as usize).max(1);
    let (w, h) = (side(analysis.width()), side(analysis.height()));
    let copy = RotatedExemplar::with_size(analysis, angle, options.color_filter, w, h);
    let rotated = ExemplarAnalysis::new(&copy.image, analysis_options, progress)?;
    let jac = domain.jacobian.iter().map(|&j| copy.residual(j)).collect();
    let residual = ImageDomain::new(domain.width, domain.height, jac)?;
    let mut result = synthesize(&rotated, &residual, options, progress)?;
    for u in &mut result.coords {
        *u = copy.to_exemplar(*u);
    }
    Ok(result)
}
