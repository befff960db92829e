//! Precondition checks shared by the geometry operators.

use crate::{MeshError, TriMesh};

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
