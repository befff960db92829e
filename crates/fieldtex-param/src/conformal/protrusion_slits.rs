//! Genus-0 surfaces with protrusions: one slit at the tip of every protrusion, then the
//! double cover. This is our construction for the case paper C (Wang, Gu, Mueller & Yau
//! 2005) leaves open; issue 13 asks for "a few short slits at extremal points, then
//! proceed as for a surface with boundary".
//!
//! The two-point slit cylinder ([`super::slit_cylinder`]) maps a genus-0 surface onto one
//! cylinder whose ends are two extremal points. A protrusion that holds neither end (a
//! leg, an ear, a tail) is a finger on the cylinder's side, and a conformal map shrinks a
//! finger of length `ℓ` and circumference `c` by about `e^(−2πℓ/c)` in length: on the
//! horse the texel scale spans eight orders of magnitude. Opening every protrusion at its
//! tip makes the surface a sphere with `k` holes; its double cover (paper §3,
//! [`super::double_cover`]) is closed of genus `k − 1`, each protrusion becomes a tube
//! between the two copies, and the holomorphic forms run along a tube at one scale.
//!
//! 1. **Protrusions** ([`compressed_tips`]): on the slit-cylinder map, the faces whose
//!    area scale `A_uv / A_3d` lies below the area-weighted median by a factor of more than
//!    `e^COMPRESSION` form edge-connected regions; a region of at least
//!    [`MIN_REGION_AREA`] of the surface is a protrusion, its tip the most compressed face's
//!    first vertex. The cylinder's two slit points are candidates too.
//! 2. **Slit size** ([`cap_rim`]): around a candidate tip, the length `C(r)` of the
//!    geodesic circle of radius `r` (edge-graph distances from the tip, level sets
//!    interpolated linearly on the triangles) is compared with `4r`; the first `r` with
//!    `C(r) ≤ 4r` is the rim of the tip's cap (on a round tip of radius `R` its equator:
//!    `r = πR/2`, `C = 2πR`; on a flat or saddle neighbourhood `C(r) ≥ 2πr` and there is
//!    no rim). A candidate without a rim within [`MAX_CAP_RADIUS`] `√area` is no tip.
//! 3. **Slit path** ([`slit_path`]): the slit's half-length is `C/4`, so the hole it opens
//!    (its boundary is the slit twice) is as long as the rim and the doubled protrusion
//!    keeps its width instead of becoming a thin neck (a doubled point-sized hole is a thin
//!    handle whose conformal factor is extreme). Its two ends are the points of the
//!    geodesic circle of radius `C/4` farthest apart; it follows the shortest-path tree
//!    from each end back to where the two paths meet, next to the tip.
//! 4. **Cut** ([`cut_along_paths`]): every inner slit vertex gets a copy that takes the
//!    faces on the left of the slit, so each slit becomes one boundary loop.
//!
//! The caller doubles the cut mesh and keeps the first copy's map.

use super::ComponentMap;
use super::double_cover::{DoubleCover, double_cover};
use super::holomorphic_map::{GHOST_RINGS, LayoutOptions, holomorphic_map_with};
use super::homology_loops::{edge_lengths, shortest_path_tree};
use super::mass_spring::map_distortion;
use super::periodic_uv::signed_area;
use super::similarity_ghosts::similarity_ghosts;
use super::slit_cylinder::slit_cylinder;
use super::translation_patches::Ghost;
use super::tree_cotree::vertex_edges;
use crate::ParamError;
use fieldtex_core::vec3;
use fieldtex_mesh::{Topology, TriMesh, UnionFind};
use serde::Serialize;
use std::collections::{HashMap, HashSet};

/// A face is compressed when its area scale is below the median's by more than
/// `e^COMPRESSION` (here 144: a length scale below 1/12, the largest enlargement the
/// multi-scale quilting's exemplar levels offer, so texture there cannot keep its size).
pub const COMPRESSION: f64 = 4.97;
/// Smallest compressed region that counts as a protrusion, as a share of the surface.
pub const MIN_REGION_AREA: f64 = 0.002;
/// Largest cap rim radius searched, in units of `√area`.
pub const MAX_CAP_RADIUS: f64 = 0.3;
/// Most slits (protrusions) per component.
pub const MAX_SLITS: usize = 12;
/// Radii sampled up to the largest cap radius.
const RADIUS_SAMPLES: usize = 96;

