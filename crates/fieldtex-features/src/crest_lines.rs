//! Crest lines (ridges and valleys) of a triangle mesh, with strengths and levels of
//! detail: the salient curves of paper A (Xu et al., "Feature-aligned shape
//! texturing", §3 and §6, which uses Yoshizawa et al. 2005 for them).
//!
//! # Method
//! *Crest lines = curvature extrema ∪ sharp creases.*
//!
//! 1. **Curvature** (`fieldtex_mesh::principal_curvatures`, Rusinkiewicz 2004):
//!    `k_max ≥ k_min` and unit directions `t_max`, `t_min` per vertex; positive
//!    curvature bends away from the outward normal (convex). The per-vertex tensors are
//!    averaged over [`CrestOptions::curvature_smoothing`] rings first: derivatives of
//!    curvature amplify noise, and Yoshizawa, Belyaev & Seidel 2005 likewise smooth the
//!    curvature tensor over a small neighbourhood before differentiating.
//! 2. **Extremality** ([`crate::extremality`]): `e_max = ∇k_max · t_max`,
//!    `e_min = ∇k_min · t_min`, gradients from per-triangle linear interpolation.
//! 3. **Zero crossings and linking** (module `crest_crossings`): ridges are maxima
//!    of `k_max` along `t_max` where `k_max > |k_min|`, valleys minima of `k_min` where
//!    `k_min < −|k_max|` (Ohtake, Belyaev & Seidel 2004, eq. 2 and 3); directions are
//!    oriented per edge, triangles that cannot be oriented are skipped, crossings are
//!    linked into polylines. Crossings where `|k| · diagonal` is below
//!    [`CrestOptions::flat_curvature`] (flat and nearly flat regions) or where the
//!    anisotropy `|k_max − k_min| / |k|` is below [`CrestOptions::min_anisotropy`]
//!    (near umbilics) are ignored, and so are traced lines whose mean sharpness
//!    `|∂e/∂t| / |k|³` is below [`CrestOptions::min_sharpness`] (where `k` hardly
//!    varies across the line, its extremality is noise).
//! 4. **Sharp creases** ([`crate::sharp_edges`]): edges with a dihedral angle above
//!    [`CrestOptions::sharp_angle_deg`] that stand out from their neighbourhood
//!    (at least [`CrestOptions::crease_contrast`] times the median angle around their
//!    vertices, so rough scans do not turn into crease networks) are chained; convex
//!    chains are ridges, concave ones valleys. Curvature crossings within
//!    [`CrestOptions::crease_exclusion_rings`] rings of a crease vertex, or
//!    [`CrestOptions::boundary_exclusion_rings`] of a boundary or non-manifold vertex,
//!    are not traced: there the curvature estimate is dominated by the crease (or
//!    one-sided) and its derivative is noise.
//! 5. **Preprocessing** ([`crate::curve_preprocessing`]): fragments of one feature are
//!    joined, lines broken at sharp turns, short pieces (below
//!    [`CurvePreprocessOptions::min_length`]) dropped.
//! 6. **Strength and levels.** The strength of a line is `∫ |k| ds` along it (`k_max`
//!    for ridges, `k_min` for valleys, interpolated at each point from its triangle's
//!    vertices), Yoshizawa et al.'s measure. It is dimensionless, hence invariant to a
//!    uniform scaling of the mesh (equivalently: curvature normalised by the bounding
//!    diagonal, integrated over length normalised by it). A crease turns by its
//!    dihedral angle `θ` within about one edge, so at crease vertices `|k|` is at least
//!    `θ / h` (`h` the mean edge length): a crease of `n` edges at 90° has strength
//!    ≈ `1.6 n`. A line is kept when its strength reaches `levels[0]`; its
//!    [`CrestLine::level`] is the highest `i` with `strength ≥ levels[i]`, so higher
//!    levels are coarser, more salient subsets.
//!
//! # Not implemented
//! The focal-surface curvature estimate and the implicit (MPU) surface fit of the
//! cited papers (the mesh's own tensor estimate is used); crest lines
//! crossing between a crease and the smooth part of the surface are not connected
//! geometrically, only by the endpoint joining of step 5.

