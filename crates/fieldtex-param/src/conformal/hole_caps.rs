//! Closing the holes of a surface with fans, so that one closed-surface construction
//! serves open meshes too.
//!
//! Every boundary loop gets a new vertex at the centroid of its vertices and a fan of
//! triangles, oriented against the loop's boundary edges so the capped surface is
//! consistently oriented. A conformal map of the capped surface restricted to the
//! original triangles is still conformal (conformality is local), so the caps only
//! decide how the global structure is chosen; the cap triangles are dropped afterwards.
//! This replaces the double cover of Wang, Gu, Mueller & Yau (2005, §3) — a documented
//! substitute: the capped surface has genus `g` where the double cover has `2g + b − 1`.

use fieldtex_core::vec3;
use fieldtex_mesh::{Topology, TriMesh};
use std::collections::HashSet;

/// A capped copy of a mesh: the first `n_original_faces` triangles and
/// `n_original_vertices` vertices are the input's.
#[derive(Debug, Clone)]
pub struct CappedMesh {
    pub mesh: TriMesh,
    pub n_original_vertices: usize,
    pub n_original_faces: usize,
    /// Number of boundary loops that were capped.
    pub n_holes: usize,
    /// `(cap centre vertex, boundary loop length)` per capped loop.
    pub caps: Vec<(u32, f64)>,
}

/// Caps every boundary loop of `mesh` (see the module docs).
pub fn cap_holes(mesh: &TriMesh) -> CappedMesh {
    let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
    let loops = topo.boundary_loops(&mesh.triangles);
    let mut half: HashSet<(u32, u32)> = HashSet::with_capacity(3 * mesh.triangles.len());
    for t in &mesh.triangles {
        for k in 0..3 {
            half.insert((t[k], t[(k + 1) % 3]));
        }
    }
    let mut positions = mesh.positions.clone();
    let mut triangles = mesh.triangles.clone();
    let mut n_holes = 0;
    let mut caps = Vec::new();
    for lp in &loops {
        if lp.len() < 3 {
            continue;
        }
        n_holes += 1;
        let mut c = [0.0; 3];
        for &v in lp {
            c = vec3::add(c, positions[v as usize]);
        }
        let c = vec3::scale(c, 1.0 / lp.len() as f64);
        let cv = positions.len() as u32;
        positions.push(c);
        let len: f64 = (0..lp.len())
            .map(|i| {
                vec3::norm(vec3::sub(
                    positions[lp[(i + 1) % lp.len()] as usize],
                    positions[lp[i] as usize],
                ))
            })
            .sum();
        caps.push((cv, len));
        for i in 0..lp.len() {
            let (a, b) = (lp[i], lp[(i + 1) % lp.len()]);
            if half.contains(&(a, b)) {
                triangles.push([b, a, cv]);
            } else {
                triangles.push([a, b, cv]);
            }
        }
    }
    CappedMesh {
        mesh: TriMesh::new(positions, triangles),
        n_original_vertices: mesh.n_vertices(),
        n_original_faces: mesh.triangles.len(),
        n_holes,
        caps,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn capping_a_disk_gives_a_closed_sphere() {
        // A square split into two triangles: one boundary loop of 4 vertices.
        let m = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let c = cap_holes(&m);
        assert_eq!(c.n_holes, 1);
        let topo = Topology::build(c.mesh.n_vertices(), &c.mesh.triangles);
        assert!((0..topo.n_edges()).all(|e| topo.edge_faces(e).len() == 2));
        // Consistent orientation: every edge used once in each direction.
        let mut half = HashSet::new();
        for t in &c.mesh.triangles {
            for k in 0..3 {
                assert!(half.insert((t[k], t[(k + 1) % 3])));
            }
        }
        let chi = c.mesh.n_vertices() as i64 - topo.n_edges() as i64 + c.mesh.n_triangles() as i64;
        assert_eq!(chi, 2);
    }
}
