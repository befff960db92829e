//! Least Squares Conformal Maps (Lévy, Petitjean, Ray & Maillot 2002, "Least Squares
//! Conformal Maps for Automatic Texture Atlas Generation", §3) for one chart.
//!
//! A map `U = u + iv` is conformal on a triangle when `∂U/∂z̄ = 0`. With the triangle in
//! an orthonormal frame of its plane (complex corners `z_k`, area `A`), the linear
//! interpolant gives `∂U/∂z̄ = i/(4A) Σ_k e_k U_k` with `e_k = z_{k+2} − z_{k+1}` (the
//! edge opposite corner `k`, counter-clockwise). LSCM minimises
//! `Σ_T |Σ_k e_k U_k|² / A_T` (the paper's eq. 5 up to a constant), two real rows per
//! triangle:
//! `Re: Σ (Re e_k · u_k − Im e_k · v_k)`, `Im: Σ (Im e_k · u_k + Re e_k · v_k)`, each
//! scaled by `1/√A_T`.
//!
//! **Variant:** two pinned vertices (the farthest pair of boundary vertices, pinned at
//! their 3-D distance apart on the u axis), the rest solved in the least-squares sense
//! through the normal equations `MᵀM x = −MᵀM_p x_p`, assembled directly as the
//! `2n × 2n` SPD matrix (unknowns interleaved `u_0, v_0, u_1, …`) and factored with the
//! sparse Cholesky of `fieldtex-linalg`. The free-boundary spectral variant (Mullen et
//! al. 2008) is not implemented.
//!
//! Zero-area triangles keep their rows with the area clamped to `10⁻⁶` of the chart's
//! mean triangle area, which asks their corners to stay collinear in UV. The result is
//! mirrored if its total signed area is negative. [`planar_projection`] is the fallback
//! when the solve fails. [`flattening_defects`] finds flipped or collapsed triangles and
//! crossings of the chart's boundary in UV (a locally injective map of a disk with a
//! simple boundary is injective, so both being absent means the chart does not overlap
//! itself).

use crate::chart_topology::ChartMesh;
use crate::face_graph::{FaceGraph, NONE};
use fieldtex_core::vec3::{self, V3};
use fieldtex_linalg::{Cholesky, LinalgError, SparseMatrix};
use fieldtex_mesh::TriMesh;

/// Complex corners `z_k` of a triangle in an orthonormal frame of its plane; the longest
/// edge is the base so that zero-area (collinear) triangles stay well defined.
fn local_corners(p: [V3; 3]) -> [[f64; 2]; 3] {
    let len = |k: usize| vec3::norm(vec3::sub(p[(k + 1) % 3], p[k]));
    let k = (0..3).max_by(|&a, &b| len(a).total_cmp(&len(b)).then(b.cmp(&a))).unwrap_or(0);
    let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
    let e1 = vec3::sub(b, a);
    let l = vec3::norm(e1);
    let mut z = [[0.0; 2]; 3];
    if l > 0.0 {
        let x = vec3::scale(e1, 1.0 / l);
        let e2 = vec3::sub(c, a);
        let cx = vec3::dot(e2, x);
        let cy = vec3::norm(vec3::sub(e2, vec3::scale(x, cx)));
        z[k] = [0.0, 0.0];
        z[(k + 1) % 3] = [l, 0.0];
        z[(k + 2) % 3] = [cx, cy];
    }
    z
}

/// The two real residual rows of one triangle with complex corners `z`, over its six
/// scalar unknowns (`u_k` at `2k`, `v_k` at `2k + 1`), scaled by `w` (module docs).
fn face_rows(z: &[[f64; 2]; 3], w: f64) -> [[f64; 6]; 2] {
    let mut rows = [[0.0f64; 6]; 2];
    for k in 0..3 {
        let a = z[(k + 2) % 3];
        let b = z[(k + 1) % 3];
        let (ex, ey) = (a[0] - b[0], a[1] - b[1]);
        rows[0][2 * k] = ex * w;
        rows[0][2 * k + 1] = -ey * w;
        rows[1][2 * k] = ey * w;
        rows[1][2 * k + 1] = ex * w;
    }
    rows
}

