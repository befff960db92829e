//! Mesh inspection: everything that is wrong or unusual about a triangle mesh, counted,
//! with the first few offending elements, for `fieldtex inspect [--json]` and reports.
//!
//! What is checked, and the definitions used:
//! - *invalid-index* triangles (an index `≥ #V`) and *repeated-index* triangles (two
//!   equal corners) are set aside first; all topology below is computed on the other
//!   ("valid") triangles.
//! - *components*: triangles connected through shared vertices (and, as a second
//!   count, through edges with exactly two triangles). Per component: χ =
//!   V − E + F over its own vertices, edges and triangles, boundary loops `b`, and the
//!   genus `g = (2 − χ − b) / 2` when the component is manifold and orientable; for a
//!   manifold non-orientable one the non-orientable genus `k = 2 − χ − b` instead.
//! - *boundary loops*: see [`crate::boundary_cycles`] (orientation-independent walk).
//! - *non-manifold edges*: edges with more than two triangles.
//! - *non-manifold vertices*: vertices whose triangles form more than one fan
//!   ([`crate::vertex_fans`]) while all their edges have at most two triangles (e.g. two
//!   cones touching at the tip). Vertices on non-manifold edges are counted separately.
//! - *orientation*: inconsistent edges (two triangles traversing a manifold edge in the
//!   same direction) and non-orientable components ([`crate::orientation`]).
//! - *zero-area* triangles: area `≤ zero_area_relative · diagonal²`; *slivers*: not
//!   zero-area and smallest angle `< sliver_min_angle_deg` (see [`crate::triangle_quality`]).
//! - *duplicate triangles*: same three vertices as an earlier triangle, in any order.
//! - *duplicate vertices*: exactly equal positions, and positions within
//!   `near_duplicate_relative · diagonal` (single linkage, [`crate::coincident_vertices`]);
//!   only exact duplicates that a weld would stitch together, and near ones, are problems.
//! - *UV sanity*: index consistency, non-finite values, range, negative (clockwise) and
//!   zero-area triangles in UV space.
//!
//! All passes are linear or `O(n log n)` (edge sort); no pairwise search.

use crate::boundary_cycles::boundary_cycles;
use crate::coincident_vertices::{
    count_merged, exact_coincident_classes, near_coincident_classes_from,
};
use crate::orientation::orientation_patches;
use crate::triangle_quality::{
    DEFAULT_SLIVER_MIN_ANGLE_DEG, DEFAULT_ZERO_AREA_RELATIVE, signed_area_2d, triangle_area,
    triangle_min_angle,
};
use crate::vertex_fans::{FanRule, corner_fans, vertex_face_table};
use crate::{Aabb, Topology, TriMesh};
use rayon::prelude::*;
use serde::Serialize;

/// Options of [`inspect`].
#[derive(Debug, Clone, Serialize)]
pub struct InspectOptions {
    /// Offending elements listed per check. Default 10.
    pub max_examples: usize,
    /// Components described one by one (the largest first). Default 100.
    pub max_components_listed: usize,
    /// Zero-area tolerance relative to the squared bounding-box diagonal. Default `1e-12`.
    pub zero_area_relative: f64,
    /// Sliver threshold on the smallest angle, degrees. Default 1°.
    pub sliver_min_angle_deg: f64,
    /// Near-duplicate vertex distance relative to the bounding-box diagonal. Default `1e-6`.
    pub near_duplicate_relative: f64,
}

impl Default for InspectOptions {
    fn default() -> Self {
        Self {
            max_examples: 10,
            max_components_listed: 100,
            zero_area_relative: DEFAULT_ZERO_AREA_RELATIVE,
            sliver_min_angle_deg: DEFAULT_SLIVER_MIN_ANGLE_DEG,
            near_duplicate_relative: 1e-6,
        }
    }
}

/// A count with the first few examples (element indices refer to the input mesh).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Examples<T> {
    pub count: usize,
    pub examples: Vec<T>,
}

impl<T> Examples<T> {
    fn new() -> Self {
        Self { count: 0, examples: Vec::new() }
    }
    fn push(&mut self, item: T, max: usize) {
        self.count += 1;
        if self.examples.len() < max {
            self.examples.push(item);
        }
    }
}

