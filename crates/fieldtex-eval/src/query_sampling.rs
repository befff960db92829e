//! Seeded cluster sampling of query patches, and the standard error of the sampled
//! mean: how the default nearest-patch metrics estimate a mean over every patch of a
//! large image from a few thousand of them.
//!
//! The sample is made of short horizontal *runs* of [`RUN_LENGTH`] consecutive patch
//! positions, each run starting at a uniformly drawn position (a seeded hash of the run
//! number, so the sample is a pure function of the seed and the image size, whatever
//! the thread count). Runs rather than single positions keep the coherent candidate of
//! the approximate search useful (the match of the previous patch, shifted by one
//! pixel: Ashikhmin 2001), which makes each query as accurate as in a full scan.
//!
//! The estimate of the mean is the mean over all sampled patches. Patches in one run
//! are correlated, so the standard error is computed from the run means treated as
//! independent draws (one-stage cluster sampling with equal cluster sizes and
//! replacement; Cochran 1977, *Sampling Techniques*, §9.2, eq. 9.6 without the finite
//! population correction, which only makes it conservative):
//! `SE = sd(run means) / sqrt(runs)`. Unlike a regular sub-grid, a random sample cannot
//! alias with a texture's period (the step-4 grid measured −12 to −18 % on the test
//! patchworks, `docs/perf/orient.md`).

use fieldtex_core::rng::hash_unit;

/// Consecutive patch positions per sampled run.
pub const RUN_LENGTH: usize = 4;

/// Patch indices (row-major over a `cols × rows` grid of positions) of `runs` seeded
/// runs of [`RUN_LENGTH`] positions along x, grouped run by run; every position of
/// the grid, in order, when the runs would cover at least as many patches as the grid
/// holds or when the grid is narrower than a run (then the mean is exact over the
/// grid and [`run_standard_error`] is 0). `stream` separates independent samples.
pub fn sampled_runs(cols: usize, rows: usize, runs: usize, seed: u64, stream: &str) -> Vec<usize> {
    let count = cols * rows;
    if runs * RUN_LENGTH >= count || cols < RUN_LENGTH || runs == 0 {
        return (0..count).collect();
    }
    let starts_x = cols - RUN_LENGTH + 1;
    let mut out = Vec::with_capacity(runs * RUN_LENGTH);
    for r in 0..runs as u64 {
        let x = ((hash_unit(seed, stream, 2 * r) * starts_x as f64) as usize).min(starts_x - 1);
        let y = ((hash_unit(seed, stream, 2 * r + 1) * rows as f64) as usize).min(rows - 1);
        out.extend((0..RUN_LENGTH).map(|t| y * cols + x + t));
    }
    out
}

/// Standard error of the mean of `values` (already normalised) taken as consecutive
/// runs of [`RUN_LENGTH`] (module docs); 0 for fewer than two runs or when `values` is
/// not a whole number of runs (the whole-grid case of [`sampled_runs`]).
pub fn run_standard_error(values: &[f64], whole_grid: bool) -> f64 {
    if whole_grid || !values.len().is_multiple_of(RUN_LENGTH) {
        return 0.0;
    }
    let means: Vec<f64> =
        values.chunks_exact(RUN_LENGTH).map(|c| c.iter().sum::<f64>() / c.len() as f64).collect();
    let m = means.len();
    if m < 2 {
        return 0.0;
    }
    let mu = means.iter().sum::<f64>() / m as f64;
    let var = means.iter().map(|v| (v - mu) * (v - mu)).sum::<f64>() / (m - 1) as f64;
    (var / m as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_stay_inside_the_grid_and_depend_only_on_the_seed() {
        let a = sampled_runs(50, 40, 100, 7, "q");
        assert_eq!(a.len(), 100 * RUN_LENGTH);
        assert_eq!(a, sampled_runs(50, 40, 100, 7, "q"));
        assert_ne!(a, sampled_runs(50, 40, 100, 8, "q"));
        for run in a.chunks_exact(RUN_LENGTH) {
            let (y0, x0) = (run[0] / 50, run[0] % 50);
            assert!(x0 + RUN_LENGTH <= 50 && y0 < 40);
            assert!(run.windows(2).all(|w| w[1] == w[0] + 1));
        }
        assert_eq!(sampled_runs(10, 10, 1000, 1, "q"), (0..100).collect::<Vec<_>>());
    }

    #[test]
    fn standard_error_matches_the_spread_of_run_means() {
        // Two kinds of runs, alternating: run means 0 and 2, so sd = sqrt(4·m/(4(m−1))).
        let m = 10;
        let v: Vec<f64> =
            (0..m).flat_map(|r| std::iter::repeat_n((r % 2 * 2) as f64, RUN_LENGTH)).collect();
        let expected = ((m as f64) / (m as f64 - 1.0)).sqrt() / (m as f64).sqrt();
        assert!((run_standard_error(&v, false) - expected).abs() < 1e-12);
        assert_eq!(run_standard_error(&v, true), 0.0);
    }
}
