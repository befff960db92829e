//! Options of the parallel synthesis ([`crate::synthesize`]) and their validation.

use crate::SynthError;
use crate::color_lookup::ColorFilter;
use crate::exemplar_analysis::ExemplarAnalysis;

/// Largest k-coherence count the engine uses (the analysis may store more).
pub(crate) const MAX_K: usize = 8;

/// Options of [`crate::synthesize`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SynthesisOptions {
    /// Seed of the initialisation and jitter streams. Default 0.
    pub seed: u64,
    /// Correction passes per level (level 1 only when [`Self::finest_passes`] and
    /// [`Self::coarse_passes`] are set, as by default). Default 6: coarse levels hold a quarter of the samples, and extra passes
    /// there settle the layout (measured: lower patch coherence distance on stripes,
    /// weave and bands exemplars than 2 passes; 6 instead of 4 lowered the guided
    /// coherence on the whorl preset for weave-diagonal .00376 → .00340, stripes .00137
    /// → .00130, bands .00050 → .00048, woodgrain .000076 → .000074, for ≈ 80 ms more:
    /// 544 → 626 ms median of 7 at 512², load ≈ 3.5; `examples/orient_probe`).
    pub correction_passes: usize,
    /// Correction passes at the finest level (`None`: [`Self::correction_passes`]). The
    /// finest level holds three quarters of the samples and dominates the cost.
    /// Default `Some(2)` (Lefebvre & Hoppe 2005 use 2 passes).
    #[serde(default = "default_finest_passes")]
    pub finest_passes: Option<usize>,
    /// Correction passes on levels `c ≥ 2` (`None`: [`Self::correction_passes`]). These
    /// levels hold 1/16 of the finest samples and less, so passes there are cheap
    /// (≈ 10 % of the synthesis time for 6 passes at 512²). Default `Some(12)`: with
    /// [`Self::trapezoid_frames`], 6 → 12 lowered the guided coherence on
    /// weave-diagonal left-loop / whorl / tented-arch (seeds 1, 2) .00319 / .00347 /
    /// .00331 → .00302 / .00315 / .00298 and at a constant 0° .00240 → .00214; 16 was
    /// not better than 12 (`examples/orient_probe`, stride 8, load ≈ 2).
    #[serde(default = "default_coarse_passes")]
    pub coarse_passes: Option<usize>,
    /// With [`Self::rosy_fix`]: every frame offset is integrated with the trapezoid
    /// rule, the mean of the frames at both ends of the offset. A prediction of `p` by
    /// its neighbour `q = p + δ` becomes `S[q] − h ½(F(q) + (−1)^α J(p)) δ` (Lefebvre &
    /// Hoppe 2006 §6 use `J(p)`, paper D §4 `J(q)` with the flip; either is exact only
    /// for a constant field, the mean is exact to second order in the field's turn
    /// between the two samples), and a child at offset `o` from its parent gets
    /// `S[parent] + h ½(F(parent) + ±J(child)) o` (`±`: the child's representative
    /// sign-aligned with the parent's effective frame). On curved fields the eight
    /// predictions of a coherent patch then agree better, so the four-corner
    /// neighbourhoods are sharper. Default true: guided coherence, weave-diagonal
    /// left-loop / whorl / tented-arch over seeds 1–3, lower in 7 of 8 runs (−4 % on
    /// average, e.g. left-loop seed 3 .00341 → .00315); stripes whorl with
    /// [`Self::coarse_passes`] 12: .00144 → .00100. Without the 2-RoSy fix the engine
    /// keeps `J(p)` and the parent's `J` (plain Lefebvre & Hoppe 2006).
    #[serde(default = "default_true")]
    pub trapezoid_frames: bool,
    /// With [`Self::rosy_fix`], on 2-D domains: where the field curves, each corner of
    /// the output's four-corner neighbourhood is read along its predicting neighbour's
    /// frame (the corner offset turned from `p`'s frame to the neighbour segment's,
    /// [`mod@crate::warped_neighbourhood`]) instead of in `p`'s own frame. Where the
    /// field is constant the reads, and so the results, are unchanged.
    /// Default false: on bands-fingerprint-like whorl it left the guided coherence at
    /// 0.000456 and raised the phase defects 757 → 858 (`examples/orient_probe --warp`,
    /// seed 1; docs/real-exemplars.md).
    #[serde(default)]
    pub warped_corners: bool,
    /// Subpasses per correction pass: 4 (2×2 interleaving, Lefebvre & Hoppe 2005 §3.4)
    /// or 1 (all samples at once from the previous state). Default 4.
    pub subpasses: usize,
    /// Jitter amplitude as a fraction of the level spacing. Default 0.4.
    pub jitter: f32,
    /// Number of finest levels synthesised without jitter (level `c` is jittered when
    /// `c ≥ unjittered_levels`; Lefebvre & Hoppe 2005 §3.2 give every level its own
    /// jitter amplitude and note that fine levels need little). Finest-level jitter
    /// gives every sample its own sub-pixel phase, which breaks pixel-exact coherence
    /// that the correction passes then only partly restore. Default 1: with cubic
    /// colours it lowered the guided coherence on 10 of 12 (exemplar × whorl, left-loop,
    /// constant 0°) cases, e.g. weave-diagonal whorl .00399 → .00376, stripes left-loop
    /// .00139 → .00130 (`examples/orient_probe`, stride 16, seed 1, load ≈ 2.5).
    #[serde(default = "default_unjittered_levels")]
    pub unjittered_levels: usize,
    /// k-coherence candidates used per neighbour (at most the analysis' k). Default 2.
    pub k: usize,
    /// Whether the k-coherence jumps of the sample's own coordinate join the candidate
    /// set (the `δ = 0` entry of the 3×3 set of Lefebvre & Hoppe 2005 §3.3). Default true.
    #[serde(default = "default_true")]
    pub own_candidates: bool,
    /// Multiplier of every domain Jacobian (exemplar pixels per domain sample on top
    /// of the domain's own scale). Default 1.
    pub scale: f32,
    /// Paper D §4 2-RoSy handling (flip indicator, rotated appearance space). Default
    /// true; false is the ablation `--no-rosy-fix`.
    pub rosy_fix: bool,
    /// With [`Self::rosy_fix`]: start from *combed* flip indicators instead of all
    /// zeros — on the initialisation level each sample takes the flip that makes its
    /// effective frame `(−1)^I J` agree with the neighbour that reached it first in a
    /// breadth-first sweep, so representative jumps that are not forced by a
    /// singularity are gone before synthesis starts (paper D leaves the initial `I`
    /// open). Default true.
    #[serde(default = "default_true")]
    pub comb_flips: bool,
    /// With [`Self::rosy_fix`]: corrections keep each sample's flip indicator — only
    /// candidates with `α = I(p)` are considered (a restriction of the candidate set of
    /// paper D §4, where the winner's `α` replaces `I(p)`); flips still change through
    /// the upsampling consistency bits `c_{L,L+1}`. Free flips let the boundaries
    /// between flipped and unflipped regions wander during the corrections: on the
    /// whorl preset with the stripes exemplar they grew to 13 853 effective-frame seam
    /// pairs against the field's own 463 representative jumps, each one a break of the
    /// texture; kept flips leave 483. Default true.
    #[serde(default = "default_true")]
    pub keep_flips: bool,
    /// How coordinates become colours ([`mod@crate::color_lookup`]). Default
    /// [`ColorFilter::Cubic`].
    #[serde(default)]
    pub color_filter: ColorFilter,
    /// Integer initial coordinates and jitter offsets rounded to whole pixels
    /// (Lefebvre & Hoppe 2005 §3.2 quantise the jitter the same way). For axis-aligned
    /// frames the upsampling offsets `h J o` are then whole pixels on every coarse level
    /// and `±½` on the finest, so finest coordinates sit on pixel centres and the cubic
    /// lookup returns exemplar pixels unchanged. Default true: guided coherence lower in
    /// 19 of 20 (exemplar × preset) cases, e.g. weave-diagonal arch .00336 → .00284,
    /// woodgrain arch .000073 → .000067, stripes left-loop .00137 → .00123; with a
    /// constant 0° field (unguided) weave .00307 → .00222, bands .000362 → .000265,
    /// woodgrain .000062 → .000044 (Embark `texture-synthesis`: .0026, .00024,
    /// .000039); `examples/orient_probe`, stride 16, seed 1, load ≈ 2.
    #[serde(default = "default_true")]
    pub snap_coordinates: bool,
    /// Initial coordinates integrated from the effective frames over the
    /// initialisation level (least squares, [`mod@crate::integrated_coordinates`]) plus
    /// one seeded offset, instead of an independent random coordinate per sample
    /// (Lefebvre & Hoppe 2005 §3.1). Default false.
    #[serde(default)]
    pub integrated_init: bool,
    /// With [`Self::integrated_init`]: the largest relative misfit of the integral
    /// (`|U(q) − U(p) − h F̄ δ| / |h F̄ δ|`) at which a sample, and all its neighbours,
    /// follow it. Default `f32::MAX` (no bound; finite so that it serialises): every sample follows the integral except those next
    /// to a forced seam (measured: a finite bound, 0.1 or 0.25, made the arch preset
    /// worse and the designs with singularities no better; docs/real-exemplars.md).
    #[serde(default = "default_integrated_trust")]
    pub integrated_trust: f32,
    /// With [`Self::integrated_init`]: the finest levels on which the trusted samples
    /// are corrected too (coarser levels correct only the others). Default 1.
    #[serde(default = "default_one")]
    pub integrated_free_levels: usize,
}

