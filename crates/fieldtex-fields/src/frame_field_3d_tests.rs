//! Tests of `frame_field_3d.rs`.

use super::*;

fn grid() -> FrameGrid {
    FrameGrid::over_box([0.0; 3], [1.0, 1.2, 1.5], 12).unwrap()
}

fn curve(points: Vec<[f64; 3]>, normal: [f64; 3], axis: usize) -> FrameCurve {
    let normals = vec![normal; points.len()];
    FrameCurve { points, normals, axis, weight: 1.0, refine: false }
}

/// 41 points on 90 % of a horizontal circle (radius 0.4 around (0.5, 0.6), z = 0.7).
fn arc_points() -> Vec<[f64; 3]> {
    (0..=40)
        .map(|i| {
            let a = i as f64 / 40.0 * std::f64::consts::TAU * 0.9;
            [0.5 + 0.4 * a.cos(), 0.6 + 0.4 * a.sin(), 0.7]
        })
        .collect()
}

#[test]
fn constraints_are_met_within_five_degrees() {
    let mut field = FrameField3d::new(grid(), FrameFieldOptions::default()).unwrap();
    // A bent curve (quarter circle in the xy plane) with normal +z, tangent → x.
    let pts: Vec<[f64; 3]> = (0..=20)
        .map(|i| {
            let a = i as f64 / 20.0 * std::f64::consts::FRAC_PI_2;
            [0.5 + 0.4 * a.cos(), 0.1 + 0.4 * a.sin(), 0.5]
        })
        .collect();
    field.add_curve(&curve(pts, [0.0, 0.0, 1.0], 0)).unwrap();
    field.add_curve(&curve(vec![[0.1, 1.0, 1.2], [0.9, 1.1, 1.3]], [0.0, 1.0, 0.0], 1)).unwrap();
    let errs = field.constraint_errors_deg();
    assert!(!errs.is_empty());
    let max = errs.iter().cloned().fold(0.0, f64::max);
    assert!(max <= 5.0, "max constraint error {max}°");
    // Far from the curves the field is still a unit rotation.
    let q = field.frame_at([0.0, 0.0, 0.0]);
    assert!((quaternion::dot(q, q) - 1.0).abs() < 1e-9);
}

#[test]
fn signs_are_continuous_along_a_curve_and_against_the_field() {
    let mut field = FrameField3d::new(grid(), FrameFieldOptions::default()).unwrap();
    // A full turn of the tangent makes the quaternion go to −q by continuity;
    // the chosen signs must stay continuous between consecutive samples.
    let pts = arc_points();
    let id = field.add_curve(&curve(pts, [0.0, 0.0, 1.0], 0)).unwrap();
    let targets = field.curves[id].as_ref().unwrap();
    // Consecutive targets (nodes in curve order) differ by small rotations and
    // their 4-D dot product is positive (no sign flips along the curve).
    for w in targets.nodes.windows(2) {
        assert!(quaternion::dot(w[0].2, w[1].2) > 0.5, "sign flip along the curve");
    }
    // A later curve through the same region takes the sign of the current field.
    let id2 = field
        .add_curve(&curve(vec![[0.2, 0.6, 0.7], [0.8, 0.6, 0.7]], [0.0, 0.0, -1.0], 1))
        .unwrap();
    for &(i, _, q) in &field.curves[id2].as_ref().unwrap().nodes {
        let _ = i;
        assert!(q.iter().all(|v| v.is_finite()));
    }
    // Removing it restores the previous field exactly (downdate of the kept factor).
    let before: Vec<Quat> = {
        let mut f2 = FrameField3d::new(grid(), FrameFieldOptions::default()).unwrap();
        let pts = arc_points();
        f2.add_curve(&curve(pts, [0.0, 0.0, 1.0], 0)).unwrap();
        f2.frames().to_vec()
    };
    field.remove_curve(id2).unwrap();
    let worst = field
        .frames()
        .iter()
        .zip(&before)
        .map(|(a, b)| quaternion::angle_between_deg(*a, *b))
        .fold(0.0, f64::max);
    assert!(worst < 0.5, "after removal the field differs by {worst}°");
}

#[test]
fn an_edited_field_equals_a_field_solved_from_scratch() {
    let arc = |r: f64, z: f64| -> Vec<[f64; 3]> {
        (0..=12)
            .map(|i| {
                let a = i as f64 / 12.0 * std::f64::consts::FRAC_PI_2;
                [r * a.cos(), r * a.sin(), z]
            })
            .collect()
    };
    let a = curve(arc(0.6, 0.4), [0.0, 0.0, 1.0], 0);
    let b = curve(vec![[0.1, 1.0, 1.2], [0.9, 1.1, 1.3]], [0.0, 1.0, 0.0], 1);
    let c = curve(arc(0.9, 1.0), [0.0, 0.0, 1.0], 0);
    let c_moved = curve(arc(0.8, 1.1), [0.0, 0.0, 1.0], 0);
    // Edits: add a, b, c; remove b; move c; add b again.
    let mut edited = FrameField3d::new(grid(), FrameFieldOptions::default()).unwrap();
    edited.add_curve(&a).unwrap();
    let ib = edited.add_curve(&b).unwrap();
    let ic = edited.add_curve(&c).unwrap();
    edited.remove_curve(ib).unwrap();
    edited.replace_curve(ic, &c_moved).unwrap();
    edited.add_curve(&b).unwrap();
    assert_eq!(edited.curve_ids(), vec![0, 2, 3]);
    // From scratch: a, the moved c and b in one factorisation.
    let mut scratch = FrameField3d::new(grid(), FrameFieldOptions::default()).unwrap();
    for k in [&a, &c_moved, &b] {
        scratch.curves.push(Some(scratch.curve_targets(k, 0).unwrap()));
    }
    scratch.solve().unwrap();
    let worst = edited
        .frames()
        .iter()
        .zip(scratch.frames())
        .map(|(p, q)| quaternion::angle_between_deg(*p, *q))
        .fold(0.0, f64::max);
    // Rounding only (an angle from acos near 1 resolves about 1e-6°).
    assert!(worst < 1e-4, "edited and from-scratch fields differ by {worst}°");
    assert!(edited.last_residual() < 1e-10);
    assert!(edited.factor_nnz().unwrap() > 0);
    // Unknown ids are refused.
    assert!(edited.replace_curve(ib, &b).is_err());
}

#[test]
fn refinement_turns_the_nearest_direction_onto_the_tangent() {
    let mut field = FrameField3d::new(grid(), FrameFieldOptions::default()).unwrap();
    field.add_curve(&curve(vec![[0.1, 0.5, 0.5], [0.9, 0.5, 0.5]], [0.0, 0.0, 1.0], 0)).unwrap();
    let refine = FrameCurve {
        points: vec![[0.2, 0.3, 1.0], [0.8, 0.5, 1.0]],
        normals: vec![],
        axis: 0,
        weight: 1.0,
        refine: true,
    };
    field.add_curve(&refine).unwrap();
    let q = field.frame_at([0.5, 0.4, 1.0]);
    let x = quaternion::axis_of(q, 0);
    let t = [0.6f64, 0.2, 0.0];
    let tn = (t[0] * t[0] + t[1] * t[1]).sqrt();
    let c = (x[0] * t[0] + x[1] * t[1]).abs() / tn;
    assert!(
        c.acos().to_degrees() < 5.0,
        "x is {:.1}° off the refinement tangent",
        c.acos().to_degrees()
    );
}
