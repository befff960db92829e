//! Stroke edits through the kept checkpoint factor (a copy of an earlier factor plus one
//! multiple-rank update instead of downdates): long sequences of adds, drags and removes
//! of several strokes give the field of a design built from scratch, take the checkpoint
//! path, never refactor, and are bit-identical for 1 and 2 threads.

use fieldtex_fields::presets::preset;
use fieldtex_fields::*;

mod common;
use common::{max_abs, max_diff};

fn stroke_a(dy: f64) -> Stroke {
    Stroke::from_pixels(&[[30.0, 80.0 + dy], [120.0, 65.0 + dy], [230.0, 90.0 + dy]])
}

fn stroke_b(dx: f64) -> Stroke {
    Stroke::from_pixels(&[[60.0 + dx, 150.0], [90.0 + dx, 200.0], [80.0 + dx, 240.0]])
}

/// Edit steps: `(a, b)` = offsets of the live strokes (`None`: absent).
const STEPS: [(Option<f64>, Option<f64>); 10] = [
    (Some(0.0), None),
    (Some(3.0), None),
    (Some(6.5), None),
    (Some(6.5), Some(0.0)),
    (Some(6.5), Some(4.0)),
    (Some(6.5), Some(9.0)),
    (None, Some(9.0)),
    (None, Some(2.5)),
    (Some(1.0), Some(2.5)),
    (None, None),
];

/// Brings the stroke `id` of `d` to `want`: added, moved, removed or left absent.
fn edit_stroke(d: &mut FieldDesign, id: &mut Option<StrokeId>, want: Option<Stroke>) {
    match (*id, want) {
        (None, Some(s)) => *id = Some(d.add_stroke(s).unwrap()),
        (Some(i), Some(s)) => d.set_stroke(i, s).unwrap(),
        (Some(i), None) => {
            d.remove_stroke(i).unwrap();
            *id = None;
        }
        (None, None) => {}
    }
}

/// Runs the edit sequence on one design; returns the one-forms after every step and
/// the counters (refactorisations, checkpoint restores).
fn edit_sequence() -> (Vec<Vec<f64>>, usize, usize) {
    let file = preset("whorl", 256.0, 256.0, 64).unwrap();
    let mut d = file.build(None).unwrap();
    d.solve().unwrap();
    let refactors = d.refactor_count();
    let (mut a, mut b) = (None, None);
    let mut out = Vec::new();
    for (sa, sb) in STEPS {
        edit_stroke(&mut d, &mut a, sa.map(stroke_a));
        edit_stroke(&mut d, &mut b, sb.map(stroke_b));
        out.push(d.solve().unwrap().one_form);
    }
    (out, d.refactor_count() - refactors, d.checkpoint_restore_count())
}

#[test]
fn checkpoint_edits_match_fresh_designs() {
    let file = preset("whorl", 256.0, 256.0, 64).unwrap();
    let (fields, refactors, restores) = edit_sequence();
    assert_eq!(refactors, 0, "stroke edits below the limit must not refactor");
    assert!(restores >= 3, "drags and removals of long strokes use the checkpoint: {restores}");
    for (step, ((sa, sb), got)) in STEPS.iter().zip(&fields).enumerate() {
        let mut fresh = file.build(None).unwrap();
        if let Some(y) = sa {
            fresh.add_stroke(stroke_a(*y)).unwrap();
        }
        if let Some(x) = sb {
            fresh.add_stroke(stroke_b(*x)).unwrap();
        }
        let reference = fresh.solve().unwrap().one_form;
        let scale = max_abs(&reference);
        let diff = max_diff(got, &reference);
        assert!(diff <= 1e-9 * scale, "step {step}: {diff:e} (scale {scale:e})");
    }
    // the last step removed both strokes: the preset's own field again
    let original = file.build(None).unwrap().solve().unwrap().one_form;
    assert!(max_diff(&fields[9], &original) <= 1e-9 * max_abs(&original));
    assert!(max_diff(&fields[5], &original) > 1e-3 * max_abs(&original));
}

#[test]
fn checkpoint_edits_are_identical_for_one_and_two_threads() {
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(edit_sequence)
    };
    let (one, two) = (run(1), run(2));
    assert_eq!((one.1, one.2), (two.1, two.2));
    for (p, q) in one.0.iter().zip(&two.0) {
        assert!(p.iter().zip(q).all(|(x, y)| x.to_bits() == y.to_bits()));
    }
}
