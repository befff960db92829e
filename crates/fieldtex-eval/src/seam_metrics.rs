//! Seams of any textured mesh: total length of the edges where the per-corner UVs jump,
//! and the colour jump across them compared with the colour change between neighbouring
//! texels inside charts (issue 13, paper C evaluation).
//!
//! Across a seam edge, five points along the edge are sampled in each of its two
//! triangles, each pulled half a texel into its triangle (towards the centroid), with
//! bilinear lookups; the jump is the mean absolute RGB difference (sRGB values, mean
//! over channels). Inside charts, each triangle compares the texture at its UV centroid
//! with the texel one to the right (when that point is still inside the triangle). The
//! ratio of the two means is the figure of merit (≈ 1: seams are invisible).

use fieldtex_core::{Image, vec3};
use fieldtex_mesh::{Topology, TriMesh};
use serde::Serialize;

/// See the module docs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SeamMetrics {
    /// Number of seam edges.
    pub seam_edges: usize,
    /// Total 3-D length of seam edges.
    pub seam_length: f64,
    /// `seam_length / √(surface area)` (scale-free).
    pub seam_length_relative: f64,
    /// Mean colour jump across seams.
    pub seam_colour_jump: f64,
    /// Mean colour change between neighbouring texels inside charts.
    pub interior_colour_jump: f64,
    /// `seam_colour_jump / interior_colour_jump`.
    pub ratio: f64,
}

fn sample(tex: &Image, uv: [f64; 2]) -> [f32; 4] {
    tex.sample_bilinear(uv[0] * tex.width as f64, (1.0 - uv[1]) * tex.height as f64)
}

fn diff(a: [f32; 4], b: [f32; 4]) -> f64 {
    ((a[0] - b[0]).abs() + (a[1] - b[1]).abs() + (a[2] - b[2]).abs()) as f64 / 3.0
}

/// Seam statistics of `mesh` (with per-corner UVs; `None` without) textured by `tex`.
pub fn seam_metrics(mesh: &TriMesh, tex: &Image) -> Option<SeamMetrics> {
    seam_metrics_where(mesh, tex, &|_| true)
}

/// [`seam_metrics`] over the seam edges `[a, b]` (vertex ids) that `counts` accepts;
/// the interior jump is over every triangle as before.
pub fn seam_metrics_where(
    mesh: &TriMesh,
    tex: &Image,
    counts: &dyn Fn([u32; 2]) -> bool,
) -> Option<SeamMetrics> {
    let uvs = mesh.uvs.as_ref()?;
    let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
    let uv_of = |f: usize, v: u32| -> [f64; 2] {
        let k = (0..3).find(|&k| mesh.triangles[f][k] == v).unwrap_or(0);
        uvs.values[uvs.indices[f][k] as usize]
    };
    let centroid = |f: usize| {
        let c = uvs.indices[f].map(|i| uvs.values[i as usize]);
        [(c[0][0] + c[1][0] + c[2][0]) / 3.0, (c[0][1] + c[1][1] + c[2][1]) / 3.0]
    };
    let texel = 1.0 / tex.width.max(tex.height) as f64;
    let pull = |p: [f64; 2], c: [f64; 2]| {
        let d = [c[0] - p[0], c[1] - p[1]];
        let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
        if l <= 0.5 * texel {
            c
        } else {
            [p[0] + d[0] * 0.5 * texel / l, p[1] + d[1] * 0.5 * texel / l]
        }
    };
    let (mut n, mut length, mut jump, mut jn) = (0usize, 0.0, 0.0, 0usize);
    for e in 0..topo.n_edges() {
        let fs = topo.edge_faces(e);
        if fs.len() != 2 {
            continue;
        }
        let [a, b] = topo.edges[e];
        let (f0, f1) = (fs[0] as usize, fs[1] as usize);
        let (a0, b0, a1, b1) = (uv_of(f0, a), uv_of(f0, b), uv_of(f1, a), uv_of(f1, b));
        let d = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).abs() + (p[1] - q[1]).abs();
        if (d(a0, a1) <= 1e-9 && d(b0, b1) <= 1e-9) || !counts([a, b]) {
            continue;
        }
        n += 1;
        length += vec3::norm(vec3::sub(mesh.positions[b as usize], mesh.positions[a as usize]));
        let (c0, c1) = (centroid(f0), centroid(f1));
        for k in 1..=5 {
            let t = k as f64 / 6.0;
            let p0 = [a0[0] + t * (b0[0] - a0[0]), a0[1] + t * (b0[1] - a0[1])];
            let p1 = [a1[0] + t * (b1[0] - a1[0]), a1[1] + t * (b1[1] - a1[1])];
            jump += diff(sample(tex, pull(p0, c0)), sample(tex, pull(p1, c1)));
            jn += 1;
        }
    }
    let (mut inner, mut inn) = (0.0, 0usize);
    for f in 0..mesh.n_triangles() {
        let c = uvs.indices[f].map(|i| uvs.values[i as usize]);
        let g = centroid(f);
        let q = [g[0] + 1.0 / tex.width as f64, g[1]];
        let det =
            (c[1][0] - c[0][0]) * (c[2][1] - c[0][1]) - (c[1][1] - c[0][1]) * (c[2][0] - c[0][0]);
        if det.abs() <= 0.0 {
            continue;
        }
        let l1 =
            ((q[0] - c[0][0]) * (c[2][1] - c[0][1]) - (q[1] - c[0][1]) * (c[2][0] - c[0][0])) / det;
        let l2 =
            ((c[1][0] - c[0][0]) * (q[1] - c[0][1]) - (c[1][1] - c[0][1]) * (q[0] - c[0][0])) / det;
        if l1 < 0.0 || l2 < 0.0 || l1 + l2 > 1.0 {
            continue;
        }
        inner += diff(sample(tex, g), sample(tex, q));
        inn += 1;
    }
    let area: f64 = (0..mesh.n_triangles())
        .map(|f| {
            let p = mesh.triangle_positions(f);
            0.5 * vec3::norm(vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0])))
        })
        .sum();
    let seam_colour_jump = if jn > 0 { jump / jn as f64 } else { 0.0 };
    let interior_colour_jump = if inn > 0 { inner / inn as f64 } else { f64::NAN };
    Some(SeamMetrics {
        seam_edges: n,
        seam_length: length,
        seam_length_relative: length / area.sqrt().max(f64::MIN_POSITIVE),
        seam_colour_jump,
        interior_colour_jump,
        ratio: seam_colour_jump / interior_colour_jump,
    })
}