/// The slit-open surface (see the module docs).
#[derive(Debug, Clone)]
pub struct ProtrusionSlits {
    /// Per vertex of the cut mesh (the input's vertices, then one copy per inner slit
    /// vertex; [`cut_along_paths`]; the double cover's first copy): the input vertex it
    /// is or copies.
    pub original: Vec<u32>,
    /// Per slit: the tip it opens and its vertex path (input ids).
    pub tips: Vec<u32>,
    pub paths: Vec<Vec<u32>>,
}

/// Protrusion tips of a closed genus-0 `mesh` (its first `n_keep` faces the input's)
/// from its slit-cylinder map: `(tip vertex, log area scale below the median)`, most
/// compressed first.
pub fn compressed_tips(mesh: &TriMesh, n_keep: usize, map: &ComponentMap) -> Vec<(u32, f64)> {
    let nf = n_keep.min(map.corner.len()).min(mesh.n_triangles());
    let mut scale = vec![f64::NAN; nf];
    let mut area = vec![0.0; nf];
    let mut rows = Vec::with_capacity(nf);
    for f in 0..nf {
        let p = mesh.triangle_positions(f);
        let a3 = 0.5 * vec3::norm(vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0])));
        area[f] = a3;
        if map.apex.get(f).is_some_and(|a| a.is_some()) {
            continue;
        }
        let auv = signed_area(&map.corner[f]);
        if a3 > 0.0 && auv > 0.0 && auv.is_finite() {
            scale[f] = (auv / a3).ln();
            rows.push((scale[f], a3));
        }
    }
    let total: f64 = area.iter().sum();
    if rows.is_empty() || total.is_nan() || total <= 0.0 {
        return Vec::new();
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    let half = 0.5 * rows.iter().map(|r| r.1).sum::<f64>();
    let mut acc = 0.0;
    let mut median = rows[rows.len() - 1].0;
    for r in &rows {
        acc += r.1;
        if acc >= half {
            median = r.0;
            break;
        }
    }
    let compressed: Vec<bool> = scale.iter().map(|&s| s < median - COMPRESSION).collect();
    let topo = Topology::build(mesh.n_vertices(), &mesh.triangles[..nf]);
    let mut regions = UnionFind::new(nf);
    for e in 0..topo.n_edges() {
        if let [f, g] = topo.edge_faces(e)
            && compressed[*f as usize]
            && compressed[*g as usize]
        {
            regions.union(*f as usize, *g as usize);
        }
    }
    // Per region root: (area, most compressed face).
    let mut by_root: HashMap<usize, (f64, usize)> = HashMap::new();
    for f in (0..nf).filter(|&f| compressed[f]) {
        let r = regions.find(f);
        let entry = by_root.entry(r).or_insert((0.0, f));
        entry.0 += area[f];
        if scale[f] < scale[entry.1] {
            entry.1 = f;
        }
    }
    let mut tips: Vec<(u32, f64)> = by_root
        .values()
        .filter(|(a, _)| *a >= MIN_REGION_AREA * total)
        .map(|&(_, f)| (mesh.triangles[f][0], scale[f] - median))
        .collect();
    tips.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    tips
}

/// Distances from a tip and its cap rim (see the module docs).
pub struct CapRim {
    /// Rim radius and circumference.
    pub radius: f64,
    pub circumference: f64,
    /// Per vertex: edge-graph distance from the tip (exact within the largest searched
    /// radius) and the shortest-path tree edge to its parent.
    pub dist: Vec<f64>,
    pub parent: Vec<u32>,
}