use crate::FeaturesError;
use crate::crest_crossings::{CrossingCounts, Family, RawLine, trace_family};
use crate::curve_preprocessing::{CurvePreprocessOptions, preprocess_lines};
use crate::error::check_option;
use crate::extremality::{extremality, vertex_corners};
use crate::mesh_scale::mean_edge_length_of;
use crate::sharp_edges::{salient_creases, sharp_edge_chains};
use fieldtex_core::vec3::{self, V3};
use fieldtex_core::{NoProgress, Progress, Warning};
use fieldtex_mesh::{CurvatureOptions, MeshGeometry, PrincipalCurvatures, Topology, TriMesh};
use serde::Serialize;

/// What a line is the crest of. Ridge and valley assume outward-facing triangles
/// (counter-clockwise seen from outside, as `fieldtex_mesh::repair` orients closed
/// meshes); on an inside-out mesh they swap.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum LineKind {
    /// Maximum of `k_max` (convex), or a convex crease.
    Ridge,
    /// Minimum of `k_min` (concave), or a concave crease.
    Valley,
    /// A curve given by the user (no crest type).
    Given,
}

/// Where a line came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum LineSource {
    /// Zero crossings of an extremality coefficient.
    Curvature,
    /// A chain of sharp edges.
    Crease,
    /// Joined from pieces of both.
    Mixed,
    /// Given by the user.
    User,
}

/// One salient curve: a polyline on the surface.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CrestLine {
    /// `#P × 3` points; a closed line repeats its first point at the end.
    pub points: Vec<V3>,
    /// `#P` triangle containing (or nearest to) each point; empty when unknown
    /// (polylines preprocessed without a mesh).
    pub faces: Vec<u32>,
    pub kind: LineKind,
    pub source: LineSource,
    pub closed: bool,
    /// Polyline length in mesh units.
    pub length: f64,
    /// `∫ |k| ds` along the line (dimensionless; module docs).
    pub strength: f64,
    /// Level of detail: the highest `i` with `strength ≥ levels[i]` (module docs).
    pub level: usize,
}

/// Counters of a detection run.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct CrestStats {
    /// Mean edge length (the unit of the distance options).
    pub mean_edge_length: f64,
    /// Bounding-box diagonal.
    pub diagonal: f64,
    pub ridge_crossings: usize,
    pub valley_crossings: usize,
    /// Triangles skipped because their principal directions cannot be oriented.
    pub inconsistent_triangles: usize,
    /// Traced curvature lines dropped for a low sharpness.
    pub blunt_lines: usize,
    pub sharp_edges: usize,
    pub sharp_chains: usize,
    /// Polylines before preprocessing (curvature + crease).
    pub raw_lines: usize,
    /// Lines left after preprocessing, before the strength threshold.
    pub preprocessed_lines: usize,
    /// Lines dropped for a strength below `levels[0]`.
    pub weak_lines_dropped: usize,
    /// Lines returned.
    pub lines: usize,
}

/// Result of [`crest_lines`].
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct CrestLines {
    /// Lines sorted by decreasing strength.
    pub lines: Vec<CrestLine>,
    pub stats: CrestStats,
    pub warnings: Vec<Warning>,
}

impl CrestLines {
    /// The polylines' points, e.g. for an OBJ writer or the coverage metric.
    pub fn polylines(&self) -> Vec<&[V3]> {
        self.lines.iter().map(|l| l.points.as_slice()).collect()
    }
    /// Owned polylines of the lines at level `≥ level`, strongest first (for
    /// `fieldtex_io::write_obj_polylines`).
    pub fn polylines_at_level(&self, level: usize) -> Vec<Vec<V3>> {
        self.at_level(level).map(|l| l.points.clone()).collect()
    }
    /// Lines at level `≥ level` (coarser subsets as `level` grows).
    pub fn at_level(&self, level: usize) -> impl Iterator<Item = &CrestLine> {
        self.lines.iter().filter(move |l| l.level >= level)
    }
}

