//! Options of [`optimise`](crate::optimise) and the feature-alignment input.

use crate::TexOptError;
use serde::{Deserialize, Serialize};

/// Options of the surface texture optimisation; every field has a documented default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TexOptOptions {
    /// Patch widths `w` in exemplar pixels, coarse to fine; each a multiple of 8 (the
    /// descriptor is an 8 × 8 grid every `w/8` pixels). Default `[32, 16, 8]` (Kwatra
    /// et al. 2005 §3.1 use 32, 16, 8).
    pub patch_sizes: Vec<usize>,
    /// `h`: surface length of one exemplar pixel (surface units). Default `None`: the
    /// carrier spacing `sqrt(area / #C)`, i.e. one exemplar pixel per carrier.
    pub pixel_size: Option<f64>,
    /// `r` of paper A §5.1: samples are `r·w·h` apart. Default 0.25.
    pub sample_spacing_ratio: f64,
    /// Robust exponent of Kwatra et al. 2005 eq. 2: energy `Σ |x_p − z_p|^r`, IRLS
    /// weights `|x_p − z_p|^(r−2)`. Default 0.8.
    pub robust_exponent: f64,
    /// Search/blend iterations per patch size at most. Default 4.
    pub max_iterations: usize,
    /// Iterations of the levels with `w ≤ 16` at most (they start from upsampled,
    /// coherent sources and hold most carriers: the cost of `align`). Default 2
    /// (measured on fandisk, bricks 512², 512² atlas: see docs/real-exemplars.md).
    pub fine_iterations: usize,
    /// A level stops when at most this fraction of samples changed match. Default 0.01.
    pub converge_fraction: f64,
    /// Random exemplar candidates per sample and iteration (alternately uniform and in a
    /// shrinking window around the current match), at most 16. Default 6.
    pub random_candidates: usize,
    /// Neighbouring samples whose shifted matches are candidates. Default 8.
    pub coherence_neighbours: usize,
    /// PCA components of the 192-D descriptors for exhaustive search. Default 24.
    pub pca_components: usize,
    /// Exhaustive PCA search when `samples × positions` is at most this; above it, over
    /// a strided subset of positions of this many pairs in all (per iteration). Default
    /// 1.5 million.
    pub exact_search_budget: usize,
    /// Rotation (radians, counter-clockwise from `t` towards `b`) of the exemplar's `+x`
    /// axis relative to the field. Default 0: exemplar rows follow the field.
    pub exemplar_angle: f64,
    /// Treat the exemplar as tileable (wrapped lookups, every pixel a patch origin).
    /// Default false (patches stay inside the exemplar).
    pub toroidal: bool,
    /// Paper A §5.2 feature-to-feature alignment when a [`FeatureAlignment`] is given;
    /// false for the ablation. Default true.
    pub feature_align: bool,
    /// Accepted difference (exemplar pixels) between a sample's curve distance and a
    /// candidate centre's feature distance. Default 0.5: measured with `fieldtex align`
    /// (stripes, 512² atlas), feature coverage within one texel rose from 0.77 / 0.75 /
    /// 0.82 at 1.0 to 0.97 / 0.90 / 0.93 on fandisk / blub / rocker-arm, with the same
    /// orientation error.
    pub feature_threshold: f64,
    /// Carriers whose normal makes a cosine below this with the patch normal are not
    /// part of the patch (the other side of thin parts). Default 0.3.
    pub normal_cosine: f64,
    /// `σ` (patch grid units, one unit = `w/8` pixels) of the Gaussian falloff weighting
    /// patch pixels in the blend; `None` for Kwatra 2005's uniform patch weights (blurrier
    /// where overlapping matches disagree). Default `Some(1.5)`.
    pub blend_falloff: Option<f64>,
    /// Coherence bias `κ` (Ashikhmin 2001): the squared distance of random and PCA
    /// candidates is multiplied by `1 + κ`, so a sample leaves its own or a
    /// neighbour-continued patch only for a clearly better one. Without it, thin
    /// structures (mortar, cracks) that overlapping patches place slightly apart blend
    /// into faint lines that flat exemplar regions match as well, and fade level by
    /// level. Default 0.25.
    pub coherence_bias: f64,
    /// Crisp final pass: after the last iteration of the finest level each carrier
    /// takes the colour of the covering patch closest to the blended average instead of
    /// the average ([`robust_blend`](crate::robust_blend)). Default true; false keeps
    /// the softer least-squares blend.
    pub crisp: bool,
    /// Which covering patch a carrier shows in the crisp pass. Default
    /// [`CrispChoice::BestMatch`].
    pub crisp_choice: CrispChoice,
    /// Final colour step: match the RGB distribution of the carriers' colours to the
    /// exemplar's (n-D histogram transfer, Pitié, Kokaram & Dahyot 2005,
    /// `fieldtex_linalg::stats::match_histograms_nd`). Texture optimisation prefers flat
    /// exemplar regions, whose patches match blended neighbourhoods well (Kopf et al.
    /// 2007 §4 "histogram matching" name the same drift and reweight the blend by the
    /// histograms inside the loop; this one-shot transfer after the crisp pass is our
    /// substitute), so the result has less contrast than the exemplar. Colours then are
    /// monotone-ish remaps of exemplar pixels, no longer the pixels themselves; the
    /// sources are unchanged. Default true (measured on fandisk with the photo
    /// exemplars: docs/real-exemplars.md).
    pub histogram_match: bool,
    /// Seed of all random streams. Default 0.
    pub seed: u64,
}

