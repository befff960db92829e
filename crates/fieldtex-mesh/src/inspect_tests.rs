//! Tests of [`crate::inspect()`] over the shared fixtures (counts from
//! `shared/data/README.md`) and procedural defects.

use crate::inspect::{InspectOptions, InspectReport, inspect};
use crate::primitives::{grid, icosphere};
use crate::test_meshes::load;
use crate::{CornerUvs, TriMesh};

fn run(rel: &str) -> InspectReport {
    inspect(&load(rel), &InspectOptions::default())
}

fn codes(r: &InspectReport) -> Vec<String> {
    r.problems().into_iter().map(|w| w.code).collect()
}

#[test]
fn beetle_matches_readme() {
    let r = run("defects/beetle-1972-nonmanifold.obj");
    assert_eq!((r.n_vertices, r.n_triangles), (1148, 2053));
    assert_eq!(r.non_manifold_edges.count, 47);
    assert!(r.non_manifold_edges.examples.iter().all(|e| e.triangles.len() > 2));
    assert_eq!(r.components.edge_connected, 33);
    assert_eq!(r.components.count, 2);
    assert_eq!(r.boundary_loops.count, 23);
    let big = &r.components.listed[0];
    assert!(!big.manifold && big.genus.is_none());
    assert_eq!(big.genus_unavailable.as_deref(), Some("non-manifold"));
    assert!(codes(&r).contains(&"non-manifold-edges".to_string()));
}

#[test]
fn nonmanifold_edge_fixture() {
    let r = run("defects/nonmanifold_edge.obj");
    assert_eq!((r.n_vertices, r.n_triangles), (8, 6));
    assert_eq!(r.non_manifold_edges.count, 1);
    let e = &r.non_manifold_edges.examples[0];
    assert_eq!(e.vertices, [3, 5]);
    assert_eq!(e.triangles.len(), 3);
    assert_eq!(r.vertices_on_non_manifold_edges, 2);
    assert_eq!(r.non_manifold_vertices.count, 0);
    assert_eq!(r.components.edge_connected, 3);
}

#[test]
fn nonmanifold_vertex_fixture() {
    let r = run("defects/nonmanifold_vertex.obj");
    assert_eq!(r.non_manifold_edges.count, 0);
    assert_eq!(r.non_manifold_vertices.count, 1);
    assert_eq!(r.non_manifold_vertices.examples[0].vertex, 3);
    assert_eq!(r.non_manifold_vertices.examples[0].fans, 2);
    assert_eq!(r.boundary_loops.count, 2);
    assert_eq!(codes(&r), vec!["non-manifold-vertices"]);
}

#[test]
fn nonoriented_edge_fixture() {
    let r = run("defects/nonoriented_edge.obj");
    assert_eq!(r.orientation.inconsistent_edges.count, 1);
    assert_eq!(r.orientation.inconsistent_edges.examples, vec![[3, 5]]);
    // Flipping one quad fixes it: orientable, a disk.
    assert!(r.orientation.non_orientable_components.is_empty());
    assert_eq!(r.components.listed[0].genus, Some(0));
    assert_eq!(r.boundary_loops.count, 1);
}

#[test]
fn narrow_triangles_fixture() {
    let r = run("defects/narrow_triangles.obj");
    assert_eq!(r.shape.zero_area.count, 0);
    assert_eq!(r.shape.slivers.count, 20);
    let a = r.shape.min_angle_deg.unwrap();
    assert!(a > 0.03 && a < 0.04, "{a}");
    assert_eq!(codes(&r), vec!["sliver-triangles"]);
    // A stricter threshold finds fewer.
    let opts = InspectOptions { sliver_min_angle_deg: 0.1, ..Default::default() };
    assert_eq!(inspect(&load("defects/narrow_triangles.obj"), &opts).shape.slivers.count, 4);
}

#[test]
fn cube_soup_fixture() {
    let r = run("defects/cube_soup.obj");
    assert_eq!((r.n_vertices, r.n_triangles), (24, 12));
    assert_eq!(r.components.count, 6);
    assert_eq!(r.boundary_loops.count, 6);
    assert_eq!(r.duplicate_vertices.exact, 16);
    assert_eq!(r.duplicate_vertices.weldable, 16);
    assert_eq!(r.duplicate_vertices.near, 16);
    let uv = r.uv.as_ref().unwrap();
    assert_eq!(uv.values, 24);
    assert!(uv.index_problem.is_none());
    assert_eq!(codes(&r), vec!["duplicate-vertices"]);
}

#[test]
fn moebius_fixture() {
    let r = run("defects/moebius-160-10.ply");
    assert_eq!((r.n_vertices, r.n_triangles), (1600, 2880));
    assert_eq!(r.orientation.non_orientable_components, vec![0]);
    assert!(r.orientation.inconsistent_edges.count >= 1);
    let c = &r.components.listed[0];
    assert_eq!((c.euler_characteristic, c.boundary_loops), (0, 1));
    assert_eq!((c.genus, c.nonorientable_genus), (None, Some(1)));
    assert!(!c.orientable && c.manifold);
}

#[test]
fn bunny_fertility_torus() {
    let r = run("stanford-bunny.obj");
    assert_eq!(r.boundary_loops.count, 5);
    assert_eq!(r.unreferenced_vertices.count, 1113);
    assert_eq!(r.components.count, 1);
    assert_eq!(r.components.listed[0].genus, Some(0));
    let r = run("fertility.obj");
    assert_eq!(r.components.listed[0].genus, Some(4));
    assert!(r.problems().is_empty(), "{:?}", r.problems());
    let r = run("torus.obj");
    assert_eq!(r.components.listed[0].genus, Some(1));
    assert!(r.is_clean());
}

