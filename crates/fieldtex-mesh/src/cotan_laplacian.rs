//! The cotangent Laplacian (Pinkall & Polthier 1993; MacNeal 1949), robust to
//! zero-area and needle triangles.
//!
//! **Sign convention.** [`cotan_laplacian`] returns the `#V × #V` positive
//! semi-definite "stiffness" matrix `L` with
//! `L_ij = −w_ij` for an edge `ij`, `L_ii = Σ_j w_ij`, and
//! `w_ij = ½ (cot α_ij + cot β_ij)` summed over the triangles sharing the edge (one on a
//! boundary, more on a non-manifold edge). So `L · 1 = 0`, `uᵀ L u` is the Dirichlet
//! energy of the piecewise-linear `u`, and `−M⁻¹ L` approximates the Laplace–Beltrami
//! operator (`M` from [`crate::mass_matrix`]). Both triangles are stored; the pattern is
//! the edge graph plus the diagonal (every vertex has a stored diagonal, unreferenced ones
//! a `0`).
//!
//! **Robustness (clamped cotangents).** Per triangle the cotangent at a corner is computed
//! from the two edge vectors leaving it as `cot = (u · v) / |u × v|`, i.e. the intrinsic
//! formula `(b² + c² − a²) / (4 A)`, but with the area floored relative to the triangle's
//! own size: `A_eff = max(A, δ · (a² + b² + c²))`, `δ =`
//! [`CotanOptions::relative_area_floor`] (default `1e-6`). This bounds every `|cot|` by
//! `1 / (4δ)` (`2.5e5`), so zero-area ("cap" or collinear) triangles and needles stay
//! finite, and because a triangle's cotan block is its Dirichlet form divided by its area,
//! replacing `A` by a larger `A_eff` scales a positive semi-definite 3×3 block by a
//! positive factor: `L` stays symmetric positive semi-definite with `L · 1 = 0`. Only
//! triangles flatter than `δ` are touched (an equilateral triangle has `A / Σl² ≈ 0.144`;
//! a needle with apex angle θ has `≈ θ / 4`, so the floor acts below θ ≈ 4e-6 rad).
//! Triangles whose three corners coincide, or with a non-finite corner, contribute
//! nothing. Both counts are returned as [`Warning`]s (`cotan-area-floored`,
//! `cotan-triangles-skipped`) and in [`CotanStats`].
//!
//! **DEC Hodge star.** [`hodge_star1`] gives the same edge cotangents for DEC code, with
//! the Hodge-star clamp (`|cot| ≤ 1e3`, `⋆1 ≥ 0`) as an explicit option
//! ([`HodgeStarClamp`]); `fieldtex-fields`' `Dec` uses it with the clamp.
//!
//! Not implemented: intrinsic Delaunay edge flips (Sharp, Soliman & Crane 2019), which
//! would make every weight non-negative but change the sparsity pattern away from the mesh
//! edges; obtuse triangles therefore still give negative weights, as in libigl.
//!
//! **Speed.** Half-cotangents are computed once per triangle in parallel while a
//! counting sort groups triangle corners by vertex; then the CSC matrix is assembled
//! directly, column by column in parallel (gather the column's ≈ 12 entries, sort, merge
//! duplicates). No global triplet sort and no [`crate::Topology`] are needed.
//! Deterministic for any thread count: duplicates are summed in triangle order and the
//! parallel chunks are fixed. [`cotan_edge_weights`] gives the per-edge weights indexed
//! like a [`crate::Topology`] for DEC code, [`cotan_laplacian_triplets`] the raw
//! triplets.

use crate::areas::{VertexAreaKind, mixed_voronoi_corner_areas, triangle_area};
use crate::{MeshError, Topology, TriMesh};
use fieldtex_core::Warning;
use fieldtex_core::vec3;
use fieldtex_linalg::SparseMatrix;
use rayon::prelude::*;

/// `(row, col, value)` entries of a sparse matrix.
pub type Triplets = Vec<(usize, usize, f64)>;

/// Options of the cotan Laplacian.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CotanOptions {
    /// `δ` in `A_eff = max(A, δ Σ l²)` (module docs). Default `1e-6`; must be `> 0`
    /// (values `≤ 0` or non-finite are replaced by the default).
    pub relative_area_floor: f64,
}

