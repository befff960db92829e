//! Source coverage: completeness read from a synthesis's own exemplar coordinates,
//! without any patch search.
//!
//! A pixel-copying synthesis (the appearance-space synthesis of Lefebvre & Hoppe 2006,
//! and `fieldtex orient`, which writes `coords.npy`) knows which exemplar pixel each
//! output pixel copies. The *sources* are those exemplar pixels: `S = { round(c(p)) }`
//! over output pixels `p`, wrapped on the exemplar torus when the exemplar tiles. For
//! every exemplar position `q` (a patch centre; all `W·H` positions of a tiling
//! exemplar, else those whose `N×N` patch lies inside it) let `d(q)` be the Euclidean
//! distance, in exemplar pixels, from `q` to the nearest source (toroidal when tiling).
//! The report gives
//! - `covered_share`: the share of exemplar patches with `d(q) ≤ r` (default `r = ⌊N/2⌋`,
//!   the patch half-width: some output pixel copies a pixel inside the central
//!   `(2r+1)`-disc of that patch), and `copied_share`, the same at `r = 0`;
//! - the mean and largest `d(q)`: how far the output's sources stay from the parts of
//!   the exemplar it never uses.
//!
//! **Relation to the search-based completeness** ([`crate::completeness()`], Simakov et
//! al. 2008: the mean over exemplar patches of the distance to the nearest output
//! patch). Coverage answers "did the synthesis copy from here", completeness "does this
//! appearance occur in the output". They agree on what completeness is meant to catch,
//! an output that repeats only part of its exemplar, and differ in two ways: (1) a patch
//! whose appearance repeats elsewhere in the exemplar (a periodic texture) is complete
//! without being covered, so coverage is stricter on repetitive exemplars; (2) coverage
//! cannot see a covered region whose neighbourhood is broken (a seam through it): that
//! is what coherence measures. It is rotation-invariant (a region copied along a
//! turning field still counts), where the search-based value compares axis-aligned
//! patches only. The measured relation on the test exemplars is in
//! `tests/source_coverage.rs` and `docs/perf/orient.md`.
//!
//! The distances are exact: the squared Euclidean distance transform of Felzenszwalb &
//! Huttenlocher (2012, "Distance transforms of sampled functions", Theory of Computing
//! 8, §2), toroidal on a tiling exemplar (`fieldtex_features::distance_transform`).

use crate::EvalError;
use fieldtex_features::squared_distance_transform;
use serde::Serialize;

/// Options of [`source_coverage`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SourceCoverageOptions {
    /// Patch side `N` (sets the default radius and, without wrapping, the valid patch
    /// centres). Default 7, as the search-based metrics.
    pub patch_size: usize,
    /// Covered radius `r` in exemplar pixels; `None` = `⌊N/2⌋`. Default `None`.
    pub radius: Option<f64>,
    /// The exemplar tiles: coordinates wrap and every position is a patch centre.
    /// Default true (what `orient` synthesises with).
    pub wrap_exemplar: bool,
}

impl Default for SourceCoverageOptions {
    fn default() -> Self {
        Self { patch_size: 7, radius: None, wrap_exemplar: true }
    }
}

/// Result of [`source_coverage`] (module docs for the definitions).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SourceCoverageReport {
    /// Share of exemplar patches whose centre is within `radius_px` of a source.
    pub covered_share: f64,
    /// Share of exemplar patches whose centre pixel itself is copied (radius 0).
    pub copied_share: f64,
    /// Mean distance (exemplar pixels) from an exemplar patch centre to the nearest
    /// source.
    pub mean_distance_px: f64,
    /// Largest such distance: the radius of the biggest unused part of the exemplar.
    pub max_distance_px: f64,
    pub radius_px: f64,
    /// Exemplar patch centres measured.
    pub exemplar_patches: usize,
    /// Distinct exemplar pixels copied.
    pub source_pixels: usize,
    /// Output pixels whose coordinate fell outside a non-tiling exemplar (ignored).
    pub outside: usize,
    pub patch_size: usize,
}