/// How the crisp final pass ([`TexOptOptions::crisp`]) picks, per carrier, the covering
/// patch whose exemplar pixel it shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum CrispChoice {
    /// The best-matching patch: the largest blend weight (robust IRLS weight of its
    /// match times the centre falloff), i.e. the patch that matches best near its
    /// centre. Neighbouring carriers mostly share a patch, so each region is a whole
    /// exemplar copy (a Voronoi-like mosaic of the matches). Measured on fandisk with
    /// the photo exemplars: see docs/real-exemplars.md.
    #[default]
    BestMatch,
    /// The patch whose colour is closest to the weighted average among those with at
    /// least half the largest weight (ties: the larger weight). Picks the consensus
    /// per carrier, which pulls fine grain towards the mean (softer).
    Consensus,
}

impl Default for TexOptOptions {
    fn default() -> Self {
        Self {
            patch_sizes: vec![32, 16, 8],
            pixel_size: None,
            sample_spacing_ratio: 0.25,
            robust_exponent: 0.8,
            max_iterations: 4,
            fine_iterations: 2,
            converge_fraction: 0.01,
            random_candidates: 6,
            coherence_neighbours: 8,
            pca_components: 24,
            exact_search_budget: 1_500_000,
            exemplar_angle: 0.0,
            toroidal: false,
            feature_align: true,
            feature_threshold: 0.5,
            normal_cosine: 0.3,
            blend_falloff: Some(1.5),
            coherence_bias: 1.0,
            crisp: true,
            crisp_choice: CrispChoice::BestMatch,
            histogram_match: true,
            seed: 0,
        }
    }
}

