//! Tests of the cotan Laplacian over the procedural categories and fixture meshes.

use super::*;
use crate::areas::{VertexAreaKind, vertex_areas};
use crate::primitives::{grid, icosphere, torus};
use crate::test_meshes::{categories, defective_patch, load_obj};

/// Symmetric, kills constants, finite, PSD on a few pseudo-random vectors.
fn check_invariants(name: &str, mesh: &TriMesh) {
    let (l, _) = cotan_laplacian(mesh).unwrap();
    assert_eq!(l.nrows(), mesh.n_vertices(), "{name}");
    assert!(l.first_non_finite().is_none(), "{name}: non-finite entry");
    assert!(l.first_asymmetry(1e-14).is_none(), "{name}: not symmetric");
    let scale = l.values().iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1.0);
    let ones = vec![1.0; mesh.n_vertices()];
    let r = l.mul_vec(&ones);
    assert!(r.iter().all(|x| x.abs() <= 1e-12 * scale), "{name}: L·1 ≠ 0");
    for seed in 0..4u64 {
        let u: Vec<f64> = (0..mesh.n_vertices())
            .map(|i| fieldtex_core::rng::hash_unit(seed, "cotan-test", i as u64) - 0.5)
            .collect();
        let lu = l.mul_vec(&u);
        let e: f64 = u.iter().zip(&lu).map(|(a, b)| a * b).sum();
        assert!(e >= -1e-10 * scale, "{name}: uᵀLu = {e} < 0");
    }
    for v in 0..mesh.n_vertices() {
        assert!(l.get(v, v) >= 0.0 || mesh.n_triangles() == 0, "{name}: negative diagonal");
    }
}

#[test]
fn invariants_over_categories() {
    for (name, mesh) in categories() {
        check_invariants(name, &mesh);
    }
}

#[test]
fn invariants_over_fixtures() {
    let mut seen = 0;
    for name in [
        "fandisk.obj",
        "fertility.obj",
        "stanford-bunny.obj",
        "defects/narrow_triangles.obj",
        "defects/nonmanifold_edge.obj",
        "defects/beetle-1972-nonmanifold.obj",
    ] {
        if let Some(m) = load_obj(name) {
            check_invariants(name, &m);
            seen += 1;
        }
    }
    assert!(seen >= 4, "fixture meshes not found under shared/data/meshes");
}

#[test]
fn matches_triplet_assembly() {
    let m = torus(2.0, 0.5, 17, 9);
    let (fw, _) = cotan_face_weights(&m, &CotanOptions::default()).unwrap();
    let mut t = Vec::new();
    for (tri, w) in m.triangles.iter().zip(&fw) {
        for i in 0..3 {
            let (a, b) = (tri[i] as usize, tri[(i + 1) % 3] as usize);
            t.extend([(a, b, -w[i]), (b, a, -w[i]), (a, a, w[i]), (b, b, w[i])]);
        }
    }
    let reference = SparseMatrix::from_triplets(m.n_vertices(), m.n_vertices(), &t).unwrap();
    let (l, _) = cotan_laplacian(&m).unwrap();
    assert_eq!(l.col_ptr(), reference.col_ptr());
    assert_eq!(l.row_idx(), reference.row_idx());
    for (a, b) in l.values().iter().zip(reference.values()) {
        assert!((a - b).abs() < 1e-13 * (1.0 + b.abs()));
    }
    let (trip, _) = cotan_laplacian_triplets(&m, &CotanOptions::default()).unwrap();
    assert_eq!(trip.len(), l.nnz());
}