/// The rim of the cap around `tip`, or `None` when there is none within `max_radius`
/// (see the module docs).
pub fn cap_rim(
    mesh: &TriMesh,
    topo: &Topology,
    vertex_edges: &[Vec<u32>],
    lengths: &[f64],
    tip: usize,
    max_radius: f64,
) -> Option<CapRim> {
    let (dist, parent) = shortest_path_tree(topo, vertex_edges, lengths, tip, max_radius);
    let local: f64 = vertex_edges[tip].iter().map(|&e| lengths[e as usize]).sum::<f64>()
        / vertex_edges[tip].len().max(1) as f64;
    let step = max_radius / RADIUS_SAMPLES as f64;
    let mut circ = vec![0.0; RADIUS_SAMPLES];
    let mut seen = vec![false; mesh.n_triangles()];
    for v in (0..dist.len()).filter(|&v| dist[v] <= max_radius) {
        for &f in topo.vertex_faces(v) {
            let f = f as usize;
            if std::mem::replace(&mut seen[f], true) {
                continue;
            }
            let t = mesh.triangles[f];
            let d = t.map(|v| dist[v as usize]);
            if d.iter().any(|x| !x.is_finite()) {
                continue;
            }
            let p = t.map(|v| mesh.positions[v as usize]);
            let (lo, hi) = (d[0].min(d[1]).min(d[2]), d[0].max(d[1]).max(d[2]));
            let first = ((lo / step).floor() as usize).min(RADIUS_SAMPLES);
            for (i, c) in circ.iter_mut().enumerate().skip(first) {
                let r = (i + 1) as f64 * step;
                if r >= hi {
                    break;
                }
                if r <= lo {
                    continue;
                }
                // The level set crosses two of the three edges (a < r ≤ b or b < r ≤ a).
                let mut pts = [[0.0; 3]; 2];
                let mut n = 0;
                for k in 0..3 {
                    let (a, b) = (d[k], d[(k + 1) % 3]);
                    if (a < r && r <= b) || (b < r && r <= a) {
                        if n < 2 {
                            let s = (r - a) / (b - a);
                            pts[n] =
                                vec3::add(p[k], vec3::scale(vec3::sub(p[(k + 1) % 3], p[k]), s));
                        }
                        n += 1;
                    }
                }
                if n == 2 {
                    *c += vec3::norm(vec3::sub(pts[1], pts[0]));
                }
            }
        }
    }
    let i = (0..RADIUS_SAMPLES).find(|&i| {
        let r = (i + 1) as f64 * step;
        r >= 2.0 * local && circ[i] > 0.0 && circ[i] <= 4.0 * r
    })?;
    Some(CapRim { radius: (i + 1) as f64 * step, circumference: circ[i], dist, parent })
}

/// The slit through a tip's cap (see the module docs): a simple vertex path of at least
/// two edges whose ends lie at distance `half_length` from the tip, or `None`.
pub fn slit_path(
    mesh: &TriMesh,
    topo: &Topology,
    rim: &CapRim,
    half_length: f64,
) -> Option<Vec<u32>> {
    let up = |v: usize| -> Option<usize> {
        let e = *rim.parent.get(v)?;
        (e != u32::MAX).then(|| {
            let ed = topo.edges[e as usize];
            if ed[0] as usize == v { ed[1] as usize } else { ed[0] as usize }
        })
    };
    let frontier: Vec<usize> = (0..rim.dist.len())
        .filter(|&v| {
            rim.dist[v].is_finite()
                && rim.dist[v] >= half_length
                && up(v).is_some_and(|w| rim.dist[w] < half_length)
        })
        .collect();
    if frontier.len() < 2 {
        return None;
    }
    let centre = vec3::scale(
        frontier.iter().fold([0.0; 3], |c, &v| vec3::add(c, mesh.positions[v])),
        1.0 / frontier.len() as f64,
    );
    let farthest = |from: [f64; 3]| {
        frontier
            .iter()
            .copied()
            .max_by(|&a, &b| {
                vec3::norm2(vec3::sub(mesh.positions[a], from))
                    .total_cmp(&vec3::norm2(vec3::sub(mesh.positions[b], from)))
                    .then(b.cmp(&a))
            })
            .unwrap_or(frontier[0])
    };
    let e1 = farthest(centre);
    let e2 = farthest(mesh.positions[e1]);
    let to_root = |mut v: usize| {
        let mut path = vec![v as u32];
        while let Some(w) = up(v) {
            path.push(w as u32);
            v = w;
        }
        path
    };
    let (p1, p2) = (to_root(e1), to_root(e2));
    let on_p2: HashMap<u32, usize> = p2.iter().enumerate().map(|(i, &v)| (v, i)).collect();
    let (i1, &i2) = p1.iter().enumerate().find_map(|(i, v)| on_p2.get(v).map(|j| (i, j)))?;
    let mut path: Vec<u32> = p1[..=i1].to_vec();
    path.extend(p2[..i2].iter().rev());
    (path.len() >= 3).then_some(path)
}

