//! Merging of translation patches into maximal charts (Wang, Gu, Mueller & Yau 2005 §3:
//! the critical horizontal trajectories cut the surface into patches that each map to a
//! rectangle — "conformal geometry images" — so a chart should be the whole region
//! between critical trajectories, not the fragments a breadth-first growth leaves).
//!
//! Every patch of [`super::translation_patches`] is developed by integrating the same
//! holomorphic form, so the charts of two patches that meet across an edge differ by a
//! pure translation `t` (the same at both ends of the edge). Translating one patch by
//! `t` removes that seam; the union is still one injective chart when no face of one
//! overlaps a face of the other. Candidates `(P, Q, t)` are ranked by the 3-D length of
//! the seam they would remove (longest first, ties by patch ids and shift, so the result
//! is deterministic) and merged greedily when the overlap test (separating axes on a
//! hash grid, [`super::translation_patches::triangles_overlap`]) passes. A refused
//! candidate can never become feasible later (charts only grow), so one pass suffices.
//!
//! Faces the discrete form folds next to zero points (non-positive developed area) have
//! no translation chart. Instead of a one-face chart each is *attached* to a neighbour's
//! patch: its shared edge keeps the neighbour's corners and its third corner is placed so
//! the triangle is similar to the surface triangle (conformal on that face), when it
//! does not overlap the patch. Its other two edges stay seams.
//!
//! Finally [`shorten_seams`] moves single faces across seams (to the position the
//! translation across the seam gives them) where that shortens the seams around them
//! and keeps the chart injective: the jagged fronts where a breadth-first patch met
//! itself around a handle straighten out. A greedy local descent, not a global minimum
//! cut.

use super::translation_patches::{cell_range, insert, triangles_overlap};
use fieldtex_core::vec3;
use fieldtex_mesh::Topology;
use std::collections::HashMap;

type Grid = HashMap<(i64, i64), Vec<u32>>;
/// `(lower patch, higher patch, quantised shift)`.
type CandKey = (u32, u32, i64, i64);
/// `(shared seam length, face in the lower patch, face in the higher patch, vertex)`.
type CandVal = (f64, u32, u32, u32);

/// What [`merge_patches`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MergeOutcome {
    /// Patches after merging (ids `0..n_patches`, in order of their lowest face).
    pub n_patches: usize,
    /// Merges performed.
    pub merges: usize,
    /// Folded faces attached to a neighbouring patch.
    pub attached_folded: usize,
}

/// The faces being laid out, as [`merge_patches`] and [`shorten_seams`] read them:
/// `keep` the faces of the layout, `folded` the faces laid out on their own (their
/// corners are not the form's development), `cell` the hash-grid cell size and `tol`
/// the tolerance under which two shifts are equal.
#[derive(Debug, Clone, Copy)]
pub struct LayoutFaces<'a> {
    pub positions: &'a [[f64; 3]],
    pub triangles: &'a [[u32; 3]],
    pub topology: &'a Topology,
    pub keep: &'a [bool],
    pub folded: &'a [bool],
    pub cell: f64,
    pub tol: f64,
}

impl LayoutFaces<'_> {
    /// Hash-grid cell of a point.
    fn key(&self, p: [f64; 2]) -> (i64, i64) {
        ((p[0] / self.cell).floor() as i64, (p[1] / self.cell).floor() as i64)
    }

    /// Number of patch ids in use, and per patch: its faces and their hash grid.
    fn patch_grids(&self, corner: &[[[f64; 2]; 3]], patch: &[u32]) -> (Vec<Vec<u32>>, Vec<Grid>) {
        let n =
            patch.iter().filter(|&&p| p != u32::MAX).map(|&p| p as usize + 1).max().unwrap_or(0);
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); n];
        let mut grids: Vec<Grid> = vec![Grid::new(); n];
        let key = |p| self.key(p);
        for f in (0..self.triangles.len()).filter(|&f| self.keep[f] && patch[f] != u32::MAX) {
            members[patch[f] as usize].push(f as u32);
            insert(&mut grids[patch[f] as usize], &key, f as u32, &corner[f]);
        }
        (members, grids)
    }
}