/// Source coverage of an output whose pixels copy the exemplar pixels `coords`
/// (`[x, y]` pairs, exemplar pixels, one pair per output pixel; `coords.npy` flattened)
/// from an exemplar of `exemplar_size = [W, H]` pixels. Errors on non-finite
/// coordinates, an odd-length buffer, no coordinates, or an exemplar smaller than a
/// patch.
pub fn source_coverage(
    coords: &[f32],
    exemplar_size: [usize; 2],
    options: &SourceCoverageOptions,
) -> Result<SourceCoverageReport, EvalError> {
    let [w, h] = exemplar_size;
    let n = options.patch_size;
    if n == 0 || n > 64 {
        return Err(EvalError::InvalidOption {
            name: "patch_size",
            value: n.to_string(),
            reason: "must be in 1..=64 pixels",
        });
    }
    let radius = options.radius.unwrap_or((n / 2) as f64);
    if !(radius.is_finite() && radius >= 0.0) {
        return Err(EvalError::InvalidOption {
            name: "radius",
            value: radius.to_string(),
            reason: "must be a finite distance ≥ 0",
        });
    }
    if w < n || h < n {
        return Err(EvalError::TooSmall { what: "exemplar", width: w, height: h, min: n });
    }
    if coords.is_empty() || !coords.len().is_multiple_of(2) {
        let pixels = coords.len().div_ceil(2).max(1);
        return Err(EvalError::BufferSize {
            what: "coordinates",
            width: pixels,
            height: 1,
            channels: 2,
            expected: 2 * pixels,
            found: coords.len(),
        });
    }
    let mut site = vec![false; w * h];
    let mut outside = 0;
    for (i, c) in coords.chunks_exact(2).enumerate() {
        if !(c[0].is_finite() && c[1].is_finite()) {
            let value = if c[0].is_finite() { c[1] } else { c[0] };
            return Err(EvalError::NonFinite { what: "coordinates", index: i, value });
        }
        let (x, y) = ((c[0] as f64).round() as i64, (c[1] as f64).round() as i64);
        let (x, y) = if options.wrap_exemplar {
            (x.rem_euclid(w as i64), y.rem_euclid(h as i64))
        } else if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
            outside += 1;
            continue;
        } else {
            (x, y)
        };
        site[y as usize * w + x as usize] = true;
    }
    let d2 = squared_distance_transform(&site, w, h, options.wrap_exemplar);
    // Patch centres: every position on the torus, else those with the patch inside.
    let (lo, hi_x, hi_y) = if options.wrap_exemplar {
        (0, w, h)
    } else {
        (n / 2, w - (n - 1 - n / 2), h - (n - 1 - n / 2))
    };
    let r2 = radius * radius;
    let (mut count, mut covered, mut copied, mut sum, mut max) = (0usize, 0usize, 0usize, 0.0, 0.0);
    for y in lo..hi_y {
        for &v in &d2[y * w + lo..y * w + hi_x] {
            count += 1;
            covered += (v <= r2) as usize;
            copied += (v == 0.0) as usize;
            let d = v.sqrt();
            sum += d;
            max = f64::max(max, d);
        }
    }
    let c = count.max(1) as f64;
    Ok(SourceCoverageReport {
        covered_share: covered as f64 / c,
        copied_share: copied as f64 / c,
        mean_distance_px: sum / c,
        max_distance_px: max,
        radius_px: radius,
        exemplar_patches: count,
        source_pixels: site.iter().filter(|&&s| s).count(),
        outside,
        patch_size: n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_the_exemplar_is_half_covered() {
        // Every output pixel copies a pixel of the left half of a 40×30 exemplar.
        let (w, h) = (40usize, 30usize);
        let coords: Vec<f32> =
            (0..h).flat_map(|y| (0..w / 2).flat_map(move |x| [x as f32, y as f32])).collect();
        let r = source_coverage(&coords, [w, h], &SourceCoverageOptions::default()).unwrap();
        // Covered: the left half plus 3 columns on each side of it (torus).
        assert!((r.covered_share - 26.0 / 40.0).abs() < 1e-12, "{r:?}");
        assert!((r.copied_share - 0.5).abs() < 1e-12);
        // The middle of the unused half is 10 columns from either copied edge.
        assert_eq!(r.max_distance_px, 10.0);
        assert_eq!(r.source_pixels, w * h / 2);
        let bad = [0.0, f32::NAN];
        assert!(source_coverage(&bad, [w, h], &SourceCoverageOptions::default()).is_err());
    }
}