/// Cuts `mesh` open along vertex `paths` (simple, pairwise disjoint, through interior
/// vertices of a closed manifold mesh): see [`ProtrusionSlits::mesh`]. `None` when a
/// path leaves the mesh's edges.
pub fn cut_along_paths(mesh: &TriMesh, paths: &[Vec<u32>]) -> Option<(TriMesh, Vec<u32>)> {
    let mut half: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * mesh.n_triangles());
    for (f, t) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            half.insert((t[k], t[(k + 1) % 3]), f as u32);
        }
    }
    let mut positions = mesh.positions.clone();
    let mut original: Vec<u32> = (0..mesh.n_vertices() as u32).collect();
    let mut triangles = mesh.triangles.clone();
    for path in paths {
        for i in 1..path.len().saturating_sub(1) {
            let (prev, v, next) = (path[i - 1], path[i], path[i + 1]);
            let copy = positions.len() as u32;
            positions.push(mesh.positions[v as usize]);
            original.push(v);
            // Sweep the faces left of the path at `v`: from the face holding v → next,
            // across the edge before `v` in each face, to the face holding prev → v.
            let mut f = *half.get(&(v, next))?;
            let mut steps = 0;
            loop {
                let t = mesh.triangles[f as usize];
                let k = (0..3).find(|&k| t[k] == v)?;
                triangles[f as usize][k] = copy;
                let before = t[(k + 2) % 3];
                if before == prev {
                    break;
                }
                f = *half.get(&(v, before))?;
                steps += 1;
                if steps > 4096 {
                    return None;
                }
            }
        }
    }
    Some((TriMesh::new(positions, triangles), original))
}

/// The tips that qualify (see the module docs), their slit paths and rim lengths, on a
/// closed genus-0 `mesh` (first `n_keep` faces the input's; no slit touches the others)
/// whose slit-cylinder map is `cylinder`. Empty when no face is compressed.
pub fn protrusion_tips(
    mesh: &TriMesh,
    n_keep: usize,
    cylinder: &ComponentMap,
) -> (Vec<u32>, Vec<Vec<u32>>, Vec<f64>) {
    let (mut tips, mut paths, mut rims) = (Vec::new(), Vec::new(), Vec::new());
    let compressed = compressed_tips(mesh, n_keep, cylinder);
    if compressed.is_empty() {
        return (tips, paths, rims);
    }
    let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
    let lengths = edge_lengths(&mesh.positions, &topo);
    let vertex_edges = vertex_edges(&topo);
    let scale = fieldtex_mesh::areas::total_area(mesh).sqrt();
    let mut candidates: Vec<u32> = cylinder.slit_vertices.clone();
    candidates.extend(compressed.iter().map(|c| c.0));
    // Vertices of added faces (hole caps) take no slit.
    let mut used = vec![false; mesh.n_vertices()];
    for t in &mesh.triangles[n_keep.min(mesh.n_triangles())..] {
        for &v in t {
            used[v as usize] = true;
        }
    }
    for &tip in &candidates {
        if tips.len() >= MAX_SLITS || used[tip as usize] {
            continue;
        }
        let Some(rim) =
            cap_rim(mesh, &topo, &vertex_edges, &lengths, tip as usize, MAX_CAP_RADIUS * scale)
        else {
            continue;
        };
        let Some(path) = slit_path(mesh, &topo, &rim, 0.25 * rim.circumference) else {
            continue;
        };
        // Slits stay apart: no vertex of this one within one ring of an earlier one.
        if path.iter().any(|&v| used[v as usize]) {
            continue;
        }
        for &v in &path {
            for &e in &vertex_edges[v as usize] {
                for w in topo.edges[e as usize] {
                    used[w as usize] = true;
                }
            }
        }
        tips.push(tip);
        paths.push(path);
        rims.push(rim.circumference);
    }
    (tips, paths, rims)
}