impl Default for CotanOptions {
    fn default() -> Self {
        Self { relative_area_floor: 1e-6 }
    }
}

/// What the robust cotangent computation had to do.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CotanStats {
    /// Triangles whose area was raised to the floor (zero-area, caps, extreme needles).
    pub n_floored: usize,
    /// Triangles skipped: all corners coincide or a corner is not finite.
    pub n_skipped: usize,
    /// First floored triangle, if any.
    pub first_floored: Option<usize>,
    /// First skipped triangle, if any.
    pub first_skipped: Option<usize>,
}

impl CotanStats {
    /// The warnings describing these statistics (empty when nothing was touched).
    pub fn warnings(&self) -> Vec<Warning> {
        let mut w = Vec::new();
        if let Some(f) = self.first_floored {
            w.push(Warning::new(
                "cotan-area-floored",
                format!(
                    "{} nearly degenerate triangles (first: {f}) had their area floored in the \
                     cotan Laplacian, so their weights stay finite",
                    self.n_floored
                ),
            ));
        }
        if let Some(f) = self.first_skipped {
            w.push(Warning::new(
                "cotan-triangles-skipped",
                format!(
                    "{} triangles (first: {f}) were left out of the cotan Laplacian because \
                     their corners coincide or are not finite; run `fieldtex repair`",
                    self.n_skipped
                ),
            ));
        }
        w
    }
}

/// Triangles per parallel task (fixed: results never depend on the thread count).
const FACE_CHUNK: usize = 4096;
/// Columns per parallel task in the assembly (fixed for the same reason).
const COL_CHUNK: usize = 1024;

/// Half-cotangent weights of one triangle: `w[i] = ½ cot` of the angle opposite the
/// edge from corner `i` to corner `(i + 1) % 3` (the angle at corner `(i + 2) % 3`),
/// and a status: `0` ok, `1` area floored, `2` skipped.
#[inline]
fn face_half_cotans(p: [[f64; 3]; 3], floor: f64) -> ([f64; 3], u8) {
    let e = [vec3::sub(p[1], p[0]), vec3::sub(p[2], p[1]), vec3::sub(p[0], p[2])];
    let sum_l2 = vec3::norm2(e[0]) + vec3::norm2(e[1]) + vec3::norm2(e[2]);
    if !(sum_l2 > 0.0 && sum_l2.is_finite()) {
        return ([0.0; 3], 2);
    }
    let dbl_area = vec3::norm(vec3::cross(e[0], e[1]));
    let dbl_floor = 2.0 * floor * sum_l2;
    let (denom, status) = if dbl_area >= dbl_floor { (dbl_area, 0) } else { (dbl_floor, 1) };
    // Corner k: the edges leaving it are e[k] and −e[(k + 2) % 3].
    let s = -0.5 / denom;
    let w = [vec3::dot(e[2], e[1]) * s, vec3::dot(e[0], e[2]) * s, vec3::dot(e[1], e[0]) * s];
    (w, status)
}

