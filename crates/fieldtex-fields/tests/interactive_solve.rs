//! The interactive path: the deviation solve equals the full normal equations, edits
//! through rank-1 updates match a fresh design, and buffered sampling matches the
//! allocating one.

use fieldtex_fields::orientation_field::{sample_plane, sample_plane_into};
use fieldtex_fields::presets::preset;
use fieldtex_fields::*;
use fieldtex_linalg::{Cholesky, SparseMatrix};

mod common;
use common::{max_abs, max_diff};

/// `A` with the strokes of `d`: the base matrix plus the stroke weights on the diagonal
/// (rebuilt with the public constraint builder).
fn full_matrix(d: &FieldDesign) -> SparseMatrix {
    let mut diag = vec![0.0; d.dec().n_edges()];
    for (_, s) in d.strokes() {
        let locate = |p: [f64; 3]| d.locate(p);
        let cs = stroke_constraints::stroke_edge_constraints(
            d.dec(),
            &locate,
            d.frames(),
            d.symmetry(),
            s,
            d.options().stroke_weight,
            0,
        )
        .unwrap();
        for (e, w, _) in cs {
            diag[e] += w;
        }
    }
    d.base_matrix().add_diagonal(&diag)
}

#[test]
fn deviation_solve_equals_the_normal_equations() {
    let file = preset("whorl", 160.0, 160.0, 32).unwrap();
    let mut d = file.build(None).unwrap();
    assert!(!d.strokes().is_empty() && !d.singularities().is_empty());
    let f = d.solve().unwrap();
    // Reference: the full normal equations A ω = b solved with a fresh factorisation.
    let a = full_matrix(&d);
    let b = d.right_hand_side();
    let reference = Cholesky::factor(&a).unwrap().solve(&b).unwrap();
    let scale = max_abs(&reference);
    assert!(scale > 0.0);
    let diff = max_diff(&f.one_form, &reference);
    assert!(diff <= 1e-9 * scale, "deviation vs full solve: {diff:e} (scale {scale:e})");
    assert!(f.residual < 1e-10, "residual {}", f.residual);

    // Without strokes the solution is the model field itself, with no solve.
    let ids: Vec<StrokeId> = d.strokes().into_iter().map(|(id, _)| id).collect();
    for id in ids {
        d.remove_stroke(id).unwrap();
    }
    let f = d.solve().unwrap();
    assert_eq!(f.residual, 0.0);
    let a = d.base_matrix().clone();
    let b = d.right_hand_side();
    let reference = Cholesky::factor(&a).unwrap().solve(&b).unwrap();
    let diff = max_diff(&f.one_form, &reference);
    assert!(diff <= 1e-9 * max_abs(&reference), "stroke-free: {diff:e}");
}

#[test]
fn long_stroke_edits_by_rank1_updates_match_a_fresh_design() {
    let file = preset("left-loop", 200.0, 200.0, 40).unwrap();
    let built = file.build(None).unwrap();
    let options = built.options().clone().with_rank1_update_limit(100_000);
    let mut d =
        FieldDesign::new(Domain::Plane(*built.plane().unwrap()), Symmetry::Orientation, options)
            .unwrap();
    for s in file.singularity_list().unwrap() {
        d.add_singularity(s).unwrap();
    }
    for s in file.stroke_list() {
        d.add_stroke(s).unwrap();
    }
    d.solve().unwrap();
    let refactors = d.refactor_count();
    let long = Stroke::from_pixels(&[[20.0, 60.0], [100.0, 50.0], [180.0, 70.0]]);
    let moved = Stroke::from_pixels(&[[20.0, 63.0], [100.0, 53.0], [180.0, 73.0]]);
    let id = d.add_stroke(long).unwrap();
    d.solve().unwrap();
    d.set_stroke(id, moved.clone()).unwrap();
    let edited = d.solve().unwrap();
    assert!(d.rank1_update_count() > 20, "updates {}", d.rank1_update_count());
    assert_eq!(d.refactor_count(), refactors, "a stroke edit this size is updated");

    let mut fresh = file.build(None).unwrap();
    fresh.add_stroke(moved).unwrap();
    let reference = fresh.solve().unwrap();
    let scale = max_abs(&reference.one_form);
    let diff = max_diff(&edited.one_form, &reference.one_form);
    assert!(diff <= 1e-9 * scale, "updated vs fresh: {diff:e}");

    d.remove_stroke(id).unwrap();
    let back = d.solve().unwrap();
    let original = file.build(None).unwrap().solve().unwrap();
    let diff = max_diff(&back.one_form, &original.one_form);
    assert!(diff <= 1e-9 * scale, "downdated vs original: {diff:e}");
}

#[test]
fn buffered_sampling_matches_and_reuses_the_buffer() {
    let mut d = preset("tented-arch", 120.0, 90.0, 30).unwrap().build(None).unwrap();
    let f = d.solve().unwrap();
    let fresh = sample_plane(&d, &f, 97, 61).unwrap();
    let mut buf = vec![[7.0f32; 2]; 10];
    sample_plane_into(&d, &f, 97, 61, &mut buf).unwrap();
    assert_eq!(buf, fresh);
    // A smaller request shrinks the buffer; every pixel is rewritten.
    sample_plane_into(&d, &f, 13, 11, &mut buf).unwrap();
    assert_eq!(buf, sample_plane(&d, &f, 13, 11).unwrap());
    assert!(buf.iter().all(|p| ((p[0] * p[0] + p[1] * p[1]) - 1.0).abs() < 1e-5));
    assert!(sample_plane_into(&d, &f, 0, 11, &mut buf).is_err());
}
