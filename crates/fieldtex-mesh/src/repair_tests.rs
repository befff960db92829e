//! Tests of [`crate::repair()`]: every fixture repairs to a clean, valid mesh, a second
//! repair changes nothing, attributes stay attached to their elements.

use crate::inspect::{InspectOptions, InspectReport, inspect};
use crate::primitives::{grid, icosphere, torus};
use crate::repair::{RepairOptions, RepairResult, repair};
use crate::test_meshes::load;
use crate::triangle_quality::signed_volume6;
use crate::{CornerUvs, TriMesh};

const FIXTURES: [&str; 10] = [
    "defects/beetle-1972-nonmanifold.obj",
    "defects/nonmanifold_edge.obj",
    "defects/nonmanifold_vertex.obj",
    "defects/nonoriented_edge.obj",
    "defects/narrow_triangles.obj",
    "defects/cube_soup.obj",
    "defects/moebius-160-10.ply",
    "stanford-bunny.obj",
    "fertility.obj",
    "torus.obj",
];

fn fix(m: &TriMesh) -> RepairResult {
    repair(m, &RepairOptions::default())
}

fn count(r: &RepairResult, code: &str) -> usize {
    r.changes.iter().find(|c| c.code == code).map_or(0, |c| c.count)
}

/// What a repaired mesh must satisfy.
fn assert_clean(what: &str, r: &InspectReport) {
    assert_eq!(r.non_finite_vertices.count, 0, "{what}");
    assert_eq!(r.invalid_index_triangles.count, 0, "{what}");
    assert_eq!(r.repeated_index_triangles.count, 0, "{what}");
    assert_eq!(r.unreferenced_vertices.count, 0, "{what}");
    assert_eq!(r.non_manifold_edges.count, 0, "{what}");
    assert_eq!(r.non_manifold_vertices.count, 0, "{what}");
    assert_eq!(r.shape.zero_area.count, 0, "{what}");
    assert_eq!(r.duplicate_triangles.count, 0, "{what}");
    assert_eq!(r.duplicate_vertices.weldable, 0, "{what}");
    assert_eq!(r.components.count, r.components.edge_connected, "{what}");
    if r.orientation.non_orientable_components.is_empty() {
        assert_eq!(r.orientation.inconsistent_edges.count, 0, "{what}");
    }
}

#[test]
fn every_fixture_repairs_clean_and_idempotent() {
    for f in FIXTURES {
        let m = load(f);
        let r = fix(&m);
        assert_eq!(r.mesh.validate(), Ok(()), "{f}");
        assert_clean(f, &inspect(&r.mesh, &InspectOptions::default()));
        let again = fix(&r.mesh);
        assert!(again.changes.is_empty(), "{f}: second repair changed {:?}", again.changes);
        assert!(again.mesh == r.mesh, "{f}");
    }
}

#[test]
fn clean_meshes_are_untouched() {
    for m in [load("fertility.obj"), load("torus.obj"), icosphere(2), torus(2.0, 0.5, 16, 8)] {
        let r = fix(&m);
        assert!(r.changes.is_empty(), "{:?}", r.changes);
        assert!(r.warnings.is_empty());
        assert!(r.mesh == m);
    }
}

