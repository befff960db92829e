//! The parallel engine ([`crate::parallel_synthesis`]) over a 3-D lattice: a voxel
//! volume whose samples carry 2-D exemplar coordinates (what a rank-2 Jacobian makes of
//! a 2-D exemplar in 3-D: [`crate::lattice_domain`]). The same code as the 2-D
//! synthesis, instantiated for 26 neighbours and 8 subpass classes; the same options,
//! seed streams and determinism (bit-identical for any thread count), and the same
//! requested-subset evaluation (Lefebvre & Hoppe 2005's window property, here for a
//! box of voxels).

use fieldtex_core::Progress;

use crate::SynthError;
use crate::exemplar_analysis::ExemplarAnalysis;
use crate::lattice_domain::LatticeDomain;
use crate::parallel_synthesis::{
    SubsetSynthesis, SynthesisOptions, avx2_available, max_candidates, synthesize_with,
};

/// Synthesises the voxels `requested` (all when `None`, in index order; x fastest) of a
/// 3-D lattice from the analysed 2-D exemplar. The result type is the 2-D subset's
/// ([`SubsetSynthesis`]: the voxels, their colours, coordinates, flips and the
/// dependency-set sizes). `options.subpasses == 4` means interleaved subpasses (the
/// lattice's 2³ classes), 1 all voxels at once. Errors as [`crate::synthesize`], and
/// on a requested index outside the finest level.
pub fn synthesize_volume(
    analysis: &ExemplarAnalysis,
    domain: &dyn LatticeDomain<3>,
    options: &SynthesisOptions,
    requested: Option<&[usize]>,
    progress: &dyn Progress,
) -> Result<SubsetSynthesis, SynthError> {
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
    Ok(run.subset(analysis, samples, options.color_filter))
}
