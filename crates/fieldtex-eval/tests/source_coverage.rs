//! Source coverage (completeness from the synthesis's exemplar coordinates, no search)
//! against the search-based completeness on the shared test exemplars: the relation
//! stated in `fieldtex_eval::source_coverage`'s docs and `docs/perf/orient.md`.

mod common;
use common::{TEST_EXEMPLARS, load, patchwork_with_coords};
use fieldtex_eval::*;

/// A patchwork drawing its blocks from the whole exemplar against one drawing only from
/// its left third: both measures must call the second less complete, coverage by at
/// least 0.3 of the exemplar, and coverage must follow the known copied pixels exactly.
#[test]
fn coverage_and_search_completeness_agree_on_the_test_exemplars() {
    let size = 160;
    for name in TEST_EXEMPLARS {
        let (ex, w, h) = load(name);
        let e = ImageView::new(&ex, w, h, 3).unwrap();
        let exact = PatchDistanceOptions::default().with_wrap_exemplar(true);
        let mut rows = Vec::new();
        for share in [1.0, 1.0 / 3.0] {
            let (out, coords) = patchwork_with_coords(&ex, w, h, size, 3, share);
            let o = ImageView::new(&out, size, size, 3).unwrap();
            let search = completeness(&o, &e, &exact).unwrap();
            let cov = source_coverage(&coords, [w, h], &SourceCoverageOptions::default()).unwrap();
            // Exactness: the copied share is the share of distinct copied pixels.
            assert!((cov.copied_share - cov.source_pixels as f64 / (w * h) as f64).abs() < 1e-12);
            assert!(cov.covered_share >= cov.copied_share);
            println!(
                "{name} blocks from {share:.2} of the exemplar: covered {:.3} (copied {:.3}, \
                 mean distance {:.2} px, max {:.1} px), search completeness {:.6}",
                cov.covered_share,
                cov.copied_share,
                cov.mean_distance_px,
                cov.max_distance_px,
                search.mean
            );
            rows.push((cov, search.mean));
        }
        let ((full, full_search), (third, third_search)) = (&rows[0], &rows[1]);
        assert!(full.covered_share > 0.9, "{name}: {full:?}");
        assert!(third.covered_share < full.covered_share - 0.3, "{name}: {third:?}");
        assert!(third.max_distance_px > full.max_distance_px, "{name}");
        assert!(third_search > full_search, "{name}: search {third_search} vs {full_search}");
    }
}
