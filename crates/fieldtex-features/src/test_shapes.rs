//! Small meshes for unit tests.

use fieldtex_mesh::TriMesh;

/// An axis-aligned cube `[0,1]³`, 2 triangles per side, outward normals.
pub(crate) fn cube() -> TriMesh {
    let p = (0..8).map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]);
    let quads =
        [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let t = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    TriMesh::new(p.collect(), t)
}
