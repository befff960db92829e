//! The non-parametric engine (image analogies on surface samples with Ashikhmin
//! coherence, paper B §5.1) on procedural meshes: a known answer, determinism for 1 and
//! 2 threads, the coherence parameter's effect, and refused options.

use fieldtex_core::NoProgress;
use fieldtex_mesh::primitives;
use fieldtex_transfer::{Engine, MatchMode, TransferError, TransferOptions, transfer};

mod common;
use common::{pearson, small_options, textured, with_threads};

fn np_options() -> TransferOptions {
    let mut o = small_options();
    o.engine = Engine::Nonparametric;
    o
}

/// Sphere source whose colour follows the normal's y; torus target with y up.
fn sphere_to_torus() -> (fieldtex_mesh::TriMesh, fieldtex_core::Image, fieldtex_mesh::TriMesh) {
    let sphere = primitives::icosphere(4);
    let (src, tex) = textured(&sphere, |p| {
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        let v = (0.5 + 0.4 * p[1] / r) as f32;
        [v, 0.8 * v, 0.6 * v]
    });
    let mut tgt = primitives::torus(1.0, 0.35, 64, 24);
    for p in &mut tgt.positions {
        *p = [p[0], p[2], -p[1]];
    }
    (src, tex, tgt)
}

#[test]
fn nonparametric_colour_follows_the_normal_on_another_shape() {
    let (src, tex, tgt) = sphere_to_torus();
    let opts = np_options();
    let r = transfer(&src, &tex, None, &tgt, &opts, &NoProgress).unwrap();
    assert!(r.parametric.is_none());
    let stats = r.nonparametric.as_ref().expect("non-parametric statistics");
    assert_eq!(stats.levels.len(), 3);
    assert_eq!(stats.levels[2].level, 0, "coarse to fine");
    // 5×5 colour + guidance, then 3×3 parent colour + guidance.
    assert_eq!(stats.levels[2].vector_dims, 25 * 6 + 9 * 6);
    assert_eq!(stats.levels[0].vector_dims, 25 * 6);
    let truth: Vec<f64> = r.target_samples.normals.iter().map(|n| 0.5 + 0.4 * n[1]).collect();
    let got: Vec<f64> = r.target_colors.chunks_exact(3).map(|c| c[0]).collect();
    let corr = pearson(&truth, &got);
    // Sphere → torus is strongly seed-dependent for both engines (on the sphere height
    // and normal y are the same function, so the split CCA makes between them is
    // arbitrary). Measured r for seeds 0–3 at these sizes: non-parametric 0.53 / 0.63 /
    // 0.67 / 0.31 with the nested samples (0.57 / 0.77 / 0.65 / 0.24 with the earlier
    // independent levels), parametric 0.55 / 0.62 / 0.67 / 0.35. Issue 14's bound (≥ 0.7)
    // is measured on the known-answer benchmark (`bench/transfer_bench.sh`); here the
    // test checks that the dependence clearly survives.
    assert!(corr > 0.5, "Pearson r {corr}");
    // Every output colour is a source colour (copied, not blended).
    let src_min = r.source_colors.chunks_exact(3).map(|c| c[0]).fold(f64::MAX, f64::min);
    assert!(got.iter().all(|&v| v >= src_min - 1e-9));
}

#[test]
fn nonparametric_is_identical_for_one_and_two_threads() {
    let (src, tex, tgt) = sphere_to_torus();
    let mut opts = np_options();
    opts.samples = 3000;
    opts.matching = MatchMode::Marginals;
    let run = |t: usize| {
        with_threads(t, || transfer(&src, &tex, None, &tgt, &opts, &NoProgress).unwrap())
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.target_colors, b.target_colors);
    assert_eq!(a.nonparametric, b.nonparametric);
}

#[test]
fn coherence_parameter_raises_the_share_of_coherent_copies() {
    let (src, tex, tgt) = sphere_to_torus();
    let mut opts = np_options();
    opts.samples = 3000;
    let frac = |k: f64| {
        let mut o = opts.clone();
        o.nonparametric.coherence = k;
        let r = transfer(&src, &tex, None, &tgt, &o, &NoProgress).unwrap();
        r.nonparametric.unwrap().levels.last().unwrap().coherent_fraction
    };
    let (none, strong) = (frac(0.0), frac(20.0));
    assert!(strong > none + 0.2, "coherent fraction κ=0: {none}, κ=20: {strong}");
}

#[test]
fn nonparametric_options_out_of_range_are_refused() {
    let (src, tex, tgt) = sphere_to_torus();
    for change in [
        |o: &mut TransferOptions| o.nonparametric.neighbourhood = 4,
        |o: &mut TransferOptions| o.nonparametric.coherence = -1.0,
        |o: &mut TransferOptions| o.nonparametric.passes = 0,
    ] {
        let mut o = np_options();
        change(&mut o);
        let e = transfer(&src, &tex, None, &tgt, &o, &NoProgress).unwrap_err();
        assert!(matches!(e, TransferError::InvalidOption { .. }), "{e}");
        assert!(e.is_bad_input());
    }
}
