//! The parallel engine ([`crate::parallel_synthesis`]) over a 3-D lattice: a voxel
//! volume whose samples carry 2-D exemplar coordinates (what a rank-2 Jacobian makes of
//! a 2-D exemplar in 3-D: [`crate::lattice_domain`]). The same code as the 2-D
//! synthesis, instantiated for 26 neighbours and 8 subpass classes; the same options,
//! seed streams and determinism (bit-identical for any thread count), and the same
//! requested-subset evaluation (Lefebvre & Hoppe 2005's window property, here for a
//! box of voxels).

use fieldtex_core::Progress;
use rayon::prelude::*;

use crate::SynthError;
use crate::color_lookup::color_lookup;
use crate::exemplar_analysis::ExemplarAnalysis;
use crate::lattice_domain::LatticeDomain;
use crate::parallel_synthesis::{
    SynthesisOptions, avx2_available, max_candidates, synthesize_with,
};

/// Result of [`synthesize_volume`] for the requested voxels (all of them, in index
/// order, when none were named).
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeSynthesis {
    /// The voxel indices the other fields describe (finest level, x fastest).
    pub samples: Vec<usize>,
    /// Exemplar colour of each voxel ([`SynthesisOptions::color_filter`]).
    pub colors: Vec<[f32; 4]>,
    /// Exemplar coordinate of each voxel, in `[0, W) × [0, H)`.
    pub coords: Vec<[f32; 2]>,
    /// Flip indicator of each voxel.
    pub flips: Vec<bool>,
    /// Voxels computed per level, finest first (the dependency sets' sizes with a
    /// request; the finest level's count otherwise).
    pub evaluated_per_level: Vec<usize>,
    /// Wall time per synthesis level, coarsest first, milliseconds.
    pub level_timings_ms: Vec<f64>,
}

/// Synthesises the voxels `requested` (all when `None`) of a 3-D lattice from the
/// analysed 2-D exemplar. `options.subpasses == 4` means interleaved subpasses (the
/// lattice's 2³ classes), 1 all voxels at once. Errors as [`crate::synthesize`], and
/// on a requested index outside the finest level.
pub fn synthesize_volume(
    analysis: &ExemplarAnalysis,
    domain: &dyn LatticeDomain<3>,
    options: &SynthesisOptions,
    requested: Option<&[usize]>,
    progress: &dyn Progress,
) -> Result<VolumeSynthesis, SynthError> {
    let n0 = domain.sample_count(0);
    if let Some(&bad) = requested.and_then(|r| r.iter().find(|&&r| r >= n0)) {
        return Err(SynthError::InvalidDomain {
            reason: format!("requested voxel {bad} ≥ finest voxel count {n0}"),
        });
    }
    let run = synthesize_with::<3, 26, { max_candidates(26) }>(
        analysis,
        domain,
        options,
        progress,
        avx2_available(),
        requested,
    )?;
    let samples: Vec<usize> = requested.map_or_else(|| (0..n0).collect(), <[usize]>::to_vec);
    let filter = options.color_filter;
    Ok(VolumeSynthesis {
        colors: samples
            .par_iter()
            .map(|&r| color_lookup(analysis, run.coords[r], filter))
            .collect(),
        coords: samples.iter().map(|&r| run.coords[r]).collect(),
        flips: samples.iter().map(|&r| run.flips[r]).collect(),
        samples,
        evaluated_per_level: run.evaluated_per_level,
        level_timings_ms: run.level_timings_ms,
    })
}