/// One connected component.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComponentReport {
    /// Component id (numbered by first triangle).
    pub id: usize,
    pub triangles: usize,
    pub vertices: usize,
    pub edges: usize,
    pub boundary_loops: usize,
    pub euler_characteristic: i64,
    /// No non-manifold edge or vertex.
    pub manifold: bool,
    pub orientable: bool,
    /// Genus when manifold and orientable.
    pub genus: Option<u32>,
    /// Non-orientable genus (number of cross-caps) when manifold but not orientable.
    pub nonorientable_genus: Option<u32>,
    /// Why `genus` is missing.
    pub genus_unavailable: Option<String>,
}

/// Non-manifold edge: its vertices and all its triangles.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NonManifoldEdge {
    pub vertices: [u32; 2],
    pub triangles: Vec<u32>,
}

/// Non-manifold vertex and the number of fans its triangles form.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NonManifoldVertex {
    pub vertex: u32,
    pub fans: u32,
}

/// Components summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComponentsReport {
    /// Components connected through shared vertices (what a viewer shows as pieces).
    pub count: usize,
    /// Components connected through edges with exactly two triangles (the mesh cut
    /// along its non-manifold edges and vertices); equals `count` on a manifold mesh.
    pub edge_connected: usize,
    /// The largest components (by triangles, then id), at most `max_components_listed`.
    pub listed: Vec<ComponentReport>,
}

/// Boundary loops summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BoundaryReport {
    pub count: usize,
    /// Walks that could not close (only around non-manifold configurations).
    pub open_chains: usize,
    /// Loop lengths in edges, largest first, at most `max_components_listed`.
    pub lengths: Vec<usize>,
}

/// Orientation summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrientationReport {
    /// Manifold edges traversed twice in the same direction (vertex pairs).
    pub inconsistent_edges: Examples<[u32; 2]>,
    /// Components with a contradiction in orientation (e.g. a Möbius strip).
    pub non_orientable_components: Vec<usize>,
}

/// Triangle shape summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShapeReport {
    /// Absolute area tolerance used (`zero_area_relative · diagonal²`).
    pub zero_area_tolerance: f64,
    pub zero_area: Examples<u32>,
    pub sliver_threshold_deg: f64,
    pub slivers: Examples<u32>,
    /// Smallest angle of any non-zero-area triangle with finite corners, degrees.
    pub min_angle_deg: Option<f64>,
    /// Triangles with a non-finite corner (no shape measured).
    pub non_finite: usize,
}

/// Duplicate vertices summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DuplicateVerticesReport {
    /// Vertices at exactly the position of a lower-index vertex.
    pub exact: usize,
    /// Those of `exact` that repair's fan-aware weld ([`crate::vertex_welding`]) would
    /// merge. The others sit in separate fans of triangles (e.g. the copies repair makes
    /// when it splits a non-manifold vertex) and are kept apart on purpose.
    pub weldable: usize,
    /// Vertices a weld within `epsilon` would remove (includes `exact`).
    pub near: usize,
    /// Absolute distance used (`near_duplicate_relative · diagonal`).
    pub epsilon: f64,
    /// `[vertex, lower-index vertex it coincides with]` (exact).
    pub examples: Vec<[u32; 2]>,
}

/// Texture-coordinate sanity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UvReport {
    pub values: usize,
    /// Set when the UV index table does not match the triangles; nothing else checked.
    pub index_problem: Option<String>,
    pub non_finite_values: usize,
    /// Range of the finite UV values (`None` when there are none).
    pub min: Option<[f64; 2]>,
    pub max: Option<[f64; 2]>,
    /// Triangles clockwise in UV space (mirrored relative to the 3D orientation).
    pub negative_area: Examples<u32>,
    /// Triangles with UV area `≤ zero_area_relative · (UV box diagonal)²`.
    pub zero_area: Examples<u32>,
}

/// Everything [`inspect`] found. Triangle and vertex indices refer to the input mesh.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InspectReport {
    pub n_vertices: usize,
    pub n_triangles: usize,
    pub bounding_box: Option<Aabb>,
    pub diagonal: f64,
    pub non_finite_vertices: Examples<u32>,
    pub invalid_index_triangles: Examples<u32>,
    pub repeated_index_triangles: Examples<u32>,
    pub unreferenced_vertices: Examples<u32>,
    pub components: ComponentsReport,
    pub boundary_loops: BoundaryReport,
    pub non_manifold_edges: Examples<NonManifoldEdge>,
    pub non_manifold_vertices: Examples<NonManifoldVertex>,
    /// Vertices lying on a non-manifold edge.
    pub vertices_on_non_manifold_edges: usize,
    pub orientation: OrientationReport,
    pub shape: ShapeReport,
    /// Triangles repeating an earlier one's vertices: `[triangle, earlier triangle]`.
    pub duplicate_triangles: Examples<[u32; 2]>,
    pub duplicate_vertices: DuplicateVerticesReport,
    pub uv: Option<UvReport>,
    /// Attribute tables whose length does not match (colours, normals).
    pub attribute_problems: Vec<String>,
}