/// Options of [`crest_lines`]. Distances are in mean edge lengths, curvatures relative
/// to the bounding-box diagonal, so the defaults suit any scale and resolution.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CrestOptions {
    /// Rings of curvature-tensor averaging before differentiating. Default 2.
    pub curvature_smoothing: usize,
    /// Crossings with `|k| · diagonal` below this are ignored as flat. Default 4.
    pub flat_curvature: f64,
    /// Crossings where `|k_max − k_min| / |k|` is below this are ignored as nearly
    /// umbilic (principal directions unreliable). Default 0.25.
    pub min_anisotropy: f64,
    /// Curvature lines whose mean sharpness `|∂e/∂t| / |k|³` is below this are dropped
    /// (constant curvature across the line: cylinders, tori). Default 0.3 (an
    /// elliptic ridge profile with axis ratio above ~0.95 is dropped).
    pub min_sharpness: f64,
    /// Trace ridges. Default `true`.
    pub ridges: bool,
    /// Trace valleys. Default `true`.
    pub valleys: bool,
    /// Dihedral angle (degrees) above which an edge is a crease. Default 30;
    /// 180 switches crease detection off.
    pub sharp_angle_deg: f64,
    /// A crease edge's dihedral angle must be at least this many times the median
    /// angle of the edges around its vertices (rejects roughness). Default 2; 0 keeps
    /// every edge above `sharp_angle_deg`.
    pub crease_contrast: f64,
    /// Curvature crossings are not traced within this many rings of a crease vertex.
    /// Default 2.
    pub crease_exclusion_rings: usize,
    /// Curvature crossings are not traced within this many rings of a boundary vertex.
    /// Default 1.
    pub boundary_exclusion_rings: usize,
    /// Ascending strength thresholds (`∫|k| ds`); lines below `levels[0]` are dropped.
    /// Default `[3, 9, 27]`. Empty keeps every line at level 0.
    pub levels: Vec<f64>,
    /// Joining, breaking and minimum length; `None` links crossings only (and then
    /// drops nothing by length). Default `Some(CurvePreprocessOptions::default())`.
    pub preprocess: Option<CurvePreprocessOptions>,
}

impl Default for CrestOptions {
    fn default() -> Self {
        Self {
            curvature_smoothing: 2,
            flat_curvature: 4.0,
            min_anisotropy: 0.25,
            min_sharpness: 0.3,
            ridges: true,
            valleys: true,
            sharp_angle_deg: 30.0,
            crease_contrast: 2.0,
            crease_exclusion_rings: 2,
            boundary_exclusion_rings: 1,
            levels: vec![3.0, 9.0, 27.0],
            preprocess: Some(CurvePreprocessOptions::default()),
        }
    }
}

impl CrestOptions {
    /// Checks every field; called by [`crest_lines`].
    pub fn validate(&self) -> Result<(), FeaturesError> {
        check_option("flat_curvature", self.flat_curvature, self.flat_curvature >= 0.0, "≥ 0")?;
        check_option("min_anisotropy", self.min_anisotropy, self.min_anisotropy >= 0.0, "≥ 0")?;
        check_option("min_sharpness", self.min_sharpness, self.min_sharpness >= 0.0, "≥ 0")?;
        check_option(
            "sharp_angle_deg",
            self.sharp_angle_deg,
            (0.0..=180.0).contains(&self.sharp_angle_deg),
            "in [0, 180]",
        )?;
        check_option("crease_contrast", self.crease_contrast, self.crease_contrast >= 0.0, "≥ 0")?;
        for (i, l) in self.levels.iter().enumerate() {
            let prev = if i == 0 { f64::NEG_INFINITY } else { self.levels[i - 1] };
            check_option("levels", *l, *l >= 0.0 && *l >= prev, "≥ 0 and ascending")?;
        }
        if let Some(p) = &self.preprocess {
            p.validate()?;
        }
        Ok(())
    }
}

