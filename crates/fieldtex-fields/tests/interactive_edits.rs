//! Interactive edits with the default options: long strokes added, dragged and removed
//! through multiple-rank factor updates give the field of a design built from scratch;
//! singularity moves re-solve only; pixel sampling matches point location for odd sizes
//! and is bit-identical for 1 and 2 threads after a sequence of edits.

use fieldtex_fields::orientation_field::{sample_plane, sample_plane_into};
use fieldtex_fields::presets::preset;
use fieldtex_fields::*;

mod common;
use common::{max_abs, max_diff, reference_pixels};

fn long_stroke(dy: f64) -> Stroke {
    Stroke::from_pixels(&[[30.0, 90.0 + dy], [120.0, 75.0 + dy], [230.0, 100.0 + dy]])
}

#[test]
fn default_options_update_stroke_edits_and_match_fresh_designs() {
    let file = preset("whorl", 256.0, 256.0, 64).unwrap();
    let mut d = file.build(None).unwrap();
    assert!(d.options().rank1_update_limit >= 640);
    let original = d.solve().unwrap();
    let refactors = d.refactor_count();
    let scale = max_abs(&original.one_form);

    let fresh_with = |stroke: Stroke| {
        let mut f = file.build(None).unwrap();
        f.add_stroke(stroke).unwrap();
        f.solve().unwrap()
    };

    // Add a long stroke: updates, no refactorisation.
    let id = d.add_stroke(long_stroke(0.0)).unwrap();
    let added = d.solve().unwrap();
    let updates = d.rank1_update_count();
    assert!(updates > 60, "a long stroke changes many edges: {updates}");
    assert_eq!(d.refactor_count(), refactors, "adding a long stroke must not refactor");
    let diff = max_diff(&added.one_form, &fresh_with(long_stroke(0.0)).one_form);
    assert!(diff <= 1e-9 * scale, "added vs fresh: {diff:e} (scale {scale:e})");
    assert!(max_diff(&added.one_form, &original.one_form) > 1e-3 * scale);

    // Drag it by a few pixels, several times (updates and downdates accumulate).
    let mut last = added;
    for dy in [2.0, 5.0, 3.5] {
        d.set_stroke(id, long_stroke(dy)).unwrap();
        last = d.solve().unwrap();
        let diff = max_diff(&last.one_form, &fresh_with(long_stroke(dy)).one_form);
        assert!(diff <= 1e-9 * scale, "dragged by {dy} vs fresh: {diff:e}");
    }
    assert_eq!(d.refactor_count(), refactors, "dragging a stroke must not refactor");
    assert!(d.rank1_update_count() > updates);
    assert!(last.residual < 1e-10, "residual {}", last.residual);

    // Move a singularity while the dragged stroke is there: right-hand side only.
    let (sid, s) = d.singularities()[0];
    let target = [s.position[0] + 6.3, s.position[1] - 4.1, 0.0];
    d.move_singularity(sid, target).unwrap();
    let moved = d.solve().unwrap();
    assert_eq!(d.refactor_count(), refactors);
    let mut moved_file = file.clone();
    moved_file.singularities[0].x = Some(target[0]);
    moved_file.singularities[0].y = Some(target[1]);
    let mut fresh = moved_file.build(None).unwrap();
    fresh.add_stroke(long_stroke(3.5)).unwrap();
    let diff = max_diff(&moved.one_form, &fresh.solve().unwrap().one_form);
    assert!(diff <= 1e-9 * scale, "moved singularity vs fresh: {diff:e}");
    d.move_singularity(sid, s.position).unwrap();

    // Remove it: downdates bring the original field back.
    d.remove_stroke(id).unwrap();
    let back = d.solve().unwrap();
    assert_eq!(d.refactor_count(), refactors, "removing a stroke must not refactor");
    let diff = max_diff(&back.one_form, &original.one_form);
    assert!(diff <= 1e-9 * scale, "removed vs original: {diff:e}");

    // A refresh refactors and gives the same field.
    d.refresh_factorization().unwrap();
    assert_eq!(d.refactor_count(), refactors + 1);
    let refreshed = d.solve().unwrap();
    assert!(max_diff(&refreshed.one_form, &original.one_form) <= 1e-9 * scale);
}

