//! Paper A §4: the eq. (1) score, update-vs-refactor equivalence of the penalty system,
//! singularity index sums, bad input.

use std::f64::consts::PI;

use fieldtex_core::vec3::{self, V3};
use fieldtex_fields::harmonic_diffusion::{CurveFieldOptions, CurveFieldSolver};
use fieldtex_fields::surface_field_metrics::surface_field_metrics;
use fieldtex_fields::{
    CurveOrientationOptions, OverlapPolicy, VertexFieldStatus, orient_curves, orientation_score,
};
use fieldtex_mesh::primitives::{grid, icosphere, torus};
use fieldtex_mesh::{Topology, TriMesh};

mod common;
use common::{line, meridian};

#[test]
fn score_of_a_straight_curve_against_a_constant_field() {
    let mesh = grid(20, 20, 1.0, 1.0);
    let solver = CurveFieldSolver::new(&mesh, &CurveFieldOptions::default()).unwrap();
    let c = solver.sample_curve(&line([0.2, 0.5, 0.0], [0.8, 0.5, 0.0], 3));
    let n = c.vertices.len();
    assert!(n >= 12, "a 0.6-long curve on a 0.05 grid reaches >= 12 vertices, got {n}");
    assert!((c.length - 0.6).abs() < 1e-9, "on-mesh length {}", c.length);
    let along = orientation_score(&c.tangents, |_| Some([1.0, 0.0, 0.0]));
    assert_eq!(along.n_points, n);
    assert!((along.forward - n as f64).abs() < 1e-9 && along.backward.abs() < 1e-9);
    assert_eq!(along.sign(), 1);
    assert!((along.signed() - n as f64).abs() < 1e-9);
    // The same curve given the other way round scores the mirror image.
    let r = solver.sample_curve(&line([0.8, 0.5, 0.0], [0.2, 0.5, 0.0], 3));
    let rev = orientation_score(&r.tangents, |_| Some([1.0, 0.0, 0.0]));
    assert!(rev.forward.abs() < 1e-9 && (rev.backward - n as f64).abs() < 1e-9);
    assert_eq!(rev.sign(), -1);
    assert!((rev.signed() + n as f64).abs() < 1e-9);
    assert!((rev.best() - along.best()).abs() < 1e-12, "g is orientation invariant");
    // Perpendicular: θ = π/2 gives 1/3 for both orientations; θ = π/3 gives 1/2 forward
    // and (π/3)/(5π/3) = 1/5 backward.
    let perp = orientation_score(&c.tangents, |_| Some([0.0, 1.0, 0.0]));
    assert!((perp.forward - n as f64 / 3.0).abs() < 1e-9);
    assert!((perp.backward - n as f64 / 3.0).abs() < 1e-9);
    let u = [(PI / 3.0).cos(), (PI / 3.0).sin(), 0.0];
    let s = orientation_score(&c.tangents, |_| Some(u));
    assert!((s.forward - 0.5 * n as f64).abs() < 1e-9);
    assert!((s.backward - 0.2 * n as f64).abs() < 1e-9);
    // Undefined field points do not count.
    let half = orientation_score(&c.tangents, |k| (k % 2 == 0).then_some([1.0, 0.0, 0.0]));
    assert_eq!(half.n_points, n.div_ceil(2));
}

#[test]
fn rank1_updates_match_a_fresh_factorisation() {
    let mesh = icosphere(4);
    let mut solver = CurveFieldSolver::new(&mesh, &CurveFieldOptions::default()).unwrap();
    let curves = [
        meridian(0.0, -1.0, 1.0, 40),
        meridian(2.0, -0.8, 1.1, 40),
        meridian(4.0, 1.0, -1.0, 40),
        line([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], 10), // chord: projected to the sphere's vertices
    ];
    let mut total_updates = 0;
    for (k, c) in curves.iter().enumerate() {
        let cc = solver.sample_curve(c);
        assert!(!cc.vertices.is_empty(), "curve {k} must land on the sphere");
        let r = solver.add_constraints(&cc, if k % 2 == 0 { 1.0 } else { -1.0 }).unwrap();
        if k == 0 {
            assert_eq!((r.factorisations, r.rank1_updates), (1, 0));
        } else {
            assert_eq!(r.factorisations, 0, "step {k} must not refactor");
            assert_eq!(r.rank1_updates, r.new_vertices);
            total_updates += r.rank1_updates;
        }
        solver.solve().unwrap();
    }
    assert!(total_updates > 50, "{total_updates} updates");
    let updated = solver.raw_solution().to_vec();
    let (fresh, _) = solver.refactored_solution().unwrap();
    let scale = fresh.iter().map(|v| vec3::norm(*v)).fold(0.0, f64::max);
    let diff =
        updated.iter().zip(&fresh).map(|(a, b)| vec3::norm(vec3::sub(*a, *b))).fold(0.0, f64::max);
    assert!(scale > 0.5, "solution scale {scale}");
    assert!(diff <= 1e-8 * scale, "updated vs refactored: max diff {diff:e} (scale {scale})");
    // The penalty makes the constrained vertices follow their targets closely.
    for (v, t) in solver.constraints() {
        let x = updated[v as usize];
        assert!(vec3::norm(vec3::sub(x, t)) < 1e-5, "vertex {v}: {x:?} vs {t:?}");
    }
}