/// Crest lines of `mesh` with the default progress sink (module docs).
pub fn crest_lines(mesh: &TriMesh, options: &CrestOptions) -> Result<CrestLines, FeaturesError> {
    crest_lines_with_progress(mesh, options, &NoProgress)
}

/// Crest lines of `mesh` (module docs), reporting stages to `progress`.
///
/// Errors: invalid options, a mesh without triangles, out-of-range indices or
/// non-finite positions ([`TriMesh::validate`]), all edges of zero length. Anything else
/// (degenerate or non-manifold triangles, boundaries, flipped faces) degrades to fewer
/// lines and warnings, never to NaN or a panic.
pub fn crest_lines_with_progress(
    mesh: &TriMesh,
    options: &CrestOptions,
    progress: &dyn Progress,
) -> Result<CrestLines, FeaturesError> {
    crest_lines_with_geometry(&MeshGeometry::new(mesh), options, progress)
}

/// [`crest_lines_with_progress`] taking the topology and face normals from a pipeline's
/// [`MeshGeometry`] (computed once per mesh; the same values, so the same lines).
pub fn crest_lines_with_geometry(
    geometry: &MeshGeometry,
    options: &CrestOptions,
    progress: &dyn Progress,
) -> Result<CrestLines, FeaturesError> {
    let mesh = geometry.mesh();
    options.validate()?;
    if mesh.triangles.is_empty() {
        return Err(FeaturesError::EmptyMesh);
    }
    mesh.validate()?;
    progress.stage("crest lines: curvature", 4);
    let topo = geometry.require_topology();
    let h = mean_edge_length_of(mesh, topo)?;
    let diagonal = mesh.bounding_box().map_or(0.0, |b| b.diagonal());
    let mut stats = CrestStats { mean_edge_length: h, diagonal, ..Default::default() };
    let curv_opts = CurvatureOptions {
        smoothing_iterations: options.curvature_smoothing,
        ..Default::default()
    };
    let (curv, mut warnings) = fieldtex_mesh::principal_curvatures(mesh, &curv_opts)?;
    progress.advance(1);

    // Creases.
    let face_normals = geometry.require_face_normals();
    let sharp = if options.sharp_angle_deg < 180.0 {
        salient_creases(
            mesh,
            topo,
            face_normals,
            options.sharp_angle_deg.to_radians(),
            options.crease_contrast,
        )
    } else {
        Vec::new()
    };
    let chains = sharp_edge_chains(topo, &sharp);
    stats.sharp_edges = sharp.len();
    stats.sharp_chains = chains.len();
    let mut raw: Vec<(RawLine, LineKind, LineSource)> = chains
        .iter()
        .map(|c| {
            let points = c.vertices.iter().map(|&v| mesh.positions[v as usize]).collect();
            let mut faces: Vec<u32> = c.edges.iter().map(|&i| sharp[i as usize].face).collect();
            faces.push(*faces.last().unwrap_or(&0));
            let kind = if c.convex { LineKind::Ridge } else { LineKind::Valley };
            (RawLine { points, faces, closed: c.closed }, kind, LineSource::Crease)
        })
        .collect();
    progress.advance(1);

    // Curvature extrema, away from creases and boundaries.
    let face_allowed = traceable_faces(mesh, topo, &sharp, options);
    let corners = vertex_corners(mesh.n_vertices(), &mesh.triangles);
    let flat = if diagonal > 0.0 { options.flat_curvature / diagonal } else { f64::INFINITY };
    let trace = |ridge: bool, raw: &mut Vec<(RawLine, LineKind, LineSource)>| {
        let (k, k_other, t) = if ridge {
            (&curv.k_max, &curv.k_min, &curv.dir_max)
        } else {
            (&curv.k_min, &curv.k_max, &curv.dir_min)
        };
        let e = extremality(mesh, k, t, &curv.normals, (&corners.0, &corners.1));
        let fam = Family {
            k,
            k_other,
            t,
            e: &e,
            ridge,
            flat,
            anisotropy: options.min_anisotropy,
            sharpness: options.min_sharpness,
        };
        let (lines, counts): (_, CrossingCounts) = trace_family(mesh, topo, &fam, &face_allowed);
        let kind = if ridge { LineKind::Ridge } else { LineKind::Valley };
        raw.extend(lines.into_iter().map(|l| (l, kind, LineSource::Curvature)));
        counts
    };
    if options.ridges {
        let c = trace(true, &mut raw);
        stats.ridge_crossings = c.crossings;
        stats.inconsistent_triangles += c.inconsistent_triangles;
        stats.blunt_lines += c.blunt_lines;
    }
    if options.valleys {
        let c = trace(false, &mut raw);
        stats.valley_crossings = c.crossings;
        stats.inconsistent_triangles += c.inconsistent_triangles;
        stats.blunt_lines += c.blunt_lines;
    }
    progress.advance(1);
    stats.raw_lines = raw.len();

    let mut lines: Vec<CrestLine> = raw
        .into_iter()
        .map(|(r, kind, source)| CrestLine {
            length: polyline_length(&r.points),
            points: r.points,
            faces: r.faces,
            kind,
            source,
            closed: r.closed,
            strength: 0.0,
            level: 0,
        })
        .collect();
    if let Some(p) = &options.preprocess {
        lines = preprocess_lines(lines, h, p);
    }
    stats.preprocessed_lines = lines.len();
    let before = lines.len();
    // A crease turns by its dihedral angle θ within about one edge: its curvature is
    // taken as θ / h at its vertices (when larger than the tensor estimate).
    let mut crease_k = vec![0.0; mesh.n_vertices()];
    for s in &sharp {
        for v in topo.edges[s.edge as usize] {
            crease_k[v as usize] = f64::max(crease_k[v as usize], s.angle / h);
        }
    }
    let mut lines = assign_strength_and_levels(mesh, &curv, &crease_k, lines, &options.levels);
    stats.weak_lines_dropped = before - lines.len();
    lines.iter_mut().for_each(|l| l.length = polyline_length(&l.points));
    stats.lines = lines.len();
    progress.advance(1);
    progress.finish_stage();
    if lines.is_empty() {
        warnings.push(Warning::new(
            "no-crest-lines",
            "no crest line passed the thresholds (a sphere-like or very smooth surface); \
             lower `levels[0]` or `flat_curvature`, pass your own curves, or fall back to \
             principal curvature directions",
        ));
    }
    Ok(CrestLines { lines, stats, warnings })
}