/// LSCM of `chart` (module docs): one UV per local vertex.
pub fn lscm(
    chart: &ChartMesh,
    mesh: &TriMesh,
    graph: &FaceGraph,
) -> Result<Vec<[f64; 2]>, LinalgError> {
    let n = chart.n_vertices;
    let pos: Vec<V3> = chart.vertex_global.iter().map(|&v| mesh.positions[v as usize]).collect();
    if chart.faces.len() == 1 {
        let z = local_corners(mesh.triangle_positions(chart.faces[0] as usize));
        let mut uv = vec![[0.0; 2]; n];
        for k in 0..3 {
            uv[chart.corners[0][k] as usize] = z[k];
        }
        return Ok(uv);
    }
    // Pins: farthest pair among boundary vertices (all vertices if there is none).
    let boundary = chart.boundary_vertices(graph);
    let cand: Vec<usize> = {
        let b: Vec<usize> = (0..n).filter(|&v| boundary[v]).collect();
        if b.len() >= 2 { b } else { (0..n).collect() }
    };
    let farthest = |from: usize| -> usize {
        let mut best = cand[0];
        let mut bd = -1.0;
        for &v in &cand {
            let d = vec3::norm2(vec3::sub(pos[v], pos[from]));
            if d > bd {
                bd = d;
                best = v;
            }
        }
        best
    };
    let pa = farthest(cand[0]);
    let pb = farthest(pa);
    let dist = vec3::norm(vec3::sub(pos[pa], pos[pb]));
    if pa == pb || dist.is_nan() || dist <= 0.0 {
        return Err(LinalgError::InvalidArgument {
            what: "pin distance",
            value: dist,
            reason: "chart has no extent",
        });
    }
    let mut free = vec![u32::MAX; n];
    let mut nfree = 0u32;
    for (v, slot) in free.iter_mut().enumerate() {
        if v != pa && v != pb {
            *slot = nfree;
            nfree += 1;
        }
    }
    let pinned = |v: usize| -> Option<[f64; 2]> {
        if v == pa {
            Some([0.0, 0.0])
        } else if v == pb {
            Some([dist, 0.0])
        } else {
            None
        }
    };
    let m = 2 * nfree as usize;
    let mean_area: f64 = chart.faces.iter().map(|&f| graph.areas[f as usize]).sum::<f64>()
        / chart.faces.len() as f64;
    let floor = (1e-6 * mean_area).max(f64::MIN_POSITIVE);
    let pattern = BlockPattern::build(chart, &free, nfree as usize);
    let mut blocks = vec![[0.0f64; 4]; pattern.rows.len()];
    let mut rhs = vec![0.0; m];
    for (lf, &f) in chart.faces.iter().enumerate() {
        let z = local_corners(mesh.triangle_positions(f as usize));
        let rows = face_rows(&z, 1.0 / graph.areas[f as usize].max(floor).sqrt());
        // Global unknown of each local scalar (None when pinned) and pinned values.
        let mut gidx = [None; 6];
        let mut xp = [0.0; 6];
        for k in 0..3 {
            let v = chart.corners[lf][k] as usize;
            match pinned(v) {
                Some(x) => {
                    xp[2 * k] = x[0];
                    xp[2 * k + 1] = x[1];
                }
                None => {
                    gidx[2 * k] = Some(2 * free[v] as usize);
                    gidx[2 * k + 1] = Some(2 * free[v] as usize + 1);
                }
            }
        }
        // Normal-equation block Σ_rows r rᵀ and right-hand side −Σ_rows r (r · x_p).
        for r in &rows {
            let rp: f64 = r.iter().zip(&xp).map(|(c, x)| c * x).sum();
            for i in 0..6 {
                if let Some(gi) = gidx[i] {
                    rhs[gi] -= r[i] * rp;
                }
            }
        }
        // Entries are added in the order a triplet list would sum them (face by face,
        // row-major within a face), so the matrix is the same to the last bit.
        let mut bidx = [[0usize; 3]; 3];
        for k in 0..3 {
            for l in 0..3 {
                if let (Some(gk), Some(gl)) = (gidx[2 * k], gidx[2 * l]) {
                    bidx[k][l] = pattern.find(gl / 2, gk / 2);
                }
            }
        }
        for i in 0..6 {
            let Some(gi) = gidx[i] else { continue };
            for j in 0..6 {
                let Some(gj) = gidx[j] else { continue };
                blocks[bidx[i / 2][j / 2]][2 * (gi % 2) + gj % 2] +=
                    rows[0][i] * rows[0][j] + rows[1][i] * rows[1][j];
            }
        }
    }
    let mut uv = vec![[0.0; 2]; n];
    uv[pa] = [0.0, 0.0];
    uv[pb] = [dist, 0.0];
    if m > 0 {
        let a = pattern.into_matrix(&blocks)?;
        let chol = Cholesky::factor(&a)?;
        let x = chol.solve(&rhs)?;
        for v in 0..n {
            if free[v] != u32::MAX {
                let k = 2 * free[v] as usize;
                uv[v] = [x[k], x[k + 1]];
            }
        }
    }
    orient_positive(chart, &mut uv);
    Ok(uv)
}

