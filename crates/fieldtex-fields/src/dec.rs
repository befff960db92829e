//! Discrete exterior calculus (DEC) on a triangle mesh.
//!
//! Follows the standard primal/circumcentric-dual construction (Desbrun, Hirani, Leok &
//! Marsden 2005, "Discrete exterior calculus"; Desbrun, Kanso & Tong 2008) as used for
//! vector field design by Fisher, Schröder, Desbrun & Hoppe 2007 ("Design of tangent
//! vector fields") and Liu et al. (paper D, §2.1).
//!
//! Conventions (from [`fieldtex_mesh::Topology`]):
//! - a 0-form is one value per vertex (`#V`), a 1-form one value per edge (`#E`): the
//!   line integral from `edges[e][0]` to `edges[e][1]` (low → high index); a 2-form one
//!   value per triangle (`#F`): the integral over the triangle, positive for the
//!   triangle's own orientation.
//! - `d0` is `#E × #V` (`(d0 f)[e] = f[high] − f[low]`), `d1` is `#F × #E` (signed edge
//!   incidence using `face_edge_signs`), so `d1 · d0 = 0` exactly.
//! - The Hodge stars are diagonal: `⋆0` = barycentric dual area (`Σ area/3`, always
//!   positive), `⋆1` = `(cot α + cot β) / 2` (ratio of circumcentric dual to primal edge
//!   length; one cotangent on a boundary edge), `⋆2` = `1 / area`.
//!
//! Robustness (documented substitutes, counted in [`Dec::clamped_star1`]):
//! - `⋆1` comes from `fieldtex_mesh::hodge_star1` (the cotangent weights' one home) with
//!   its explicit Hodge-star clamp: cotangents are clamped to `[−COT_LIMIT, COT_LIMIT]`
//!   (`1e3`), so slivers cannot blow up the operator; an edge's `⋆1` is then clamped to be `≥ 0`, since a negative
//!   dual length (non-Delaunay edge, obtuse boundary angle) would make the divergence
//!   energy indefinite. Right isosceles grids give exactly `⋆1 = 0` on their diagonals
//!   (zero dual length), which is correct and not counted as a clamp.
//! - triangle areas below `1e-12 ·` the mean area are raised to that floor (a warning);
//!   such a triangle's normal is taken from the mesh's mean normal.
//!
//! Whitney interpolation: the 1-form basis function of the edge from corner `i` to
//! corner `j` is `λ_i ∇λ_j − λ_j ∇λ_i`; at the barycentre it is `(∇λ_j − ∇λ_i) / 3`.
//! Interpolating an exact 1-form `d0 f` reproduces `∇f` of the linear interpolant.
//!
//! Not implemented: circumcentric `⋆0` (the barycentric one is always positive), and
//! DEC on non-manifold or inconsistently oriented meshes (refused with an error).

use fieldtex_core::vec3::{add, cross, dot, norm, normalize, scale, sub};
use fieldtex_core::{Warning, Warnings};
use fieldtex_linalg::SparseMatrix;
use fieldtex_mesh::{HodgeStarClamp, Topology, TriMesh, hodge_star1};
use rayon::prelude::*;

use crate::FieldsError;

/// Largest accepted |cot| of a triangle angle (about 0.06° or 179.94°).
pub const COT_LIMIT: f64 = 1e3;

/// DEC operators of one triangle mesh. Build once per mesh; everything is `f64`.
#[derive(Debug, Clone)]
pub struct Dec {
    /// Edge and adjacency tables (sign conventions above).
    pub topology: Topology,
    /// `#V × 3` vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// `#F × 3` triangles.
    pub triangles: Vec<[u32; 3]>,
    /// `#F` triangle areas (floored, see module docs).
    pub face_areas: Vec<f64>,
    /// `#F` unit triangle normals (from the corner order).
    pub face_normals: Vec<[f64; 3]>,
    /// `#V` unit vertex normals (area-weighted face normals).
    pub vertex_normals: Vec<[f64; 3]>,
    /// `#F × 3` gradients of the barycentric coordinates of each corner.
    pub grad_lambda: Vec<[[f64; 3]; 3]>,
    /// `#V` ⋆0: barycentric dual areas.
    pub star0: Vec<f64>,
    /// `#E` ⋆1: cotangent weights (clamped, see module docs).
    pub star1: Vec<f64>,
    /// `#F` ⋆2: inverse areas.
    pub star2: Vec<f64>,
    /// Mean edge length (the mesh's length scale).
    pub mean_edge_length: f64,
    /// Number of edges whose `⋆1` was clamped to zero or hit the cotangent limit.
    pub clamped_star1: usize,
}

