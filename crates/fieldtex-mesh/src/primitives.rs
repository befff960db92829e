//! Procedural meshes for demos, tests and benchmarks (no files needed).
//!
//! All are consistently oriented (outward normals for closed surfaces, +z for planar
//! patches) and free of degenerate triangles.

use crate::TriMesh;
use std::f64::consts::PI;

/// A regular `nx × ny`-cell grid on `[0, w] × [0, h]` in the z = 0 plane, each cell
/// split into two triangles along alternating diagonals. Disk topology, one boundary
/// loop. Vertex `(i, j)` has index `j * (nx + 1) + i`.
pub fn grid(nx: usize, ny: usize, w: f64, h: f64) -> TriMesh {
    let nx = nx.max(1);
    let ny = ny.max(1);
    let mut positions = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            positions.push([w * i as f64 / nx as f64, h * j as f64 / ny as f64, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut triangles = Vec::with_capacity(2 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 {
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            } else {
                triangles.push([a, b, d]);
                triangles.push([b, c, d]);
            }
        }
    }
    TriMesh::new(positions, triangles)
}

/// A unit-radius sphere made by subdividing an icosahedron `level` times
/// (`20 · 4^level` triangles), closed, genus 0.
pub fn icosphere(level: usize) -> TriMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let m = subdivide_midpoint(&TriMesh::new(positions, triangles));
        positions = m.positions;
        triangles = m.triangles;
    }
    for p in &mut positions {
        let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        *p = [p[0] / n, p[1] / n, p[2] / n];
    }
    TriMesh::new(positions, triangles)
}