/// LSCM of `chart` held near a given map `anchor` (one UV per local vertex) instead of
/// by two pins: minimises the LSCM energy plus `weight · Σ_v (A_v / Ā) |U_v − anchor_v|²`
/// (`A_v` a third of the 3-D area of the chart's faces at `v`, `Ā` their mean). The
/// LSCM rows fix angles at the scale of a few triangles; the anchor keeps what varies
/// slowly (the conformal factor, the chart's placement) from `anchor`. Used by
/// [`crate::conformal::conformal_polish`].
pub fn lscm_anchored(
    chart: &ChartMesh,
    mesh: &TriMesh,
    graph: &FaceGraph,
    anchor: &[[f64; 2]],
    weight: f64,
) -> Result<Vec<[f64; 2]>, LinalgError> {
    let n = chart.n_vertices;
    let free: Vec<u32> = (0..n as u32).collect();
    let mean_area: f64 = chart.faces.iter().map(|&f| graph.areas[f as usize]).sum::<f64>()
        / chart.faces.len().max(1) as f64;
    let floor = (1e-6 * mean_area).max(f64::MIN_POSITIVE);
    let mut vertex_area = vec![0.0f64; n];
    for (lf, &f) in chart.faces.iter().enumerate() {
        for &v in &chart.corners[lf] {
            vertex_area[v as usize] += graph.areas[f as usize] / 3.0;
        }
    }
    let mean_va = vertex_area.iter().sum::<f64>() / n.max(1) as f64;
    let pattern = BlockPattern::build(chart, &free, n);
    let mut blocks = vec![[0.0f64; 4]; pattern.rows.len()];
    let mut rhs = vec![0.0; 2 * n];
    for (lf, &f) in chart.faces.iter().enumerate() {
        let z = local_corners(mesh.triangle_positions(f as usize));
        let rows = face_rows(&z, 1.0 / graph.areas[f as usize].max(floor).sqrt());
        let gidx: [usize; 6] =
            std::array::from_fn(|i| 2 * chart.corners[lf][i / 2] as usize + i % 2);
        let mut bidx = [[0usize; 3]; 3];
        for k in 0..3 {
            for l in 0..3 {
                bidx[k][l] = pattern.find(gidx[2 * l] / 2, gidx[2 * k] / 2);
            }
        }
        for i in 0..6 {
            for j in 0..6 {
                blocks[bidx[i / 2][j / 2]][2 * (gidx[i] % 2) + gidx[j] % 2] +=
                    rows[0][i] * rows[0][j] + rows[1][i] * rows[1][j];
            }
        }
    }
    for v in 0..n {
        let m = weight * vertex_area[v] / mean_va.max(f64::MIN_POSITIVE);
        let b = pattern.find(v, v);
        blocks[b][0] += m;
        blocks[b][3] += m;
        rhs[2 * v] += m * anchor[v][0];
        rhs[2 * v + 1] += m * anchor[v][1];
    }
    let a = pattern.into_matrix(&blocks)?;
    let chol = Cholesky::factor(&a)?;
    let x = chol.solve(&rhs)?;
    Ok((0..n).map(|v| [x[2 * v], x[2 * v + 1]]).collect())
}

