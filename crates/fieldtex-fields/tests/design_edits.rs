//! The editable design: strokes, moves, determinism, mesh domains, bad input.

use fieldtex_fields::orientation_field::{
    detect_design_singularities, face_directions, sample_plane,
};
use fieldtex_fields::presets::preset;
use fieldtex_fields::singularity_index::{
    cluster_singularities, mesh_singularities, vertex_indices,
};
use fieldtex_fields::*;
use fieldtex_mesh::{TriMesh, primitives};

mod common;

fn plane(size: f64, cells: usize, symmetry: Symmetry) -> FieldDesign {
    FieldDesign::new(
        Domain::Plane(PlaneGrid::with_cells(size, size, cells)),
        symmetry,
        FieldDesignOptions::default(),
    )
    .unwrap()
}

fn angle_diff(a: f64, b: f64, period: f64) -> f64 {
    let d = (a - b).rem_euclid(period);
    d.min(period - d)
}

#[test]
fn stroke_only_design_follows_the_stroke() {
    // A curved stroke (quarter circle) in a vector and in an orientation design.
    let pts: Vec<[f64; 2]> = (0..=24)
        .map(|k| {
            let t = std::f64::consts::FRAC_PI_2 * k as f64 / 24.0;
            [40.0 + 150.0 * t.cos(), 40.0 + 150.0 * t.sin()]
        })
        .collect();
    for symmetry in [Symmetry::Vector, Symmetry::Orientation] {
        let mut d = plane(256.0, 64, symmetry);
        d.add_stroke(Stroke::from_pixels(&pts)).unwrap();
        let f = d.solve().unwrap();
        let px = sample_plane(&d, &f, 256, 256).unwrap();
        let period = if symmetry == Symmetry::Vector { 360.0 } else { 180.0 };
        let mut errors = Vec::new();
        for k in 1..48 {
            let t = std::f64::consts::FRAC_PI_2 * (k as f64 + 0.5) / 48.0;
            let (x, y) = (40.0 + 150.0 * t.cos(), 40.0 + 150.0 * t.sin());
            // Tangent of the stroke in the order of its points (counter-clockwise in t).
            let tangent = (t.cos()).atan2(-t.sin()).to_degrees();
            let v = px[y as usize * 256 + x as usize];
            let a = (v[1] as f64).atan2(v[0] as f64).to_degrees();
            errors.push(angle_diff(a, tangent, period));
        }
        errors.sort_by(|a, b| a.total_cmp(b));
        let median = errors[errors.len() / 2];
        let max = errors[errors.len() - 1];
        assert!(
            median < 3.0 && max < 8.0,
            "{symmetry:?}: angle error median {median:.2}°, max {max:.2}°"
        );
        // Away from the stroke the field is smooth: no singularities.
        assert!(detect_design_singularities(&d, &f, 6.0).is_empty());
    }
}

#[test]
fn moving_a_singularity_equals_a_fresh_solve() {
    let file = preset("left-loop", 256.0, 256.0, 64).unwrap();
    let mut edited = file.build(None).unwrap();
    let first = edited.solve().unwrap();
    let (id, s) = edited.singularities()[0];
    let target = [s.position[0] + 17.3, s.position[1] - 9.1, 0.0];
    edited.move_singularity(id, target).unwrap();
    let moved = edited.solve().unwrap();
    assert_eq!(
        edited.refactor_count(),
        1,
        "moving a singularity must not refactor (one factorisation in all)"
    );
    let mut fresh_file = file.clone();
    fresh_file.singularities[0].x = Some(target[0]);
    fresh_file.singularities[0].y = Some(target[1]);
    let fresh = fresh_file.build(None).unwrap().solve().unwrap();
    let scale = fresh.one_form.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff =
        moved.one_form.iter().zip(&fresh.one_form).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(diff <= 1e-9 * scale, "moved vs fresh: max diff {diff:e} (scale {scale:e})");
    assert!(first.one_form != moved.one_form);
    // Removing and re-adding a stroke gives the same field back.
    let sid = edited.strokes()[0].0;
    let stroke = edited.strokes()[0].1.clone();
    edited.remove_stroke(sid).unwrap();
    let without = edited.solve().unwrap();
    edited.add_stroke(stroke).unwrap();
    let again = edited.solve().unwrap();
    assert!(without.one_form != again.one_form);
    let diff =
        again.one_form.iter().zip(&fresh.one_form).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(diff <= 1e-9 * scale);
    assert!(matches!(edited.remove_stroke(sid), Err(FieldsError::UnknownId { .. })));
}

