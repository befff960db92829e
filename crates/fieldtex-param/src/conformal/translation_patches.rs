//! Patches of a surface cut along critical trajectories, each mapped into the plane by
//! integrating the holomorphic 1-form (Wang, Gu, Mueller & Yau 2005 §3: "each segment is
//! conformally parameterized to a planar rectangle").
//!
//! Patches grow breadth-first over faces from the lowest unassigned face, never across a
//! cut edge; a face joins by developing its third corner from the shared edge with the
//! form (`uv_c = uv_a + ∫_a^c φ`). Because the same form is integrated everywhere, two
//! charts of one surface point differ by a pure translation, so the texture keeps one
//! orientation over the whole surface and partners across a cut are found by a shift.
//!
//! A developed patch must not overlap itself. Exactly cut, the regions between
//! critical horizontal trajectories are rectangles and strips, but the traced cuts stop
//! at a length budget and are snapped to edges (see [`super::critical_trajectories`]),
//! so a face also stays out when it would be flipped or would overlap a face already in
//! the patch (separating-axis test on a hash grid); it then seeds a later patch. This
//! guarantees an injective map per patch; the number of extra (small) patches it makes
//! is reported. A face whose own development is folded (non-positive area: the
//! discrete form is not exactly holomorphic next to zero points) gets a one-face chart
//! of its isometric layout at the form's mean scale, also counted. The patches are then
//! merged into maximal injective charts and their seams shortened face by face
//! ([`super::patch_merging`]).
//!
//! Patches longer than a piece side are cut into pieces (by face centroid) and all
//! pieces are packed without rotation (rotation would break the translation
//! structure) on shelves, tallest first, `gap` apart. Where the two faces of an edge lie
//! in different charts (different patches, or a patch that closed around a handle) the
//! edge is a seam; the faces within `rings` edge steps of a seam on its far side are
//! listed as [`Ghost`]s: drawn shifted beside the near side they fill the image margin
//! with the continuation of the surface, for boundary consistency (§4.2).

use super::patch_merging::{LayoutFaces, merge_patches, shorten_seams};
use super::periodic_uv::{along2, signed_area};
use fieldtex_core::vec3;
use fieldtex_mesh::Topology;
use std::collections::{HashMap, HashSet, VecDeque};

/// Sweeps of [`shorten_seams`] after merging.
pub const SEAM_ROUNDS: usize = 8;

/// A face drawn beside another patch to continue its chart across a seam. Across a
/// cut between translation charts its corners are `corner[face] − shift` and a point
/// `p` of the ghost shows the surface point at `p + shift` in the packed layout; across
/// a protrusion slit ([`super::protrusion_slits::slit_ghosts`]) the two charts differ
/// by a similarity, `corners` gives the ghost's corners and a point of the ghost shows
/// the point with the same barycentric coordinates in `corner[face]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ghost {
    pub face: u32,
    pub shift: [f64; 2],
    pub corners: Option<[[f64; 2]; 3]>,
}

/// Layout parameters of [`translation_patches`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchOptions {
    /// Face rings drawn as ghosts beyond each cut (the image margins).
    pub rings: usize,
    /// Largest piece side, in units of `√(total UV area)`.
    pub piece_side: f64,
    /// Merge patches into maximal injective charts ([`super::patch_merging`]).
    pub merge: bool,
}

/// The packed patch layout.
#[derive(Debug, Clone)]
pub struct PatchLayout {
    /// Per face: corner positions in the packed plane.
    pub corner: Vec<[[f64; 2]; 3]>,
    /// Per face: patch id.
    pub patch: Vec<u32>,
    pub n_patches: usize,
    /// Patches that hold fewer than 1 % of the faces (made by the overlap guard).
    pub small_patches: usize,
    /// Faces the discrete form folds (non-positive area) left on one-face charts (not
    /// attached to a neighbouring patch by [`super::patch_merging`]).
    pub folded: usize,
    /// Patch merges performed by [`super::patch_merging`].
    pub merges: usize,
    /// Edges whose two faces are in different charts.
    pub seam_edges: Vec<u32>,
    pub ghosts: Vec<Ghost>,
}