/// Sparsity of the LSCM normal matrix by free-vertex pairs: for block column `j` (a
/// free vertex), the free vertices `rows[start[j]..start[j + 1]]` (ascending, `j`
/// included) that share a triangle with it. Each pair is a 2 × 2 block of scalar
/// entries (`u`, `v` interleaved), so the matrix is written as CSC directly instead of
/// through 36 triplets per triangle and a sort.
struct BlockPattern {
    start: Vec<usize>,
    rows: Vec<u32>,
}

impl BlockPattern {
    fn build(chart: &ChartMesh, free: &[u32], nfree: usize) -> Self {
        let mut count = vec![0usize; nfree + 1];
        for c in &chart.corners {
            for &a in c {
                if free[a as usize] != u32::MAX {
                    count[free[a as usize] as usize + 1] += 3;
                }
            }
        }
        for j in 0..nfree {
            count[j + 1] += count[j];
        }
        let mut rows = vec![0u32; count[nfree]];
        let mut next = count.clone();
        for c in &chart.corners {
            for &a in c {
                let fa = free[a as usize];
                if fa == u32::MAX {
                    continue;
                }
                for &b in c {
                    let fb = free[b as usize];
                    if fb != u32::MAX {
                        rows[next[fa as usize]] = fb;
                        next[fa as usize] += 1;
                    }
                }
            }
        }
        // Sort and deduplicate each column in place, compacting as we go.
        let mut start = Vec::with_capacity(nfree + 1);
        start.push(0);
        let mut out = 0;
        for j in 0..nfree {
            let (lo, hi) = (count[j], next[j]);
            rows[lo..hi].sort_unstable();
            let col_start = out;
            for k in lo..hi {
                if out == col_start || rows[out - 1] != rows[k] {
                    rows[out] = rows[k];
                    out += 1;
                }
            }
            start.push(out);
        }
        rows.truncate(out);
        Self { start, rows }
    }

    /// Index of block (row vertex `i`, column vertex `j`).
    #[inline]
    fn find(&self, j: usize, i: usize) -> usize {
        let col = &self.rows[self.start[j]..self.start[j + 1]];
        self.start[j] + col.iter().position(|&r| r as usize == i).expect("pattern has the pair")
    }

    /// The `2n × 2n` matrix; `blocks[b]` is `[uu, uv, vu, vv]` of block `b` (row part
    /// first).
    fn into_matrix(self, blocks: &[[f64; 4]]) -> Result<SparseMatrix, LinalgError> {
        let n = self.start.len() - 1;
        let mut col_ptr = Vec::with_capacity(2 * n + 1);
        let mut row_idx = Vec::with_capacity(4 * self.rows.len());
        let mut values = Vec::with_capacity(4 * self.rows.len());
        col_ptr.push(0);
        for j in 0..n {
            for c in 0..2 {
                let col = self.start[j]..self.start[j + 1];
                for (&i, blk) in self.rows[col.clone()].iter().zip(&blocks[col]) {
                    let i = i as usize;
                    row_idx.extend([2 * i, 2 * i + 1]);
                    values.extend([blk[c], blk[2 + c]]);
                }
                col_ptr.push(row_idx.len());
            }
        }
        SparseMatrix::from_csc(2 * n, 2 * n, col_ptr, row_idx, values)
    }
}

/// Orthographic projection onto the plane orthogonal to the chart's mean normal.
pub fn planar_projection(chart: &ChartMesh, mesh: &TriMesh, graph: &FaceGraph) -> Vec<[f64; 2]> {
    let mut s = [0.0; 3];
    for &f in &chart.faces {
        s = vec3::add(s, vec3::scale(graph.normals[f as usize], graph.areas[f as usize]));
    }
    let n = vec3::normalize(s).unwrap_or([0.0, 0.0, 1.0]);
    let x = vec3::any_orthonormal(n);
    let y = vec3::cross(n, x);
    let mut uv: Vec<[f64; 2]> = chart
        .vertex_global
        .iter()
        .map(|&v| {
            let p = mesh.positions[v as usize];
            [vec3::dot(p, x), vec3::dot(p, y)]
        })
        .collect();
    orient_positive(chart, &mut uv);
    uv
}

fn signed_area(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
}