fn whorl_pixels() -> Vec<[f32; 2]> {
    let mut d = preset("whorl", 200.0, 160.0, 48).unwrap().build(None).unwrap();
    let f = d.solve().unwrap();
    sample_plane(&d, &f, 200, 160).unwrap()
}

#[test]
fn identical_for_any_thread_count() {
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(whorl_pixels);
    let three =
        rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap().install(whorl_pixels);
    let bits = |v: &Vec<[f32; 2]>| {
        v.iter().flat_map(|p| [p[0].to_bits(), p[1].to_bits()]).collect::<Vec<_>>()
    };
    assert_eq!(bits(&one), bits(&three));
    assert_eq!(bits(&one), bits(&whorl_pixels()));
}

#[test]
fn sampling_matches_point_location() {
    let mut d = preset("right-loop", 96.0, 64.0, 24).unwrap().build(None).unwrap();
    let f = d.solve().unwrap();
    let (w, h) = (77usize, 53usize);
    let px = sample_plane(&d, &f, w, h).unwrap();
    let g = *d.plane().unwrap();
    assert_eq!((g.width, g.height, f.symmetry), (96.0, 64.0, Symmetry::Orientation));
    let reference = common::reference_pixels(&d, &f, w, h);
    for (k, (p, e)) in px.iter().zip(&reference).enumerate() {
        let (c, r) = (k % w, k / w);
        let (x, y) = ((c as f64 + 0.5) * 96.0 / w as f64, (r as f64 + 0.5) * 64.0 / h as f64);
        let (face, b) = g.locate(x, y);
        let t = d.dec().triangles[face];
        assert!(
            (p[0] as f64 - e[0]).abs() < 1e-5 && (p[1] as f64 - e[1]).abs() < 1e-5,
            "pixel {c},{r}"
        );
        // The located barycentric coordinates reproduce the point.
        let q: Vec<f64> = (0..2)
            .map(|a| (0..3).map(|i| b[i] * d.dec().positions[t[i] as usize][a]).sum())
            .collect();
        assert!((q[0] - x).abs() < 1e-9 && (q[1] - y).abs() < 1e-9);
    }
}

#[test]
fn indices_on_a_sphere_sum_to_its_euler_characteristic() {
    // The tangential part of a constant vector on a sphere: a source and a sink (+1, +1);
    // as an orientation field (N = 2) the indices still sum to 2.
    let mesh = primitives::icosphere(3);
    let (dec, _) = Dec::new(&mesh).unwrap();
    let dir = [0.3, 0.5, 0.81];
    let field: Vec<[f64; 3]> = (0..dec.n_faces())
        .map(|f| {
            let n = dec.face_normals[f];
            let d = dir[0] * n[0] + dir[1] * n[1] + dir[2] * n[2];
            [dir[0] - d * n[0], dir[1] - d * n[1], dir[2] - d * n[2]]
        })
        .collect();
    for n in [1u32, 2] {
        let idx = vertex_indices(&dec, &field, n);
        assert!(idx.iter().all(Option::is_some), "closed mesh: every vertex has an index");
        let sum: i32 = idx.iter().flatten().sum();
        assert_eq!(sum as f64 / n as f64, 2.0, "N = {n}");
        // (A +1 of a 2-RoSy field may show as two adjacent +1/2: cluster them.)
        let found =
            cluster_singularities(&mesh_singularities(&dec, &field, n), 2.5 * dec.mean_edge_length);
        assert_eq!(found.len(), 2, "N = {n}: {found:?}");
        assert!(found.iter().all(|s| s.index == 1.0));
    }
}