impl Default for SynthesisOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            correction_passes: 6,
            finest_passes: default_finest_passes(),
            coarse_passes: default_coarse_passes(),
            trapezoid_frames: true,
            warped_corners: false,
            subpasses: 4,
            jitter: 0.4,
            unjittered_levels: default_unjittered_levels(),
            own_candidates: true,
            k: 2,
            scale: 1.0,
            rosy_fix: true,
            comb_flips: true,
            keep_flips: true,
            color_filter: ColorFilter::Cubic,
            snap_coordinates: true,
            integrated_init: false,
            integrated_trust: default_integrated_trust(),
            integrated_free_levels: 1,
        }
    }
}

fn default_finest_passes() -> Option<usize> {
    Some(2)
}

fn default_coarse_passes() -> Option<usize> {
    Some(12)
}

fn default_integrated_trust() -> f32 {
    f32::MAX
}

fn default_one() -> usize {
    1
}

fn default_true() -> bool {
    true
}

fn default_unjittered_levels() -> usize {
    1
}

pub(crate) fn validate(
    options: &SynthesisOptions,
    analysis: &ExemplarAnalysis,
) -> Result<(), SynthError> {
    let bad = |name, value: f64, reason| Err(SynthError::InvalidOption { name, value, reason });
    if options.correction_passes > 16 {
        return bad("correction_passes", options.correction_passes as f64, "must be at most 16");
    }
    if let Some(f) = options.finest_passes
        && f > 16
    {
        return bad("finest_passes", f as f64, "must be at most 16");
    }
    if let Some(c) = options.coarse_passes
        && c > 32
    {
        return bad("coarse_passes", c as f64, "must be at most 32");
    }
    if options.subpasses != 1 && options.subpasses != 4 {
        return bad("subpasses", options.subpasses as f64, "must be 1 or 4 (2×2 interleaving)");
    }
    if !(options.jitter.is_finite() && (0.0..=4.0).contains(&options.jitter)) {
        return bad(
            "jitter",
            options.jitter as f64,
            "must be in [0, 4] (fraction of the level spacing)",
        );
    }
    if options.k > analysis.k().min(MAX_K) {
        return bad(
            "k",
            options.k as f64,
            "must not exceed the k of the exemplar analysis (nor 8)",
        );
    }
    if !(options.scale.is_finite() && options.scale > 0.0) {
        return bad("scale", options.scale as f64, "must be a positive finite number");
    }
    Ok(())
}