#[test]
fn fixture_changes() {
    let r = fix(&load("defects/beetle-1972-nonmanifold.obj"));
    assert_eq!(count(&r, "non-manifold-edges-detached"), 47);
    assert!(count(&r, "non-manifold-vertices-split") > 0);

    let r = fix(&load("defects/nonmanifold_edge.obj"));
    assert_eq!(count(&r, "non-manifold-edges-detached"), 1);
    assert_eq!(r.mesh.n_triangles(), 6);
    // Both edge ends copied for the detached quad.
    assert_eq!(r.mesh.n_vertices(), 10);

    let r = fix(&load("defects/nonmanifold_vertex.obj"));
    assert_eq!(count(&r, "non-manifold-vertices-split"), 1);
    assert_eq!(r.mesh.n_vertices(), 8);
    assert_eq!(r.changes.len(), 1);
    // The split copy coincides with its vertex, but that is no longer a problem.
    let i = inspect(&r.mesh, &InspectOptions::default());
    assert_eq!((i.duplicate_vertices.exact, i.duplicate_vertices.weldable), (1, 0));
    assert!(i.problems().is_empty(), "{:?}", i.problems());

    let r = fix(&load("defects/nonoriented_edge.obj"));
    assert_eq!(count(&r, "orientation-made-consistent"), 2);

    // Slivers are reported by inspect but not removed by repair.
    let m = load("defects/narrow_triangles.obj");
    assert!(fix(&m).changes.is_empty());

    let r = fix(&load("stanford-bunny.obj"));
    assert_eq!(count(&r, "unreferenced-vertices-dropped"), 1113);
    assert_eq!(r.mesh.n_vertices(), 35947 - 1113);
    assert_eq!(inspect(&r.mesh, &InspectOptions::default()).boundary_loops.count, 5);

    let r = fix(&load("defects/moebius-160-10.ply"));
    assert!(r.changes.is_empty());
    assert_eq!(r.warnings.len(), 1);
    assert_eq!(r.warnings[0].code, "non-orientable");
}

#[test]
fn cube_soup_welds_into_closed_outward_cube() {
    let m = load("defects/cube_soup.obj");
    let r = fix(&m);
    assert_eq!(count(&r, "vertices-welded"), 16);
    assert_eq!((r.mesh.n_vertices(), r.mesh.n_triangles()), (8, 12));
    let i = inspect(&r.mesh, &InspectOptions::default());
    assert_eq!(i.components.count, 1);
    assert_eq!(i.boundary_loops.count, 0);
    assert_eq!(i.components.listed[0].euler_characteristic, 2);
    assert_eq!(i.components.listed[0].genus, Some(0));
    let vol: f64 = (0..12).map(|f| signed_volume6(&r.mesh.triangle_positions(f))).sum();
    assert!((vol / 6.0 - 8000.0).abs() < 1e-9, "{vol}");
    // Per-corner UVs are kept exactly (the soup had one UV per corner).
    let (a, b) = (m.uvs.as_ref().unwrap(), r.mesh.uvs.as_ref().unwrap());
    for f in 0..12 {
        let before: Vec<[f64; 2]> = a.indices[f].iter().map(|&k| a.values[k as usize]).collect();
        let after: Vec<[f64; 2]> = b.indices[f].iter().map(|&k| b.values[k as usize]).collect();
        let mut s1 = before.clone();
        let mut s2 = after.clone();
        s1.sort_by(|x, y| x.partial_cmp(y).unwrap());
        s2.sort_by(|x, y| x.partial_cmp(y).unwrap());
        assert_eq!(s1, s2);
    }
    // Without welding the soup stays six pieces.
    let no_weld = RepairOptions { weld: false, ..Default::default() };
    let r = repair(&m, &no_weld);
    assert_eq!(r.mesh.n_vertices(), 24);
}

#[test]
fn sphere_orientation() {
    let good = icosphere(2);
    let mut m = good.clone();
    m.triangles[7].swap(1, 2);
    let r = fix(&m);
    assert_eq!(count(&r, "orientation-made-consistent"), 1);
    assert_eq!(r.changes[0].examples, vec![7]);
    assert!(r.mesh == good);
    // Inside out: reversed as a whole.
    let mut m = good.clone();
    for t in &mut m.triangles {
        t.swap(1, 2);
    }
    m.triangles[3].swap(1, 2); // and one of them inconsistent
    let r = fix(&m);
    assert_eq!(count(&r, "orientation-made-consistent"), 1);
    assert_eq!(count(&r, "patches-reversed-outward"), 1);
    assert!(r.mesh == good);
    let keep_inward = RepairOptions { orient_outward: false, ..Default::default() };
    let r = repair(&m, &keep_inward);
    assert_eq!(r.changes.len(), 1);
    assert_eq!(
        r.mesh.triangles[3],
        [good.triangles[3][0], good.triangles[3][2], good.triangles[3][1]]
    );
}