/// Triangles where curvature crossings are traced: none of their vertices within the
/// exclusion rings of a crease or boundary vertex.
fn traceable_faces(
    mesh: &TriMesh,
    topo: &Topology,
    sharp: &[crate::sharp_edges::SharpEdge],
    options: &CrestOptions,
) -> Vec<bool> {
    let nv = mesh.n_vertices();
    let neighbors = topo.vertex_neighbors();
    let mut blocked = vec![false; nv];
    let mut grow = |seeds: Vec<bool>, rings: usize| {
        let mut frontier: Vec<usize> = (0..nv).filter(|&v| seeds[v]).collect();
        let mut reached = seeds;
        for _ in 0..rings {
            let mut next = Vec::new();
            for &v in &frontier {
                for &w in neighbors.row(v) {
                    if !reached[w as usize] {
                        reached[w as usize] = true;
                        next.push(w as usize);
                    }
                }
            }
            frontier = next;
        }
        for v in 0..nv {
            blocked[v] |= reached[v];
        }
    };
    let mut crease = vec![false; nv];
    for s in sharp {
        for v in topo.edges[s.edge as usize] {
            crease[v as usize] = true;
        }
    }
    grow(crease, options.crease_exclusion_rings);
    let mut boundary = topo.boundary_vertices();
    for e in 0..topo.n_edges() {
        if topo.is_nonmanifold_edge(e) {
            for v in topo.edges[e] {
                boundary[v as usize] = true;
            }
        }
    }
    grow(boundary, options.boundary_exclusion_rings);
    mesh.triangles.iter().map(|t| t.iter().all(|&v| !blocked[v as usize])).collect()
}