/// Ghost faces across the slits, for the geometry image's margins: in the double cover
/// each side of a slit continues into the second copy, which gets no texture, and the
/// two sides' charts differ by a similarity, so without them the two sides would be
/// synthesised independently ([`similarity_ghosts`] over the slit edges). `triangles`
/// and `corner` are the cut mesh's first `n_keep` faces and their packed UVs,
/// `original` maps cut-mesh vertices to the input vertices the `paths` name.
pub fn slit_ghosts(
    triangles: &[[u32; 3]],
    original: &[u32],
    paths: &[Vec<u32>],
    corner: &[[[f64; 2]; 3]],
    n_keep: usize,
    rings: usize,
) -> Vec<Ghost> {
    let slit: HashSet<(u32, u32)> =
        paths.iter().flat_map(|p| p.windows(2).map(|w| (w[0].min(w[1]), w[0].max(w[1])))).collect();
    similarity_ghosts(triangles, original, corner, n_keep, rings, Some(&slit))
}

/// What [`protrusion_map`] chose for a component.
pub enum ProtrusionChoice {
    /// The plain map (genus 0: the slit cylinder; `Some([log-area std, that of the two
    /// extremal points' cylinder])` when its ends were moved to the only two protrusion
    /// tips).
    Cylinder(Box<ComponentMap>, Option<[f64; 2]>),
    /// Slits at three or more protrusion tips, the double cover of the cut mesh and its
    /// map with the log-area std of its first copy and of the cylinder's.
    Slits { cut: Box<ProtrusionSlits>, cover: Box<DoubleCover>, map: Box<(ComponentMap, f64, f64)> },
}

/// The protrusion slits of a component as the report gives them: tips (global vertex
/// ids) and the log-area std (over the input's faces) of the map chosen and of the
/// two-point slit cylinder.
#[derive(Debug, Clone, Serialize)]
pub struct ProtrusionSummary {
    pub tips: Vec<u32>,
    /// Per slit: its vertex path (global ids; empty when the cylinder's ends moved).
    pub slit_paths: Vec<Vec<u32>>,
    pub log_area_std: f64,
    pub cylinder_log_area_std: f64,
}

/// Log-area std of a map over the first `n_keep` faces ([`map_distortion`]).
fn area_spread(mesh: &TriMesh, n_keep: usize, map: &ComponentMap) -> f64 {
    let slit = |f: usize| map.apex.get(f).is_some_and(|a| a.is_some());
    let d = map_distortion(mesh, n_keep.min(map.corner.len()), &map.corner, &slit);
    if d.flipped > 0 { f64::INFINITY } else { d.log_area_std }
}