#[test]
fn nan_vertex_and_bad_indices() {
    let mut m = icosphere(1);
    m.positions[5] = [f64::NAN, 0.0, 0.0];
    m.triangles.push([0, 1, 4000]);
    m.triangles.push([2, 2, 3]);
    let r = fix(&m);
    assert_eq!(r.mesh.validate(), Ok(()));
    assert_eq!(count(&r, "non-finite-vertices-dropped"), 1);
    assert_eq!(count(&r, "invalid-triangles-dropped"), 1);
    assert_eq!(count(&r, "repeated-index-triangles-dropped"), 1);
    assert_eq!(r.mesh.n_triangles(), 80 - 5);
    assert_eq!(r.mesh.n_vertices(), 41);
    let i = inspect(&r.mesh, &InspectOptions::default());
    assert_eq!(i.boundary_loops.count, 1);
    assert!(fix(&r.mesh).changes.is_empty());
}

#[test]
fn bowtie_splits_and_empty_results_warn() {
    let r = fix(&crate::test_meshes::bowtie());
    assert_eq!(count(&r, "non-manifold-vertices-split"), 1);
    assert_eq!(r.mesh.n_vertices(), 6);
    assert_eq!(r.mesh.triangles[1], [5, 3, 4]);
    // Only degenerate input: an empty result with a warning, no panic.
    let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    let r = fix(&TriMesh::new(p, vec![[0, 1, 2], [0, 0, 1]]));
    assert!(r.mesh.triangles.is_empty() && r.mesh.positions.is_empty());
    assert_eq!(r.warnings[0].code, "mesh-empty");
    assert!(fix(&TriMesh::default()).changes.is_empty());
}

/// Attributes must follow their elements through weld, split, flips and compaction:
/// colours and normals are functions of the vertex position, UVs of the corner
/// position, before and after.
#[test]
fn attributes_stay_attached() {
    let colour = |p: [f64; 3]| [p[0] as f32, p[1] as f32, p[2] as f32, 1.0];
    let uvf = |p: [f64; 3]| [p[0] + 2.0 * p[2], p[1]];
    let mut m = icosphere(2);
    // Soup the first 40 triangles (duplicate their vertices), flip one, add junk.
    let n0 = m.n_vertices() as u32;
    for f in 0..40 {
        let t = m.triangles[f];
        for (i, &v) in t.iter().enumerate() {
            let q = m.positions[v as usize];
            m.positions.push(q);
            m.triangles[f][i] = m.positions.len() as u32 - 1;
        }
    }
    m.triangles[50].swap(0, 2);
    m.positions.push([9.0, 9.0, 9.0]);
    m.triangles.push(m.triangles[60]);
    m.triangles.push([1, 1, 2]);
    let bowtie = m.positions.len() as u32;
    m.positions.extend([[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 0.2, 0.0]]);
    let a = (0..n0).position(|v| m.positions[v as usize][0] > 0.99).unwrap() as u32;
    m.triangles.push([a, bowtie + 1, bowtie + 2]);
    m.vertex_colors = Some(m.positions.iter().map(|&p| colour(p)).collect());
    m.vertex_normals = Some(m.positions.clone());
    let values: Vec<[f64; 2]> =
        m.triangles.iter().flat_map(|t| t.map(|v| uvf(m.positions[v as usize]))).collect();
    let indices = (0..m.n_triangles() as u32).map(|f| [3 * f, 3 * f + 1, 3 * f + 2]).collect();
    m.uvs = Some(CornerUvs { values, indices });

    let r = fix(&m);
    let out = &r.mesh;
    assert_eq!(out.validate(), Ok(()));
    assert!(count(&r, "vertices-welded") > 100);
    // 162 sphere vertices, a copy of the bowtie's pinch vertex and its two others.
    assert_eq!(out.n_vertices(), 165);
    assert_eq!(count(&r, "non-manifold-vertices-split"), 1);
    assert_eq!(count(&r, "orientation-made-consistent"), 1);
    assert_eq!(count(&r, "duplicate-triangles-dropped"), 1);
    assert_eq!(out.n_triangles(), 321);
    let (c, n, uv) = (
        out.vertex_colors.as_ref().unwrap(),
        out.vertex_normals.as_ref().unwrap(),
        out.uvs.as_ref().unwrap(),
    );
    for (f, t) in out.triangles.iter().enumerate() {
        for i in 0..3 {
            let p = out.positions[t[i] as usize];
            assert_eq!(c[t[i] as usize], colour(p));
            assert_eq!(n[t[i] as usize], p);
            assert_eq!(uv.values[uv.indices[f][i] as usize], uvf(p));
        }
    }
    let i = inspect(out, &InspectOptions::default());
    assert_clean("attributes", &i);
    assert!(fix(out).changes.is_empty());
}

