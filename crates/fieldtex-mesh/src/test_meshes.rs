//! Test-only meshes: procedural defect categories and a tiny OBJ reader for the
//! fixtures in `../shared/data/meshes` (the real readers live in `fieldtex-io`).

use crate::TriMesh;
use crate::primitives::{grid, icosphere, torus};
use std::path::PathBuf;

/// `shared/data/meshes/<name>` beside the repository.
pub fn fixture_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/meshes").join(name)
}

/// Reads `v` and `f` lines of an OBJ (polygons fanned, `v/vt/vn` and negative indices
/// accepted). Returns `None` when the file is missing so tests can skip.
pub fn load_obj(name: &str) -> Option<TriMesh> {
    let text = std::fs::read_to_string(fixture_path(name)).ok()?;
    Some(parse_obj(&text))
}

pub fn parse_obj(text: &str) -> TriMesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f64> = it.take(3).filter_map(|s| s.parse().ok()).collect();
                if c.len() == 3 {
                    positions.push([c[0], c[1], c[2]]);
                }
            }
            Some("f") => {
                let n = positions.len() as i64;
                let idx: Vec<u32> = it
                    .filter_map(|s| s.split('/').next()?.parse::<i64>().ok())
                    .map(|i| if i < 0 { (n + i) as u32 } else { (i - 1) as u32 })
                    .collect();
                for k in 1..idx.len().saturating_sub(1) {
                    triangles.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
            _ => {}
        }
    }
    TriMesh::new(positions, triangles)
}

/// A grid patch with defects attached on its boundary: a zero-area flap (collinear
/// corners), a needle (apex angle ≈ 2.5e-4), an extreme needle (≈ 2.5e-9, gets
/// floored), a triangle with three coincident corners, and one unreferenced vertex.
pub fn defective_patch() -> TriMesh {
    let mut m = grid(4, 4, 1.0, 1.0);
    let id = |i: u32, j: u32| j * 5 + i;
    let add = |m: &mut TriMesh, p: [f64; 3]| {
        m.positions.push(p);
        (m.positions.len() - 1) as u32
    };
    // Zero-area flap on the bottom edge (0,0)-(1,0): midpoint.
    let mid = add(&mut m, [0.125, 0.0, 0.0]);
    m.triangles.push([id(1, 0), id(0, 0), mid]);
    // Needle on the right edge.
    let far = add(&mut m, [1000.0, 0.375, 0.0]);
    m.triangles.push([id(4, 1), far, id(4, 2)]);
    // Extreme needle on the top edge, pointing up 1e8.
    let very_far = add(&mut m, [0.375, 1e8, 0.0]);
    m.triangles.push([id(2, 4), id(1, 4), very_far]);
    // Three coincident corners (distinct indices).
    let a = add(&mut m, [2.0, 2.0, 2.0]);
    let b = add(&mut m, [2.0, 2.0, 2.0]);
    let c = add(&mut m, [2.0, 2.0, 2.0]);
    m.triangles.push([a, b, c]);
    // Unreferenced vertex.
    add(&mut m, [-3.0, 0.0, 1.0]);
    m
}

/// Two triangles meeting only at vertex 0 (a bowtie: one non-manifold vertex, two
/// fans): positions `0..5`, triangles `[0, 1, 2]` and `[0, 3, 4]`.
pub fn bowtie() -> TriMesh {
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [-1.0, -1.0, 0.0],
    ];
    TriMesh::new(p, vec![[0, 1, 2], [0, 3, 4]])
}

/// Two components: an icosphere and a torus beside it.
pub fn two_components() -> TriMesh {
    let mut m = icosphere(2);
    let t = torus(1.0, 0.3, 24, 10);
    let off = m.n_vertices() as u32;
    m.positions.extend(t.positions.iter().map(|p| [p[0] + 4.0, p[1], p[2]]));
    m.triangles.extend(t.triangles.iter().map(|t| t.map(|i| i + off)));
    m
}

/// [`categories`] followed by the shared fixtures `names` that are present (a missing
/// file is skipped, as in [`load_obj`]).
pub fn categories_and(names: &[&'static str]) -> Vec<(&'static str, TriMesh)> {
    let mut all = categories();
    all.extend(names.iter().filter_map(|&name| load_obj(name).map(|m| (name, m))));
    all
}

/// The procedural categories every operator is run over, with a name.
pub fn categories() -> Vec<(&'static str, TriMesh)> {
    vec![
        ("closed-genus0", icosphere(3)),
        ("closed-genus1", torus(2.0, 0.6, 36, 14)),
        ("boundary-grid", grid(10, 8, 2.0, 1.5)),
        ("defective", defective_patch()),
        ("two-components", two_components()),
    ]
}