/// Inspects `mesh`; never panics, whatever the data.
pub fn inspect(mesh: &TriMesh, options: &InspectOptions) -> InspectReport {
    let nv = mesh.n_vertices();
    let max = options.max_examples;
    let bounding_box = mesh.bounding_box();
    let diagonal = bounding_box.map_or(0.0, |b| b.diagonal());

    let mut non_finite_vertices = Examples::new();
    for (v, p) in mesh.positions.iter().enumerate() {
        if !fieldtex_core::vec3::is_finite(*p) {
            non_finite_vertices.push(v as u32, max);
        }
    }

    // Split triangles into invalid, repeated-index and valid ones.
    let mut invalid_index_triangles = Examples::new();
    let mut repeated_index_triangles = Examples::new();
    let mut valid: Vec<u32> = Vec::with_capacity(mesh.n_triangles());
    let mut referenced = vec![false; nv];
    for (f, t) in mesh.triangles.iter().enumerate() {
        if t.iter().any(|&i| i as usize >= nv) {
            invalid_index_triangles.push(f as u32, max);
            continue;
        }
        for &i in t {
            referenced[i as usize] = true;
        }
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            repeated_index_triangles.push(f as u32, max);
        } else {
            valid.push(f as u32);
        }
    }
    let mut unreferenced_vertices = Examples::new();
    for (v, &r) in referenced.iter().enumerate() {
        if !r {
            unreferenced_vertices.push(v as u32, max);
        }
    }
    let tris: Vec<[u32; 3]> = valid.iter().map(|&f| mesh.triangles[f as usize]).collect();
    let topo = Topology::build(nv, &tris);
    let orig = |f: u32| valid[f as usize];

    // Non-manifold edges and vertices.
    let mut non_manifold_edges = Examples::new();
    let mut on_nm_edge = vec![false; nv];
    for e in 0..topo.n_edges() {
        if topo.is_nonmanifold_edge(e) {
            let [a, b] = topo.edges[e];
            on_nm_edge[a as usize] = true;
            on_nm_edge[b as usize] = true;
            let triangles = topo.edge_faces(e).iter().map(|&f| orig(f)).collect();
            non_manifold_edges.push(NonManifoldEdge { vertices: [a, b], triangles }, max);
        }
    }
    let fans = corner_fans(&tris, &vertex_face_table(nv, &tris), FanRule::ManifoldEdgesOnly);
    let nfans = fans.fans_at_vertex;
    let mut non_manifold_vertices = Examples::new();
    for v in 0..nv {
        if nfans[v] > 1 && !on_nm_edge[v] {
            non_manifold_vertices.push(NonManifoldVertex { vertex: v as u32, fans: nfans[v] }, max);
        }
    }
    let vertices_on_non_manifold_edges = on_nm_edge.iter().filter(|&&b| b).count();

    // Orientation.
    let patches = orientation_patches(&topo);
    let mut inconsistent_edges = Examples::new();
    for &e in &patches.inconsistent_edges {
        inconsistent_edges.push(topo.edges[e as usize], max);
    }

    // Components and per-component counts.
    let (comp, ncomp) = topo.face_components(&tris);
    let mut c_tris = vec![0usize; ncomp];
    let mut c_verts = vec![0usize; ncomp];
    let mut c_edges = vec![0usize; ncomp];
    let mut c_loops = vec![0usize; ncomp];
    let mut c_nonmanifold = vec![false; ncomp];
    let mut c_orientable = vec![true; ncomp];
    for (f, &c) in comp.iter().enumerate() {
        c_tris[c as usize] += 1;
        if !patches.orientable[patches.patch[f] as usize] {
            c_orientable[c as usize] = false;
        }
    }
    for (v, &fans_at_v) in nfans.iter().enumerate() {
        if let Some(&f) = topo.vertex_faces(v).first() {
            let c = comp[f as usize] as usize;
            c_verts[c] += 1;
            if fans_at_v > 1 {
                c_nonmanifold[c] = true;
            }
        }
    }
    for e in 0..topo.n_edges() {
        let c = comp[topo.edge_faces(e)[0] as usize] as usize;
        c_edges[c] += 1;
        if topo.is_nonmanifold_edge(e) {
            c_nonmanifold[c] = true;
        }
    }
    let cycles = boundary_cycles(&topo);
    for cy in &cycles {
        c_loops[comp[topo.edge_faces(cy.first_edge as usize)[0] as usize] as usize] += 1;
    }
    let mut order: Vec<usize> = (0..ncomp).collect();
    order.sort_by_key(|&c| (std::cmp::Reverse(c_tris[c]), c));
    let listed = order
        .iter()
        .take(options.max_components_listed)
        .map(|&c| {
            let chi = c_verts[c] as i64 - c_edges[c] as i64 + c_tris[c] as i64;
            let k = 2 - chi - c_loops[c] as i64;
            let (mut genus, mut nonorientable_genus, mut why) = (None, None, None);
            if c_nonmanifold[c] {
                why = Some("non-manifold".to_string());
            } else if k < 0 || (c_orientable[c] && k % 2 != 0) {
                why = Some(format!("inconsistent counts (2 - chi - b = {k})"));
            } else if c_orientable[c] {
                genus = Some((k / 2) as u32);
            } else {
                nonorientable_genus = Some(k as u32);
                why = Some("non-orientable".to_string());
            }
            ComponentReport {
                id: c,
                triangles: c_tris[c],
                vertices: c_verts[c],
                edges: c_edges[c],
                boundary_loops: c_loops[c],
                euler_characteristic: chi,
                manifold: !c_nonmanifold[c],
                orientable: c_orientable[c],
                genus,
                nonorientable_genus,
                genus_unavailable: why,
            }
        })
        .collect();
    let components = ComponentsReport { count: ncomp, edge_connected: patches.n_patches(), listed };
    let non_orientable_components = (0..ncomp).filter(|&c| !c_orientable[c]).collect();
    let mut lengths: Vec<usize> =
        cycles.iter().map(|c| c.vertices.len() - usize::from(!c.closed)).collect();
    lengths.sort_unstable_by(|a, b| b.cmp(a));
    lengths.truncate(options.max_components_listed);
    let boundary_loops = BoundaryReport {
        count: cycles.len(),
        open_chains: cycles.iter().filter(|c| !c.closed).count(),
        lengths,
    };

    let shape = shape_report(mesh, &valid, diagonal, options);
    let duplicate_triangles = duplicate_triangles(&tris, &valid, max);

    let exact = exact_coincident_classes(&mesh.positions);
    let epsilon = options.near_duplicate_relative.max(0.0) * diagonal;
    let near = near_coincident_classes_from(&mesh.positions, exact.clone(), epsilon);
    let n_exact = count_merged(&exact);
    let weldable = if n_exact > 0 {
        count_merged(&crate::vertex_welding::fan_aware_weld(&mesh.positions, &tris, 0.0))
    } else {
        0
    };
    let duplicate_vertices = DuplicateVerticesReport {
        exact: n_exact,
        weldable,
        near: count_merged(&near),
        epsilon,
        examples: exact
            .iter()
            .enumerate()
            .filter(|&(v, &r)| r as usize != v)
            .take(max)
            .map(|(v, &r)| [v as u32, r])
            .collect(),
    };

    let mut attribute_problems = Vec::new();
    if let Some(c) = mesh.vertex_colors.as_ref().filter(|c| c.len() != nv) {
        attribute_problems.push(format!("vertex colours: {} entries for {nv} vertices", c.len()));
    }
    if let Some(n) = mesh.vertex_normals.as_ref().filter(|n| n.len() != nv) {
        attribute_problems.push(format!("vertex normals: {} entries for {nv} vertices", n.len()));
    }

    InspectReport {
        n_vertices: nv,
        n_triangles: mesh.n_triangles(),
        bounding_box,
        diagonal,
        non_finite_vertices,
        invalid_index_triangles,
        repeated_index_triangles,
        unreferenced_vertices,
        components,
        boundary_loops,
        non_manifold_edges,
        non_manifold_vertices,
        vertices_on_non_manifold_edges,
        orientation: OrientationReport { inconsistent_edges, non_orientable_components },
        shape,
        duplicate_triangles,
        duplicate_vertices,
        uv: uv_report(mesh, options),
        attribute_problems,
    }
}