fn orient_positive(chart: &ChartMesh, uv: &mut [[f64; 2]]) {
    let total: f64 = chart
        .corners
        .iter()
        .map(|c| signed_area(uv[c[0] as usize], uv[c[1] as usize], uv[c[2] as usize]))
        .sum();
    if total < 0.0 {
        for p in uv.iter_mut() {
            p[0] = -p[0];
        }
    }
}

/// What is wrong with a flattening.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FlatteningDefects {
    /// Non-degenerate triangles with non-positive or collapsed UV area.
    pub flipped: usize,
    /// `true` when two boundary edges cross in UV.
    pub boundary_crossing: bool,
}

impl FlatteningDefects {
    pub fn is_clean(&self) -> bool {
        self.flipped == 0 && !self.boundary_crossing
    }
}

/// Flipped/collapsed triangles and boundary crossings of `uv` on `chart` (module docs).
/// A triangle counts as collapsed when its UV area is below `10⁻⁹` of its 3-D area
/// after normalising total UV area to total 3-D area.
pub fn flattening_defects(
    chart: &ChartMesh,
    uv: &[[f64; 2]],
    graph: &FaceGraph,
) -> FlatteningDefects {
    let mut d = FlatteningDefects::default();
    if uv.iter().any(|p| !(p[0].is_finite() && p[1].is_finite())) {
        d.flipped = chart.faces.len();
        return d;
    }
    let areas: Vec<f64> = chart
        .corners
        .iter()
        .map(|c| signed_area(uv[c[0] as usize], uv[c[1] as usize], uv[c[2] as usize]))
        .collect();
    let a3: f64 = chart.faces.iter().map(|&f| graph.areas[f as usize]).sum();
    let auv: f64 = areas.iter().map(|a| a.abs()).sum();
    let scale = if auv > 0.0 { a3 / auv } else { 0.0 };
    for (lf, &f) in chart.faces.iter().enumerate() {
        if graph.degenerate[f as usize] {
            continue;
        }
        let scaled = areas[lf] * scale;
        if scaled.is_nan() || scaled <= 1e-9 * graph.areas[f as usize] {
            d.flipped += 1;
        }
    }
    d.boundary_crossing = boundary_crosses(chart, uv, graph);
    d
}

/// `true` when two boundary edges that share no vertex cross or touch.
fn boundary_crosses(chart: &ChartMesh, uv: &[[f64; 2]], graph: &FaceGraph) -> bool {
    let mut edges: Vec<[u32; 2]> = Vec::new();
    for (lf, &f) in chart.faces.iter().enumerate() {
        for i in 0..3 {
            let g = graph.adj[f as usize][i];
            if g == NONE || chart.faces.binary_search(&g).is_err() {
                edges.push([chart.corners[lf][i], chart.corners[lf][(i + 1) % 3]]);
            }
        }
    }
    if edges.len() < 4 {
        return false;
    }
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    let mut total_len = 0.0;
    for e in &edges {
        let (a, b) = (uv[e[0] as usize], uv[e[1] as usize]);
        for k in 0..2 {
            lo[k] = lo[k].min(a[k]).min(b[k]);
            hi[k] = hi[k].max(a[k]).max(b[k]);
        }
        total_len += ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
    }
    let cell = (2.0 * total_len / edges.len() as f64).max(1e-300);
    let nx = (((hi[0] - lo[0]) / cell).floor() as i64 + 1).clamp(1, 1 << 20);
    let ny = (((hi[1] - lo[1]) / cell).floor() as i64 + 1).clamp(1, 1 << 20);
    let cell_of = |x: f64, y: f64| -> (i64, i64) {
        (
            (((x - lo[0]) / cell).floor() as i64).clamp(0, nx - 1),
            (((y - lo[1]) / cell).floor() as i64).clamp(0, ny - 1),
        )
    };
    let mut keyed: Vec<(i64, u32)> = Vec::new();
    for (k, e) in edges.iter().enumerate() {
        let (a, b) = (uv[e[0] as usize], uv[e[1] as usize]);
        let (x0, y0) = cell_of(a[0].min(b[0]), a[1].min(b[1]));
        let (x1, y1) = cell_of(a[0].max(b[0]), a[1].max(b[1]));
        if (x1 - x0 + 1) * (y1 - y0 + 1) > 4096 {
            // A very long edge: test it against everything once, below.
            keyed.push((-1, k as u32));
            continue;
        }
        for y in y0..=y1 {
            for x in x0..=x1 {
                keyed.push((y * nx + x, k as u32));
            }
        }
    }
    keyed.sort_unstable();
    let crosses = |i: u32, j: u32| -> bool {
        let (e, f) = (edges[i as usize], edges[j as usize]);
        if e[0] == f[0] || e[0] == f[1] || e[1] == f[0] || e[1] == f[1] {
            return false;
        }
        segments_intersect(
            uv[e[0] as usize],
            uv[e[1] as usize],
            uv[f[0] as usize],
            uv[f[1] as usize],
        )
    };
    let long: Vec<u32> = keyed.iter().take_while(|k| k.0 == -1).map(|k| k.1).collect();
    for &i in &long {
        for j in 0..edges.len() as u32 {
            if j != i && crosses(i, j) {
                return true;
            }
        }
    }
    let mut s = long.len();
    while s < keyed.len() {
        let mut e = s;
        while e < keyed.len() && keyed[e].0 == keyed[s].0 {
            e += 1;
        }
        for a in s..e {
            for b in a + 1..e {
                if crosses(keyed[a].1, keyed[b].1) {
                    return true;
                }
            }
        }
        s = e;
    }
    false
}