/// The map of a component of genus `genus`, `mesh` its capped surface (first `n_keep`
/// faces the input's) and `ends` the cap centres of the (at most two, genus 0 only)
/// large holes that the slit cylinder takes as its ends: the plain map (the slit
/// cylinder for genus 0, [`holomorphic_map`] otherwise), or — when it leaves protrusions
/// compressed and the alternative spreads the area scale less — for genus 0 the cylinder
/// between the only two openings (holes and protrusion tips), or the double cover of the
/// surface with those holes open and slits at the protrusion tips (genus `2g + openings
/// − 1`) when that is at least 2 (see the module docs).
pub fn protrusion_map(
    mesh: &TriMesh,
    n_keep: usize,
    genus: usize,
    ends: [Option<usize>; 2],
    layout: &LayoutOptions,
) -> Result<ProtrusionChoice, ParamError> {
    let cylinder = if genus == 0 {
        slit_cylinder(mesh, ends)?
    } else {
        holomorphic_map_with(mesh, genus, n_keep, layout)?
    };
    let (tips, paths, _) = protrusion_tips(mesh, n_keep, &cylinder);
    let holes: Vec<usize> = ends.iter().flatten().copied().collect();
    let openings: Vec<usize> =
        holes.iter().copied().chain(tips.iter().map(|&t| t as usize)).collect();
    let cover_genus = (2 * genus + openings.len()).saturating_sub(1);
    if tips.is_empty() || openings.len() < 2 && genus == 0 {
        return Ok(ProtrusionChoice::Cylinder(Box::new(cylinder), None));
    }
    let before = area_spread(mesh, n_keep, &cylinder);
    if genus == 0 && openings.len() == 2 {
        let mut same: Vec<usize> = cylinder.slit_vertices.iter().map(|&v| v as usize).collect();
        same.sort_unstable();
        if same == [openings[0].min(openings[1]), openings[0].max(openings[1])] {
            return Ok(ProtrusionChoice::Cylinder(Box::new(cylinder), None));
        }
        return Ok(match slit_cylinder(mesh, [Some(openings[0]), Some(openings[1])]) {
            Ok(moved) => {
                let after = area_spread(mesh, n_keep, &moved);
                if after < before {
                    ProtrusionChoice::Cylinder(Box::new(moved), Some([after, before]))
                } else {
                    ProtrusionChoice::Cylinder(Box::new(cylinder), None)
                }
            }
            Err(_) => ProtrusionChoice::Cylinder(Box::new(cylinder), None),
        });
    }
    // The large holes open (their caps dropped; every cap face comes after the input's),
    // then the slits cut.
    let open = TriMesh::new(
        mesh.positions.clone(),
        mesh.triangles
            .iter()
            .copied()
            .filter(|t| !t.iter().any(|&v| holes.contains(&(v as usize))))
            .collect(),
    );
    let Some((cut_mesh, original)) = cut_along_paths(&open, &paths) else {
        return Ok(ProtrusionChoice::Cylinder(Box::new(cylinder), None));
    };
    let cover = double_cover(&cut_mesh);
    match holomorphic_map_with(&cover.mesh, cover_genus, n_keep, layout) {
        Ok(mut map) => {
            map.ghosts.extend(slit_ghosts(
                &cover.mesh.triangles,
                &original,
                &paths,
                &map.corner,
                n_keep,
                GHOST_RINGS,
            ));
            // The slits' vertices, both sides: the "away from slits" statistics skip
            // their neighbourhoods as they skip the point slits of a cylinder.
            let on_path: HashSet<u32> = paths.iter().flatten().copied().collect();
            map.slit_vertices = (0..original.len() as u32)
                .filter(|&v| on_path.contains(&original[v as usize]))
                .collect();
            let after = area_spread(&cover.mesh, n_keep, &map);
            if after < before {
                let cut = ProtrusionSlits { original, tips, paths };
                Ok(ProtrusionChoice::Slits {
                    cut: Box::new(cut),
                    cover: Box::new(cover),
                    map: Box::new((map, after, before)),
                })
            } else {
                Ok(ProtrusionChoice::Cylinder(Box::new(cylinder), None))
            }
        }
        Err(_) => Ok(ProtrusionChoice::Cylinder(Box::new(cylinder), None)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_mesh::primitives;

    #[test]
    fn cut_path_opens_one_boundary_loop() {
        let sphere = primitives::icosphere(4);
        let topo = Topology::build(sphere.n_vertices(), &sphere.triangles);
        let lengths = edge_lengths(&sphere.positions, &topo);
        let ve = vertex_edges(&topo);
        let rim = cap_rim(&sphere, &topo, &ve, &lengths, 0, 3.0).expect("a sphere has a rim");
        // A unit sphere's cap rim is its equator: r = π/2, C = 2π (edge-graph distances
        // and a polygonal circle: a few per cent off).
        assert!((rim.radius - std::f64::consts::FRAC_PI_2).abs() < 0.2, "r {}", rim.radius);
        assert!((rim.circumference / std::f64::consts::TAU - 1.0).abs() < 0.1);
        let path = slit_path(&sphere, &topo, &rim, 0.5).expect("a slit");
        let (cut, original) = cut_along_paths(&sphere, std::slice::from_ref(&path)).unwrap();
        assert_eq!(cut.n_vertices(), sphere.n_vertices() + path.len() - 2);
        assert_eq!(original.len(), cut.n_vertices());
        let ct = Topology::build(cut.n_vertices(), &cut.triangles);
        let loops = ct.boundary_loops(&cut.triangles);
        assert_eq!(loops.len(), 1);
        assert_eq!(loops[0].len(), 2 * (path.len() - 1));
        assert!((0..ct.n_edges()).all(|e| ct.edge_faces(e).len() <= 2));
    }

    #[test]
    fn a_flat_neighbourhood_has_no_rim() {
        let grid = primitives::grid(40, 40, 1.0, 1.0);
        let topo = Topology::build(grid.n_vertices(), &grid.triangles);
        let lengths = edge_lengths(&grid.positions, &topo);
        let ve = vertex_edges(&topo);
        let centre = 20 * 41 + 20;
        assert!(cap_rim(&grid, &topo, &ve, &lengths, centre, 0.4).is_none());
    }
}