/// Zero-area and sliver triangles among the valid ones.
fn shape_report(
    mesh: &TriMesh,
    valid: &[u32],
    diagonal: f64,
    options: &InspectOptions,
) -> ShapeReport {
    let tol = options.zero_area_relative * diagonal * diagonal;
    let sliver = options.sliver_min_angle_deg.to_radians();
    // Per valid triangle: (class, min angle); class 0 ok, 1 zero-area, 2 sliver,
    // 3 non-finite. Computed in parallel, scanned in order.
    let measured: Vec<(u8, f64)> = valid
        .par_iter()
        .with_min_len(4096)
        .map(|&f| {
            let p = mesh.triangle_positions(f as usize);
            let area = triangle_area(&p);
            if !area.is_finite() {
                return (3, f64::NAN);
            }
            if area <= tol {
                return (1, 0.0);
            }
            let a = triangle_min_angle(&p);
            (if a < sliver { 2 } else { 0 }, a)
        })
        .collect();
    let (mut zero_area, mut slivers) = (Examples::new(), Examples::new());
    let mut min_angle = f64::INFINITY;
    let mut non_finite = 0;
    for (k, &(class, a)) in measured.iter().enumerate() {
        match class {
            1 => zero_area.push(valid[k], options.max_examples),
            2 => slivers.push(valid[k], options.max_examples),
            3 => non_finite += 1,
            _ => {}
        }
        if class == 0 || class == 2 {
            min_angle = min_angle.min(a);
        }
    }
    ShapeReport {
        zero_area_tolerance: tol,
        zero_area,
        sliver_threshold_deg: options.sliver_min_angle_deg,
        slivers,
        min_angle_deg: min_angle.is_finite().then(|| min_angle.to_degrees()),
        non_finite,
    }
}

