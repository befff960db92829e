//! Unit tests of curve preprocessing on hand-made polylines.

use super::*;

/// Points from `a` to `b` every `step` (both ends included).
fn segment(a: V3, b: V3, step: f64) -> Vec<V3> {
    let n = (vec3::norm(vec3::sub(b, a)) / step).round().max(1.0) as usize;
    (0..=n).map(|i| vec3::lerp(a, b, i as f64 / n as f64)).collect()
}

fn opts() -> CurvePreprocessOptions {
    CurvePreprocessOptions::default()
}

#[test]
fn joins_two_collinear_halves_with_a_gap() {
    // Two halves of a line along x, the second reversed, 1.5 units apart.
    let a = segment([0.0, 0.0, 0.0], [10.0, 0.0, 0.0], 1.0);
    let mut b = segment([11.5, 0.0, 0.0], [20.0, 0.0, 0.0], 1.0);
    b.reverse();
    let out = preprocess_polylines(&[a, b], 1.0, &opts()).unwrap();
    assert_eq!(out.len(), 1, "{out:?}");
    let l = &out[0];
    assert_eq!(l.len(), 11 + 10);
    let ends = [l[0][0], l[l.len() - 1][0]];
    assert!(ends.contains(&0.0) && ends.contains(&20.0), "{ends:?}");
    // Monotone along x: the reversed half was flipped.
    let dir = (l[1][0] - l[0][0]).signum();
    assert!(l.windows(2).all(|w| (w[1][0] - w[0][0]) * dir > 0.0));
}

#[test]
fn does_not_join_far_perpendicular_or_offset_pieces() {
    let a = segment([0.0, 0.0, 0.0], [10.0, 0.0, 0.0], 1.0);
    // Too far.
    let far = segment([13.0, 0.0, 0.0], [20.0, 0.0, 0.0], 1.0);
    assert_eq!(preprocess_polylines(&[a.clone(), far], 1.0, &opts()).unwrap().len(), 2);
    // Close but perpendicular.
    let perp = segment([11.0, 0.0, 0.0], [11.0, 8.0, 0.0], 1.0);
    assert_eq!(preprocess_polylines(&[a.clone(), perp], 1.0, &opts()).unwrap().len(), 2);
    // Parallel but side by side (the gap is across the direction).
    let side = segment([10.0, 1.5, 0.0], [0.0, 1.5, 0.0], 1.0);
    assert_eq!(preprocess_polylines(&[a, side], 1.0, &opts()).unwrap().len(), 2);
}

#[test]
fn breaks_an_l_shape_at_its_corner() {
    let mut l = segment([0.0, 0.0, 0.0], [10.0, 0.0, 0.0], 0.5);
    l.extend(segment([10.0, 0.0, 0.0], [10.0, 10.0, 0.0], 0.5).into_iter().skip(1));
    let out = preprocess_polylines(&[l], 1.0, &opts()).unwrap();
    assert_eq!(out.len(), 2, "{out:?}");
    for piece in &out {
        let corner = [10.0, 0.0, 0.0];
        assert!(piece[0] == corner || piece[piece.len() - 1] == corner);
        assert!((polyline_length(piece) - 10.0).abs() < 1e-9);
    }
}

#[test]
fn smooth_curves_and_gentle_bends_are_not_broken() {
    // A circle of radius 8 sampled every ~0.5: turning 3.6° per point.
    let n = 100;
    let circle: Vec<V3> = (0..=n)
        .map(|i| {
            let a = 2.0 * std::f64::consts::PI * (i % n) as f64 / n as f64;
            [8.0 * a.cos(), 8.0 * a.sin(), 0.0]
        })
        .collect();
    let out = preprocess_polylines(std::slice::from_ref(&circle), 1.0, &opts()).unwrap();
    assert_eq!(out.len(), 1);
    assert_eq!(out[0].len(), circle.len());
    assert_eq!(out[0].first(), out[0].last());
    // A 45° bend stays one curve.
    let mut bend = segment([0.0, 0.0, 0.0], [10.0, 0.0, 0.0], 0.5);
    bend.extend(segment([10.0, 0.0, 0.0], [17.0, 7.0, 0.0], 0.5).into_iter().skip(1));
    assert_eq!(preprocess_polylines(&[bend], 1.0, &opts()).unwrap().len(), 1);
}

