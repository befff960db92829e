//! Helpers shared by the integration tests.
#![allow(dead_code)]

use fieldtex_features::CrestLines;
use fieldtex_mesh::{RepairOptions, TriMesh, repair};
use std::path::{Path, PathBuf};

/// `../shared/data` beside the repository.
pub fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

/// Reads a mesh under the data directory as is.
pub fn load_raw(rel: &str) -> TriMesh {
    let path = data_dir().join(rel);
    fieldtex_io::read_mesh(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).mesh
}

/// Reads and repairs a mesh under the data directory.
pub fn load(rel: &str) -> TriMesh {
    repair(&load_raw(rel), &RepairOptions::default()).mesh
}

/// Invariants every result must satisfy: finite points and strengths, one valid
/// triangle per point lying on (or at a crossing inside) that triangle, lengths
/// matching the points, sorted strengths, closed lines repeating their first point.
pub fn check_invariants(name: &str, mesh: &TriMesh, crest: &CrestLines) {
    let diag = mesh.bounding_box().map_or(1.0, |b| b.diagonal());
    for (i, l) in crest.lines.iter().enumerate() {
        assert!(l.points.len() >= 2, "{name}: line {i} has {} points", l.points.len());
        assert_eq!(l.faces.len(), l.points.len(), "{name}: line {i} faces");
        assert!(l.strength.is_finite() && l.strength >= 0.0, "{name}: line {i} strength");
        assert!(l.length.is_finite() && l.length > 0.0, "{name}: line {i} length");
        let len: f64 = l
            .points
            .windows(2)
            .map(|w| fieldtex_core::vec3::norm(fieldtex_core::vec3::sub(w[1], w[0])))
            .sum();
        assert!((len - l.length).abs() <= 1e-9 * (1.0 + len), "{name}: line {i} length");
        if l.closed {
            assert_eq!(l.points.first(), l.points.last(), "{name}: closed line {i}");
        }
        for (p, &f) in l.points.iter().zip(&l.faces) {
            assert!(fieldtex_core::vec3::is_finite(*p), "{name}: line {i} non-finite point");
            assert!((f as usize) < mesh.n_triangles(), "{name}: line {i} face {f}");
            let (q, _) = fieldtex_mesh::bvh::closest_point_on_triangle(
                *p,
                mesh.triangle_positions(f as usize),
            );
            let d = fieldtex_core::vec3::norm(fieldtex_core::vec3::sub(*p, q));
            assert!(d <= 1e-9 * diag, "{name}: line {i} point {p:?} is {d} off its face {f}");
        }
    }
    for w in crest.lines.windows(2) {
        assert!(w[0].strength >= w[1].strength, "{name}: lines not sorted by strength");
    }
}