/// A torus around the z axis with major radius `major` and minor radius `minor`,
/// `nu` segments around the axis and `nv` around the tube. Closed, genus 1.
pub fn torus(major: f64, minor: f64, nu: usize, nv: usize) -> TriMesh {
    let nu = nu.max(3);
    let nv = nv.max(3);
    let mut positions = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        let u = 2.0 * PI * i as f64 / nu as f64;
        for j in 0..nv {
            let v = 2.0 * PI * j as f64 / nv as f64;
            let r = major + minor * v.cos();
            positions.push([r * u.cos(), r * u.sin(), minor * v.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    let mut triangles = Vec::with_capacity(2 * nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    TriMesh::new(positions, triangles)
}

/// The cube `[-1, 1]³` with each face an `n × n`-cell grid (`12 n²` triangles, split
/// along alternating diagonals), vertices shared along the edges and corners, outward
/// normals. Closed, genus 0, with twelve sharp 90° creases: the simplest shape whose
/// features a texture should follow.
pub fn cube(n: usize) -> TriMesh {
    let n = n.max(1);
    let mut index = std::collections::HashMap::new();
    let mut positions = Vec::with_capacity(6 * n * n + 2);
    let mut triangles = Vec::with_capacity(12 * n * n);
    let coord = |k: usize| 2.0 * k as f64 / n as f64 - 1.0;
    for axis in 0..3 {
        for side in [0usize, n] {
            // Tangent axes with e_u × e_v = e_axis; the far side (+) keeps that order.
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut id = |i: usize, j: usize| -> u32 {
                let mut lattice = [0usize; 3];
                lattice[axis] = side;
                lattice[u] = i;
                lattice[v] = j;
                *index.entry(lattice).or_insert_with(|| {
                    positions.push(lattice.map(coord));
                    (positions.len() - 1) as u32
                })
            };
            for j in 0..n {
                for i in 0..n {
                    let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                    let pair = if (i + j) % 2 == 0 {
                        [[a, b, c], [a, c, d]]
                    } else {
                        [[a, b, d], [b, c, d]]
                    };
                    for t in pair {
                        triangles.push(if side == n { t } else { [t[0], t[2], t[1]] });
                    }
                }
            }
        }
    }
    TriMesh::new(positions, triangles)
}

/// Splits every triangle into four through its edge midpoints (1→4 subdivision). Shared
/// edges get one shared midpoint, so the result keeps the input's topology, and the
/// surface is unchanged (every new vertex lies on an input edge). Vertex normals and
/// colours, when present, are carried: a midpoint gets the mean of its edge's two ends
/// (normals renormalised; a zero mean keeps the first end's); corner UVs are dropped.
pub fn subdivide_midpoint(mesh: &TriMesh) -> TriMesh {
    let topo = crate::Topology::build(mesh.n_vertices(), &mesh.triangles);
    let nv = mesh.n_vertices();
    let mut positions = mesh.positions.clone();
    positions.reserve(topo.n_edges());
    for e in &topo.edges {
        let (a, b) = (mesh.positions[e[0] as usize], mesh.positions[e[1] as usize]);
        positions.push([(a[0] + b[0]) * 0.5, (a[1] + b[1]) * 0.5, (a[2] + b[2]) * 0.5]);
    }
    let mut triangles = Vec::with_capacity(4 * mesh.n_triangles());
    for (f, t) in mesh.triangles.iter().enumerate() {
        let m = topo.face_edges[f].map(|e| nv as u32 + e);
        // m[i] is the midpoint of corners i and i+1.
        triangles.push([t[0], m[0], m[2]]);
        triangles.push([t[1], m[1], m[0]]);
        triangles.push([t[2], m[2], m[1]]);
        triangles.push([m[0], m[1], m[2]]);
    }
    let mut out = TriMesh::new(positions, triangles);
    out.vertex_normals = mesh.vertex_normals.as_ref().map(|n| {
        let mut all = n.clone();
        all.extend(topo.edges.iter().map(|e| {
            let (a, b) = (n[e[0] as usize], n[e[1] as usize]);
            let m = fieldtex_core::vec3::add(a, b);
            let len = fieldtex_core::vec3::norm(m);
            if len > 0.0 && len.is_finite() { fieldtex_core::vec3::scale(m, 1.0 / len) } else { a }
        }));
        all
    });
    out.vertex_colors = mesh.vertex_colors.as_ref().map(|c| {
        let mut all = c.clone();
        all.extend(topo.edges.iter().map(|e| {
            let (a, b) = (c[e[0] as usize], c[e[1] as usize]);
            [0, 1, 2, 3].map(|i| 0.5 * (a[i] + b[i]))
        }));
        all
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Topology;

    fn euler(m: &TriMesh) -> i64 {
        Topology::build(m.n_vertices(), &m.triangles).euler_characteristic()
    }

    #[test]
    fn euler_characteristics() {
        assert_eq!(euler(&icosphere(2)), 2);
        assert_eq!(icosphere(2).n_triangles(), 320);
        assert_eq!(euler(&torus(2.0, 0.5, 24, 12)), 0);
        assert_eq!(euler(&grid(5, 4, 1.0, 1.0)), 1);
        let c = cube(3);
        assert_eq!((euler(&c), c.n_triangles(), c.n_vertices()), (2, 108, 56));
    }

    #[test]
    fn cube_normals_point_outward() {
        let c = cube(2);
        for t in &c.triangles {
            let [a, b, d] = t.map(|k| c.positions[k as usize]);
            let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let e2 = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
            let nrm = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            let centre = [
                (a[0] + b[0] + d[0]) / 3.0,
                (a[1] + b[1] + d[1]) / 3.0,
                (a[2] + b[2] + d[2]) / 3.0,
            ];
            let dot: f64 = (0..3).map(|k| nrm[k] * centre[k]).sum();
            assert!(dot > 0.0, "inward triangle {t:?}");
        }
    }

    #[test]
    fn midpoint_subdivision_keeps_the_surface_and_carries_normals_and_colours() {
        let mut m = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            vec![[0, 1, 2], [0, 3, 1]],
        );
        m.vertex_normals =
            Some(vec![[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]);
        m.vertex_colors =
            Some(vec![[0.0, 0.0, 0.0, 1.0], [1.0, 1.0, 1.0, 1.0], [0.2; 4], [0.4; 4]]);
        let r = subdivide_midpoint(&m);
        assert_eq!((r.n_vertices(), r.n_triangles()), (4 + 5, 8));
        assert_eq!(euler(&r), euler(&m));
        let n = r.vertex_normals.as_ref().expect("normals carried");
        let c = r.vertex_colors.as_ref().expect("colours carried");
        assert_eq!((n.len(), c.len()), (9, 9));
        let topo = Topology::build(m.n_vertices(), &m.triangles);
        for (e, ends) in topo.edges.iter().enumerate() {
            let v = 4 + e;
            let (a, b) = (ends[0] as usize, ends[1] as usize);
            for k in 0..3 {
                // The midpoint lies on its edge.
                assert!(
                    (r.positions[v][k] - 0.5 * (m.positions[a][k] + m.positions[b][k])).abs()
                        < 1e-15
                );
            }
            let len = n[v].iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!((len - 1.0).abs() < 1e-12, "midpoint normal not unit: {:?}", n[v]);
            assert!((c[v][0] - 0.5 * (c[a][0] + c[b][0])).abs() < 1e-7);
        }
        // Edge (0, 1): both ends face +z, so its midpoint does too.
        let e01 =
            topo.edges.iter().position(|e| e[0].min(e[1]) == 0 && e[0].max(e[1]) == 1).unwrap();
        assert_eq!(n[4 + e01], [0.0, 0.0, 1.0]);
        assert!(
            subdivide_midpoint(&TriMesh::new(m.positions.clone(), m.triangles.clone()))
                .vertex_normals
                .is_none()
        );
    }
}