/// Length of a polyline.
pub(crate) fn polyline_length(points: &[V3]) -> f64 {
    points.windows(2).map(|w| vec3::norm(vec3::sub(w[1], w[0]))).sum()
}

/// `|k|` of the line's kind at `p` in triangle `f`, interpolated barycentrically.
fn curvature_at(
    mesh: &TriMesh,
    curv: &PrincipalCurvatures,
    crease_k: &[f64],
    kind: LineKind,
    f: usize,
    p: V3,
) -> f64 {
    let t = mesh.triangles[f].map(|v| v as usize);
    let w = barycentric(mesh.triangle_positions(f), p);
    let k = |v: usize| {
        let k = match kind {
            LineKind::Ridge => curv.k_max[v].abs(),
            LineKind::Valley => curv.k_min[v].abs(),
            LineKind::Given => curv.k_max[v].abs().max(curv.k_min[v].abs()),
        };
        k.max(crease_k.get(v).copied().unwrap_or(0.0))
    };
    w[0] * k(t[0]) + w[1] * k(t[1]) + w[2] * k(t[2])
}

/// Barycentric coordinates of the projection of `p` onto the triangle's plane, clamped
/// to the triangle (renormalised); the centroid for a degenerate triangle.
pub(crate) fn barycentric(tri: [V3; 3], p: V3) -> [f64; 3] {
    let (e1, e2, d) = (vec3::sub(tri[1], tri[0]), vec3::sub(tri[2], tri[0]), vec3::sub(p, tri[0]));
    let (a, b, c) = (vec3::dot(e1, e1), vec3::dot(e1, e2), vec3::dot(e2, e2));
    let (x, y) = (vec3::dot(d, e1), vec3::dot(d, e2));
    let det = a * c - b * b;
    if !(det > 1e-300 && det.is_finite()) {
        return [1.0 / 3.0; 3];
    }
    let v = ((c * x - b * y) / det).max(0.0);
    let w = ((a * y - b * x) / det).max(0.0);
    let u = (1.0 - v - w).max(0.0);
    let s = u + v + w;
    if s > 0.0 && s.is_finite() { [u / s, v / s, w / s] } else { [1.0 / 3.0; 3] }
}

/// Computes every line's strength (`∫|k| ds`, trapezoidal, with `|k|` raised to
/// `crease_k` at crease vertices; empty for none), drops those below `levels[0]`, sets
/// levels and sorts by decreasing strength (stable). Lines without faces get strength
/// 0 and are kept only when `levels` is empty or starts at 0.
pub(crate) fn assign_strength_and_levels(
    mesh: &TriMesh,
    curv: &PrincipalCurvatures,
    crease_k: &[f64],
    lines: Vec<CrestLine>,
    levels: &[f64],
) -> Vec<CrestLine> {
    let mut out: Vec<CrestLine> = lines
        .into_iter()
        .filter_map(|mut l| {
            let mut s = 0.0;
            if l.faces.len() == l.points.len() {
                let ks: Vec<f64> = l
                    .points
                    .iter()
                    .zip(&l.faces)
                    .map(|(&p, &f)| curvature_at(mesh, curv, crease_k, l.kind, f as usize, p))
                    .collect();
                for i in 1..l.points.len() {
                    s += 0.5
                        * (ks[i - 1] + ks[i])
                        * vec3::norm(vec3::sub(l.points[i], l.points[i - 1]));
                }
            }
            l.strength = if s.is_finite() { s } else { 0.0 };
            if levels.first().is_some_and(|&t0| l.strength < t0) {
                return None;
            }
            l.level = levels.iter().rposition(|&t| l.strength >= t).unwrap_or(0);
            Some(l)
        })
        .collect();
    out.sort_by(|a, b| b.strength.total_cmp(&a.strength));
    out
}