/// Closed segment intersection with exact orientation signs on `f64` inputs.
fn segments_intersect(p1: [f64; 2], p2: [f64; 2], q1: [f64; 2], q2: [f64; 2]) -> bool {
    let orient = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| -> f64 {
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let on_seg = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| -> bool {
        c[0] >= a[0].min(b[0])
            && c[0] <= a[0].max(b[0])
            && c[1] >= a[1].min(b[1])
            && c[1] <= a[1].max(b[1])
    };
    let d1 = orient(q1, q2, p1);
    let d2 = orient(q1, q2, p2);
    let d3 = orient(p1, p2, q1);
    let d4 = orient(p1, p2, q2);
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && on_seg(q1, q2, p1))
        || (d2 == 0.0 && on_seg(q1, q2, p2))
        || (d3 == 0.0 && on_seg(p1, p2, q1))
        || (d4 == 0.0 && on_seg(p1, p2, q2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_tests() {
        assert!(segments_intersect([0.0, 0.0], [1.0, 1.0], [0.0, 1.0], [1.0, 0.0]));
        assert!(!segments_intersect([0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]));
        assert!(segments_intersect([0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [1.0, 1.0]));
    }

    #[test]
    fn anchored_lscm_keeps_a_conformal_anchor_and_follows_a_heavy_one() {
        // A flat grid: its own coordinates, rotated, scaled and moved, are exactly
        // conformal, so the LSCM rows vanish there and the anchor is the minimiser.
        let mesh = fieldtex_mesh::primitives::grid(6, 5, 2.0, 1.5);
        let graph = FaceGraph::build(&mesh);
        let chart =
            ChartMesh::build((0..mesh.n_triangles() as u32).collect(), &graph, &mesh.triangles);
        let (c, s) = (0.6f64, 0.8f64);
        let anchor: Vec<[f64; 2]> = chart
            .vertex_global
            .iter()
            .map(|&v| {
                let p = mesh.positions[v as usize];
                [3.0 * (c * p[0] - s * p[1]) + 1.0, 3.0 * (s * p[0] + c * p[1]) - 2.0]
            })
            .collect();
        let uv = lscm_anchored(&chart, &mesh, &graph, &anchor, 1e-3).unwrap();
        for (a, b) in uv.iter().zip(&anchor) {
            assert!((a[0] - b[0]).abs() + (a[1] - b[1]).abs() < 1e-8, "{a:?} {b:?}");
        }
        // A shear is not conformal: a weak anchor undoes most of it, a heavy one keeps it.
        let sheared: Vec<[f64; 2]> = anchor.iter().map(|p| [p[0] + 0.5 * p[1], p[1]]).collect();
        let shear_left = |uv: &[[f64; 2]]| {
            // Local ids of mesh vertices 0 and 1, the grid's first edge.
            let local = |g: u32| chart.vertex_global.iter().position(|&v| v == g).unwrap();
            let (i, j) = (local(0), local(1));
            let d = |p: &[[f64; 2]]| [p[j][0] - p[i][0], p[j][1] - p[i][1]];
            let (a, b) = (d(uv), d(&sheared));
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
        };
        let heavy = lscm_anchored(&chart, &mesh, &graph, &sheared, 1e6).unwrap();
        let weak = lscm_anchored(&chart, &mesh, &graph, &sheared, 1e-4).unwrap();
        assert!(shear_left(&heavy) < 1e-4);
        assert!(shear_left(&weak) > 100.0 * shear_left(&heavy));
    }

    #[test]
    fn block_pattern_is_the_symmetric_vertex_graph() {
        let mesh = fieldtex_mesh::primitives::grid(4, 3, 1.0, 1.0);
        let graph = FaceGraph::build(&mesh);
        let chart =
            ChartMesh::build((0..mesh.n_triangles() as u32).collect(), &graph, &mesh.triangles);
        // Pin local vertex 0: the others are free, numbered in order.
        let n = chart.n_vertices;
        let free: Vec<u32> = (0..n).map(|v| if v == 0 { u32::MAX } else { v as u32 - 1 }).collect();
        let pat = BlockPattern::build(&chart, &free, n - 1);
        let mut expected = vec![std::collections::BTreeSet::new(); n - 1];
        for c in &chart.corners {
            for &a in c {
                for &b in c {
                    if a != 0 && b != 0 {
                        expected[free[a as usize] as usize].insert(free[b as usize]);
                    }
                }
            }
        }
        for (j, want) in expected.iter().enumerate() {
            let got = &pat.rows[pat.start[j]..pat.start[j + 1]];
            assert_eq!(got, want.iter().copied().collect::<Vec<_>>().as_slice(), "column {j}");
        }
        // Block b = [uu, uv, vu, vv] lands at rows (2i, 2i+1) of columns (2j, 2j+1).
        let blocks: Vec<[f64; 4]> = (0..pat.rows.len())
            .map(|b| [b as f64, b as f64 + 0.25, b as f64 + 0.5, b as f64 + 0.75])
            .collect();
        let (start, rows) = (pat.start.clone(), pat.rows.clone());
        let m = pat.into_matrix(&blocks).unwrap();
        for (j, w) in start.windows(2).enumerate() {
            for (&i, blk) in rows[w[0]..w[1]].iter().zip(&blocks[w[0]..w[1]]) {
                let i = i as usize;
                assert_eq!(m.get(2 * i, 2 * j), blk[0]);
                assert_eq!(m.get(2 * i, 2 * j + 1), blk[1]);
                assert_eq!(m.get(2 * i + 1, 2 * j), blk[2]);
                assert_eq!(m.get(2 * i + 1, 2 * j + 1), blk[3]);
            }
        }
        assert_eq!(m.nnz(), 4 * rows.len());
    }

    #[test]
    fn flat_grid_is_reproduced_up_to_similarity() {
        let mesh = fieldtex_mesh::primitives::grid(6, 4, 3.0, 2.0);
        let graph = FaceGraph::build(&mesh);
        let chart =
            ChartMesh::build((0..mesh.n_triangles() as u32).collect(), &graph, &mesh.triangles);
        let uv = lscm(&chart, &mesh, &graph).unwrap();
        assert!(flattening_defects(&chart, &uv, &graph).is_clean());
        // A similarity: all pairwise distance ratios equal.
        let p = |v: usize| mesh.positions[chart.vertex_global[v] as usize];
        let d3 = |a: usize, b: usize| vec3::norm(vec3::sub(p(a), p(b)));
        let d2 = |a: usize, b: usize| {
            ((uv[a][0] - uv[b][0]).powi(2) + (uv[a][1] - uv[b][1]).powi(2)).sqrt()
        };
        let r0 = d2(0, 1) / d3(0, 1);
        for a in 0..chart.n_vertices {
            for b in (a + 1)..chart.n_vertices {
                assert!((d2(a, b) / d3(a, b) - r0).abs() < 1e-8 * r0);
            }
        }
    }
}