/// Per-face pass shared by every builder: `#F` records `[w0, w1, w2, m]` (the
/// half-cotangents and, for barycentric mass, a third of the area), `#F × 3` mixed
/// Voronoi shares when those are asked for, and the statistics. Indices must be checked.
fn face_pass(
    mesh: &TriMesh,
    floor: f64,
    mass: Option<VertexAreaKind>,
) -> (Vec<[f64; 4]>, Vec<[f64; 3]>, CotanStats) {
    let nf = mesh.n_triangles();
    let voronoi = mass == Some(VertexAreaKind::MixedVoronoi);
    let mut recs = vec![[0.0; 4]; nf];
    let mut shares = vec![[0.0; 3]; if voronoi { nf } else { 0 }];
    let mut share_chunks: Vec<&mut [[f64; 3]]> = shares.chunks_mut(FACE_CHUNK).collect();
    share_chunks.resize_with(nf.div_ceil(FACE_CHUNK), Default::default);
    let per_chunk: Vec<CotanStats> = recs
        .par_chunks_mut(FACE_CHUNK)
        .zip(share_chunks.into_par_iter())
        .enumerate()
        .map(|(c, (rc, sc))| {
            let mut st = CotanStats::default();
            for (o, rec) in rc.iter_mut().enumerate() {
                let f = c * FACE_CHUNK + o;
                let t = mesh.triangles[f];
                let p = [0, 1, 2].map(|i| mesh.positions[t[i] as usize]);
                let (w, status) = face_half_cotans(p, floor);
                if status == 1 {
                    st.n_floored += 1;
                    st.first_floored.get_or_insert(f);
                } else if status == 2 {
                    st.n_skipped += 1;
                    st.first_skipped.get_or_insert(f);
                }
                let m = match mass {
                    Some(VertexAreaKind::Barycentric) => triangle_area(p[0], p[1], p[2]) / 3.0,
                    Some(VertexAreaKind::MixedVoronoi) => {
                        sc[o] = mixed_voronoi_corner_areas(p[0], p[1], p[2]);
                        0.0
                    }
                    None => 0.0,
                };
                *rec = [w[0], w[1], w[2], m];
            }
            st
        })
        .collect();
    let mut stats = CotanStats::default();
    for st in per_chunk {
        stats.n_floored += st.n_floored;
        stats.n_skipped += st.n_skipped;
        stats.first_floored = stats.first_floored.or(st.first_floored);
        stats.first_skipped = stats.first_skipped.or(st.first_skipped);
    }
    (recs, shares, stats)
}

/// `#F × 3` half-cotangent weights (`w[f][i]` for the edge between corners `i` and
/// `i + 1`, the convention of [`Topology::face_edges`]) and what had to be clamped.
pub fn cotan_face_weights(
    mesh: &TriMesh,
    options: &CotanOptions,
) -> Result<(Vec<[f64; 3]>, CotanStats), MeshError> {
    crate::checks::check_indices(mesh)?;
    let (recs, _, stats) = face_pass(mesh, effective_floor(options), None);
    Ok((recs.into_iter().map(|r| [r[0], r[1], r[2]]).collect(), stats))
}

/// `#E` edge weights `w_e = ½ Σ cot` over the triangles of edge `e`, indexed like
/// `topology.edges` (which must be built from `mesh.triangles`). Degenerate edges
/// `[a, a]` get 0.
pub fn cotan_edge_weights(
    mesh: &TriMesh,
    topology: &Topology,
    options: &CotanOptions,
) -> Result<(Vec<f64>, Vec<Warning>), MeshError> {
    if topology.n_faces() != mesh.n_triangles() || topology.n_vertices != mesh.n_vertices() {
        return Err(MeshError::Precondition {
            operation: "cotan_edge_weights",
            requirement: "a topology built from this mesh",
            found: format!(
                "{} faces / {} vertices vs {} / {}",
                topology.n_faces(),
                topology.n_vertices,
                mesh.n_triangles(),
                mesh.n_vertices()
            ),
        });
    }
    let (fw, stats) = cotan_face_weights(mesh, options)?;
    let mut w = vec![0.0; topology.n_edges()];
    for (f, fe) in topology.face_edges.iter().enumerate() {
        for i in 0..3 {
            w[fe[i] as usize] += fw[f][i];
        }
    }
    for (e, ed) in topology.edges.iter().enumerate() {
        if ed[0] == ed[1] {
            w[e] = 0.0;
        }
    }
    Ok((w, stats.warnings()))
}

/// The Hodge-star clamp of DEC operators, an explicit option of [`hodge_star1`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HodgeStarClamp {
    /// Largest accepted `|cot|` of a triangle angle. Default `1e3` (about 0.06° or
    /// 179.94°).
    pub cot_limit: f64,
}

impl Default for HodgeStarClamp {
    fn default() -> Self {
        Self { cot_limit: 1e3 }
    }
}

