//! Unit tests of the parallel synthesis engine that need its private entry points.

use super::*;
use crate::{AnalysisOptions, ImageDomain};
use fieldtex_core::NoProgress;

#[test]
fn avx2_build_is_bit_identical_to_the_baseline() {
    #[cfg(target_arch = "x86_64")]
    if !std::arch::is_x86_feature_detected!("avx2") {
        return;
    }
    let ex = test_exemplar();
    let an = ExemplarAnalysis::new(&ex, &AnalysisOptions::default(), &NoProgress).unwrap();
    let dom = wedge_domain(48);
    let opts = SynthesisOptions { seed: 3, ..Default::default() };
    let a = synthesize_with(&an, &dom, &opts, &NoProgress, true, None).unwrap();
    let b = synthesize_with(&an, &dom, &opts, &NoProgress, false, None).unwrap();
    assert_eq!(a.flips, b.flips);
    assert!(a.flips.iter().any(|&f| f) && a.flips.iter().any(|&f| !f));
    assert_eq!(coord_bits(&a.coords), coord_bits(&b.coords));
}

fn coord_bits(c: &[[f32; 2]]) -> Vec<[u32; 2]> {
    c.iter().map(|u| u.map(f32::to_bits)).collect()
}

fn test_exemplar() -> Image {
    let (w, h) = (40, 36);
    let mut ex = Image::new(w, h, [0.0, 0.0, 0.0, 1.0]);
    for y in 0..h {
        for x in 0..w {
            let (fx, fy) = (x as f32, y as f32);
            let v = 0.5 + 0.45 * (fy * 0.8 + (fx * 0.3).sin()).sin();
            ex.set(x, y, [v, ((x * 7 + y * 3) % 5) as f32 / 5.0, 1.0 - v, 1.0]);
        }
    }
    ex
}

/// A wedge-like field: representatives flip by 180° across one ray (2-RoSy path).
fn wedge_domain(n: usize) -> ImageDomain {
    let c = n as f32 / 2.0 - 0.5;
    let field: Vec<f32> = (0..n * n)
        .flat_map(|i| {
            let (x, y) = ((i % n) as f32 - c, (i / n) as f32 - c);
            let a = 0.5 * y.atan2(x);
            [a.cos(), a.sin()]
        })
        .collect();
    ImageDomain::from_direction_field(n, n, &field, 1.0).unwrap()
}

/// Lefebvre & Hoppe's window property: a window synthesised alone (from its dependency
/// sets) equals the same window of the full image bit for bit, for 1 and 2 threads,
/// and touches far fewer samples than the full image.
#[test]
fn a_window_computed_alone_equals_the_full_image_window() {
    let an =
        ExemplarAnalysis::new(&test_exemplar(), &AnalysisOptions::default(), &NoProgress).unwrap();
    let n = 96;
    let dom = wedge_domain(n);
    let opts = SynthesisOptions { seed: 5, ..Default::default() };
    let full = synthesize(&an, &dom, &opts, &NoProgress).unwrap();
    // A 12×10 window off-centre (it straddles the flip ray of the wedge).
    let window: Vec<usize> = (30..40).flat_map(|y| (52..64).map(move |x| y * n + x)).collect();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let sub =
            pool.install(|| synthesize_subset(&an, &dom, &opts, &window, &NoProgress)).unwrap();
        let want: Vec<[f32; 2]> = window.iter().map(|&i| full.coords[i]).collect();
        assert_eq!(coord_bits(&sub.coords), coord_bits(&want), "{threads} threads");
        let flips: Vec<bool> = window.iter().map(|&i| full.flips[i]).collect();
        assert_eq!(sub.flips, flips);
        let colors: Vec<[u32; 4]> =
            window.iter().map(|&i| full.colors.pixels[i].map(f32::to_bits)).collect();
        assert_eq!(sub.colors.iter().map(|c| c.map(f32::to_bits)).collect::<Vec<_>>(), colors);
        // The finest level computes the window plus a margin, not the image.
        assert!(sub.evaluated_per_level[0] < n * n / 4, "{:?}", sub.evaluated_per_level);
        assert!(sub.evaluated_per_level[0] >= window.len());
    }
    // A single sample and an out-of-range request.
    let one = synthesize_subset(&an, &dom, &opts, &[7 * n + 90], &NoProgress).unwrap();
    assert_eq!(coord_bits(&one.coords), coord_bits(&[full.coords[7 * n + 90]]));
    assert!(synthesize_subset(&an, &dom, &opts, &[n * n], &NoProgress).is_err());
}