#[test]
fn edits_beyond_the_update_limit_refactor_to_the_same_field() {
    let file = preset("left-loop", 200.0, 200.0, 40).unwrap();
    let mut d = file.build(None).unwrap();
    d.solve().unwrap();
    let options = d.options().clone().with_rank1_update_limit(8);
    let mut small =
        FieldDesign::new(Domain::Plane(*d.plane().unwrap()), d.symmetry(), options).unwrap();
    for (_, s) in d.singularities() {
        small.add_singularity(s).unwrap();
    }
    for (_, s) in d.strokes() {
        small.add_stroke(s.clone()).unwrap();
    }
    small.solve().unwrap();
    let r0 = small.refactor_count();
    let stroke = Stroke::from_pixels(&[[20.0, 60.0], [100.0, 50.0], [180.0, 70.0]]);
    d.add_stroke(stroke.clone()).unwrap();
    small.add_stroke(stroke).unwrap();
    let (a, b) = (d.solve().unwrap(), small.solve().unwrap());
    assert_eq!(small.refactor_count(), r0 + 1, "more changed edges than the limit refactor");
    let scale = max_abs(&a.one_form);
    assert!(max_diff(&a.one_form, &b.one_form) <= 1e-9 * scale);
}

#[test]
fn sampling_matches_point_location_for_odd_sizes() {
    let mut d = preset("tented-arch", 90.0, 70.0, 20).unwrap().build(None).unwrap();
    let f = d.solve().unwrap();
    let mut buf = Vec::new();
    for (w, h) in [(1, 1), (3, 701), (701, 3), (64, 50), (5000, 2)] {
        sample_plane_into(&d, &f, w, h, &mut buf).unwrap();
        assert_eq!(buf.len(), w * h);
        let reference = reference_pixels(&d, &f, w, h);
        // f32 output: the half-angle vector `z + |z|` loses digits next to the negative
        // real axis (doubled angle ≈ π), ~1e-4 rad there, ~1e-7 elsewhere.
        for (k, (p, e)) in buf.iter().zip(&reference).enumerate() {
            assert!(
                (p[0] as f64 - e[0]).abs() < 2e-4 && (p[1] as f64 - e[1]).abs() < 2e-4,
                "{w}×{h} pixel {k}: {p:?} vs {e:?}"
            );
        }
    }
}

fn edited_pixels() -> Vec<[f32; 2]> {
    let file = preset("whorl", 200.0, 160.0, 48).unwrap();
    let mut d = file.build(None).unwrap();
    d.solve().unwrap();
    let id =
        d.add_stroke(Stroke::from_pixels(&[[20.0, 60.0], [100.0, 48.0], [180.0, 66.0]])).unwrap();
    d.solve().unwrap();
    d.set_stroke(id, Stroke::from_pixels(&[[20.0, 64.0], [100.0, 52.0], [180.0, 70.0]])).unwrap();
    let (sid, s) = d.singularities()[0];
    d.move_singularity(sid, [s.position[0] + 5.0, s.position[1] + 2.0, 0.0]).unwrap();
    let f = d.solve().unwrap();
    sample_plane(&d, &f, 301, 187).unwrap()
}

#[test]
fn edits_and_sampling_are_identical_for_one_and_two_threads() {
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(edited_pixels)
    };
    let bits = |v: &Vec<[f32; 2]>| {
        v.iter().flat_map(|p| [p[0].to_bits(), p[1].to_bits()]).collect::<Vec<_>>()
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(bits(&one), bits(&two));
    assert!(one.iter().all(|p| ((p[0] * p[0] + p[1] * p[1]) - 1.0).abs() < 1e-5));
}

#[test]
fn solve_and_sample_is_one_frame_of_solve_then_sample() {
    let mut d = preset("right-loop", 160.0, 120.0, 40).unwrap().build(None).unwrap();
    let mut frame = Vec::new();
    let f = d.solve_and_sample_into(123, 91, &mut frame).unwrap();
    let g = d.solve().unwrap();
    assert_eq!(f, g);
    assert_eq!(frame, sample_plane(&d, &g, 123, 91).unwrap());
    assert!(d.solve_and_sample_into(0, 91, &mut frame).is_err());
    // Mesh designs have no pixel grid: the solve works, the sampling is an error.
    let mut m = FieldDesign::new(
        Domain::Mesh(disk_mesh(1.0, 6)),
        Symmetry::Vector,
        FieldDesignOptions::default(),
    )
    .unwrap();
    m.add_singularity(Singularity::new(SingularityKind::Source, [0.1, 0.0, 0.0])).unwrap();
    assert!(m.solve().is_ok());
    assert!(m.solve_and_sample_into(16, 16, &mut frame).is_err());
}