/// Later triangles with the same vertex set as an earlier one.
fn duplicate_triangles(tris: &[[u32; 3]], valid: &[u32], max: usize) -> Examples<[u32; 2]> {
    let mut first: crate::coincident_vertices::IntMap<[u32; 3], u32> = Default::default();
    first.reserve(tris.len());
    let mut out = Examples::new();
    for (k, t) in tris.iter().enumerate() {
        let mut key = *t;
        key.sort_unstable();
        let f0 = *first.entry(key).or_insert(k as u32);
        if f0 as usize != k {
            out.push([valid[k], valid[f0 as usize]], max);
        }
    }
    out
}

fn uv_report(mesh: &TriMesh, options: &InspectOptions) -> Option<UvReport> {
    let uv = mesh.uvs.as_ref()?;
    let max = options.max_examples;
    let mut rep = UvReport {
        values: uv.values.len(),
        index_problem: None,
        non_finite_values: 0,
        min: None,
        max: None,
        negative_area: Examples::new(),
        zero_area: Examples::new(),
    };
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in &uv.values {
        if v[0].is_finite() && v[1].is_finite() {
            for k in 0..2 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        } else {
            rep.non_finite_values += 1;
        }
    }
    if lo[0] <= hi[0] {
        rep.min = Some(lo);
        rep.max = Some(hi);
    }
    if uv.indices.len() != mesh.n_triangles() {
        rep.index_problem = Some(format!(
            "{} UV index triples for {} triangles",
            uv.indices.len(),
            mesh.n_triangles()
        ));
        return Some(rep);
    }
    let n = uv.values.len();
    if let Some(f) = uv.indices.iter().position(|t| t.iter().any(|&i| i as usize >= n)) {
        rep.index_problem = Some(format!("triangle {f} refers to a UV index ≥ {n}"));
        return Some(rep);
    }
    let d2 = if lo[0] <= hi[0] { (hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) } else { 0.0 };
    let tol = options.zero_area_relative * d2;
    for (f, t) in uv.indices.iter().enumerate() {
        let [a, b, c] = t.map(|i| uv.values[i as usize]);
        let s = signed_area_2d(a, b, c);
        if !s.is_finite() {
            continue;
        }
        if s.abs() <= tol {
            rep.zero_area.push(f as u32, max);
        } else if s < 0.0 {
            rep.negative_area.push(f as u32, max);
        }
    }
    Some(rep)
}