#[test]
fn nan_invalid_and_repeated_indices() {
    let mut m = icosphere(1);
    m.positions[5][1] = f64::NAN;
    m.positions.push([f64::INFINITY, 0.0, 0.0]); // unreferenced and non-finite
    m.triangles.push([0, 1, 999]);
    m.triangles.push([2, 2, 3]);
    let r = inspect(&m, &InspectOptions::default());
    assert_eq!(r.non_finite_vertices.examples, vec![5, 42]);
    assert_eq!(r.invalid_index_triangles.examples, vec![80]);
    assert_eq!(r.repeated_index_triangles.examples, vec![81]);
    assert_eq!(r.unreferenced_vertices.examples, vec![42]);
    // The five triangles at vertex 5 have no shape; the sphere is still closed.
    assert_eq!(r.shape.non_finite, 5);
    assert_eq!(r.components.listed[0].genus, Some(0));
    assert!(r.bounding_box.unwrap().diagonal().is_finite());
    let c = codes(&r);
    for code in ["non-finite-positions", "invalid-indices", "repeated-index-triangles"] {
        assert!(c.contains(&code.to_string()), "{code} missing from {c:?}");
    }
}

#[test]
fn flipped_face_in_sphere() {
    let mut m = icosphere(2);
    m.triangles[7].swap(0, 1);
    let r = inspect(&m, &InspectOptions::default());
    assert_eq!(r.orientation.inconsistent_edges.count, 3);
    assert!(r.orientation.non_orientable_components.is_empty());
    assert_eq!(r.components.listed[0].genus, Some(0));
    assert_eq!(r.boundary_loops.count, 0);
}

#[test]
fn bowtie_and_zero_area() {
    // Bowtie at vertex 0, plus a collinear triangle 0-1-5.
    let mut m = crate::test_meshes::bowtie();
    m.positions.push([2.0, 0.0, 0.0]);
    m.triangles.push([0, 5, 1]);
    let r = inspect(&m, &InspectOptions::default());
    assert_eq!(r.non_manifold_vertices.count, 1);
    assert_eq!(r.non_manifold_vertices.examples[0].fans, 2);
    assert_eq!(r.shape.zero_area.examples, vec![2]);
    assert_eq!(r.components.count, 1);
}

#[test]
fn duplicate_triangles_and_uv_checks() {
    let mut m = grid(2, 2, 1.0, 1.0);
    let n = m.n_triangles();
    m.triangles.push(m.triangles[3]);
    let t = m.triangles[5];
    m.triangles.push([t[0], t[2], t[1]]);
    // UVs = xy, with triangle 0 mirrored and triangle 1 collapsed; one NaN value unused.
    let mut values: Vec<[f64; 2]> = m.positions.iter().map(|p| [p[0], p[1]]).collect();
    let mut indices = m.triangles.clone();
    indices[0].swap(1, 2);
    values.push([0.5, 0.5]);
    values.push([f64::NAN, 0.0]);
    let c = values.len() as u32 - 2;
    indices[1] = [c, c, c];
    m.uvs = Some(CornerUvs { values, indices });
    let r = inspect(&m, &InspectOptions::default());
    assert_eq!(r.duplicate_triangles.examples, vec![[n as u32, 3], [n as u32 + 1, 5]]);
    let uv = r.uv.unwrap();
    assert_eq!(uv.non_finite_values, 1);
    // The pushed copy of triangle 5 is reversed in 3D and keeps xy UVs: mirrored too.
    assert_eq!(uv.negative_area.examples, vec![0, n as u32 + 1]);
    assert_eq!(uv.zero_area.examples, vec![1]);
    assert_eq!((uv.min, uv.max), (Some([0.0, 0.0]), Some([1.0, 1.0])));
    // A broken UV index table is reported, not followed.
    m.uvs.as_mut().unwrap().indices.pop();
    let r = inspect(&m, &InspectOptions::default());
    assert!(r.uv.unwrap().index_problem.is_some());
}

#[test]
fn empty_and_attribute_mismatch() {
    let r = inspect(&TriMesh::default(), &InspectOptions::default());
    assert_eq!(codes(&r), vec!["empty-mesh"]);
    assert!(r.bounding_box.is_none());
    assert!(!r.summary_lines().is_empty());
    let mut m = icosphere(0);
    m.vertex_colors = Some(vec![[1.0; 4]; 3]);
    let r = inspect(&m, &InspectOptions::default());
    assert_eq!(codes(&r), vec!["attribute-length"]);
}

#[test]
fn near_duplicates_use_relative_epsilon() {
    let mut m = grid(4, 4, 1.0, 1.0);
    m.positions.push([0.5, 0.5, 1e-9]);
    m.positions.push([0.5, 0.5, 1e-3]);
    let r = inspect(&m, &InspectOptions::default());
    assert_eq!((r.duplicate_vertices.exact, r.duplicate_vertices.near), (0, 1));
    let opts = InspectOptions { near_duplicate_relative: 1e-2, ..Default::default() };
    assert_eq!(inspect(&m, &opts).duplicate_vertices.near, 2);
}

#[test]
fn summary_mentions_each_problem() {
    let r = run("defects/nonmanifold_edge.obj");
    let text = r.summary_lines().join("\n");
    assert!(text.contains("non-manifold-edges"), "{text}");
    assert!(text.contains("components: 1"), "{text}");
}