#[test]
fn closed_square_breaks_into_four_sides() {
    let c = [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 10.0, 0.0], [0.0, 10.0, 0.0]];
    let mut sq = Vec::new();
    for i in 0..4 {
        sq.extend(segment(c[i], c[(i + 1) % 4], 0.5).into_iter().skip(usize::from(i > 0)));
    }
    assert_eq!(sq.first(), sq.last());
    let out = preprocess_polylines(&[sq], 1.0, &opts()).unwrap();
    assert_eq!(out.len(), 4, "{out:?}");
    for piece in &out {
        assert!((polyline_length(piece) - 10.0).abs() < 1e-9);
    }
}

#[test]
fn two_half_circles_close_into_a_loop() {
    let arc = |a0: f64, a1: f64| -> Vec<V3> {
        (0..=40)
            .map(|i| {
                let a = a0 + (a1 - a0) * i as f64 / 40.0;
                [8.0 * a.cos(), 8.0 * a.sin(), 0.0]
            })
            .collect()
    };
    let pi = std::f64::consts::PI;
    // Small gaps at both joins.
    let out = preprocess_polylines(
        &[arc(0.05, pi - 0.05), arc(pi + 0.05, 2.0 * pi - 0.05)],
        1.0,
        &opts(),
    )
    .unwrap();
    assert_eq!(out.len(), 1);
    assert_eq!(out[0].first(), out[0].last(), "joined into a closed loop");
}

#[test]
fn tiny_pieces_are_dropped_and_kinds_are_not_mixed() {
    let tiny = segment([0.0, 0.0, 0.0], [3.0, 0.0, 0.0], 0.5);
    assert!(preprocess_polylines(&[tiny], 1.0, &opts()).unwrap().is_empty());
    let a = given_line(segment([0.0, 0.0, 0.0], [10.0, 0.0, 0.0], 1.0), Vec::new());
    let mut b = given_line(segment([11.0, 0.0, 0.0], [20.0, 0.0, 0.0], 1.0), Vec::new());
    b.kind = LineKind::Ridge;
    let out = preprocess_lines(vec![a.clone(), b], 1.0, &opts());
    assert_eq!(out.len(), 2);
    let mut c = given_line(segment([11.0, 0.0, 0.0], [20.0, 0.0, 0.0], 1.0), Vec::new());
    c.source = LineSource::Crease;
    let out = preprocess_lines(vec![a, c], 1.0, &opts());
    assert_eq!(out.len(), 1);
    assert_eq!(out[0].source, LineSource::Mixed);
}

#[test]
fn faces_follow_points_through_join_and_break() {
    let a = segment([0.0, 0.0, 0.0], [10.0, 0.0, 0.0], 1.0);
    let fa: Vec<u32> = (0..a.len() as u32).collect();
    let mut b = segment([10.0, 0.0, 0.0], [10.0, 10.0, 0.0], 1.0);
    b.reverse();
    let fb: Vec<u32> = (100..100 + b.len() as u32).collect();
    // Perpendicular pieces meeting at a corner stay apart ...
    let out = preprocess_lines(vec![given_line(a, fa), given_line(b, fb)], 1.0, &opts());
    assert_eq!(out.len(), 2);
    for l in &out {
        assert_eq!(l.faces.len(), l.points.len());
    }
    // ... and a collinear join keeps one face per point.
    let c = segment([0.0, 0.0, 0.0], [10.0, 0.0, 0.0], 1.0);
    let d = segment([10.0, 0.0, 0.0], [20.0, 0.0, 0.0], 1.0);
    let (fc, fd) = (vec![1; c.len()], vec![2; d.len()]);
    let out = preprocess_lines(vec![given_line(c, fc), given_line(d, fd)], 1.0, &opts());
    assert_eq!(out.len(), 1);
    assert_eq!(out[0].points.len(), 21);
    assert_eq!(out[0].faces.len(), 21);
}

#[test]
fn invalid_options_and_points_are_errors() {
    let o = CurvePreprocessOptions { join_angle_deg: -1.0, ..opts() };
    assert!(preprocess_polylines(&[], 1.0, &o).is_err());
    assert!(preprocess_polylines(&[], 0.0, &opts()).is_err());
    let bad = vec![vec![[0.0; 3], [f64::NAN, 0.0, 0.0]]];
    assert!(matches!(
        preprocess_polylines(&bad, 1.0, &opts()),
        Err(FeaturesError::NonFiniteCurvePoint { curve: 0, point: 1 })
    ));
}