#[test]
fn orientation_design_on_a_disk_mesh() {
    let mut d = FieldDesign::new(
        Domain::Mesh(disk_mesh(1.0, 20)),
        Symmetry::Orientation,
        FieldDesignOptions::default(),
    )
    .unwrap();
    // Frames follow a smooth (here constant) reference field.
    let e1 = d.frames()[0].0;
    assert!(d.frames().iter().all(|(a, _)| (a[0] * e1[0] + a[1] * e1[1] + a[2] * e1[2]) > 0.999));
    let mut sings = [
        Singularity::new(SingularityKind::Wedge, [0.31, -0.22, 0.0]),
        Singularity::new(SingularityKind::Trisector, [-0.35, 0.27, 0.0]),
    ];
    // Angles are measured in the design frame: compute them in frame coordinates.
    let phi = e1[1].atan2(e1[0]);
    let in_frame: Vec<Singularity> = sings
        .iter()
        .map(|s| {
            let (c, sn) = (phi.cos(), phi.sin());
            let p = s.position;
            Singularity::new(s.kind, [c * p[0] + sn * p[1], -sn * p[0] + c * p[1], 0.0])
        })
        .collect();
    let angles = zero_pole_angles(&in_frame, 0.3);
    for (s, a) in sings.iter_mut().zip(angles) {
        s.angle = a;
        d.add_singularity(*s).unwrap();
    }
    let f = d.solve().unwrap();
    let h = d.dec().mean_edge_length;
    let found = detect_design_singularities(&d, &f, 1.5 * h);
    assert_eq!(found.len(), 2, "{found:?}");
    let dirs = face_directions(&d, &f);
    assert!(dirs.iter().all(|v| ((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) - 1.0).abs() < 1e-9));
    assert!(matches!(sample_plane(&d, &f, 8, 8), Err(FieldsError::InvalidOption { .. })));
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let mut d = plane(64.0, 16, Symmetry::Orientation);
    let nan = Singularity::at_pixel(SingularityKind::Wedge, f64::NAN, 3.0);
    assert!(matches!(d.add_singularity(nan), Err(FieldsError::NonFinite { .. })));
    let wrong = Singularity::at_pixel(SingularityKind::Source, 3.0, 3.0);
    assert!(matches!(d.add_singularity(wrong), Err(FieldsError::WrongSymmetry { .. })));
    assert!(matches!(
        d.add_stroke(Stroke::from_pixels(&[[3.0, 3.0]])),
        Err(FieldsError::StrokeTooShort { .. })
    ));
    assert!(matches!(
        d.add_stroke(Stroke::from_pixels(&[[-30.0, 3.0], [-10.0, 5.0]])),
        Err(FieldsError::StrokeMissesDomain { .. })
    ));
    assert!(matches!(
        d.add_stroke(Stroke::from_pixels(&[[3.0, 3.0], [f64::INFINITY, 5.0]])),
        Err(FieldsError::NonFinite { .. })
    ));
    assert!(matches!(
        d.move_singularity(SingularityId(7), [1.0, 1.0, 0.0]),
        Err(FieldsError::UnknownId { .. })
    ));
    let huge = Stroke::from_pixels(&[[-1e15, 3.0], [1e15, 5.0]]);
    d.add_stroke(huge).unwrap(); // clipped to the domain: no runaway sampling
    let nowhere = Singularity::at_pixel(SingularityKind::Wedge, 1e12, 3.0);
    assert!(matches!(d.add_singularity(nowhere), Err(FieldsError::OutsideDomain { .. })));
    let no_cells = PlaneGrid { width: 10.0, height: 10.0, nx: 0, ny: 3 };
    assert!(
        FieldDesign::new(Domain::Plane(no_cells), Symmetry::Vector, FieldDesignOptions::default())
            .is_err()
    );
    // A singularity outside the plane is allowed (it shapes the field from outside)...
    d.add_singularity(Singularity::at_pixel(SingularityKind::Wedge, -20.0, 30.0)).unwrap();
    assert!(d.solve().is_ok());
    // ...but not outside a mesh.
    let mut m = FieldDesign::new(
        Domain::Mesh(disk_mesh(1.0, 4)),
        Symmetry::Vector,
        FieldDesignOptions::default(),
    )
    .unwrap();
    assert!(m.warnings().is_empty(), "{:?}", m.warnings());
    let sphere = FieldDesign::new(
        Domain::Mesh(primitives::icosphere(1)),
        Symmetry::Vector,
        FieldDesignOptions::default(),
    )
    .unwrap();
    assert!(sphere.warnings().iter().any(|w| w.code == "field-domain-not-a-disk"));
    let far = Singularity::new(SingularityKind::Source, [5.0, 0.0, 0.0]);
    assert!(matches!(m.add_singularity(far), Err(FieldsError::OutsideDomain { .. })));
    // Broken meshes.
    let degenerate =
        TriMesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 1]]);
    assert!(matches!(Dec::new(&degenerate), Err(FieldsError::DegenerateTriangle { .. })));
    let fan = TriMesh::new(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]],
        vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
    );
    assert!(matches!(Dec::new(&fan), Err(FieldsError::NonManifoldEdge { .. })));
    let flipped = TriMesh::new(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
        vec![[0, 1, 2], [1, 2, 3]],
    );
    assert!(matches!(Dec::new(&flipped), Err(FieldsError::InconsistentOrientation { .. })));
    let nan_mesh =
        TriMesh::new(vec![[0.0; 3], [f64::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]);
    assert!(matches!(Dec::new(&nan_mesh), Err(FieldsError::InvalidMesh(_))));
    let bad_options = FieldDesignOptions { boundary_weight: 2.0, ..Default::default() };
    assert!(
        FieldDesign::new(Domain::Mesh(disk_mesh(1.0, 3)), Symmetry::Vector, bad_options).is_err()
    );
    // A sliver triangle is repaired with a warning, not refused.
    let sliver = TriMesh::new(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [0.5, 1e-9, 0.0], [0.5, 1.0, 0.0]],
        vec![[0, 1, 2], [0, 2, 3], [2, 1, 3]],
    );
    let (_, warnings) = Dec::new(&sliver).unwrap();
    assert!(warnings.iter().any(|w| w.code == "field-star1-clamped"), "{warnings:?}");
}