impl Dec {
    /// Builds the operators. Refuses invalid indices, non-finite positions, triangles
    /// with a repeated vertex, non-manifold edges and inconsistent orientation; zero-area
    /// triangles and clamped Hodge stars are reported as warnings.
    pub fn new(mesh: &TriMesh) -> Result<(Self, Warnings), FieldsError> {
        mesh.validate()?;
        for (f, t) in mesh.triangles.iter().enumerate() {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                let vertex = if t[0] == t[1] || t[0] == t[2] { t[0] } else { t[1] };
                return Err(FieldsError::DegenerateTriangle { triangle: f, vertex });
            }
        }
        let nv = mesh.n_vertices();
        let topology = Topology::build(nv, &mesh.triangles);
        for e in 0..topology.n_edges() {
            let faces = topology.edge_faces(e);
            let [a, b] = topology.edges[e];
            if faces.len() > 2 {
                return Err(FieldsError::NonManifoldEdge { edge: e, a, b, faces: faces.len() });
            }
            if faces.len() == 2 {
                let s0 = edge_sign_in_face(&topology, faces[0] as usize, e);
                let s1 = edge_sign_in_face(&topology, faces[1] as usize, e);
                if s0 == s1 {
                    return Err(FieldsError::InconsistentOrientation { edge: e, a, b });
                }
            }
        }
        let mut warnings = Warnings::new();
        let nf = mesh.n_triangles();
        let raw: Vec<([f64; 3], f64)> = (0..nf)
            .map(|f| {
                let [p0, p1, p2] = mesh.triangle_positions(f);
                let c = cross(sub(p1, p0), sub(p2, p0));
                (c, 0.5 * norm(c))
            })
            .collect();
        let mean_area = raw.iter().map(|r| r.1).sum::<f64>() / nf as f64;
        let area_floor = (1e-12 * mean_area).max(f64::MIN_POSITIVE);
        let mean_normal =
            normalize(raw.iter().fold([0.0; 3], |acc, r| add(acc, r.0))).unwrap_or([0.0, 0.0, 1.0]);
        let mut n_small = 0usize;
        let mut face_areas = Vec::with_capacity(nf);
        let mut face_normals = Vec::with_capacity(nf);
        for (c, a) in &raw {
            if *a < area_floor {
                n_small += 1;
                face_areas.push(area_floor);
                face_normals.push(mean_normal);
            } else {
                face_areas.push(*a);
                face_normals.push(scale(*c, 0.5 / a));
            }
        }
        if n_small > 0 {
            warnings.push(Warning::new(
                "field-zero-area-triangles",
                format!(
                    "{n_small} triangle(s) have (almost) zero area; their area was raised to {area_floor:e} for the field operators"
                ),
            ));
        }
        let grad_lambda: Vec<[[f64; 3]; 3]> = (0..nf)
            .map(|f| {
                let p = mesh.triangle_positions(f);
                let n = face_normals[f];
                let inv = 1.0 / (2.0 * face_areas[f]);
                std::array::from_fn(|i| scale(cross(n, sub(p[(i + 2) % 3], p[(i + 1) % 3])), inv))
            })
            .collect();
        let mut star0 = vec![0.0; nv];
        let mut vertex_normals = vec![[0.0; 3]; nv];
        for (f, t) in mesh.triangles.iter().enumerate() {
            for &v in t {
                star0[v as usize] += face_areas[f] / 3.0;
                vertex_normals[v as usize] =
                    add(vertex_normals[v as usize], scale(face_normals[f], face_areas[f]));
            }
        }
        for (v, n) in vertex_normals.iter_mut().enumerate() {
            *n = normalize(*n).unwrap_or(mean_normal);
            if star0[v] <= 0.0 {
                star0[v] = area_floor; // unreferenced vertex: keeps ⋆0⁻¹ finite
            }
        }
        let ne = topology.n_edges();
        let clamp = HodgeStarClamp { cot_limit: COT_LIMIT };
        let (star1, clamped_star1) = hodge_star1(mesh, &topology, &face_areas, Some(&clamp));
        if clamped_star1 > 0 {
            warnings.push(Warning::new(
                "field-star1-clamped",
                format!(
                    "{clamped_star1} edge(s) have a negative or extreme cotangent weight (obtuse or sliver triangles); their Hodge star was clamped"
                ),
            ));
        }
        let star2 = face_areas.iter().map(|a| 1.0 / a).collect();
        let mean_edge_length = topology
            .edges
            .iter()
            .map(|e| norm(sub(mesh.positions[e[1] as usize], mesh.positions[e[0] as usize])))
            .sum::<f64>()
            / ne.max(1) as f64;
        let dec = Self {
            topology,
            positions: mesh.positions.clone(),
            triangles: mesh.triangles.clone(),
            face_areas,
            face_normals,
            vertex_normals,
            grad_lambda,
            star0,
            star1,
            star2,
            mean_edge_length,
            clamped_star1,
        };
        Ok((dec, warnings))
    }

    pub fn n_vertices(&self) -> usize {
        self.positions.len()
    }
    pub fn n_edges(&self) -> usize {
        self.topology.n_edges()
    }
    pub fn n_faces(&self) -> usize {
        self.triangles.len()
    }

    /// Vector of edge `e` from its low to its high vertex.
    #[inline]
    pub fn edge_vector(&self, e: usize) -> [f64; 3] {
        let [a, b] = self.topology.edges[e];
        sub(self.positions[b as usize], self.positions[a as usize])
    }

    /// Barycentre of triangle `f`.
    #[inline]
    pub fn face_center(&self, f: usize) -> [f64; 3] {
        let t = self.triangles[f];
        let s = add(
            add(self.positions[t[0] as usize], self.positions[t[1] as usize]),
            self.positions[t[2] as usize],
        );
        scale(s, 1.0 / 3.0)
    }

    /// `d0`, `#E × #V`.
    pub fn d0(&self) -> SparseMatrix {
        let mut t = Vec::with_capacity(2 * self.n_edges());
        for (e, ed) in self.topology.edges.iter().enumerate() {
            t.push((e, ed[0] as usize, -1.0));
            t.push((e, ed[1] as usize, 1.0));
        }
        SparseMatrix::from_triplets(self.n_edges(), self.n_vertices(), &t)
            .expect("edge indices are in range")
    }

    /// `d1`, `#F × #E`.
    pub fn d1(&self) -> SparseMatrix {
        let mut t = Vec::with_capacity(3 * self.n_faces());
        for f in 0..self.n_faces() {
            for k in 0..3 {
                let e = self.topology.face_edges[f][k] as usize;
                t.push((f, e, self.topology.face_edge_signs[f][k] as f64));
            }
        }
        SparseMatrix::from_triplets(self.n_faces(), self.n_edges(), &t)
            .expect("face edge indices are in range")
    }

    /// Diagonal `⋆0` (`#V × #V`), `⋆1` (`#E × #E`) or `⋆2` (`#F × #F`) as a matrix.
    pub fn star_matrix(&self, k: usize) -> SparseMatrix {
        match k {
            0 => SparseMatrix::from_diagonal(&self.star0),
            1 => SparseMatrix::from_diagonal(&self.star1),
            2 => SparseMatrix::from_diagonal(&self.star2),
            _ => panic!("Dec::star_matrix: k must be 0, 1 or 2 on a surface, got {k}"),
        }
    }

    /// Integrated curl `(d1 ω)[f]`, the circulation around triangle `f`.
    #[inline]
    pub fn face_curl(&self, f: usize, omega: &[f64]) -> f64 {
        (0..3)
            .map(|k| {
                self.topology.face_edge_signs[f][k] as f64
                    * omega[self.topology.face_edges[f][k] as usize]
            })
            .sum()
    }

    /// The three Whitney basis vectors of triangle `f` at its barycentre, one per local
    /// edge `k` (corner `k` → `k+1`), for the edge's *reference* orientation: the face
    /// vector is `Σ_k ω[face_edges[f][k]] · basis[k]`.
    #[inline]
    pub fn whitney_at_barycenter(&self, f: usize) -> [[f64; 3]; 3] {
        let g = &self.grad_lambda[f];
        std::array::from_fn(|k| {
            let s = self.topology.face_edge_signs[f][k] as f64 / 3.0;
            scale(sub(g[(k + 1) % 3], g[k]), s)
        })
    }

    /// Whitney interpolation of the 1-form `omega` at the barycentre of triangle `f`.
    #[inline]
    pub fn face_vector(&self, f: usize, omega: &[f64]) -> [f64; 3] {
        let w = self.whitney_at_barycenter(f);
        let mut u = [0.0; 3];
        for (k, wk) in w.iter().enumerate() {
            u = add(u, scale(*wk, omega[self.topology.face_edges[f][k] as usize]));
        }
        u
    }

    /// Whitney interpolation of `omega` at barycentric coordinates `bary` of triangle `f`
    /// (tangential components are continuous across edges, normal ones are not).
    pub fn whitney_at(&self, f: usize, bary: [f64; 3], omega: &[f64]) -> [f64; 3] {
        let g = &self.grad_lambda[f];
        let mut u = [0.0; 3];
        for k in 0..3 {
            let j = (k + 1) % 3;
            let s = self.topology.face_edge_signs[f][k] as f64;
            let c = s * omega[self.topology.face_edges[f][k] as usize];
            u = add(u, scale(sub(scale(g[j], bary[k]), scale(g[k], bary[j])), c));
        }
        u
    }

    /// `#F` face vectors (Whitney at barycentres) of the 1-form `omega`.
    pub fn face_vectors(&self, omega: &[f64]) -> Vec<[f64; 3]> {
        (0..self.n_faces()).into_par_iter().map(|f| self.face_vector(f, omega)).collect()
    }

    /// The inverse map: a 1-form from one tangent vector per triangle, integrating each
    /// adjacent triangle's (constant) vector along the edge and averaging the triangles.
    pub fn one_form_from_face_vectors(&self, vectors: &[[f64; 3]]) -> Vec<f64> {
        (0..self.n_edges())
            .into_par_iter()
            .map(|e| {
                let faces = self.topology.edge_faces(e);
                let d = self.edge_vector(e);
                let s: f64 = faces.iter().map(|&f| dot(vectors[f as usize], d)).sum();
                s / faces.len().max(1) as f64
            })
            .collect()
    }

    /// `#V` vertex vectors: area-weighted mean of the incident face vectors, projected
    /// to the vertex tangent plane.
    pub fn vertex_vectors(&self, face_vectors: &[[f64; 3]]) -> Vec<[f64; 3]> {
        (0..self.n_vertices())
            .into_par_iter()
            .map(|v| {
                let mut s = [0.0; 3];
                for &f in self.topology.vertex_faces(v) {
                    s = add(s, scale(face_vectors[f as usize], self.face_areas[f as usize]));
                }
                let n = self.vertex_normals[v];
                sub(s, scale(n, dot(n, s)))
            })
            .collect()
    }

    /// Integrated divergence with the boundary flux included, `#V × #E` triplets
    /// `(vertex, edge, value)`: `(D ω)[v]` is the flux of the field out of the dual cell
    /// of `v`, through its interior dual edges (`⋆1 ω`) and, at a boundary vertex,
    /// through the two half boundary edges (flux of the boundary triangle's Whitney
    /// vector). This is Fisher et al.'s (2007) free-boundary treatment: a constant field
    /// has `D ω = 0` at every vertex, boundary vertices included.
    pub fn divergence_triplets(&self) -> Vec<(usize, usize, f64)> {
        let mut t = Vec::with_capacity(2 * self.n_edges() + 12 * 64);
        for (e, ed) in self.topology.edges.iter().enumerate() {
            t.push((ed[0] as usize, e, self.star1[e]));
            t.push((ed[1] as usize, e, -self.star1[e]));
        }
        for e in 0..self.n_edges() {
            if !self.topology.is_boundary_edge(e) {
                continue;
            }
            let f = self.topology.edge_faces(e)[0] as usize;
            let k = (0..3).find(|&k| self.topology.face_edges[f][k] as usize == e).unwrap_or(0);
            let tri = self.triangles[f];
            let (a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize);
            // Outward normal times edge length: (b − a) × n for a counter-clockwise face.
            let nu = cross(sub(self.positions[b], self.positions[a]), self.face_normals[f]);
            let w = self.whitney_at_barycenter(f);
            for j in 0..3 {
                let flux = 0.5 * dot(w[j], nu);
                let ej = self.topology.face_edges[f][j] as usize;
                t.push((a, ej, flux));
                t.push((b, ej, flux));
            }
        }
        t
    }
}

/// Sign of edge `e` in face `f` (0 if `e` is not an edge of `f`).
pub(crate) fn edge_sign_in_face(topology: &Topology, f: usize, e: usize) -> i8 {
    (0..3)
        .find(|&k| topology.face_edges[f][k] as usize == e)
        .map(|k| topology.face_edge_signs[f][k])
        .unwrap_or(0)
}
