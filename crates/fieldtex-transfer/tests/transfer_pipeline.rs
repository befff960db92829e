//! End-to-end tests of the transfer crate on procedural meshes (no files).

use fieldtex_core::{Image, NoProgress};
use fieldtex_mesh::{TriMesh, primitives};
use fieldtex_transfer::{MatchMode, TransferError, transfer};

mod common;
use common::{pearson, small_options, textured, with_threads};

/// Upward-facing parts are light, downward-facing dark: a function of the normal only.
fn up_shade(n_y: f64) -> f32 {
    (0.5 + 0.4 * n_y) as f32
}

#[test]
fn colour_that_follows_the_normal_transfers_to_another_shape() {
    // Source: a sphere (centroid direction = normal); target: a torus lying in x-z.
    let sphere = primitives::icosphere(4);
    let (src, tex) = textured(&sphere, |p| {
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        let v = up_shade(p[1] / r);
        [v, 0.8 * v, 0.6 * v]
    });
    let torus = primitives::torus(1.0, 0.35, 64, 24);
    // Torus primitives lie in the x-y plane; turn it so y is up.
    let mut tgt = torus.clone();
    for p in &mut tgt.positions {
        *p = [p[0], p[2], -p[1]];
    }
    let opts = small_options();
    let r = transfer(&src, &tex, None, &tgt, &opts, &NoProgress).unwrap();
    assert!(r.strengths[0] > 0.9, "canonical correlations {:?}", r.strengths);
    let truth: Vec<f64> = r.target_samples.normals.iter().map(|n| up_shade(n[1]) as f64).collect();
    let got: Vec<f64> = r.target_colors.chunks_exact(3).map(|c| c[0]).collect();
    let corr = pearson(&truth, &got);
    // Default guidance (CCA weighted by the correlations) with multiscale matching:
    // measured 0.988 / 0.989 / 0.992 / 0.989 for seeds 0–3.
    assert!(corr > 0.95, "Pearson r {corr}");
    // Without feature matching the torus's guidance falls outside what the sphere
    // taught (height and normal y are one function on a sphere, two on a torus), and
    // the dependence degrades: measured 0.805 / 0.752 / 0.984 / 0.993 for seeds 0–3
    // (seed 1 here). With unweighted CCA matching did not help on this pair (means over
    // the 4 seeds: none 0.75, multiscale 0.55): the rotations mix the uninformative
    // variates into the informative one (docs/transfer.md, "Feature matching").
    let mut plain = opts.clone();
    plain.matching = MatchMode::None;
    let u = transfer(&src, &tex, None, &tgt, &plain, &NoProgress).unwrap();
    let got_u: Vec<f64> = u.target_colors.chunks_exact(3).map(|c| c[0]).collect();
    let truth_u: Vec<f64> =
        u.target_samples.normals.iter().map(|n| up_shade(n[1]) as f64).collect();
    let corr_u = pearson(&truth_u, &got_u);
    assert!(corr_u < corr - 0.1, "no matching r {corr_u} vs multiscale r {corr}");
    // On the source sphere height = (n_y + 1) / 2, so the two collinear descriptors
    // share the weight; together they carry almost all of it.
    let w = &r.descriptor_weights;
    assert!(w[0] + w[2] > 0.8, "weights {w:?}");
}

/// Constrained Heeger–Bergen with one cluster is plain H&B: the output's colour
/// histogram equals the source's (grey colours, so the decorrelated channel is RGB).
#[test]
fn heeger_bergen_histograms_equal_with_one_cluster() {
    let sphere = primitives::icosphere(4);
    let (src, tex) = textured(&sphere, |p| {
        let v = (0.3 + 0.2 * (5.0 * p[0]).sin() + 0.15 * p[1] * p[1]) as f32;
        [v, v, v]
    });
    let mut opts = small_options();
    opts.parametric.clusters = 1;
    opts.matching = MatchMode::None;
    let tgt = primitives::torus(1.0, 0.4, 48, 20);
    let r = transfer(&src, &tex, None, &tgt, &opts, &NoProgress).unwrap();
    let q = |v: Vec<f64>| fieldtex_linalg::stats::QuantileFunction::from_samples(&v, 32).unwrap();
    let qs = q(r.source_colors.chunks_exact(3).map(|c| c[0]).collect());
    let qt = q(r.target_colors.chunks_exact(3).map(|c| c[0]).collect());
    for (a, b) in qs.values.iter().zip(&qt.values) {
        assert!((a - b).abs() < 0.01, "source quantile {a} vs target {b}");
    }
}

#[test]
fn same_output_for_one_and_two_threads() {
    let sphere = primitives::icosphere(3);
    let (src, tex) =
        textured(&sphere, |p| [(0.5 + 0.3 * p[1]) as f32, 0.4, (0.5 - 0.2 * p[0]) as f32]);
    let tgt = primitives::torus(1.0, 0.3, 40, 16);
    let mut opts = small_options();
    opts.samples = 3000;
    let run = |t: usize| {
        with_threads(t, || transfer(&src, &tex, None, &tgt, &opts, &NoProgress).unwrap())
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.target_colors, b.target_colors);
    assert_eq!(a.target_guidance, b.target_guidance);
    assert_eq!(a.source_descriptors, b.source_descriptors);
}

#[test]
fn bad_inputs_are_clear_errors() {
    let sphere = primitives::icosphere(2);
    let (src, tex) = textured(&sphere, |_| [0.5; 3]);
    let opts = small_options();
    let mut no_uv = src.clone();
    no_uv.uvs = None;
    let e = transfer(&no_uv, &tex, None, &sphere, &opts, &NoProgress).unwrap_err();
    assert!(matches!(e, TransferError::SourceNotTextured { .. }), "{e}");
    assert!(e.is_bad_input());
    let empty = TriMesh::new(sphere.positions.clone(), Vec::new());
    let e = transfer(&src, &tex, None, &empty, &opts, &NoProgress).unwrap_err();
    assert!(matches!(e, TransferError::EmptyMesh { which: "target" }), "{e}");
    let mask = Image::new(tex.width + 1, tex.height, [0.0; 4]);
    let e = transfer(&src, &tex, Some(&mask), &sphere, &opts, &NoProgress).unwrap_err();
    assert!(matches!(e, TransferError::MaskSize { .. }), "{e}");
    // A mask that hides everything leaves too few samples.
    let all = Image::new(tex.width, tex.height, [1.0; 4]);
    let e = transfer(&src, &tex, Some(&all), &sphere, &opts, &NoProgress).unwrap_err();
    assert!(matches!(e, TransferError::TooFewSamples { .. }), "{e}");
}