impl TexOptOptions {
    pub fn with_patch_sizes(mut self, sizes: Vec<usize>) -> Self {
        self.patch_sizes = sizes;
        self
    }
    pub fn with_pixel_size(mut self, h: f64) -> Self {
        self.pixel_size = Some(h);
        self
    }
    pub fn with_max_iterations(mut self, n: usize) -> Self {
        self.max_iterations = n;
        self
    }
    pub fn with_fine_iterations(mut self, n: usize) -> Self {
        self.fine_iterations = n;
        self
    }
    pub fn with_exemplar_angle(mut self, radians: f64) -> Self {
        self.exemplar_angle = radians;
        self
    }
    pub fn with_feature_align(mut self, on: bool) -> Self {
        self.feature_align = on;
        self
    }
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Checks every field once, at the boundary.
    pub fn validate(&self) -> Result<(), TexOptError> {
        let bad =
            |name, value: f64, reason| Err(TexOptError::InvalidOption { name, value, reason });
        if self.patch_sizes.is_empty() {
            return bad("patch_sizes.len()", 0.0, "give at least one patch size");
        }
        if let Some(&w) = self.patch_sizes.iter().find(|&&w| w < 8 || w % 8 != 0 || w > 512) {
            return bad(
                "patch_sizes",
                w as f64,
                "each patch size must be a multiple of 8 between 8 and 512",
            );
        }
        if let Some(h) = self.pixel_size
            && !(h.is_finite() && h > 0.0)
        {
            return bad("pixel_size", h, "must be positive and finite");
        }
        let r = self.sample_spacing_ratio;
        if !(r.is_finite() && r > 0.0 && r <= 1.0) {
            return bad("sample_spacing_ratio", r, "must be in (0, 1]");
        }
        let e = self.robust_exponent;
        if !(e.is_finite() && e > 0.0 && e <= 2.0) {
            return bad("robust_exponent", e, "must be in (0, 2]");
        }
        if self.max_iterations == 0 {
            return bad("max_iterations", 0.0, "must be at least 1");
        }
        let c = self.converge_fraction;
        if !(c.is_finite() && (0.0..=1.0).contains(&c)) {
            return bad("converge_fraction", c, "must be in [0, 1]");
        }
        if self.pca_components == 0 {
            return bad("pca_components", 0.0, "must be at least 1");
        }
        if !self.exemplar_angle.is_finite() {
            return bad("exemplar_angle", self.exemplar_angle, "must be finite");
        }
        let t = self.feature_threshold;
        if !(t.is_finite() && t >= 0.0) {
            return bad("feature_threshold", t, "must be non-negative and finite");
        }
        if let Some(sigma) = self.blend_falloff
            && !(sigma.is_finite() && sigma > 0.0)
        {
            return bad("blend_falloff", sigma, "must be positive and finite (or None)");
        }
        let k = self.coherence_bias;
        if !(k.is_finite() && k >= 0.0) {
            return bad("coherence_bias", k, "must be non-negative and finite");
        }
        let n = self.normal_cosine;
        if !(n.is_finite() && (-1.0..=1.0).contains(&n)) {
            return bad("normal_cosine", n, "must be in [-1, 1]");
        }
        Ok(())
    }
}

/// Inputs of paper A §5.2 feature-to-feature alignment (plain arrays; the feature lines
/// and distances are computed elsewhere).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FeatureAlignment {
    /// `W × H` (row-major, exemplar size): distance in exemplar pixels from each pixel
    /// to the nearest exemplar feature line. Non-finite values mean "no feature".
    pub exemplar_distance: Vec<f32>,
    /// `#C`: surface (geodesic) distance from each carrier to the salient curves, in
    /// surface units. `+∞` for carriers the curves cannot reach; NaN is an error.
    pub carrier_curve_distance: Vec<f64>,
}

/// Coarse-to-fine patch widths for an exemplar whose largest structure is `structure`
/// pixels and whose shorter side is `min_side` pixels: `w_max, w_max/2, …, 8` with
/// `w_max` the smallest `8·2^k ≥ structure`, at least 32 (Kwatra et al. 2005's
/// `32, 16, 8`), at most 256 and at most half the shorter side (so that patches still
/// have room to move; never below 8 and never above `min_side`). Levels of step
/// `s = w/8` see the exemplar as its `s`-times reduced pyramid level, so the coarsest
/// patches span the largest structures.
pub fn pyramid_patch_sizes(structure: f64, min_side: usize) -> Vec<usize> {
    let fits = |w: usize| w <= 256 && 2 * w <= min_side;
    let mut cap = 8;
    while fits(cap * 2) {
        cap *= 2;
    }
    let cap = if min_side >= 32 { cap.max(32).min(min_side / 8 * 8) } else { 8 };
    let mut w_max = 32;
    while (w_max as f64) < structure && w_max * 2 <= cap {
        w_max *= 2;
    }
    let w_max = w_max.min(cap);
    let mut sizes = vec![w_max];
    while *sizes.last().unwrap_or(&8) > 8 {
        let next = sizes.last().unwrap_or(&8) / 2;
        sizes.push(next.max(8) / 8 * 8);
    }
    sizes
}

#[cfg(test)]
mod tests {
    use super::pyramid_patch_sizes;

    #[test]
    fn pyramid_patch_sizes_span_the_structure_within_the_exemplar() {
        assert_eq!(pyramid_patch_sizes(6.0, 116), vec![32, 16, 8]);
        assert_eq!(pyramid_patch_sizes(75.0, 512), vec![128, 64, 32, 16, 8]);
        assert_eq!(pyramid_patch_sizes(75.0, 200), vec![64, 32, 16, 8]);
        assert_eq!(pyramid_patch_sizes(900.0, 2048), vec![256, 128, 64, 32, 16, 8]);
        assert_eq!(pyramid_patch_sizes(40.0, 40), vec![32, 16, 8]);
    }
}
