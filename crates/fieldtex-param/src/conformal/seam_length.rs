//! 3-D length of a layout's seams: the mesh edges whose two faces disagree on the UVs of
//! the edge's ends.

use fieldtex_core::vec3;
use fieldtex_mesh::{Topology, TriMesh};

/// Seam length of the per-face corner UVs `corner` (`#F × 3`, in `mesh`'s corner order)
/// over the interior edges whose two faces `counts(f, g)` accepts (e.g. faces of the same
/// component). UVs closer than `10⁻⁹` of the layout's extent count as equal.
pub fn seam_length(
    mesh: &TriMesh,
    corner: &[[[f64; 2]; 3]],
    counts: &dyn Fn(usize, usize) -> bool,
) -> f64 {
    let nf = mesh.n_triangles().min(corner.len());
    let extent =
        corner[..nf].iter().flatten().fold(0.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs()));
    let tol = 1e-9 * extent.max(1e-300);
    let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
    let uv_at = |f: usize, v: u32| {
        let k = mesh.triangles[f].iter().position(|&w| w == v)?;
        Some(corner[f][k])
    };
    let mut length = 0.0;
    for (e, ends) in topo.edges.iter().enumerate() {
        let faces = topo.edge_faces(e);
        if faces.len() != 2 {
            continue;
        }
        let (f, g) = (faces[0] as usize, faces[1] as usize);
        if f >= nf || g >= nf || !counts(f, g) {
            continue;
        }
        let differs = ends.iter().any(|&v| match (uv_at(f, v), uv_at(g, v)) {
            (Some(a), Some(b)) => (a[0] - b[0]).abs() > tol || (a[1] - b[1]).abs() > tol,
            _ => false,
        });
        if differs {
            let (a, b) = (mesh.positions[ends[0] as usize], mesh.positions[ends[1] as usize]);
            length += vec3::norm(vec3::sub(a, b));
        }
    }
    length
}