/// Builds the patches of the faces with `keep` of the mesh cut along `cut` (per edge),
/// see the module docs; other faces get NaN corners and patch `u32::MAX`. `d` is the
/// form per edge (low → high); pieces are at most `piece_side · √(total UV area)` wide
/// and tall.
pub fn translation_patches(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    topology: &Topology,
    d: &[[f64; 2]],
    cut: &[bool],
    keep: &[bool],
    options: PatchOptions,
) -> PatchLayout {
    let PatchOptions { rings, piece_side, merge } = options;
    let nf = triangles.len();
    let ne = topology.n_edges();
    let mean_len = (d.iter().map(|v| (v[0] * v[0] + v[1] * v[1]).sqrt()).sum::<f64>()
        / ne.max(1) as f64)
        .max(1e-300);
    let cell = mean_len;
    // Form length per surface length, for the faces the discrete form folds.
    let (mut l3, mut n3) = (0.0, 0usize);
    for e in &topology.edges {
        l3 += vec3::norm(vec3::sub(positions[e[1] as usize], positions[e[0] as usize]));
        n3 += 1;
    }
    let form_scale = mean_len / (l3 / n3.max(1) as f64).max(1e-300);
    let mut folded = 0usize;
    let mut is_folded = vec![false; nf];
    let mut corner = vec![[[f64::NAN; 2]; 3]; nf];
    let mut patch = vec![u32::MAX; nf];
    let mut n_patches = 0u32;
    let key = |p: [f64; 2]| ((p[0] / cell).floor() as i64, (p[1] / cell).floor() as i64);
    for seed in 0..nf {
        if patch[seed] != u32::MAX || !keep[seed] {
            continue;
        }
        let pid = n_patches;
        n_patches += 1;
        let mut grid: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
        let c0 = [0.0, 0.0];
        let d1 = along2(topology, d, seed, 0, 1);
        let d2 = along2(topology, d, seed, 0, 2);
        corner[seed] = [c0, d1, d2];
        if signed_area(&corner[seed]) <= 0.0 {
            // The discrete form folds this face (next to a zero point): it gets its own
            // chart, the triangle laid out isometrically at the form's mean scale.
            folded += 1;
            is_folded[seed] = true;
            let p = triangles[seed].map(|v| positions[v as usize]);
            let (e1, e2) = (vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0]));
            let l1 = vec3::norm(e1);
            let x = if l1 > 0.0 { vec3::dot(e2, e1) / l1 } else { 0.0 };
            let y = vec3::norm(vec3::cross(e1, e2)) / l1.max(1e-300);
            corner[seed] = [c0, [form_scale * l1, 0.0], [form_scale * x, form_scale * y]];
        }
        patch[seed] = pid;
        insert(&mut grid, &key, seed as u32, &corner[seed]);
        let mut queue = VecDeque::from([seed]);
        while let Some(f) = queue.pop_front() {
            for k in 0..3 {
                let e = topology.face_edges[f][k] as usize;
                if cut[e] {
                    continue;
                }
                let Some(&g) = topology.edge_faces(e).iter().find(|&&g| g as usize != f) else {
                    continue;
                };
                let g = g as usize;
                if patch[g] != u32::MAX || !keep[g] {
                    continue;
                }
                let (a, b) = (triangles[f][k], triangles[f][(k + 1) % 3]);
                let ga = (0..3).find(|&j| triangles[g][j] == a).unwrap_or(0);
                let gb = (0..3).find(|&j| triangles[g][j] == b).unwrap_or(0);
                let gc = 3 - ga - gb;
                let mut cg = [[0.0; 2]; 3];
                cg[ga] = corner[f][k];
                cg[gb] = corner[f][(k + 1) % 3];
                let dc = along2(topology, d, g, ga, gc);
                cg[gc] = [cg[ga][0] + dc[0], cg[ga][1] + dc[1]];
                if signed_area(&cg) <= 0.0 || overlaps(&grid, &key, &corner, &cg) {
                    continue;
                }
                corner[g] = cg;
                patch[g] = pid;
                insert(&mut grid, &key, g as u32, &cg);
                queue.push_back(g);
            }
        }
    }
    let tol = 1e-9 * mean_len.max(1e-300) * 1e3;
    let (n_patches, merges) = if merge {
        let faces =
            LayoutFaces { positions, triangles, topology, keep, folded: &is_folded, cell, tol };
        let m = merge_patches(&faces, &mut corner, &mut patch);
        folded -= m.attached_folded;
        // Faces still on one-face charts are not moved; attached ones are not
        // translation-developed either.
        shorten_seams(&faces, &mut corner, &mut patch, SEAM_ROUNDS);
        let n = patch.iter().filter(|&&p| p != u32::MAX).map(|&p| p + 1).max().unwrap_or(0);
        (n, m.merges)
    } else {
        (n_patches, 0)
    };
    // Long strips (trajectories that spiral make them) are cut into pieces no longer
    // than `piece` along x and y, so that the pieces pack densely; the cuts become
    // seams like any other.
    let uv_area: f64 = (0..nf).filter(|&f| keep[f]).map(|f| signed_area(&corner[f]).abs()).sum();
    let piece = (piece_side * uv_area.sqrt()).max(4.0 * mean_len);
    let mut pbox = vec![[f64::INFINITY; 2]; n_patches as usize];
    let centroid = |c: &[[f64; 2]; 3]| {
        [(c[0][0] + c[1][0] + c[2][0]) / 3.0, (c[0][1] + c[1][1] + c[2][1]) / 3.0]
    };
    for f in (0..nf).filter(|&f| keep[f]) {
        let g = centroid(&corner[f]);
        let b = &mut pbox[patch[f] as usize];
        b[0] = b[0].min(g[0]);
        b[1] = b[1].min(g[1]);
    }
    let mut renumber: HashMap<(u32, i64, i64), u32> = HashMap::new();
    for f in (0..nf).filter(|&f| keep[f]) {
        let g = centroid(&corner[f]);
        let b = pbox[patch[f] as usize];
        let k = (
            patch[f],
            ((g[0] - b[0]) / piece).floor() as i64,
            ((g[1] - b[1]) / piece).floor() as i64,
        );
        let next = renumber.len() as u32;
        patch[f] = *renumber.entry(k).or_insert(next);
    }
    let n_patches = renumber.len();
    // Shelf packing, tallest first.
    shelf_pack(&mut corner, &patch, keep, n_patches, (2.0 * rings as f64 + 1.0) * mean_len);
    let mut count = vec![0usize; n_patches];
    for f in (0..nf).filter(|&f| keep[f]) {
        count[patch[f] as usize] += 1;
    }
    // Seams: edges whose faces disagree on a shared corner.
    let uv_of = |f: usize, v: u32| corner[f][(0..3).find(|&j| triangles[f][j] == v).unwrap_or(0)];
    let mut is_seam = vec![false; ne];
    let mut seam_edges = Vec::new();
    for (e, seam) in is_seam.iter_mut().enumerate() {
        let fs = topology.edge_faces(e);
        if fs.len() != 2 {
            continue;
        }
        let (f, g) = (fs[0] as usize, fs[1] as usize);
        if !keep[f] || !keep[g] {
            continue;
        }
        let a = topology.edges[e][0];
        let (p, q) = (uv_of(f, a), uv_of(g, a));
        let b = topology.edges[e][1];
        let (r, s) = (uv_of(f, b), uv_of(g, b));
        if (p[0] - q[0]).abs() + (p[1] - q[1]).abs() > tol
            || (r[0] - s[0]).abs() + (r[1] - s[1]).abs() > tol
        {
            *seam = true;
            seam_edges.push(e as u32);
        }
    }
    // Ghosts: the far side of every seam, `rings` steps deep through non-seam edges.
    let mut ghosts = Vec::new();
    let mut seen: HashSet<(u32, i64, i64)> = HashSet::new();
    let q = |s: [f64; 2]| ((s[0] / tol).round() as i64, (s[1] / tol).round() as i64);
    for &e in &seam_edges {
        let e = e as usize;
        let fs = topology.edge_faces(e);
        let a = topology.edges[e][0];
        for (near, far) in [(fs[0] as usize, fs[1] as usize), (fs[1] as usize, fs[0] as usize)] {
            let (pn, pf) = (uv_of(near, a), uv_of(far, a));
            let shift = [pf[0] - pn[0], pf[1] - pn[1]];
            let mut frontier = vec![far];
            for depth in 0..=rings {
                let mut next = Vec::new();
                for &g in &frontier {
                    let (kx, ky) = q(shift);
                    if !seen.insert((g as u32, kx, ky)) {
                        continue;
                    }
                    ghosts.push(Ghost { face: g as u32, shift, corners: None });
                    if depth == rings {
                        continue;
                    }
                    for k in 0..3 {
                        let e2 = topology.face_edges[g][k] as usize;
                        if is_seam[e2] {
                            continue;
                        }
                        if let Some(&h) = topology.edge_faces(e2).iter().find(|&&h| h as usize != g)
                            && keep[h as usize]
                        {
                            next.push(h as usize);
                        }
                    }
                }
                frontier = next;
            }
        }
    }
    let n_kept = keep.iter().filter(|k| **k).count();
    let small_patches = count.iter().filter(|&&c| (c as f64) < 0.01 * n_kept as f64).count();
    PatchLayout { corner, patch, n_patches, small_patches, folded, merges, seam_edges, ghosts }
}

