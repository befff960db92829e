//! The steps of [`crate::repair()`], in order; see that module for what each does.

use crate::Topology;
use crate::coincident_vertices::IntMap;
use crate::non_manifold_split::split_non_manifold;
use crate::orientation::orientation_patches;
use crate::repair::{RepairOptions, Work};
use crate::triangle_quality::{signed_volume6, triangle_area};
use crate::vertex_welding::fan_aware_weld;
use fieldtex_core::Warning;
use fieldtex_core::vec3::{is_finite, sub};

/// Step 1: attribute tables of the wrong length and out-of-range triangles.
pub(crate) fn sanitise(w: &mut Work) {
    let nv = w.positions.len();
    let colors = w.colors.as_ref().map(Vec::len).filter(|&n| n != nv);
    if colors.is_some() {
        w.colors = None;
    }
    let normals = w.normals.as_ref().map(Vec::len).filter(|&n| n != nv);
    if normals.is_some() {
        w.normals = None;
    }
    for (what, dropped) in [("vertex colours", colors), ("vertex normals", normals)] {
        if let Some(n) = dropped {
            let message = format!("{what} ({n} for {nv} vertices) dropped");
            w.change("attribute-dropped", 1, message, vec![]);
        }
    }
    let nf = w.triangles.len();
    if let Some(uv) = &w.uv {
        let nuv = uv.values.len();
        let problem = if uv.indices.len() != nf {
            Some(format!("{} UV index triples for {nf} triangles", uv.indices.len()))
        } else {
            uv.indices
                .iter()
                .position(|t| t.iter().any(|&i| i as usize >= nuv))
                .map(|f| format!("triangle {f} refers to a missing UV value"))
        };
        if let Some(p) = problem {
            w.uv = None;
            w.change("uvs-dropped", 1, format!("texture coordinates dropped: {p}"), vec![]);
        }
    }
    let keep: Vec<bool> =
        w.triangles.iter().map(|t| t.iter().all(|&i| (i as usize) < nv)).collect();
    let dropped = w.retain_triangles(&keep);
    let msg = format!("{} triangles referring to missing vertices dropped", dropped.len());
    w.change("invalid-triangles-dropped", dropped.len(), msg, dropped);
}

/// Step 2: vertices with NaN/Inf coordinates and their triangles.
pub(crate) fn drop_non_finite(w: &mut Work) {
    let bad: Vec<bool> = w.positions.iter().map(|p| !is_finite(*p)).collect();
    let examples: Vec<u32> = (0..bad.len() as u32).filter(|&v| bad[v as usize]).collect();
    if examples.is_empty() {
        return;
    }
    let keep: Vec<bool> = w.triangles.iter().map(|t| t.iter().all(|&v| !bad[v as usize])).collect();
    let dropped = w.retain_triangles(&keep);
    for (d, b) in w.dead.iter_mut().zip(&bad) {
        *d |= *b;
    }
    let msg = format!(
        "{} vertices with NaN/Inf coordinates dropped, with the {} triangles using them",
        examples.len(),
        dropped.len()
    );
    w.change("non-finite-vertices-dropped", examples.len(), msg, examples);
}

/// Step 3: fan-aware weld within `epsilon` (absolute); returns how many vertices
/// were welded away. With `epsilon > 0` an exact weld follows: merging more points
/// can make an edge non-manifold in the tentative mesh and so block stitches that
/// exactly coincident vertices alone would allow.
pub(crate) fn weld(w: &mut Work, epsilon: f64, pass: usize) -> usize {
    let mut welded: Vec<u32> = Vec::new();
    let epsilons: &[f64] = if epsilon > 0.0 { &[epsilon, 0.0] } else { &[0.0] };
    for &eps in epsilons {
        let map = fan_aware_weld(&w.positions, &w.triangles, eps);
        let n0 = welded.len();
        welded.extend((0..map.len() as u32).filter(|&v| map[v as usize] != v));
        if welded.len() == n0 {
            continue;
        }
        for t in &mut w.triangles {
            *t = t.map(|v| map[v as usize]);
        }
        for &v in &welded[n0..] {
            w.dead[v as usize] = true;
        }
    }
    if welded.is_empty() {
        return 0;
    }
    welded.sort_unstable();
    let how = if epsilon > 0.0 {
        format!("within {epsilon:.3e}")
    } else {
        "at exactly equal positions".to_string()
    };
    let again = if pass > 0 { ", where dropping triangles made stitching possible" } else { "" };
    let msg = format!("{} vertices welded into coincident vertices ({how}{again})", welded.len());
    let examples = welded.iter().map(|&v| w.orig_vertex[v as usize]).collect();
    w.change("vertices-welded", welded.len(), msg, examples);
    welded.len()
}

