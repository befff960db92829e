//! Planar units: connected groups of (nearly) coplanar triangles that chart growing
//! treats as one element.
//!
//! Meshes refined by subdivision, CAD tessellations and scans of flat parts have large
//! regions whose triangles share one plane. Growing charts over such a region
//! triangle by triangle costs one heap operation per triangle and gains nothing: a
//! chart either takes the plane's triangles all at once or leaves them to a
//! neighbour. Units group them before segmentation (in the spirit of xatlas's planar
//! charts, Young 2018, and of the face clustering of Garland, Willmott & Heckbert 2001,
//! "Hierarchical face clustering on polygonal surfaces"), so that the growing, seeding
//! and Lloyd steps of [`crate::chart_segmentation`] work on fewer, larger elements.
//!
//! A unit is grown breadth first from its lowest-numbered free triangle through chart
//! adjacency ([`crate::face_graph`]) and takes a neighbour when that neighbour's normal
//! is within [`PLANAR_ANGLE_DEG`] of the *seed's* normal (so a unit never bends by
//! more than twice that angle), up to [`MAX_UNIT_TRIANGLES`] triangles. Degenerate triangles form units of their own. Units are numbered
//! in the order of their first triangle, so a mesh without coplanar neighbours gets
//! exactly one unit per triangle, in triangle order, and segmentation on units is the
//! same as on triangles.
//!
//! Per unit: area, area-weighted unit normal and centroid, the neighbouring units with
//! the length of the shared boundary (a CSR list, neighbours in order of first
//! contact), and the perimeter (boundary edges of the unit, mesh borders included).

use crate::face_graph::{FaceGraph, NONE};
use fieldtex_core::vec3::{self, V3};

/// Largest angle in degrees between a triangle's normal and its unit's first
/// triangle's normal: coplanar up to rounding and export precision. (Wider angles,
/// 0.5° was tried, let units swallow gently curved CAD faces and made the fandisk's
/// charts pack worse: 0.548 against 0.682.)
pub const PLANAR_ANGLE_DEG: f64 = 0.01;

/// Most triangles in one unit: a large flat region becomes several compact units, so
/// chart boundaries can still cross it where the compactness term asks for it (with
/// 32, the fandisk got 23 charts instead of 9).
pub const MAX_UNIT_TRIANGLES: usize = 8;

/// Planar units of a mesh and their adjacency (module docs).
#[derive(Debug, Clone)]
pub(crate) struct Units {
    /// `#F` unit of each triangle.
    pub unit_of_face: Vec<u32>,
    /// Neighbours of unit `u`: `adj[adj_start[u]..adj_start[u + 1]]` with the shared
    /// boundary length in `adj_len` at the same index.
    pub adj_start: Vec<u32>,
    pub adj: Vec<u32>,
    pub adj_len: Vec<f64>,
    /// Boundary length of each unit (shared and open edges).
    pub perimeter: Vec<f64>,
    pub areas: Vec<f64>,
    /// Area-weighted mean normal, normalised (the first triangle's normal when that
    /// vanishes; `[0; 3]` for degenerate units).
    pub normals: Vec<V3>,
    /// Area-weighted centroid (the first triangle's centroid for zero area).
    pub centroids: Vec<V3>,
    /// The unit is a single degenerate triangle (no cone test applies to it).
    pub degenerate: Vec<bool>,
}

impl Units {
    pub fn n_units(&self) -> usize {
        self.areas.len()
    }