/// Merges patches as in the module docs. `corner` and `patch` (per face, `u32::MAX`
/// outside `keep`) are updated in place.
pub fn merge_patches(
    faces: &LayoutFaces,
    corner: &mut [[[f64; 2]; 3]],
    patch: &mut [u32],
) -> MergeOutcome {
    let LayoutFaces { positions, triangles, topology, keep, folded, tol, .. } = *faces;
    let nf = triangles.len();
    let key = |p| faces.key(p);
    let (mut members, mut grids) = faces.patch_grids(corner, patch);
    let corner_of = |f: usize, v: u32| (0..3).find(|&k| triangles[f][k] == v).unwrap_or(0);
    let fits = |grid: &Grid, corner: &[[[f64; 2]; 3]], c: &[[f64; 2]; 3]| {
        let (lo, hi) = cell_range(&key, c);
        for i in lo.0..=hi.0 {
            for j in lo.1..=hi.1 {
                if let Some(list) = grid.get(&(i, j))
                    && list.iter().any(|&h| triangles_overlap(&corner[h as usize], c))
                {
                    return false;
                }
            }
        }
        true
    };
    // 1. Folded faces join a neighbour's patch with a similar triangle on the shared edge.
    let mut attached = 0;
    for f in 0..nf {
        if !keep[f] || !folded[f] || members[patch[f] as usize].len() != 1 {
            continue;
        }
        for k in 0..3 {
            let e = topology.face_edges[f][k] as usize;
            let Some(&g) = topology.edge_faces(e).iter().find(|&&g| g as usize != f) else {
                continue;
            };
            let g = g as usize;
            if !keep[g] || folded[g] {
                continue;
            }
            let (a, b, c) = (triangles[f][k], triangles[f][(k + 1) % 3], triangles[f][(k + 2) % 3]);
            let (pa, pb) = (corner[g][corner_of(g, a)], corner[g][corner_of(g, b)]);
            let p = [a, b, c].map(|v| positions[v as usize]);
            let (e1, e2) = (vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0]));
            let l2 = vec3::dot(e1, e1);
            if l2 <= 0.0 {
                continue;
            }
            let x = vec3::dot(e2, e1) / l2;
            let y = vec3::norm(vec3::cross(e1, e2)) / l2;
            let d = [pb[0] - pa[0], pb[1] - pa[1]];
            let pc = [pa[0] + x * d[0] - y * d[1], pa[1] + x * d[1] + y * d[0]];
            let mut c3 = [[0.0; 2]; 3];
            c3[k] = pa;
            c3[(k + 1) % 3] = pb;
            c3[(k + 2) % 3] = pc;
            let target = patch[g] as usize;
            if y <= 0.0 || !fits(&grids[target], &*corner, &c3) {
                continue;
            }
            let old = patch[f] as usize;
            members[old].clear();
            grids[old].clear();
            corner[f] = c3;
            patch[f] = target as u32;
            members[target].push(f as u32);
            insert(&mut grids[target], &key, f as u32, &c3);
            attached += 1;
            break;
        }
    }
    // 2. Candidate merges: patch pairs and the shift that joins them, with the seam length
    //    they would remove.
    let q = |s: [f64; 2]| ((s[0] / tol).round() as i64, (s[1] / tol).round() as i64);
    let mut cands: HashMap<CandKey, CandVal> = HashMap::new();
    for e in 0..topology.n_edges() {
        let fs = topology.edge_faces(e);
        if fs.len() != 2 {
            continue;
        }
        let (f, g) = (fs[0] as usize, fs[1] as usize);
        if !keep[f] || !keep[g] || patch[f] == patch[g] {
            continue;
        }
        let [a, b] = topology.edges[e];
        let sa = sub2(corner[f][corner_of(f, a)], corner[g][corner_of(g, a)]);
        let sb = sub2(corner[f][corner_of(f, b)], corner[g][corner_of(g, b)]);
        if (sa[0] - sb[0]).abs() + (sa[1] - sb[1]).abs() > tol {
            continue; // not a translation (an attached folded face)
        }
        // Orient: translating the higher patch by `t` joins it to the lower one.
        let (lo_f, hi_f, t) =
            if patch[f] < patch[g] { (f, g, sa) } else { (g, f, [-sa[0], -sa[1]]) };
        let (kx, ky) = q(t);
        let len = vec3::norm(vec3::sub(positions[b as usize], positions[a as usize]));
        let entry = cands.entry((patch[lo_f], patch[hi_f], kx, ky)).or_insert((
            0.0,
            lo_f as u32,
            hi_f as u32,
            a,
        ));
        entry.0 += len;
    }
    let mut order: Vec<(CandKey, CandVal)> = cands.into_iter().collect();
    order.sort_by(|x, y| y.1.0.total_cmp(&x.1.0).then(x.0.cmp(&y.0)));
    // 3. Greedy merging with union–find over patch ids; corners move with their group.
    let mut parent: Vec<u32> = (0..members.len() as u32).collect();
    let find = |parent: &mut Vec<u32>, mut p: u32| {
        while parent[p as usize] != p {
            let up = parent[parent[p as usize] as usize];
            parent[p as usize] = up;
            p = up;
        }
        p
    };
    let mut merges = 0;
    for (_, (_, f, g, a)) in order {
        let (f, g) = (f as usize, g as usize);
        let (rf, rg) = (find(&mut parent, patch[f]), find(&mut parent, patch[g]));
        if rf == rg {
            continue;
        }
        // Shift that moves g's group onto f's chart.
        let mut t = sub2(corner[f][corner_of(f, a)], corner[g][corner_of(g, a)]);
        let (big, small) = if members[rf as usize].len() >= members[rg as usize].len() {
            (rf as usize, rg as usize)
        } else {
            t = [-t[0], -t[1]];
            (rg as usize, rf as usize)
        };
        let ok = members[small].iter().all(|&h| {
            let c = corner[h as usize].map(|p| [p[0] + t[0], p[1] + t[1]]);
            fits(&grids[big], &*corner, &c)
        });
        if !ok {
            continue;
        }
        let moved = std::mem::take(&mut members[small]);
        grids[small].clear();
        for &h in &moved {
            let c = &mut corner[h as usize];
            for p in c.iter_mut() {
                p[0] += t[0];
                p[1] += t[1];
            }
            insert(&mut grids[big], &key, h, c);
        }
        members[big].extend(moved);
        parent[small] = big as u32;
        merges += 1;
    }
    // 4. Compact ids in order of each group's lowest face.
    let mut renumber: HashMap<u32, u32> = HashMap::new();
    for f in 0..nf {
        if !keep[f] || patch[f] == u32::MAX {
            continue;
        }
        let r = find(&mut parent, patch[f]);
        let next = renumber.len() as u32;
        patch[f] = *renumber.entry(r).or_insert(next);
    }
    MergeOutcome { n_patches: renumber.len(), merges, attached_folded: attached }
}