/// The DEC Hodge star on edges, `⋆1_e = ½ Σ cot` over the triangles of edge `e`
/// (indexed like `topology.edges`, built from `mesh.triangles`), with each cotangent
/// computed as `(a · b) / (2 A_f)` from the caller's `face_areas` (`#F`, positive; DEC
/// code floors zero areas itself). With `clamp`, every cotangent is limited to
/// `±cot_limit` and every edge weight raised to `≥ 0` (a negative dual length has no
/// meaning for a Hodge star) — the rule of paper D's field design; without it the raw
/// weights are returned (what conformal maps need). Returns the weights and the number
/// of clamped edges (0 without a clamp).
///
/// This and the Laplacian's relative area floor (module docs) are the workspace's two
/// cotangent robustness rules, both here: the floor keeps `L` positive semi-definite and
/// keeps negative (obtuse) weights; the Hodge-star clamp makes `⋆1 ≥ 0`.
pub fn hodge_star1(
    mesh: &TriMesh,
    topology: &Topology,
    face_areas: &[f64],
    clamp: Option<&HodgeStarClamp>,
) -> (Vec<f64>, usize) {
    let ne = topology.n_edges();
    let limit = clamp.map_or(f64::INFINITY, |c| c.cot_limit);
    let mut star1 = vec![0.0; ne];
    let mut hit_limit = vec![false; ne];
    for (f, &area) in face_areas.iter().enumerate().take(mesh.n_triangles()) {
        let p = mesh.triangle_positions(f);
        let twice_area = 2.0 * area;
        for k in 0..3 {
            // Angle at corner k is opposite the edge between corners k+1 and k+2.
            let a = vec3::sub(p[(k + 1) % 3], p[k]);
            let b = vec3::sub(p[(k + 2) % 3], p[k]);
            let raw_cot = vec3::dot(a, b) / twice_area;
            let cot = raw_cot.clamp(-limit, limit);
            let e = topology.face_edges[f][(k + 1) % 3] as usize;
            if cot != raw_cot {
                hit_limit[e] = true;
            }
            star1[e] += 0.5 * cot;
        }
    }
    let mut clamped = 0usize;
    if clamp.is_some() {
        for e in 0..ne {
            if star1[e] < 0.0 || hit_limit[e] {
                clamped += 1;
                star1[e] = star1[e].max(0.0);
            }
        }
    }
    (star1, clamped)
}

/// The counting step of the two groupings below: `offsets[v]..offsets[v + 1]` is the
/// range of vertex `v`'s corners (`n + 1` prefix sums of the corner counts).
fn corner_offsets(n: usize, triangles: &[[u32; 3]]) -> Vec<u32> {
    let mut offsets = vec![0u32; n + 1];
    for t in triangles {
        for &v in t {
            offsets[v as usize + 1] += 1;
        }
    }
    for v in 0..n {
        offsets[v + 1] += offsets[v];
    }
    offsets
}

/// Corners grouped by vertex (counting sort): `items[offsets[v]..offsets[v + 1]]` are
/// the corners `3 f + i` with `triangles[f][i] == v`, in triangle order.
pub(crate) fn vertex_corners(n: usize, triangles: &[[u32; 3]]) -> (Vec<u32>, Vec<u32>) {
    let offsets = corner_offsets(n, triangles);
    let mut next = offsets.clone();
    let mut items = vec![0u32; 3 * triangles.len()];
    for (f, t) in triangles.iter().enumerate() {
        for (i, &v) in t.iter().enumerate() {
            let k = &mut next[v as usize];
            items[*k as usize] = 3 * f as u32 + i as u32;
            *k += 1;
        }
    }
    (offsets, items)
}

/// Corners grouped by vertex (counting sort), with their two neighbours:
/// `items[offsets[v]..offsets[v + 1]]` are `[next, prev, 3 f + i]` for every corner `i`
/// of triangle `f` at `v`, in triangle order (`u32::MAX` for a neighbour equal to `v`).
fn vertex_corner_neighbours(n: usize, triangles: &[[u32; 3]]) -> (Vec<u32>, Vec<[u32; 3]>) {
    let offsets = corner_offsets(n, triangles);
    let mut next = offsets.clone();
    let mut items = vec![[0u32; 3]; 3 * triangles.len()];
    for (f, t) in triangles.iter().enumerate() {
        for i in 0..3 {
            let v = t[i];
            let other = |u: u32| if u == v { u32::MAX } else { u };
            let k = &mut next[v as usize];
            items[*k as usize] =
                [other(t[(i + 1) % 3]), other(t[(i + 2) % 3]), 3 * f as u32 + i as u32];
            *k += 1;
        }
    }
    (offsets, items)
}