#[test]
fn linear_functions_are_harmonic_on_a_flat_grid() {
    let m = grid(9, 7, 2.0, 1.0);
    let (l, w) = cotan_laplacian(&m).unwrap();
    assert!(w.is_empty());
    let topo = Topology::build(m.n_vertices(), &m.triangles);
    let boundary = topo.boundary_vertices();
    let f: Vec<f64> = m.positions.iter().map(|p| 0.3 * p[0] - 1.7 * p[1] + 2.0).collect();
    let lf = l.mul_vec(&f);
    for v in 0..m.n_vertices() {
        if !boundary[v] {
            assert!(lf[v].abs() < 1e-12, "vertex {v}: {}", lf[v]);
        }
    }
    // Edge weights indexed by the topology agree with the matrix.
    let (ew, _) = cotan_edge_weights(&m, &topo, &CotanOptions::default()).unwrap();
    for (e, ed) in topo.edges.iter().enumerate() {
        assert!((-l.get(ed[0] as usize, ed[1] as usize) - ew[e]).abs() < 1e-12);
    }
    // Square cells: the diagonals get weight 0 (right angles opposite), axis edges 1.
    let sq = grid(4, 4, 1.0, 1.0);
    let st = Topology::build(sq.n_vertices(), &sq.triangles);
    let (sw, _) = cotan_edge_weights(&sq, &st, &CotanOptions::default()).unwrap();
    for (e, ed) in st.edges.iter().enumerate() {
        let (a, b) = (sq.positions[ed[0] as usize], sq.positions[ed[1] as usize]);
        let diagonal = (a[0] - b[0]).abs() > 1e-9 && (a[1] - b[1]).abs() > 1e-9;
        let expect = if diagonal { 0.0 } else { 0.5 * st.edge_faces(e).len() as f64 };
        assert!((sw[e] - expect).abs() < 1e-12, "edge {ed:?}: {}", sw[e]);
    }
}

#[test]
fn sphere_coordinates_are_eigenfunctions() {
    // On the unit sphere Δx = −2x, so L x ≈ 2 M x.
    let m = icosphere(4);
    let (l, _) = cotan_laplacian(&m).unwrap();
    let mass = vertex_areas(&m, VertexAreaKind::MixedVoronoi);
    for k in 0..3 {
        let x: Vec<f64> = m.positions.iter().map(|p| p[k]).collect();
        let lx = l.mul_vec(&x);
        let num: f64 = lx.iter().zip(&x).map(|(a, b)| a * b).sum();
        let den: f64 = x.iter().zip(&mass).map(|(a, b)| a * a * b).sum();
        let rayleigh = num / den;
        assert!((rayleigh - 2.0).abs() < 0.02, "Rayleigh quotient {rayleigh}");
    }
}

#[test]
fn defects_are_counted_and_finite() {
    let m = defective_patch();
    let (l, stats) = cotan_laplacian_with(&m, &CotanOptions::default()).unwrap();
    assert_eq!(stats.n_floored, 2, "{stats:?}");
    assert_eq!(stats.n_skipped, 1, "{stats:?}");
    assert!(l.first_non_finite().is_none());
    let max = l.values().iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(max <= 1.0 / (4.0 * 1e-6), "max |L_ij| {max}");
    assert_eq!(stats.warnings().len(), 2);
    // The unreferenced (last) vertex has only its zero diagonal.
    let last = m.n_vertices() - 1;
    assert_eq!(l.col_ptr()[last + 1] - l.col_ptr()[last], 1);
    assert_eq!(l.get(last, last), 0.0);
    // Out-of-range index: an error naming the triangle, not a panic.
    let mut bad = m.clone();
    bad.triangles.push([0, 1, 10_000]);
    assert!(matches!(cotan_laplacian(&bad), Err(MeshError::IndexOutOfRange { .. })));
}

#[test]
fn narrow_triangles_fixture_reports_its_slivers() {
    let Some(m) = load_obj("defects/narrow_triangles.obj") else { return };
    let (l, stats) = cotan_laplacian_with(&m, &CotanOptions::default()).unwrap();
    assert!(l.first_non_finite().is_none());
    assert_eq!(stats.n_skipped, 0);
    // A mesh of slivers: the floor must act on only a minority of them, if any.
    assert!(stats.n_floored < m.n_triangles() / 2, "{stats:?}");
}

#[test]
fn deterministic_across_thread_counts() {
    let m = crate::primitives::subdivide_midpoint(&icosphere(3));
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| cotan_laplacian(&m).unwrap().0)
    };
    let (a, b) = (run(1), run(3));
    assert_eq!(a.values().iter().map(|v| v.to_bits()).collect::<Vec<_>>(), {
        b.values().iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    });
}

#[test]
fn combined_assembly_matches_separate_calls() {
    for (name, m) in categories() {
        let (l, _) = cotan_laplacian(&m).unwrap();
        for kind in [VertexAreaKind::Barycentric, VertexAreaKind::MixedVoronoi] {
            let (l2, mass, _) =
                cotan_laplacian_and_mass(&m, &CotanOptions::default(), kind).unwrap();
            assert_eq!(l, l2, "{name}");
            let reference = crate::mass_matrix::lumped_mass(&m, kind).unwrap();
            assert_eq!(
                mass.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                reference.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                "{name} {kind:?}"
            );
        }
    }
}
