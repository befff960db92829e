//! The double cover of a surface with boundary (Wang, Gu, Mueller & Yau 2005 §3, the
//! bunny of Fig. 3; Gu & Yau 2003): two copies of the surface, the second with reversed
//! orientation, glued along their boundaries. The result is closed, of genus
//! `2g + b − 1` for genus `g` with `b` boundary loops, and carries holomorphic 1-forms
//! whose restriction to the first copy is a conformal map of the original surface.
//!
//! Layout: the first `n_original_vertices` vertices and `n_original_faces` triangles
//! are the input's; every interior vertex `v` gets a twin `twin[v]` after them,
//! boundary vertices are their own twins; the second copy's triangles are the first
//! copy's with two corners swapped, in the same order, except that a chord (an interior
//! edge joining two boundary vertices) is split at its midpoint in the second copy (one
//! new vertex, its own twin, and one more triangle on each side), so that the doubled
//! mesh stays manifold.

use fieldtex_core::vec3;
use fieldtex_mesh::{Topology, TriMesh};

/// See the module docs.
#[derive(Debug, Clone)]
pub struct DoubleCover {
    pub mesh: TriMesh,
    pub n_original_vertices: usize,
    pub n_original_faces: usize,
    /// Per doubled-mesh vertex: its mirror image.
    pub twin: Vec<u32>,
}

/// Doubles `mesh` along its boundary (see the module docs).
pub fn double_cover(mesh: &TriMesh) -> DoubleCover {
    let nv = mesh.n_vertices();
    let topo = Topology::build(nv, &mesh.triangles);
    let boundary = topo.boundary_vertices();
    let mut positions = mesh.positions.clone();
    let mut twin: Vec<u32> = (0..nv as u32).collect();
    for v in 0..nv {
        if !boundary[v] {
            twin[v] = positions.len() as u32;
            positions.push(mesh.positions[v]);
        }
    }
    let mut back = vec![0u32; positions.len() - nv];
    for v in 0..nv {
        if !boundary[v] {
            back[twin[v] as usize - nv] = v as u32;
        }
    }
    twin.extend(back);
    let mut second: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .map(|t| [twin[t[0] as usize], twin[t[2] as usize], twin[t[1] as usize]])
        .collect();
    // A chord (an interior edge between two boundary vertices) would exist in both
    // copies with the same ends: split it at its midpoint in the second copy.
    for (e, ed) in topo.edges.iter().enumerate() {
        if topo.edge_faces(e).len() != 2 || !boundary[ed[0] as usize] || !boundary[ed[1] as usize] {
            continue;
        }
        let (a, b) = (ed[0], ed[1]);
        let m = positions.len() as u32;
        positions.push(vec3::scale(
            vec3::add(mesh.positions[a as usize], mesh.positions[b as usize]),
            0.5,
        ));
        twin.push(m);
        for f in 0..second.len() {
            let t = second[f];
            for k in 0..3 {
                let (p, q, r) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                if (p == a && q == b) || (p == b && q == a) {
                    second[f] = [p, m, r];
                    second.push([m, q, r]);
                    break;
                }
            }
        }
    }
    let mut triangles = mesh.triangles.clone();
    triangles.extend(second);
    DoubleCover {
        mesh: TriMesh::new(positions, triangles),
        n_original_vertices: nv,
        n_original_faces: mesh.n_triangles(),
        twin,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_mesh::primitives;

    #[test]
    fn doubled_annulus_is_a_closed_torus() {
        // A grid with a square hole is an annulus (g = 0, b = 2): its double is a torus.
        let grid = primitives::grid(9, 9, 1.0, 1.0);
        let annulus = super::super::tests::keep_faces(&grid, |_, t| {
            let c = t.iter().fold([0.0; 2], |c, &v| {
                let p = grid.positions[v as usize];
                [c[0] + p[0] / 3.0, c[1] + p[1] / 3.0]
            });
            !((0.35..0.65).contains(&c[0]) && (0.35..0.65).contains(&c[1]))
        });
        let d = double_cover(&annulus);
        let topo = Topology::build(d.mesh.n_vertices(), &d.mesh.triangles);
        assert!((0..topo.n_edges()).all(|e| topo.edge_faces(e).len() == 2), "not closed");
        let used = (0..d.mesh.n_vertices()).filter(|&v| !topo.vertex_faces(v).is_empty()).count();
        let chi = used as i64 - topo.n_edges() as i64 + d.mesh.n_triangles() as i64;
        assert_eq!(chi, 0, "a torus has χ = 0");
        assert!(d.mesh.n_triangles() >= 2 * annulus.n_triangles());
        for v in 0..d.mesh.n_vertices() {
            assert_eq!(d.twin[d.twin[v] as usize] as usize, v);
        }
    }
}