#[test]
fn epsilon_weld_closes_a_cracked_seam() {
    // Two halves of a grid whose seam vertices differ by 1e-9.
    let left = grid(4, 4, 1.0, 1.0);
    let mut right = grid(4, 4, 1.0, 1.0);
    for p in &mut right.positions {
        p[0] += 1.0 + if p[0] == 0.0 { 1e-9 } else { 0.0 };
    }
    let nl = left.n_vertices() as u32;
    let mut m = left.clone();
    m.positions.extend(&right.positions);
    m.triangles.extend(right.triangles.iter().map(|t| t.map(|v| v + nl)));
    assert!(fix(&m).changes.is_empty());
    let opts = RepairOptions { weld_epsilon_relative: 1e-6, ..Default::default() };
    let r = repair(&m, &opts);
    assert_eq!(count(&r, "vertices-welded"), 5);
    let i = inspect(&r.mesh, &InspectOptions::default());
    assert_eq!((i.components.count, i.boundary_loops.count), (1, 1));
    assert!(repair(&r.mesh, &opts).changes.is_empty());
}

/// Random garbage (coincident points, NaN, out-of-range and repeated indices, stacked
/// triangles): inspect and repair never panic, repair output is clean, valid (or empty)
/// and a fixed point. Small cases with exact welding, larger ones with an epsilon.
#[test]
fn random_soups_repair_to_fixed_points() {
    let mut state = 7u64;
    let mut next = |n: u64| {
        state = fieldtex_core::rng::mix64(state.wrapping_add(0x9e37_79b9_7f4a_7c15));
        state % n.max(1)
    };
    let eps = RepairOptions { weld_epsilon_relative: 1e-6, ..Default::default() };
    for case in 0..400 {
        let (grid_n, max_v, max_f, opts) = if case < 300 {
            (3, 24, 40, RepairOptions::default())
        } else {
            (6, 200, 400, eps.clone())
        };
        let nv = next(max_v) as usize;
        let positions: Vec<[f64; 3]> = (0..nv)
            .map(|_| {
                if next(40) == 0 {
                    [f64::NAN, 0.0, 0.0]
                } else {
                    let jitter = next(3) as f64 * 1e-8;
                    [next(grid_n) as f64 + jitter, next(grid_n) as f64, next(2) as f64]
                }
            })
            .collect();
        let nf = next(max_f) as usize;
        let triangles: Vec<[u32; 3]> =
            (0..nf).map(|_| [0; 3].map(|_| next(nv as u64 + 1) as u32)).collect();
        let mut m = TriMesh::new(positions, triangles);
        if case % 3 == 0 {
            m.vertex_colors = Some(vec![[0.5; 4]; nv]);
            let values = vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
            m.uvs = Some(CornerUvs { values, indices: vec![[0, 1, 2]; nf] });
        }
        let _ = inspect(&m, &InspectOptions::default()).summary_lines();
        let r = repair(&m, &opts);
        if !r.mesh.triangles.is_empty() {
            assert_eq!(r.mesh.validate(), Ok(()), "case {case}");
        }
        assert_clean(&format!("case {case}"), &inspect(&r.mesh, &InspectOptions::default()));
        let again = repair(&r.mesh, &opts);
        assert!(again.changes.is_empty(), "case {case}: {:?}\n{m:?}", again.changes);
        assert!(again.mesh == r.mesh, "case {case}");
    }
}