/// Shelf packing without rotation, tallest chart first: moves the corners of every kept
/// face by its chart's offset so that the `n_patches` charts' bounding boxes, `gap`
/// apart, fill rows about `1.2 √(total box area)` wide.
pub(super) fn shelf_pack(
    corner: &mut [[[f64; 2]; 3]],
    patch: &[u32],
    keep: &[bool],
    n_patches: usize,
    gap: f64,
) {
    let nf = corner.len();
    let mut bbox =
        vec![[f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY]; n_patches];
    for f in (0..nf).filter(|&f| keep[f]) {
        let b = &mut bbox[patch[f] as usize];
        for p in &corner[f] {
            b[0] = b[0].min(p[0]);
            b[1] = b[1].min(p[1]);
            b[2] = b[2].max(p[0]);
            b[3] = b[3].max(p[1]);
        }
    }
    let area: f64 = bbox.iter().map(|b| (b[2] - b[0] + gap) * (b[3] - b[1] + gap)).sum();
    let widest = bbox.iter().map(|b| b[2] - b[0] + gap).fold(0.0, f64::max);
    let row_width = (1.2 * area.sqrt()).max(widest);
    let mut order: Vec<usize> = (0..n_patches).collect();
    order.sort_by(|&i, &j| {
        (bbox[j][3] - bbox[j][1]).total_cmp(&(bbox[i][3] - bbox[i][1])).then(i.cmp(&j))
    });
    let mut offset = vec![[0.0; 2]; n_patches];
    let (mut x, mut y, mut row_h) = (0.0, 0.0, 0.0f64);
    for &i in &order {
        let (w, h) = (bbox[i][2] - bbox[i][0] + gap, bbox[i][3] - bbox[i][1] + gap);
        if x > 0.0 && x + w > row_width {
            x = 0.0;
            y += row_h;
            row_h = 0.0;
        }
        offset[i] = [x - bbox[i][0], y - bbox[i][1]];
        x += w;
        row_h = row_h.max(h);
    }
    for f in (0..nf).filter(|&f| keep[f]) {
        let o = offset[patch[f] as usize];
        for p in corner[f].iter_mut() {
            p[0] += o[0];
            p[1] += o[1];
        }
    }
}