/// Step 4: repeated-index and zero-area triangles.
pub(crate) fn drop_degenerate(w: &mut Work, options: &RepairOptions, diagonal: f64) {
    let keep: Vec<bool> =
        w.triangles.iter().map(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2]).collect();
    let dropped = w.retain_triangles(&keep);
    let msg = format!("{} triangles with a repeated vertex dropped", dropped.len());
    w.change("repeated-index-triangles-dropped", dropped.len(), msg, dropped);
    if !options.drop_zero_area {
        return;
    }
    let tol = options.zero_area_relative * diagonal * diagonal;
    let keep: Vec<bool> = w
        .triangles
        .iter()
        .map(|t| triangle_area(&t.map(|v| w.positions[v as usize])) > tol)
        .collect();
    let dropped = w.retain_triangles(&keep);
    let msg = format!("{} triangles with area ≤ {tol:.3e} dropped", dropped.len());
    w.change("zero-area-triangles-dropped", dropped.len(), msg, dropped);
}

/// Step 5: triangles with the vertex set of an earlier one.
pub(crate) fn drop_duplicates(w: &mut Work) {
    let mut seen: IntMap<[u32; 3], ()> = IntMap::default();
    seen.reserve(w.triangles.len());
    let keep: Vec<bool> = w
        .triangles
        .iter()
        .map(|t| {
            let mut k = *t;
            k.sort_unstable();
            seen.insert(k, ()).is_none()
        })
        .collect();
    let dropped = w.retain_triangles(&keep);
    let msg = format!("{} duplicate triangles dropped", dropped.len());
    w.change("duplicate-triangles-dropped", dropped.len(), msg, dropped);
}

/// Step 6: split non-manifold vertices, detach non-manifold edges.
pub(crate) fn split(w: &mut Work) {
    let (tris, rep) = split_non_manifold(w.positions.len(), &w.triangles);
    if rep.is_noop() {
        return;
    }
    let mut keep = vec![true; w.triangles.len()];
    for &f in &rep.removed_triangles {
        keep[f as usize] = false;
    }
    let removed = w.retain_triangles(&keep);
    w.triangles = tris;
    for &src in &rep.copies_of {
        let s = src as usize;
        w.positions.push(w.positions[s]);
        if let Some(c) = &mut w.colors {
            c.push(c[s]);
        }
        if let Some(n) = &mut w.normals {
            n.push(n[s]);
        }
        w.orig_vertex.push(w.orig_vertex[s]);
        w.dead.push(false);
    }
    let n_edges = rep.non_manifold_edges.len();
    let msg = format!(
        "{n_edges} edges shared by more than two triangles: one consistently oriented pair kept \
         attached, the other triangles detached (examples: endpoint pairs)"
    );
    let ex = rep.non_manifold_edges.iter().flatten().map(|&v| w.orig_vertex[v as usize]).collect();
    w.change("non-manifold-edges-detached", n_edges, msg, ex);
    let n = rep.split_vertices.len();
    let msg = format!(
        "{n} vertices joining separate fans of triangles split into {} new vertices",
        rep.copies_of.len()
    );
    let ex = rep.split_vertices.iter().map(|&v| w.orig_vertex[v as usize]).collect();
    w.change("non-manifold-vertices-split", n, msg, ex);
    let msg = format!(
        "{} triangles still on a non-manifold edge after splitting were dropped",
        removed.len()
    );
    w.change("non-manifold-triangles-dropped", removed.len(), msg, removed);
}