#[test]
fn average_overlap_changes_only_the_right_hand_side() {
    let mesh = grid(20, 20, 1.0, 1.0);
    let options = CurveFieldOptions { overlap: OverlapPolicy::Average, ..Default::default() };
    let mut solver = CurveFieldSolver::new(&mesh, &options).unwrap();
    let a = solver.sample_curve(&line([0.1, 0.5, 0.0], [0.9, 0.5, 0.0], 1));
    let b = solver.sample_curve(&line([0.5, 0.1, 0.0], [0.5, 0.9, 0.0], 1));
    solver.add_constraints(&a, 1.0).unwrap();
    let r = solver.add_constraints(&b, 1.0).unwrap();
    assert!(r.overlapping_vertices >= 1);
    assert_eq!(r.rank1_updates, r.new_vertices);
    solver.solve().unwrap();
    let centre = 10 * 21 + 10;
    let t = solver.constraints().into_iter().find(|&(v, _)| v == centre).unwrap().1;
    let d = std::f64::consts::FRAC_1_SQRT_2;
    assert!(vec3::norm(vec3::sub(t, [d, d, 0.0])) < 1e-9, "averaged target {t:?}");
    let (fresh, _) = solver.refactored_solution().unwrap();
    let diff = solver
        .raw_solution()
        .iter()
        .zip(&fresh)
        .map(|(a, b)| vec3::norm(vec3::sub(*a, *b)))
        .fold(0.0, f64::max);
    assert!(diff < 1e-8, "{diff:e}");
}

/// `u` projected per vertex; used for analytic test fields.
fn field_of(mesh: &TriMesh, f: impl Fn(V3) -> V3) -> Vec<V3> {
    mesh.positions.iter().map(|&p| f(p)).collect()
}

fn check_index_sum(mesh: &TriMesh, field: &[V3], chi: i32, what: &str) -> usize {
    let m = surface_field_metrics(mesh, field, &[]).unwrap();
    assert_eq!(m.undetermined_faces, 0, "{what}: undetermined faces");
    assert_eq!(m.index_sum, chi, "{what}: index sum {} (χ = {chi})", m.index_sum);
    assert_eq!(m.euler_characteristic, i64::from(chi), "{what}");
    m.singularities.len()
}

#[test]
fn index_sums_equal_the_euler_characteristic() {
    let sphere = icosphere(3);
    let topo = Topology::build(sphere.n_vertices(), &sphere.triangles);
    assert_eq!(topo.euler_characteristic(), 2);
    // Rotation about a tilted axis: two +1 vortices.
    let axis = vec3::normalize([0.3, 0.2, 1.0]).unwrap();
    let n = check_index_sum(&sphere, &field_of(&sphere, |p| vec3::cross(axis, p)), 2, "vortex");
    assert!((2..=4).contains(&n), "vortex field: {n} singular faces");
    // Projected constant vector: source and sink.
    let m = check_index_sum(&sphere, &field_of(&sphere, |_| [0.9, 0.3, 0.2]), 2, "constant");
    assert!((2..=4).contains(&m), "constant field: {m} singular faces");
    // A wild field still sums to χ.
    check_index_sum(
        &sphere,
        &field_of(&sphere, |p| [(7.0 * p[1]).sin() + 0.1, (5.0 * p[2]).cos(), (3.0 * p[0]).sin()]),
        2,
        "wild",
    );

    let tor = torus(2.0, 0.7, 48, 24);
    let topo = Topology::build(tor.n_vertices(), &tor.triangles);
    assert_eq!(topo.euler_characteristic(), 0);
    let n = check_index_sum(&tor, &field_of(&tor, |p| [-p[1], p[0], 0.0]), 0, "torus circles");
    assert_eq!(n, 0, "the field along the major circles has no singularity");
    let m = check_index_sum(&tor, &field_of(&tor, |_| [1.0, 0.35, 0.1]), 0, "torus constant");
    assert!(m >= 4, "a projected constant field on a torus has >= 4 singularities, got {m}");
}