/// Stable insertion sort by row (columns hold ≈ 12 entries), so duplicates are adjacent
/// and in triangle order.
#[inline]
fn sort_by_row<T: Copy>(buf: &mut [(u32, T)]) {
    for k in 1..buf.len() {
        let x = buf[k];
        let mut j = k;
        while j > 0 && buf[j - 1].0 > x.0 {
            buf[j] = buf[j - 1];
            j -= 1;
        }
        buf[j] = x;
    }
}

/// Splits `data` into consecutive mutable pieces of the given lengths.
fn split_lengths<'a, T>(mut data: &'a mut [T], lengths: &[usize]) -> Vec<&'a mut [T]> {
    let mut out = Vec::with_capacity(lengths.len());
    for &len in lengths {
        let (head, tail) = data.split_at_mut(len);
        out.push(head);
        data = tail;
    }
    out
}

/// CSC arrays of `L`, the masses (empty when `mass` is `None`) and the statistics.
/// Indices must be checked.
///
/// The per-face pass runs beside a counting sort of the corners by vertex that also
/// records each corner's two neighbours; then two column-parallel passes count the
/// distinct rows of every column (from the neighbour lists alone) and fill the final
/// arrays directly, reading each corner's face record once. Intermediate arrays are kept
/// few and small: on large meshes cache misses and first-touch page faults cost more
/// than the arithmetic.
#[allow(clippy::type_complexity)]
fn assemble(
    mesh: &TriMesh,
    floor: f64,
    mass: Option<VertexAreaKind>,
) -> (Vec<usize>, Vec<usize>, Vec<f64>, Vec<f64>, CotanStats) {
    let n = mesh.n_vertices();
    let tris = &mesh.triangles;
    let ((recs, shares, stats), (offsets, items)) =
        rayon::join(|| face_pass(mesh, floor, mass), || vertex_corner_neighbours(n, tris));
    let col_items = |v: usize| &items[offsets[v] as usize..offsets[v + 1] as usize];
    // Pass 1: column lengths (distinct neighbours + the diagonal).
    let mut col_ptr = vec![0usize; n + 1];
    col_ptr[1..].par_chunks_mut(COL_CHUNK).enumerate().for_each(|(c, lens)| {
        let mut buf: Vec<(u32, ())> = Vec::with_capacity(32);
        for (o, len) in lens.iter_mut().enumerate() {
            buf.clear();
            for it in col_items(c * COL_CHUNK + o) {
                buf.extend(it[..2].iter().filter(|&&r| r != u32::MAX).map(|&r| (r, ())));
            }
            sort_by_row(&mut buf);
            *len = 1 + buf.len() - buf.windows(2).filter(|w| w[0].0 == w[1].0).count();
        }
    });
    for v in 0..n {
        col_ptr[v + 1] += col_ptr[v];
    }
    // Pass 2: fill rows and values; the diagonal is the sum of the column's weights.
    let nnz = col_ptr[n];
    let mut row_idx = vec![0usize; nnz];
    let mut values = vec![0.0f64; nnz];
    let mut masses = vec![0.0f64; if mass.is_some() { n } else { 0 }];
    let n_chunks = n.div_ceil(COL_CHUNK);
    let chunk_nnz: Vec<usize> = (0..n_chunks)
        .map(|c| col_ptr[((c + 1) * COL_CHUNK).min(n)] - col_ptr[c * COL_CHUNK])
        .collect();
    let mass_lens: Vec<usize> = (0..n_chunks)
        .map(|c| if mass.is_some() { ((c + 1) * COL_CHUNK).min(n) - c * COL_CHUNK } else { 0 })
        .collect();
    let parts: Vec<_> = split_lengths(&mut row_idx, &chunk_nnz)
        .into_iter()
        .zip(split_lengths(&mut values, &chunk_nnz))
        .zip(split_lengths(&mut masses, &mass_lens))
        .enumerate()
        .collect();
    let voronoi = mass == Some(VertexAreaKind::MixedVoronoi);
    parts.into_par_iter().for_each(|(c, ((ri, va), ma))| {
        let (c0, c1) = (c * COL_CHUNK, ((c + 1) * COL_CHUNK).min(n));
        let base = col_ptr[c0];
        let mut buf: Vec<(u32, f64)> = Vec::with_capacity(32);
        for v in c0..c1 {
            buf.clear();
            let mut m = 0.0;
            for &[nx, pv, corner] in col_items(v) {
                let (f, i) = ((corner / 3) as usize, (corner % 3) as usize);
                let rec = recs[f];
                if nx != u32::MAX {
                    buf.push((nx, rec[i]));
                }
                if pv != u32::MAX {
                    buf.push((pv, rec[(i + 2) % 3]));
                }
                m += if voronoi { shares[f][i] } else { rec[3] };
            }
            if !ma.is_empty() {
                ma[v - c0] = m;
            }
            sort_by_row(&mut buf);
            let mut k = col_ptr[v] - base;
            let mut diag = 0.0;
            let mut diag_at = None;
            let mut last = u32::MAX;
            for &(r, w) in buf.iter() {
                diag += w;
                if diag_at.is_none() && r as usize > v {
                    diag_at = Some(k);
                    ri[k] = v;
                    k += 1;
                }
                if r == last {
                    va[k - 1] -= w;
                } else {
                    ri[k] = r as usize;
                    va[k] = -w;
                    k += 1;
                    last = r;
                }
            }
            let d = diag_at.unwrap_or(k);
            ri[d] = v;
            va[d] = diag;
        }
    });
    (col_ptr, row_idx, values, masses, stats)
}