    /// Neighbouring units of `u` and the shared boundary lengths.
    pub fn neighbours(&self, u: usize) -> impl Iterator<Item = (u32, f64)> + '_ {
        let r = self.adj_start[u] as usize..self.adj_start[u + 1] as usize;
        self.adj[r.clone()].iter().copied().zip(self.adj_len[r].iter().copied())
    }

    /// Groups the triangles of `graph` into planar units (module docs).
    pub fn build(graph: &FaceGraph) -> Self {
        let nf = graph.n_faces();
        let cos_eps = PLANAR_ANGLE_DEG.to_radians().cos();
        let mut unit_of_face = vec![NONE; nf];
        let mut face_start = vec![0u32];
        let mut faces = Vec::with_capacity(nf);
        for s in 0..nf {
            if unit_of_face[s] != NONE {
                continue;
            }
            let u = (face_start.len() - 1) as u32;
            let start = faces.len();
            unit_of_face[s] = u;
            faces.push(s as u32);
            if !graph.degenerate[s] {
                // Breadth first, so that a capped unit stays compact.
                let n0 = graph.normals[s];
                let mut head = start;
                'bfs: while head < faces.len() {
                    let f = faces[head] as usize;
                    head += 1;
                    for &g in &graph.adj[f] {
                        if g == NONE
                            || unit_of_face[g as usize] != NONE
                            || graph.degenerate[g as usize]
                            || vec3::dot(graph.normals[g as usize], n0) < cos_eps
                        {
                            continue;
                        }
                        unit_of_face[g as usize] = u;
                        faces.push(g);
                        if faces.len() - start >= MAX_UNIT_TRIANGLES {
                            break 'bfs;
                        }
                    }
                }
            }
            faces[start..].sort_unstable();
            face_start.push(faces.len() as u32);
        }
        let nu = face_start.len() - 1;
        let mut areas = vec![0.0; nu];
        let mut normals = vec![[0.0; 3]; nu];
        let mut centroids = vec![[0.0; 3]; nu];
        let mut degenerate = vec![false; nu];
        let mut perimeter = vec![0.0; nu];
        let mut adj_start = Vec::with_capacity(nu + 1);
        let mut adj: Vec<u32> = Vec::new();
        let mut adj_len: Vec<f64> = Vec::new();
        adj_start.push(0u32);
        for u in 0..nu {
            let fs = &faces[face_start[u] as usize..face_start[u + 1] as usize];
            let first = fs[0] as usize;
            let mut nsum = [0.0; 3];
            let mut csum = [0.0; 3];
            let mut area = 0.0;
            let row = adj.len();
            for &f in fs {
                let f = f as usize;
                let a = graph.areas[f];
                nsum = vec3::add(nsum, vec3::scale(graph.normals[f], a));
                csum = vec3::add(csum, vec3::scale(graph.centroids[f], a));
                area += a;
                for (&g, &len) in graph.adj[f].iter().zip(&graph.edge_len[f]) {
                    let v = if g == NONE { NONE } else { unit_of_face[g as usize] };
                    if v == u as u32 {
                        continue;
                    }
                    let len = if len.is_finite() { len } else { 0.0 };
                    perimeter[u] += len;
                    if v == NONE {
                        continue;
                    }
                    match adj[row..].iter().position(|&w| w == v) {
                        Some(k) => adj_len[row + k] += len,
                        None => {
                            adj.push(v);
                            adj_len.push(len);
                        }
                    }
                }
            }
            adj_start.push(adj.len() as u32);
            areas[u] = area;
            degenerate[u] = fs.len() == 1 && graph.degenerate[first];
            // A single triangle keeps its own normal and centroid bit for bit.
            let single = fs.len() == 1;
            normals[u] = if degenerate[u] {
                [0.0; 3]
            } else if single {
                graph.normals[first]
            } else {
                vec3::normalize(nsum).unwrap_or(graph.normals[first])
            };
            centroids[u] = if area > 0.0 && !single {
                vec3::scale(csum, 1.0 / area)
            } else {
                graph.centroids[first]
            };
        }
        Self {
            unit_of_face,
            adj_start,
            adj,
            adj_len,
            perimeter,
            areas,
            normals,
            centroids,
            degenerate,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_mesh::TriMesh;

    /// A flat 2×2 square split into 8 triangles, with the right column folded up at a right angle.
    fn bent_grid() -> TriMesh {
        let mut positions = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                let x = i as f64;
                let z = if i == 2 { 1.0 } else { 0.0 };
                positions.push([x.min(1.0), j as f64, z]);
            }
        }
        let mut triangles = Vec::new();
        for j in 0..2u32 {
            for i in 0..2u32 {
                let a = j * 3 + i;
                triangles.push([a, a + 1, a + 4]);
                triangles.push([a, a + 4, a + 3]);
            }
        }
        TriMesh::new(positions, triangles)
    }

    #[test]
    fn coplanar_triangles_share_a_unit_and_bends_separate_them() {
        let mesh = bent_grid();
        let graph = FaceGraph::build(&mesh);
        let units = Units::build(&graph);
        assert_eq!(units.n_units(), 2);
        // Left column (triangles of cells i = 0) flat, right column bent.
        assert_eq!(units.unit_of_face, vec![0, 0, 1, 1, 0, 0, 1, 1]);
        let total: f64 = graph.areas.iter().sum();
        assert!((units.areas[0] + units.areas[1] - total).abs() < 1e-12);
        // The two units share the fold line of length 2.
        let n: Vec<(u32, f64)> = units.neighbours(0).collect();
        assert_eq!(n.len(), 1);
        assert_eq!(n[0].0, 1);
        assert!((n[0].1 - 2.0).abs() < 1e-12);
        // Perimeter of the flat unit: the 1×2 rectangle.
        assert!((units.perimeter[0] - 6.0).abs() < 1e-12);
    }

    #[test]
    fn subdivided_triangles_group_into_their_parents() {
        // Midpoint subdivision keeps the four children of a triangle in its plane;
        // neighbouring parents of an icosphere are not coplanar.
        let parent = fieldtex_mesh::primitives::icosphere(2);
        let mesh = fieldtex_mesh::primitives::subdivide_midpoint(&parent);
        let graph = FaceGraph::build(&mesh);
        let units = Units::build(&graph);
        assert_eq!(units.n_units(), parent.n_triangles());
        for (p, children) in units.unit_of_face.chunks(4).enumerate() {
            assert!(children.iter().all(|&u| u == children[0]), "parent {p}: {children:?}");
        }
        // Units are numbered by first triangle: parent p is unit p.
        assert!(units.unit_of_face.chunks(4).enumerate().all(|(p, c)| c[0] == p as u32));
    }

    #[test]
    fn large_flat_regions_are_split_into_capped_units() {
        let mesh = fieldtex_mesh::primitives::grid(8, 8, 1.0, 1.0);
        let graph = FaceGraph::build(&mesh);
        let units = Units::build(&graph);
        let mut sizes = vec![0usize; units.n_units()];
        for &u in &units.unit_of_face {
            sizes[u as usize] += 1;
        }
        assert!(sizes.iter().all(|&n| (1..=MAX_UNIT_TRIANGLES).contains(&n)), "{sizes:?}");
        assert!(units.n_units() >= 128 / MAX_UNIT_TRIANGLES);
        // Shared lengths are symmetric and the perimeters add up to twice the interior
        // unit boundaries plus the grid's outline (4).
        let mut shared = 0.0;
        for u in 0..units.n_units() {
            for (v, len) in units.neighbours(u) {
                let back = units.neighbours(v as usize).find(|&(w, _)| w == u as u32).unwrap();
                assert!((back.1 - len).abs() < 1e-12);
                shared += len;
            }
        }
        let per: f64 = units.perimeter.iter().sum();
        assert!((per - shared - 4.0).abs() < 1e-9, "{per} {shared}");
    }
}
