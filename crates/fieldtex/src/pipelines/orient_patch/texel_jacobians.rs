//! The texel field and the per-texel synthesis Jacobians of `orient --mesh`
//! (steps 4 and 5 of [`super`]).

use super::patch_parameterization::Patch;
use fieldtex_core::vec3::{add, cross, dot, norm, normalize, scale, sub};
use fieldtex_fields::Symmetry;
use fieldtex_param::TexelMap;
use rayon::prelude::*;

/// Complex square (`N = 2`) or identity of an image-space direction.
#[inline]
fn power(w: [f64; 2], symmetry: Symmetry) -> [f64; 2] {
    match symmetry {
        Symmetry::Vector => w,
        Symmetry::Orientation => [w[0] * w[0] - w[1] * w[1], 2.0 * w[0] * w[1]],
    }
}

/// Image-space direction of surface direction `d` on a triangle with Jacobian `[px, py]`
/// (least squares `P w = d`), normalised.
fn pull_back(jac: [[f64; 3]; 2], d: [f64; 3]) -> [f64; 2] {
    let [px, py] = jac;
    let (a, b, c) = (dot(px, px), dot(px, py), dot(py, py));
    let (r0, r1) = (dot(px, d), dot(py, d));
    let det = a * c - b * b;
    let w = if det.abs() > 0.0 {
        [(c * r0 - b * r1) / det, (a * r1 - b * r0) / det]
    } else {
        [1.0, 0.0]
    };
    let l = (w[0] * w[0] + w[1] * w[1]).sqrt();
    if l > 0.0 && l.is_finite() { [w[0] / l, w[1] / l] } else { [1.0, 0.0] }
}

/// Texel field from per-triangle surface directions (module docs, step 4).
pub(super) fn sample_texels(
    patch: &Patch,
    map: &TexelMap,
    dirs: &[[f64; 3]],
    symmetry: Symmetry,
) -> Vec<[f32; 2]> {
    let mesh = &patch.mesh;
    let z_face: Vec<[f64; 2]> = (0..mesh.n_triangles())
        .map(|f| match patch.jacobian[f] {
            Some(j) => power(pull_back(j, dirs[f]), symmetry),
            None => [0.0, 0.0],
        })
        .collect();
    let mut z_vertex = vec![[0.0f64; 2]; mesh.n_vertices()];
    for (f, t) in mesh.triangles.iter().enumerate() {
        let p = mesh.triangle_positions(f);
        let a = 0.5 * norm(cross(sub(p[1], p[0]), sub(p[2], p[0])));
        for &v in t {
            let z = &mut z_vertex[v as usize];
            z[0] += a * z_face[f][0];
            z[1] += a * z_face[f][1];
        }
    }
    (0..map.width * map.height)
        .into_par_iter()
        .map(|i| {
            let Some(e) = map.entries[i] else { return [1.0, 0.0] };
            let t = mesh.triangles[e.triangle as usize];
            let mut z = [0.0f64; 2];
            for k in 0..3 {
                let zv = z_vertex[t[k] as usize];
                z[0] += e.bary[k] as f64 * zv[0];
                z[1] += e.bary[k] as f64 * zv[1];
            }
            let z = [z[0] as f32, z[1] as f32];
            fieldtex_fields::orientation_field::nrosy_root_f32(z, symmetry)
        })
        .collect()
}

/// Per-texel Jacobians (module docs, step 5), the field with texels outside the chart
/// filled from the nearest chart texel, and the chart mask. `per_texel`: exemplar
/// pixels per texel (`1 / (--scale × exemplar reduction)`).
pub(super) fn jacobians(
    patch: &Patch,
    map: &TexelMap,
    field: &[[f32; 2]],
    per_texel: f64,
) -> (Vec<[f32; 4]>, Vec<[f32; 2]>, Vec<bool>) {
    let inv_s = per_texel / patch.length_per_texel;
    let own: Vec<Option<[f32; 4]>> = (0..map.width * map.height)
        .into_par_iter()
        .map(|i| {
            if !map.is_covered(i) {
                return None;
            }
            let e = map.entries[i]?;
            let f = e.triangle as usize;
            let [px, py] = patch.jacobian[f]?;
            let w = [field[i][0] as f64, field[i][1] as f64];
            let d = normalize(add(scale(px, w[0]), scale(py, w[1])))?;
            let dp = cross(patch.normals[f], d);
            let r1 = [dot(d, px) * inv_s, dot(d, py) * inv_s];
            let mut r2 = [dot(dp, px) * inv_s, dot(dp, py) * inv_s];
            let det = r1[0] * r2[1] - r1[1] * r2[0];
            if det < 0.0 {
                r2 = [-r2[0], -r2[1]];
            }
            let j = [r1[0] as f32, r1[1] as f32, r2[0] as f32, r2[1] as f32];
            let (jd, jn) = (j[0] * j[3] - j[1] * j[2], j.iter().map(|v| v * v).sum::<f32>());
            (j.iter().all(|v| v.is_finite()) && jd > 1e-5 * jn && jn > 1e-12).then_some(j)
        })
        .collect();
    let inside: Vec<bool> = own.iter().map(Option::is_some).collect();
    let source = nearest_source(map.width, map.height, &inside);
    let mut jac = Vec::with_capacity(own.len());
    let mut out_field = Vec::with_capacity(own.len());
    let fallback = [per_texel as f32, 0.0, 0.0, per_texel as f32];
    for &s in &source {
        if s == u32::MAX {
            jac.push(fallback);
            out_field.push([1.0, 0.0]);
        } else {
            jac.push(own[s as usize].unwrap_or(fallback));
            out_field.push(field[s as usize]);
        }
    }
    (jac, out_field, inside)
}

/// For each texel, a chart texel near it: itself when inside, else the first one a
/// breadth-first flood (8-neighbours, row-major seeds, fixed neighbour order) reaches.
fn nearest_source(w: usize, h: usize, inside: &[bool]) -> Vec<u32> {
    let mut source = vec![u32::MAX; w * h];
    let mut queue = std::collections::VecDeque::new();
    for (i, &b) in inside.iter().enumerate() {
        if b {
            source[i] = i as u32;
            queue.push_back(i);
        }
    }
    while let Some(i) = queue.pop_front() {
        let (x, y) = ((i % w) as i64, (i / w) as i64);
        for (dx, dy) in [(-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (1, -1), (-1, 1), (1, 1)] {
            let (nx, ny) = (x + dx, y + dy);
            if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                continue;
            }
            let j = ny as usize * w + nx as usize;
            if source[j] == u32::MAX {
                source[j] = source[i];
                queue.push_back(j);
            }
        }
    }
    source
}