/// Local seam shortening after merging: a face on a seam may take the position its
/// neighbour across the seam gives it (its corners shifted by that translation, joining
/// the neighbour's patch) when this lowers the 3-D length of seam edges around it and the
/// moved face overlaps nothing in its new patch. Jagged fronts where a breadth-first
/// patch met itself around a handle become straighter; each move lowers the total seam
/// length, so the faces are swept in index order until no move helps (at most `rounds`
/// sweeps). Folded faces (laid out on their own) are not moved. Returns the moves.
pub fn shorten_seams(
    faces: &LayoutFaces,
    corner: &mut [[[f64; 2]; 3]],
    patch: &mut [u32],
    rounds: usize,
) -> usize {
    let LayoutFaces { positions, triangles, topology, keep, folded: fixed, tol, .. } = *faces;
    let nf = triangles.len();
    let key = |p| faces.key(p);
    let (_, mut grids) = faces.patch_grids(corner, patch);
    let corner_of = |f: usize, v: u32| (0..3).find(|&k| triangles[f][k] == v).unwrap_or(0);
    let edge_len: Vec<f64> = topology
        .edges
        .iter()
        .map(|e| vec3::norm(vec3::sub(positions[e[1] as usize], positions[e[0] as usize])))
        .collect();
    let other = |f: usize, k: usize| -> Option<usize> {
        let e = topology.face_edges[f][k] as usize;
        let g = *topology.edge_faces(e).iter().find(|&&g| g as usize != f)? as usize;
        keep[g].then_some(g)
    };
    // Seam length around `f` placed at `c`.
    let seam_around = |corner: &[[[f64; 2]; 3]], f: usize, c: &[[f64; 2]; 3]| -> f64 {
        let mut len = 0.0;
        for k in 0..3 {
            let Some(g) = other(f, k) else { continue };
            let (a, b) = (triangles[f][k], triangles[f][(k + 1) % 3]);
            let (qa, qb) = (corner[g][corner_of(g, a)], corner[g][corner_of(g, b)]);
            let d = (c[k][0] - qa[0]).abs()
                + (c[k][1] - qa[1]).abs()
                + (c[(k + 1) % 3][0] - qb[0]).abs()
                + (c[(k + 1) % 3][1] - qb[1]).abs();
            if d > tol {
                len += edge_len[topology.face_edges[f][k] as usize];
            }
        }
        len
    };
    let mut moves = 0;
    for _ in 0..rounds {
        let mut changed = false;
        for f in 0..nf {
            if !keep[f] || fixed[f] || patch[f] == u32::MAX {
                continue;
            }
            let now = seam_around(&*corner, f, &corner[f]);
            if now <= 0.0 {
                continue;
            }
            for k in 0..3 {
                let Some(g) = other(f, k) else { continue };
                if fixed[g] {
                    continue;
                }
                let (a, b) = (triangles[f][k], triangles[f][(k + 1) % 3]);
                let sa = sub2(corner[g][corner_of(g, a)], corner[f][k]);
                let sb = sub2(corner[g][corner_of(g, b)], corner[f][(k + 1) % 3]);
                if (sa[0] - sb[0]).abs() + (sa[1] - sb[1]).abs() > tol
                    || sa[0].abs() + sa[1].abs() <= tol
                {
                    continue; // not a seam, or not a translation
                }
                let c = corner[f].map(|p| [p[0] + sa[0], p[1] + sa[1]]);
                if seam_around(&*corner, f, &c) >= now - 1e-12 * now {
                    continue;
                }
                let target = patch[g] as usize;
                let (lo, hi) = cell_range(&key, &c);
                let mut free = true;
                'cells: for i in lo.0..=hi.0 {
                    for j in lo.1..=hi.1 {
                        if let Some(list) = grids[target].get(&(i, j))
                            && list.iter().any(|&h| {
                                h as usize != f && triangles_overlap(&corner[h as usize], &c)
                            })
                        {
                            free = false;
                            break 'cells;
                        }
                    }
                }
                if !free {
                    continue;
                }
                let (olo, ohi) = cell_range(&key, &corner[f]);
                let old = &mut grids[patch[f] as usize];
                for i in olo.0..=ohi.0 {
                    for j in olo.1..=ohi.1 {
                        if let Some(list) = old.get_mut(&(i, j)) {
                            list.retain(|&h| h as usize != f);
                        }
                    }
                }
                corner[f] = c;
                patch[f] = target as u32;
                insert(&mut grids[target], &key, f as u32, &c);
                moves += 1;
                changed = true;
                break;
            }
        }
        if !changed {
            break;
        }
    }
    // Compact ids (a patch may have lost all its faces).
    let mut renumber: HashMap<u32, u32> = HashMap::new();
    for f in 0..nf {
        if keep[f] && patch[f] != u32::MAX {
            let next = renumber.len() as u32;
            patch[f] = *renumber.entry(patch[f]).or_insert(next);
        }
    }
    moves
}

fn sub2(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}