#[test]
fn design_file_errors_name_the_problem() {
    let err = |text: &str| match DesignFile::from_toml_str(text) {
        Err(FieldsError::DesignFile { message }) => message,
        other => panic!("expected a design-file error, got {other:?}"),
    };
    let plane = "[domain]\nkind = \"plane\"\nwidth = 64\nheight = 64\n";
    assert!(err("[domain]\nkind = \"plane\"\nwidth = 64\n").contains("height"));
    assert!(err(&format!("{plane}colour = 3\n")).contains("colour"));
    assert!(
        err(&format!("{plane}[[singularity]]\nkind = \"wedgie\"\nx = 1\ny = 2\n"))
            .contains("wedgie")
    );
    assert!(
        err(&format!("{plane}[[singularity]]\nkind = \"wedge\"\nx = 1\n"))
            .contains("singularity 0")
    );
    assert!(err(&format!(
        "{plane}[[singularity]]\nkind = \"wedge\"\nx = 1\ny = 1\n[[singularity]]\nkind = \"source\"\nx = 1\ny = 1\n"
    ))
    .contains("mixes"));
    assert!(err(&format!("{plane}[[stroke]]\npoints = [[1, 2]]\n")).contains("stroke 0"));
    assert!(
        err(&format!("{plane}[[stroke]]\npoints = [[1, 2, 3, 4], [1, 2]]\n"))
            .contains("coordinates")
    );
    assert!(err(&format!("{plane}[weights]\nboundary = 3\n")).contains("boundary"));
    assert!(err("[domain]\nkind = \"plane\"\nwidth = -4\nheight = 4\n").contains("width"));
    assert!(err("not toml at all [").len() > 3);
    // A vector design with the ablation switch, on a plane.
    let ok = DesignFile::from_toml_str(&format!(
        "{plane}grid = 16\n[[singularity]]\nkind = \"vortex\"\nx = 30.5\ny = 31.2\nstrength = -1\n[weights]\nboundary = 0\n"
    ))
    .unwrap();
    assert_eq!(ok.symmetry().unwrap(), Symmetry::Vector);
    assert!(!ok.options().natural_boundary);
    let mut d = ok.build(None).unwrap();
    assert!(d.solve().is_ok());
    // Mesh designs need a mesh.
    let mesh_file = DesignFile::from_toml_str(
        "[domain]\nkind = \"mesh\"\n[[singularity]]\nkind = \"source\"\nposition = [0.1, 0.2, 0.0]\n",
    )
    .unwrap();
    assert!(mesh_file.build(None).is_err());
    assert!(mesh_file.build(Some(disk_mesh(1.0, 6))).is_ok());
}