#[test]
fn index_sum_on_genus_four_fixture() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/meshes/fertility.obj");
    let mesh = fieldtex_io::read_mesh(&path).unwrap().mesh;
    let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
    assert_eq!(topo.euler_characteristic(), -6);
    check_index_sum(&mesh, &field_of(&mesh, |_| [0.31, 0.9, 0.17]), -6, "fertility constant");
}

#[test]
fn solved_sphere_field_is_tangent_unit_and_aligned() {
    let mesh = icosphere(4);
    let curves = vec![meridian(0.0, -1.2, 1.2, 50), meridian(2.1, -1.2, 1.2, 50)];
    let r = orient_curves(
        &mesh,
        &curves,
        &CurveOrientationOptions::default(),
        &fieldtex_core::NoProgress,
    )
    .unwrap();
    assert_eq!(r.signs, vec![1, 1]);
    let normals = r.solver.normals().to_vec();
    for (v, (u, s)) in r.field.vectors.iter().zip(&r.field.status).enumerate() {
        if *s == VertexFieldStatus::Solved {
            assert!((vec3::norm(*u) - 1.0).abs() < 1e-12);
            assert!(vec3::dot(*u, normals[v]).abs() < 1e-12);
        }
    }
    let m = surface_field_metrics(&mesh, &r.field.vectors, &r.solver.constraints()).unwrap();
    assert!(m.alignment.n > 50 && m.alignment.mean_deg < 1e-3, "{:?}", m.alignment);
    assert_eq!((m.index_sum, m.undetermined_faces), (2, 0));
    assert!(m.dirichlet_energy > 0.0 && m.dirichlet_energy.is_finite());
}

#[test]
fn bad_input_gives_errors_or_warnings() {
    // Empty mesh, non-finite positions, invalid options: errors.
    let empty = TriMesh::default();
    assert!(CurveFieldSolver::new(&empty, &CurveFieldOptions::default()).is_err());
    let mut nan = grid(2, 2, 1.0, 1.0);
    nan.positions[0][1] = f64::NAN;
    assert!(CurveFieldSolver::new(&nan, &CurveFieldOptions::default()).is_err());
    let g = grid(10, 10, 1.0, 1.0);
    let bad = CurveFieldOptions { penalty: -1.0, ..Default::default() };
    assert!(CurveFieldSolver::new(&g, &bad).is_err());
    for (spacing, distance) in [(f64::NAN, 2.0), (1e-9, 2.0), (0.5, 1e9), (0.5, 0.0)] {
        let bad = CurveFieldOptions {
            sample_spacing: spacing,
            max_distance: distance,
            ..Default::default()
        };
        assert!(CurveFieldSolver::new(&g, &bad).is_err(), "{spacing} {distance}");
    }

    // A grid plus a second grid far away, a component of coincident points and an
    // unreferenced vertex.
    let mut mesh = grid(10, 10, 1.0, 1.0);
    let far = grid(4, 4, 1.0, 1.0);
    let off = mesh.n_vertices() as u32;
    mesh.positions.extend(far.positions.iter().map(|p| [p[0] + 5.0, p[1] + 5.0, p[2]]));
    mesh.triangles.extend(far.triangles.iter().map(|t| t.map(|i| i + off)));
    let d = mesh.n_vertices() as u32;
    mesh.positions.extend([[9.0, 9.0, 9.0]; 4]);
    mesh.triangles.extend([[d, d + 1, d + 2], [d + 1, d + 3, d + 2]]);
    mesh.positions.push([3.0, 3.0, 3.0]);
    let curves = vec![
        line([0.1, 0.5, 0.0], [0.9, 0.5, 0.0], 4),   // fine
        line([0.1, 0.5, 40.0], [0.9, 0.5, 40.0], 4), // off the mesh
        vec![],                                      // empty
        vec![[0.5, 0.5, 0.0]],                       // a single point
        vec![[f64::NAN, 0.0, 0.0], [f64::INFINITY, 1.0, 0.0]],
        line([9.0, 9.0, 9.0], [9.0, 9.0, 9.0], 3), // zero length, on the degenerate part
        vec![[1e6, 0.5, 0.0], [-1e6, 0.5, 0.0]],   // long: only the part near the mesh
        vec![[1.7e308, 0.0, 0.0], [-1.7e308, 0.0, 0.0]], // the length overflows
        vec![[1e300, 0.5, 0.0], [-1e300, 0.5, 1e-300]], // beyond f64 resolution: no hang
    ];
    for mode in [
        fieldtex_fields::OrientationMode::Greedy,
        fieldtex_fields::OrientationMode::Arbitrary { seed: 3 },
    ] {
        let options = CurveOrientationOptions { mode, ..Default::default() };
        let r = orient_curves(&mesh, &curves, &options, &fieldtex_core::NoProgress).unwrap();
        assert_eq!(r.signs[1..6], [0, 0, 0, 0, 0]);
        assert_ne!(r.signs[6], 0, "the huge segment crosses the grid at y = 0.5");
        assert_eq!(r.signs[7], 0);
        // It crosses the first grid, plus up to 2 mean edge lengths beyond its ends.
        assert!((1.0..1.8).contains(&r.curves[6].length), "{}", r.curves[6].length);
        assert_ne!(r.signs[0], 0);
        let codes: Vec<&str> = r.warnings.iter().map(|w| w.code.as_str()).collect();
        for c in [
            "curves-without-constraints",
            "curve-samples-off-mesh",
            "field-isolated-vertices",
            "field-unconstrained-components",
        ] {
            assert!(codes.contains(&c), "missing warning {c} in {codes:?}");
        }
        let st = &r.field.status;
        assert_eq!(st[off as usize + 3], VertexFieldStatus::Fallback);
        assert_eq!(st[d as usize], VertexFieldStatus::Isolated);
        assert_eq!(*st.last().unwrap(), VertexFieldStatus::Isolated);
        assert!(r.field.vectors.iter().all(|v| vec3::is_finite(*v)));
        let m = surface_field_metrics(&mesh, &r.field.vectors, &r.solver.constraints()).unwrap();
        assert!(m.dirichlet_energy.is_finite() && m.undetermined_faces >= 2);
    }
    // Only degenerate curves: no field at all, every component falls back.
    let r = orient_curves(
        &g,
        &[vec![]],
        &CurveOrientationOptions::default(),
        &fieldtex_core::NoProgress,
    )
    .unwrap();
    assert!(r.field.status.iter().all(|s| *s == VertexFieldStatus::Fallback));
    assert!(r.steps.is_empty());
}