fn effective_floor(options: &CotanOptions) -> f64 {
    if options.relative_area_floor > 0.0 && options.relative_area_floor.is_finite() {
        options.relative_area_floor
    } else {
        CotanOptions::default().relative_area_floor
    }
}

/// The `#V × #V` cotan Laplacian `L` (positive semi-definite, `L · 1 = 0`; module docs)
/// with default options, and warnings about clamped or skipped triangles.
pub fn cotan_laplacian(mesh: &TriMesh) -> Result<(SparseMatrix, Vec<Warning>), MeshError> {
    let (l, stats) = cotan_laplacian_with(mesh, &CotanOptions::default())?;
    Ok((l, stats.warnings()))
}

/// [`cotan_laplacian`] with explicit options, returning the statistics.
pub fn cotan_laplacian_with(
    mesh: &TriMesh,
    options: &CotanOptions,
) -> Result<(SparseMatrix, CotanStats), MeshError> {
    crate::checks::check_indices(mesh)?;
    let n = mesh.n_vertices();
    let (col_ptr, row_idx, values, _, stats) = assemble(mesh, effective_floor(options), None);
    let l = SparseMatrix::from_csc(n, n, col_ptr, row_idx, values)?;
    Ok((l, stats))
}

/// `L` and the `#V` lumped masses of the given kind in one pass over the corners
/// (what most solvers need: `M + t L`, `L + P`); the masses equal
/// [`crate::lumped_mass`] bit for bit.
pub fn cotan_laplacian_and_mass(
    mesh: &TriMesh,
    options: &CotanOptions,
    mass: VertexAreaKind,
) -> Result<(SparseMatrix, Vec<f64>, CotanStats), MeshError> {
    crate::checks::check_indices(mesh)?;
    let n = mesh.n_vertices();
    let (col_ptr, row_idx, values, m, stats) = assemble(mesh, effective_floor(options), Some(mass));
    let l = SparseMatrix::from_csc(n, n, col_ptr, row_idx, values)?;
    Ok((l, m, stats))
}

/// The entries of `L` as `(row, col, value)` triplets (both triangles and the diagonal,
/// duplicates already summed), for assembling `L` into a larger system.
pub fn cotan_laplacian_triplets(
    mesh: &TriMesh,
    options: &CotanOptions,
) -> Result<(Triplets, Vec<Warning>), MeshError> {
    crate::checks::check_indices(mesh)?;
    let (col_ptr, row_idx, values, _, stats) = assemble(mesh, effective_floor(options), None);
    let mut t = Vec::with_capacity(values.len());
    for c in 0..mesh.n_vertices() {
        for k in col_ptr[c]..col_ptr[c + 1] {
            t.push((row_idx[k], c, values[k]));
        }
    }
    Ok((t, stats.warnings()))
}

#[cfg(test)]
#[path = "cotan_laplacian_tests.rs"]
mod tests;