/// Step 7: consistent orientation per patch, then closed patches outward.
pub(crate) fn orient(w: &mut Work, options: &RepairOptions) {
    let topo = Topology::build(w.positions.len(), &w.triangles);
    let pat = orientation_patches(&topo);
    let np = pat.n_patches();
    let nf = w.triangles.len();
    let (mut size, mut odd) = (vec![0usize; np], vec![0usize; np]);
    let mut closed = vec![true; np];
    for f in 0..nf {
        let p = pat.patch[f] as usize;
        size[p] += 1;
        odd[p] += usize::from(pat.parity[f]);
        if topo.face_edges[f].iter().any(|&e| topo.edge_faces(e as usize).len() != 2) {
            closed[p] = false;
        }
    }
    // Faces keep their orientation when their parity equals keep[p].
    let keep: Vec<bool> = (0..np).map(|p| 2 * odd[p] > size[p]).collect();
    let consistent_after =
        |p: usize| pat.orientable[p] && (options.orient_consistently || odd[p] == 0);
    let mut flip: Vec<bool> = (0..nf)
        .map(|f| {
            let p = pat.patch[f] as usize;
            options.orient_consistently && pat.orientable[p] && pat.parity[f] != keep[p]
        })
        .collect();
    let flipped: Vec<u32> = (0..nf).filter(|&f| flip[f]).map(|f| w.orig_face[f]).collect();
    let mut reversed = Vec::new();
    if options.orient_outward {
        let mut vol = vec![0.0f64; np];
        let mut abs = vec![0.0f64; np];
        let mut origin: Vec<Option<[f64; 3]>> = vec![None; np];
        for (f, &fl) in flip.iter().enumerate() {
            let p = pat.patch[f] as usize;
            if !(closed[p] && consistent_after(p)) {
                continue;
            }
            let t = w.triangles[f];
            let o = *origin[p].get_or_insert(w.positions[t[0] as usize]);
            let q = t.map(|v| sub(w.positions[v as usize], o));
            let v6 = signed_volume6(&q);
            vol[p] += if fl { -v6 } else { v6 };
            abs[p] += v6.abs();
        }
        reversed = (0..np).filter(|&p| vol[p] < -1e-9 * abs[p]).collect::<Vec<usize>>();
        for (fl, &p) in flip.iter_mut().zip(&pat.patch) {
            if reversed.binary_search(&(p as usize)).is_ok() {
                *fl = !*fl;
            }
        }
    }
    for (f, &fl) in flip.iter().enumerate() {
        if fl {
            w.flip(f);
        }
    }
    let msg = format!(
        "{} triangles flipped to agree with the majority of their connected patch",
        flipped.len()
    );
    w.change("orientation-made-consistent", flipped.len(), msg, flipped);
    let first_face = |p: usize| (0..nf).find(|&f| pat.patch[f] as usize == p).unwrap_or(0);
    let n_tris: usize = reversed.iter().map(|&p| size[p]).sum();
    let msg = format!(
        "{} closed patches ({n_tris} triangles) were inside out and were reversed to face \
         outward (examples: a triangle of each)",
        reversed.len()
    );
    let ex = reversed.iter().take(w.max_examples).map(|&p| w.orig_face[first_face(p)]).collect();
    w.change("patches-reversed-outward", reversed.len(), msg, ex);
    let bad: Vec<usize> = (0..np).filter(|&p| !pat.orientable[p]).collect();
    if !bad.is_empty() {
        let tris: usize = bad.iter().map(|&p| size[p]).sum();
        w.warnings.push(Warning::new(
            "non-orientable",
            format!(
                "{} connected patches ({tris} triangles) are non-orientable (Möbius-like) \
                 and were left with their input orientation",
                bad.len()
            ),
        ));
    }
}

/// Step 8: drop dead and (optionally) unreferenced vertices and unused UV values.
pub(crate) fn compact(w: &mut Work, drop_unreferenced: bool) {
    let nv = w.positions.len();
    let mut used = vec![false; nv];
    for t in &w.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let unreferenced: Vec<u32> = (0..nv as u32)
        .filter(|&v| !used[v as usize] && !w.dead[v as usize])
        .map(|v| w.orig_vertex[v as usize])
        .collect();
    let remove: Vec<bool> = (0..nv).map(|v| w.dead[v] || (drop_unreferenced && !used[v])).collect();
    if remove.iter().any(|&r| r) {
        let mut new_index = vec![u32::MAX; nv];
        let mut n = 0u32;
        for v in 0..nv {
            if !remove[v] {
                new_index[v] = n;
                n += 1;
            }
        }
        for t in &mut w.triangles {
            *t = t.map(|v| new_index[v as usize]);
        }
        let keep_v = |v: &mut Vec<_>| {
            let mut k = 0;
            v.retain(|_| {
                k += 1;
                !remove[k - 1]
            });
        };
        keep_v(&mut w.positions);
        if let Some(c) = &mut w.colors {
            let mut k = 0;
            c.retain(|_| {
                k += 1;
                !remove[k - 1]
            });
        }
        if let Some(nm) = &mut w.normals {
            keep_v(nm);
        }
        let mut k = 0;
        w.orig_vertex.retain(|_| {
            k += 1;
            !remove[k - 1]
        });
        w.dead = vec![false; n as usize];
    }
    if drop_unreferenced {
        let msg = format!("{} vertices used by no triangle dropped", unreferenced.len());
        w.change("unreferenced-vertices-dropped", unreferenced.len(), msg, unreferenced);
    }
    if let Some(uv) = &mut w.uv {
        let mut used = vec![false; uv.values.len()];
        for t in &uv.indices {
            for &i in t {
                used[i as usize] = true;
            }
        }
        let unused = used.iter().filter(|&&u| !u).count();
        if unused > 0 {
            let mut map = vec![u32::MAX; used.len()];
            let mut values = Vec::with_capacity(used.len() - unused);
            for (i, &u) in used.iter().enumerate() {
                if u {
                    map[i] = values.len() as u32;
                    values.push(uv.values[i]);
                }
            }
            for t in &mut uv.indices {
                *t = t.map(|i| map[i as usize]);
            }
            uv.values = values;
            let msg = format!("{unused} texture coordinates used by no triangle dropped");
            w.change("unused-uvs-dropped", unused, msg, vec![]);
        }
    }
}