pub(super) fn insert(
    grid: &mut HashMap<(i64, i64), Vec<u32>>,
    key: &impl Fn([f64; 2]) -> (i64, i64),
    f: u32,
    c: &[[f64; 2]; 3],
) {
    let (lo, hi) = cell_range(key, c);
    for i in lo.0..=hi.0 {
        for j in lo.1..=hi.1 {
            grid.entry((i, j)).or_default().push(f);
        }
    }
}

pub(super) fn cell_range(
    key: &impl Fn([f64; 2]) -> (i64, i64),
    c: &[[f64; 2]; 3],
) -> ((i64, i64), (i64, i64)) {
    let lo = [c[0][0].min(c[1][0]).min(c[2][0]), c[0][1].min(c[1][1]).min(c[2][1])];
    let hi = [c[0][0].max(c[1][0]).max(c[2][0]), c[0][1].max(c[1][1]).max(c[2][1])];
    (key(lo), key(hi))
}

pub(super) fn overlaps(
    grid: &HashMap<(i64, i64), Vec<u32>>,
    key: &impl Fn([f64; 2]) -> (i64, i64),
    corner: &[[[f64; 2]; 3]],
    c: &[[f64; 2]; 3],
) -> bool {
    let (lo, hi) = cell_range(key, c);
    for i in lo.0..=hi.0 {
        for j in lo.1..=hi.1 {
            if let Some(list) = grid.get(&(i, j))
                && list.iter().any(|&h| triangles_overlap(&corner[h as usize], c))
            {
                return true;
            }
        }
    }
    false
}

