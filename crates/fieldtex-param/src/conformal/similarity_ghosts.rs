//! Ghost faces across a seam whose two charts differ by a similarity, for the geometry
//! image's margins (Wang et al. 2005 §4.2's boundary consistency, extended beyond
//! translations): the slits of a protrusion-slit layout ([`super::protrusion_slits`]),
//! and every seam of a patch layout after the quasi-isometric relaxation
//! ([`super::patch_relaxation`]), which breaks the translations between charts.
//!
//! For every seam edge and each of its two faces (`near`), the face on the other side
//! (`far`) and its neighbours up to `rings` steps (not across a UV seam) are drawn in
//! `near`'s chart by the similarity that maps the shared edge of `far`'s chart onto
//! `near`'s (`z ↦ a_n + (z − a_f)(b_n − a_n)/(b_f − a_f)` in complex numbers); where
//! both charts are conformal it continues one into the other to first order. A point
//! of the ghost shows the point with the same barycentric coordinates in the face's own
//! chart ([`super::geometry_image`]).

use super::translation_patches::Ghost;
use fieldtex_mesh::Topology;
use std::collections::{HashMap, HashSet};

/// Similarity ghosts (see the module docs) over the first `n_keep` faces of
/// `triangles` with packed UVs `corner`; `original` names each vertex's surface point
/// (two vertices with the same original are the two sides of a cut, as on a slit), and
/// the seams are the edges of originals whose two faces disagree on the UVs, restricted
/// to `only` when given (pairs `(min, max)` of originals).
pub fn similarity_ghosts(
    triangles: &[[u32; 3]],
    original: &[u32],
    corner: &[[[f64; 2]; 3]],
    n_keep: usize,
    rings: usize,
    only: Option<&HashSet<(u32, u32)>>,
) -> Vec<Ghost> {
    let n = n_keep.min(triangles.len()).min(corner.len());
    let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() + (a[1] - b[1]).abs() <= 1e-9;
    let mut sides: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (f, t) in triangles[..n].iter().enumerate() {
        let o = t.map(|v| original[v as usize]);
        for k in 0..3 {
            let key = (o[k].min(o[(k + 1) % 3]), o[k].max(o[(k + 1) % 3]));
            if only.is_none_or(|s| s.contains(&key)) {
                sides.entry(key).or_default().push(f);
            }
        }
    }
    let uv_at = |f: usize, v: u32| {
        (0..3).find(|&k| original[triangles[f][k] as usize] == v).map(|k| corner[f][k])
    };
    let topo = Topology::build(original.len(), &triangles[..n]);
    let same_uv = |f: usize, g: usize, e: usize| {
        topo.edges[e].iter().all(|&v| {
            let (a, b) = (
                (0..3).find(|&k| triangles[f][k] == v).map(|k| corner[f][k]),
                (0..3).find(|&k| triangles[g][k] == v).map(|k| corner[g][k]),
            );
            matches!((a, b), (Some(a), Some(b)) if close(a, b))
        })
    };
    let mut keys: Vec<&(u32, u32)> = sides.keys().collect();
    keys.sort_unstable();
    let mut ghosts = Vec::new();
    for key in keys {
        let faces = &sides[key];
        let [f1, f2] = faces[..] else { continue };
        for (near, far) in [(f1, f2), (f2, f1)] {
            let (Some(an), Some(bn), Some(af), Some(bf)) =
                (uv_at(near, key.0), uv_at(near, key.1), uv_at(far, key.0), uv_at(far, key.1))
            else {
                continue;
            };
            if close(an, af) && close(bn, bf) {
                continue; // not a seam: the two faces share the chart here
            }
            // Complex ratio (b_n − a_n) / (b_f − a_f).
            let (dn, df) = ([bn[0] - an[0], bn[1] - an[1]], [bf[0] - af[0], bf[1] - af[1]]);
            let den = df[0] * df[0] + df[1] * df[1];
            if den.is_nan() || den <= 0.0 {
                continue;
            }
            let r = [(dn[0] * df[0] + dn[1] * df[1]) / den, (dn[1] * df[0] - dn[0] * df[1]) / den];
            let map = |z: [f64; 2]| {
                let d = [z[0] - af[0], z[1] - af[1]];
                [an[0] + d[0] * r[0] - d[1] * r[1], an[1] + d[0] * r[1] + d[1] * r[0]]
            };
            let mut seen = vec![far];
            let mut frontier = vec![far];
            for depth in 0..=rings {
                let mut next = Vec::new();
                for &g in &frontier {
                    ghosts.push(Ghost {
                        face: g as u32,
                        shift: [0.0; 2],
                        corners: Some(corner[g].map(map)),
                    });
                    if depth == rings {
                        continue;
                    }
                    for &e in &topo.face_edges[g] {
                        let e = e as usize;
                        if let Some(&h) = topo.edge_faces(e).iter().find(|&&h| h as usize != g) {
                            let h = h as usize;
                            if h != near && !seen.contains(&h) && same_uv(g, h, e) {
                                seen.push(h);
                                next.push(h);
                            }
                        }
                    }
                }
                frontier = next;
            }
        }
    }
    ghosts
}
