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
    let (w, h) = (40, 36);
    let mut ex = Image::new(w, h, [0.0, 0.0, 0.0, 1.0]);
    for y in 0..h {
        for x in 0..w {
            let (fx, fy) = (x as f32, y as f32);
            let v = 0.5 + 0.45 * (fy * 0.8 + (fx * 0.3).sin()).sin();
            ex.set(x, y, [v, ((x * 7 + y * 3) % 5) as f32 / 5.0, 1.0 - v, 1.0]);
        }
    }
    let an = ExemplarAnalysis::new(&ex, &AnalysisOptions::default(), &NoProgress).unwrap();
    // A wedge-like field: representatives flip by 180° across one ray (2-RoSy path).
    let n = 48;
    let field: Vec<f32> = (0..n * n)
        .flat_map(|i| {
            let (x, y) = ((i % n) as f32 - 23.5, (i / n) as f32 - 23.5);
            let a = 0.5 * y.atan2(x);
            [a.cos(), a.sin()]
        })
        .collect();
    let dom = ImageDomain::from_direction_field(n, n, &field, 1.0).unwrap();
    let opts = SynthesisOptions { seed: 3, ..Default::default() };
    let a = synthesize_with(&an, &dom, &opts, &NoProgress, true).unwrap();
    let b = synthesize_with(&an, &dom, &opts, &NoProgress, false).unwrap();
    assert_eq!(a.flips, b.flips);
    assert!(a.flips.iter().any(|&f| f) && a.flips.iter().any(|&f| !f));
    let bits = |r: &SynthesisResult| -> Vec<[u32; 2]> {
        r.coords.iter().map(|u| u.map(f32::to_bits)).collect()
    };
    assert_eq!(bits(&a), bits(&b));
}