#[test]
fn designs_on_a_curved_patch() {
    // A paraboloid cap z = 0.4 (1 − r²) over the unit disk.
    let mut mesh = disk_mesh(1.0, 20);
    let lift = |p: [f64; 3]| [p[0], p[1], 0.4 * (1.0 - p[0] * p[0] - p[1] * p[1])];
    for p in &mut mesh.positions {
        *p = lift(*p);
    }
    let mut v = FieldDesign::new(
        Domain::Mesh(mesh.clone()),
        Symmetry::Vector,
        FieldDesignOptions::default(),
    )
    .unwrap();
    v.add_singularity(Singularity::new(SingularityKind::Source, lift([0.2, -0.1, 0.0]))).unwrap();
    let f = v.solve().unwrap();
    let found = detect_design_singularities(&v, &f, 1.5 * v.dec().mean_edge_length);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].index, 1.0);

    let mut o =
        FieldDesign::new(Domain::Mesh(mesh), Symmetry::Orientation, FieldDesignOptions::default())
            .unwrap();
    // The frame field is smooth: neighbouring triangles' e1 differ by little.
    let frames = o.frames().to_vec();
    let dec = o.dec();
    for e in 0..dec.n_edges() {
        let faces = dec.topology.edge_faces(e);
        if faces.len() == 2 {
            let (a, b) = (frames[faces[0] as usize].0, frames[faces[1] as usize].0);
            assert!(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] > 0.9, "frame jump at edge {e}");
        }
    }
    o.add_singularity(Singularity::new(SingularityKind::Wedge, lift([0.0, 0.35, 0.0]))).unwrap();
    o.add_singularity(Singularity::new(SingularityKind::Trisector, lift([0.0, -0.35, 0.0])))
        .unwrap();
    let f = o.solve().unwrap();
    let found = detect_design_singularities(&o, &f, 1.5 * o.dec().mean_edge_length);
    let mut idx: Vec<f64> = found.iter().map(|s| s.index).collect();
    idx.sort_by(|a, b| a.total_cmp(b));
    assert_eq!(idx, vec![-0.5, 0.5], "{found:?}");
    let dirs = fieldtex_fields::orientation_field::vertex_directions(&o, &f);
    for (v, d) in dirs.iter().enumerate() {
        let n = o.dec().vertex_normals[v];
        assert!(
            (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]).abs() < 1e-9,
            "vertex direction not tangent"
        );
    }
}

#[test]
fn rank1_stroke_updates_match_refactoring() {
    let file = preset("whorl", 200.0, 200.0, 40).unwrap();
    let short = Stroke::from_pixels(&[[30.0, 100.0], [52.0, 93.0]]);
    let solve = |limit: usize| {
        let d = file.build(None).unwrap();
        let o = FieldDesignOptions { rank1_update_limit: limit, ..d.options().clone() };
        let mut d =
            FieldDesign::new(Domain::Plane(*d.plane().unwrap()), Symmetry::Orientation, o).unwrap();
        for s in file.singularity_list().unwrap() {
            d.add_singularity(s).unwrap();
        }
        for s in file.stroke_list() {
            d.add_stroke(s).unwrap();
        }
        d.solve().unwrap();
        let id = d.add_stroke(short.clone()).unwrap();
        let with = d.solve().unwrap();
        d.remove_stroke(id).unwrap();
        let without = d.solve().unwrap();
        (with, without, d.rank1_update_count(), d.refactor_count())
    };
    let (w1, wo1, updates, refactors) = solve(1000);
    assert!(updates > 0 && refactors == 1, "updates {updates}, refactors {refactors}");
    let (w0, wo0, updates, refactors) = solve(0);
    assert!(updates == 0 && refactors == 3);
    for (a, b) in [(&w1, &w0), (&wo1, &wo0)] {
        let scale = b.one_form.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff =
            a.one_form.iter().zip(&b.one_form).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(diff <= 1e-9 * scale, "rank-1 vs refactor: {diff:e}");
    }
}

#[test]
fn design_objects_can_move_between_threads() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<FieldDesign>();
    send_sync::<SolvedField>();
    send_sync::<DesignFile>();
    send_sync::<FieldsError>();
}