/// Whether two counter-clockwise triangles' interiors overlap by more than a sliver
/// (separating-axis test on the six edge normals, with a relative tolerance so that
/// triangles sharing an edge or a corner count as apart).
pub fn triangles_overlap(a: &[[f64; 2]; 3], b: &[[f64; 2]; 3]) -> bool {
    let scale = a
        .iter()
        .chain(b.iter())
        .flat_map(|p| p.iter())
        .fold(0.0f64, |s, v| s.max(v.abs()))
        .max(1e-300);
    let size = |t: &[[f64; 2]; 3]| {
        (0..3)
            .map(|k| {
                let (p, q) = (t[k], t[(k + 1) % 3]);
                ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt()
            })
            .fold(0.0, f64::max)
    };
    let eps = 1e-6 * size(a).min(size(b)) + 1e-12 * scale;
    for t in [a, b] {
        for k in 0..3 {
            let (p, q) = (t[k], t[(k + 1) % 3]);
            let n = [q[1] - p[1], p[0] - q[0]];
            let len = (n[0] * n[0] + n[1] * n[1]).sqrt();
            if len == 0.0 {
                continue;
            }
            let proj = |r: [f64; 2]| (n[0] * r[0] + n[1] * r[1]) / len;
            let (amin, amax) = a.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &r| {
                (lo.min(proj(r)), hi.max(proj(r)))
            });
            let (bmin, bmax) = b.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &r| {
                (lo.min(proj(r)), hi.max(proj(r)))
            });
            if amax <= bmin + eps || bmax <= amin + eps {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlap_test_separates_neighbours_and_catches_overlaps() {
        let a = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let shared_edge = [[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let shared_corner = [[1.0, 0.0], [2.0, 0.0], [1.0, 1.0]];
        let inside = [[0.1, 0.1], [0.5, 0.1], [0.1, 0.5]];
        let crossing = [[0.4, -0.5], [0.6, -0.5], [0.5, 0.6]];
        assert!(!triangles_overlap(&a, &shared_edge));
        assert!(!triangles_overlap(&a, &shared_corner));
        assert!(triangles_overlap(&a, &inside));
        assert!(triangles_overlap(&a, &crossing));
        assert!(triangles_overlap(&a, &a));
    }
}
