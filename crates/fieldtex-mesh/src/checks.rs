//! Precondition checks shared by the geometry operators.

use crate::{MeshError, TriMesh};
use fieldtex_core::vec3::V3;
use rayon::prelude::*;

/// The first triangle corner whose vertex index is out of range, as an error.
pub(crate) fn check_indices(mesh: &TriMesh) -> Result<(), MeshError> {
    let nv = mesh.positions.len();
    for (f, t) in mesh.triangles.iter().enumerate() {
        for &i in t {
            if i as usize >= nv {
                return Err(MeshError::IndexOutOfRange {
                    triangle: f,
                    index: u64::from(i),
                    n_vertices: nv,
                });
            }
        }
    }
    Ok(())
}

/// Panics with a message naming the right call when an index is out of range
/// (for operators whose contract is a validated mesh).
pub(crate) fn assert_indices(mesh: &TriMesh, operation: &str) {
    if let Err(e) = check_indices(mesh) {
        panic!("{operation}: {e}; call TriMesh::validate (or repair) before geometry operators");
    }
}

/// `f(a, b, c)` of every triangle's corner positions, in triangle order (in parallel;
/// the result does not depend on the thread count). Panics like [`assert_indices`].
pub(crate) fn map_triangles<T: Send>(
    mesh: &TriMesh,
    operation: &str,
    f: impl Fn(V3, V3, V3) -> T + Sync,
) -> Vec<T> {
    assert_indices(mesh, operation);
    mesh.triangles
        .par_iter()
        .with_min_len(4096)
        .map(|t| {
            let p = |i: usize| mesh.positions[t[i] as usize];
            f(p(0), p(1), p(2))
        })
        .collect()
}