#[test]
fn planar_vortex_saddle_and_parallel_fields() {
    let mesh = grid(20, 20, 2.0, 2.0);
    let centre = [1.013, 0.987, 0.0]; // inside a face, off the vertices
    let vortex = field_of(&mesh, |p| [-(p[1] - centre[1]), p[0] - centre[0], 0.0]);
    let m = surface_field_metrics(&mesh, &vortex, &[]).unwrap();
    assert_eq!(m.singularities.len(), 1, "{:?}", m.singularities);
    assert_eq!(m.singularities[0].index, 1);
    assert!(vec3::norm(vec3::sub(m.singularities[0].position, centre)) < 0.1);
    let saddle = field_of(&mesh, |p| [p[0] - centre[0], -(p[1] - centre[1]), 0.0]);
    let m = surface_field_metrics(&mesh, &saddle, &[]).unwrap();
    assert_eq!(m.singularities.iter().map(|s| s.index).collect::<Vec<_>>(), vec![-1]);
    // A parallel field costs nothing; a rotated one does.
    let parallel = field_of(&mesh, |_| [0.6, 0.8, 0.0]);
    let m = surface_field_metrics(&mesh, &parallel, &[(5, [0.0, 1.0, 0.0])]).unwrap();
    assert!(m.dirichlet_energy.abs() < 1e-20 && m.dirichlet_energy_ambient.abs() < 1e-20);
    assert!((m.alignment.mean_deg - 0.8f64.acos().to_degrees()).abs() < 1e-9);
    assert!(m.singularities.is_empty() && m.undetermined_faces == 0);
    let m = surface_field_metrics(&mesh, &vortex, &[]).unwrap();
    assert!(m.dirichlet_energy > 1.0);
    // On a cylinder the circumferential field is parallel: no transported energy, while
    // the ambient energy sees the vectors turn in space.
    let (nu, nv) = (32u32, 6u32);
    let mut cyl = TriMesh::default();
    for j in 0..=nv {
        for i in 0..nu {
            let a = std::f64::consts::TAU * f64::from(i) / f64::from(nu);
            cyl.positions.push([a.cos(), a.sin(), 0.2 * f64::from(j)]);
        }
    }
    for j in 0..nv {
        for i in 0..nu {
            let (a, b) = (j * nu + i, j * nu + (i + 1) % nu);
            cyl.triangles.extend([[a, b, b + nu], [a, b + nu, a + nu]]);
        }
    }
    let around = field_of(&cyl, |p| [-p[1], p[0], 0.0]);
    let m = surface_field_metrics(&cyl, &around, &[]).unwrap();
    assert!(m.dirichlet_energy < 1e-20, "{m:?}");
    assert!(m.dirichlet_energy_ambient > 0.1, "{m:?}");
    assert!(m.singularities.is_empty() && m.undetermined_faces == 0);
}
