//! Quasi-isometric relaxation of a patch layout (Wang et al. 2005 §5 applied chart by
//! chart): the genus ≥ 2 critical-trajectory patches and the genus-0 protrusion-slit
//! layouts, whose charts the one-image relaxation of [`super::mass_spring`] cannot move
//! as one (it keeps the lattice translations of a single periodic image).
//!
//! Every chart gets its own copy of the vertices it holds (a vertex on a seam has one
//! copy per chart), so the charts become separate pieces of one mesh; [`relax`] then
//! runs on it with one gauge vertex per piece and free chart boundaries, with the same
//! targets, flip-free line search and angle bound as for one image. The relaxed charts
//! are repacked ([`super::translation_patches::shelf_pack`]) and, since the charts no
//! longer differ by translations across their seams, every seam's margin is drawn by
//! [`similarity_ghosts`] instead of translated ghosts.

use super::ComponentMap;
use super::holomorphic_map::GHOST_RINGS;
use super::mass_spring::{MassSpringOptions, MassSpringStats, relax};
use super::periodic_uv::{Lattice, signed_area};
use super::similarity_ghosts::similarity_ghosts;
use super::translation_patches::shelf_pack;
use fieldtex_mesh::TriMesh;
use std::collections::HashMap;

/// Relaxes the first `n_faces` faces of the patch layout `map` on `mesh` (see the module
/// docs); `original` names each vertex's surface point for the seams (two vertices with
/// the same original are the two sides of a slit). Returns the before/after numbers.
pub fn relax_patches(
    mesh: &TriMesh,
    n_faces: usize,
    map: &mut ComponentMap,
    original: &[u32],
    options: &MassSpringOptions,
) -> MassSpringStats {
    let n = n_faces.min(map.corner.len()).min(mesh.n_triangles());
    let (split, base) = split_by_chart(mesh, n, map);
    let mut pieces = ComponentMap {
        corner: map.corner[..n].to_vec(),
        base,
        apex: vec![None; n],
        lattice: Lattice { a: None, b: None },
        ..ComponentMap::empty(map.method)
    };
    let stats = relax(&split, n, &mut pieces, options);
    repack_with_similarity_ghosts(mesh, n, map, original, pieces.corner);
    stats
}

/// The first `n` faces of `map` as a mesh of their own in which every chart has its own
/// copy of each vertex it holds, one per distinct position (a vertex on a seam gets one
/// copy per side, also where a chart meets itself), and each copy's position in the
/// layout. Its connected pieces are the layout's charts.
pub(crate) fn split_by_chart(
    mesh: &TriMesh,
    n: usize,
    map: &ComponentMap,
) -> (TriMesh, Vec<[f64; 2]>) {
    let chart = |f: usize| map.patch.get(f).copied().unwrap_or(0);
    let extent = map.corner[..n]
        .iter()
        .flatten()
        .fold(0.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs()))
        .max(1e-300);
    let q = |x: f64| (x / (1e-9 * extent)).round() as i64;
    let mut id: HashMap<(u32, u32, i64, i64), u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut base = Vec::new();
    let mut triangles = Vec::with_capacity(n);
    for f in 0..n {
        let t: [u32; 3] = std::array::from_fn(|k| {
            let v = mesh.triangles[f][k];
            let p = map.corner[f][k];
            let next = positions.len() as u32;
            *id.entry((v, chart(f), q(p[0]), q(p[1]))).or_insert_with(|| {
                positions.push(mesh.positions[v as usize]);
                base.push(p);
                next
            })
        });
        triangles.push(t);
    }
    (TriMesh::new(positions, triangles), base)
}

/// Writes the moved chart corners `moved` (first `n` faces) into `map`, repacks the
/// charts and draws every seam's margin by similarity ghosts: after a chart-by-chart
/// change the charts no longer differ by translations across their seams, and the map
/// is no longer periodic.
pub(super) fn repack_with_similarity_ghosts(
    mesh: &TriMesh,
    n: usize,
    map: &mut ComponentMap,
    original: &[u32],
    mut moved: Vec<[[f64; 2]; 3]>,
) {
    let chart = |f: usize| map.patch.get(f).copied().unwrap_or(0);
    // Repack with the layout's gap (its mean edge length in the plane, as the patches
    // were packed) and draw every seam's margin by similarity.
    let (mut len, mut count) = (0.0, 0usize);
    for c in &moved {
        for k in 0..3 {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            len += ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            count += 1;
        }
    }
    let mean_len = len / count.max(1) as f64;
    let keep: Vec<bool> =
        (0..n).map(|f| chart(f) != u32::MAX && signed_area(&moved[f]).is_finite()).collect();
    let n_charts = (0..n).filter(|&f| keep[f]).map(|f| chart(f) as usize + 1).max().unwrap_or(0);
    let patch: Vec<u32> = (0..n).map(chart).collect();
    shelf_pack(&mut moved, &patch, &keep, n_charts, (2.0 * GHOST_RINGS as f64 + 1.0) * mean_len);
    map.corner[..n].copy_from_slice(&moved);
    map.lattice = Lattice { a: None, b: None };
    map.ghosts = similarity_ghosts(&mesh.triangles, original, &map.corner, n, GHOST_RINGS, None);
}
