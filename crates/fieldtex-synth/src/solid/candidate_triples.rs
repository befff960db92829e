//! Candidate triples with crossbar consistency (Dong, Lefebvre, Tong & Drettakis 2008,
//! §4; paper E §2).
//!
//! A *coordinate triple* `(p₀, p₁, p₂)` names one pixel in each plane exemplar. Around
//! a voxel the three `N × N` exemplar neighbourhoods meet pairwise along three sticks
//! ("crossbars") of `N` samples, `h` apart: with the plane conventions of
//! [`super::solid_exemplar`], exemplar `j`'s *column* through `p_j` (its second
//! coordinate, local axis `j + 1`) must agree with exemplar `j + 1`'s *row* through
//! `p_{j+1}` (its first coordinate, the same local axis). The crossbar error of a triple
//! is the sum over `j` of the squared differences of those stick pairs' matched values
//! (RGB, plus the feature channel when the exemplars carry masks:
//! [`super::solid_exemplar::PlaneLevel::matched`]).
//!
//! For each pixel `p` of plane `i` the table keeps the `N_T` triples with `pᵢ = p` of
//! least crossbar error, best first. Search (coarse to fine, in place of Dong 2008's
//! exhaustive search, named in the pipeline notes): the `K₁ = 8` best partners in plane
//! `i + 1` (by the stick shared with `p`) and in plane `i + 2` are found by brute force
//! over a regular sub-grid *pool* of about [`super::SolidAnalysisOptions::pool`] pixels
//! (stride `σ`), then refined at full resolution: every pixel of the `σ × σ` cell
//! around each pool hit is scored and the `K₁` best of all of them are kept (without
//! this the partners' coordinates were quantised to the pool stride, which put the
//! partner planes up to `σ/2` pixels out of phase with a stripe exemplar). All
//! `K₁²` pairs are then scored with their third stick; each stick pair's error is weighted
//! by the product of its planes' [`super::SolidAnalysisOptions::plane_weights`]. Dong's extra test that a triple be
//! consistent with a neighbouring pixel's triple is not applied.

use super::solid_exemplar::{PlaneExemplar, SolidAnalysisOptions};
use fieldtex_linalg::stats::{KdScratch, KdTree};
use rayon::prelude::*;

const K1: usize = 8;

/// Pool strides above which the partners come from a kd-tree instead (large exemplars:
/// the refinement cells grow with the stride squared, so the pool search costs about
/// `W H √(W H)` per plane; at 512² it took minutes).
const TREE_ABOVE_STRIDE: usize = 4;

/// Points a kd-tree partner search examines (best-bin-first, after the `K₁` first).
pub(crate) const TREE_CHECKS: usize = 128;

/// Exemplar pixel coordinates, one per plane (xy, yz, zx).
pub type Triple = [[i32; 2]; 3];

/// Candidate triples of one plane at one level: `n_t` per pixel, best first.
#[derive(Clone, Debug)]
pub struct CandidateTriples {
    /// Plane whose pixels index the table.
    pub plane: usize,
    pub width: usize,
    pub height: usize,
    pub n_t: usize,
    /// `width × height × n_t` triples (pixel-major).
    pub triples: Vec<Triple>,
}

impl CandidateTriples {
    /// The `k`-th candidate of pixel `(x, y)` (wrapped).
    #[inline]
    pub fn get(&self, x: i32, y: i32, k: usize) -> &Triple {
        let pixel = wrapped(y, self.height) * self.width + wrapped(x, self.width);
        &self.triples[pixel * self.n_t + k]
    }
}

/// The first `k` candidates of every pixel of one [`CandidateTriples`] table, with the
/// coordinates as `u16`: what the correction reads (it takes `k` of the `N_T`), packed
/// `k` to a pixel so that a predicted pixel's candidates share one or two cache lines
/// instead of sitting `N_T` triples apart (12 bytes a triple instead of 24; with the
/// defaults 24 bytes a pixel instead of 288). The same triples, so the same results.
#[derive(Clone, Debug)]
pub(crate) struct CandidateHeads {
    width: usize,
    height: usize,
    k: usize,
    triples: Vec<[[u16; 2]; 3]>,
}

impl CandidateHeads {
    /// The first `k` (at most `N_T`) candidates of every pixel of `table`, whose
    /// coordinates lie inside their exemplars (below `2¹⁶`, as every table's do).
    pub(crate) fn new(table: &CandidateTriples, k: usize) -> Self {
        let k = k.clamp(1, table.n_t);
        let mut triples = Vec::with_capacity(table.width * table.height * k);
        for pixel in table.triples.chunks_exact(table.n_t) {
            triples.extend(pixel[..k].iter().map(|t| t.map(|xy| xy.map(|v| v as u16))));
        }
        Self { width: table.width, height: table.height, k, triples }
    }

    /// The `kk`-th candidate (`kk < k`) of pixel `(x, y)` (wrapped), as
    /// [`CandidateTriples::get`] gives it.
    #[inline]
    pub(crate) fn get(&self, x: i32, y: i32, kk: usize) -> Triple {
        let pixel = wrapped(y, self.height) * self.width + wrapped(x, self.width);
        self.triples[pixel * self.k + kk].map(|xy| xy.map(i32::from))
    }

    /// Asks the CPU to fetch pixel `(x, y)`'s candidates ahead of [`Self::get`] (no
    /// effect on results).
    #[inline]
    pub(crate) fn prefetch(&self, x: i32, y: i32) {
        let pixel = wrapped(y, self.height) * self.width + wrapped(x, self.width);
        crate::prefetch::prefetch_read(&self.triples[pixel * self.k]);
    }
}

/// `x` wrapped into `[0, n)` (`x.rem_euclid(n)`, without the division when `x` is
/// already inside, as exemplar coordinates mostly are).
#[inline]
pub(crate) fn wrapped(x: i32, n: usize) -> usize {
    if (x as u32) < n as u32 { x as usize } else { x.rem_euclid(n as i32) as usize }
}

/// Row and column sticks of every pixel (`N × ch` floats each).
struct Sticks {
    rows: Vec<f32>,
    cols: Vec<f32>,
    len: usize,
}

fn sticks(colors: &[[f32; 4]], ch: usize, w: usize, hgt: usize, h: usize, n: usize) -> Sticks {
    let len = ch * n;
    let half = (n / 2) as i64;
    let mut rows = vec![0.0f32; w * hgt * len];
    let mut cols = vec![0.0f32; w * hgt * len];
    rows.par_chunks_mut(len).zip(cols.par_chunks_mut(len)).enumerate().for_each(|(p, (r, c))| {
        let (x, y) = ((p % w) as i64, (p / w) as i64);
        for (k, t) in (-half..=half).enumerate() {
            let xx = (x + t * h as i64).rem_euclid(w as i64) as usize;
            let yy = (y + t * h as i64).rem_euclid(hgt as i64) as usize;
            r[ch * k..ch * (k + 1)].copy_from_slice(&colors[y as usize * w + xx][..ch]);
            c[ch * k..ch * (k + 1)].copy_from_slice(&colors[yy * w + x as usize][..ch]);
        }
    });
    Sticks { rows, cols, len }
}

#[inline]
fn dist2(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// A regular sub-grid of about `size` pixels and its stride.
fn pool(w: usize, hgt: usize, size: usize) -> (Vec<usize>, usize) {
    let stride = ((w * hgt) as f64 / size.max(1) as f64).sqrt().ceil().max(1.0) as usize;
    let mut out = Vec::new();
    for y in (0..hgt).step_by(stride) {
        for x in (0..w).step_by(stride) {
            out.push(y * w + x);
        }
    }
    (out, stride)
}

/// Keeps `(d, q)` in `best` (sorted, at most `K₁`, ties to the lower index).
#[inline]
fn keep(best: &mut Vec<(f32, usize)>, d: f32, q: usize) {
    if best.len() < K1 || (d, q) < best[best.len() - 1] {
        let at = best.partition_point(|b| (b.0, b.1) <= (d, q));
        best.insert(at, (d, q));
        best.truncate(K1);
    }
}

/// The pool pixels' sticks transposed, stick element-major (`len` rows of one value
/// per pool pixel), so that the pool scan computes the distances of all pool pixels
/// at once (one vector lane per pixel) while each still sums its squared differences
/// in stick order, exactly as [`dist2`] does.
fn pool_sticks(sticks: &[f32], len: usize, pool: &[usize]) -> Vec<f32> {
    let mut out = vec![0.0f32; len * pool.len()];
    for (i, &q) in pool.iter().enumerate() {
        for k in 0..len {
            out[k * pool.len() + i] = sticks[q * len + k];
        }
    }
    out
}

/// Per-thread scratch of [`nearest`]: the pool distances and, per exemplar pixel, the
/// query that last visited it (so the refinement cells are deduplicated without
/// sorting).
#[derive(Default)]
struct Scratch {
    dists: Vec<f32>,
    visited: Vec<u32>,
    query: u32,
    kd: KdScratch,
    found: Vec<(usize, f32)>,
}

/// Where the `K₁` partners of a stick are searched: the pool and its cells, or (large
/// exemplars) a kd-tree over every pixel's stick.
enum PartnerSearch {
    Pool { pooled: Vec<f32>, pool: (Vec<usize>, usize) },
    Tree(KdTree),
}

impl PartnerSearch {
    fn new(sticks: &[f32], len: usize, w: usize, hgt: usize, pool_size: usize) -> Self {
        let pool = pool(w, hgt, pool_size);
        if pool.1 > TREE_ABOVE_STRIDE {
            PartnerSearch::Tree(KdTree::build(sticks, len))
        } else {
            PartnerSearch::Pool { pooled: pool_sticks(sticks, len, &pool.0), pool }
        }
    }

    /// The `K₁` nearest sticks to `query` (by distance, then index).
    #[allow(clippy::too_many_arguments)]
    fn nearest(
        &self,
        query: &[f32],
        sticks: &[f32],
        len: usize,
        w: usize,
        hgt: usize,
        scratch: &mut Scratch,
    ) -> Vec<(f32, usize)> {
        match self {
            PartnerSearch::Pool { pooled, pool } => {
                nearest(query, sticks, pooled, len, pool, w, hgt, scratch)
            }
            PartnerSearch::Tree(tree) => {
                tree.k_nearest(query, K1, TREE_CHECKS, &mut scratch.kd, &mut scratch.found);
                scratch.found.iter().map(|&(q, d)| (d, q)).collect()
            }
        }
    }
}

/// `dist2(a, b)` if it is at most `bound`, else some value above `bound`: the same
/// sequential sum as [`dist2`], abandoned once it exceeds `bound` (partial distance
/// search), so an accepted distance has the same bits.
#[inline]
fn dist2_within(a: &[f32], b: &[f32], bound: f32) -> f32 {
    let mut acc = 0.0f32;
    for (ca, cb) in a.chunks(4).zip(b.chunks(4)) {
        for (x, y) in ca.iter().zip(cb) {
            acc += (x - y) * (x - y);
        }
        if acc > bound {
            return acc;
        }
    }
    acc
}

/// The `K₁` pixels whose `stick(q)` is nearest `query`: the best of the pool, then the
/// best of the full-resolution `stride × stride` cells around those (module docs).
/// `pooled` is [`pool_sticks`] of `sticks` over the pool. The result depends on the
/// set of pixels scored only ([`keep`] orders by distance, then index), so the cells are
/// visited in any order, each once.
#[allow(clippy::too_many_arguments)]
fn nearest(
    query: &[f32],
    sticks: &[f32],
    pooled: &[f32],
    len: usize,
    pool: &(Vec<usize>, usize),
    w: usize,
    hgt: usize,
    scratch: &mut Scratch,
) -> Vec<(f32, usize)> {
    let (pool, stride) = (&pool.0, pool.1);
    let dists = &mut scratch.dists;
    dists.clear();
    dists.resize(pool.len(), 0.0);
    for (&a, row) in query.iter().zip(pooled.chunks_exact(pool.len())) {
        for (d, &b) in dists.iter_mut().zip(row) {
            let t = a - b;
            *d += t * t;
        }
    }
    let mut coarse: Vec<(f32, usize)> = Vec::with_capacity(K1 + 1);
    for (&d, &q) in dists.iter().zip(pool) {
        keep(&mut coarse, d, q);
    }
    if stride <= 1 {
        return coarse;
    }
    if scratch.visited.len() != w * hgt || scratch.query == u32::MAX {
        scratch.visited.clear();
        scratch.visited.resize(w * hgt, 0);
        scratch.query = 0;
    }
    scratch.query += 1;
    let stamp = scratch.query;
    let lo = -((stride / 2) as i64);
    let hi = lo + stride as i64;
    let mut best: Vec<(f32, usize)> = Vec::with_capacity(K1 + 1);
    for &(_, q) in &coarse {
        let (qx, qy) = ((q % w) as i64, (q / w) as i64);
        for dy in lo..hi {
            let y = (qy + dy).rem_euclid(hgt as i64) as usize;
            for dx in lo..hi {
                let x = (qx + dx).rem_euclid(w as i64) as usize;
                let c = y * w + x;
                if scratch.visited[c] == stamp {
                    continue;
                }
                scratch.visited[c] = stamp;
                let bound = if best.len() < K1 { f32::INFINITY } else { best[K1 - 1].0 };
                let d = dist2_within(query, &sticks[c * len..(c + 1) * len], bound);
                if d <= bound {
                    keep(&mut best, d, c);
                }
            }
        }
    }
    best
}

/// The candidate-triple table of plane `plane` at level `c` of spacing `h` (module
/// docs). `planes[j]` is plane `j`'s analysed exemplar.
pub fn candidate_triples(
    planes: [&PlaneExemplar; 3],
    c: usize,
    plane: usize,
    h: usize,
    options: &SolidAnalysisOptions,
) -> CandidateTriples {
    let n = options.neighbourhood;
    let st: Vec<Sticks> = planes
        .iter()
        .map(|e| {
            let l = &e.levels[c];
            sticks(&l.matched, l.channels, e.width, e.height, h, n)
        })
        .collect();
    let (i, j, k) = (plane, (plane + 1) % 3, (plane + 2) % 3);
    let (ei, ej, ek) = (planes[i], planes[j], planes[k]);
    let (dj, dk) = ((ej.width, ej.height), (ek.width, ek.height));
    let len = st[0].len;
    let n_t = options.triples;
    // Stick pairs weighted by the product of their planes' weights (the partner
    // searches themselves are unweighted, so a zero-weight plane still gets sensible
    // coordinates).
    let w = options.plane_weights;
    let (wij, wik, wjk) = (w[i] * w[j], w[i] * w[k], w[j] * w[k]);
    let coord = |e: &PlaneExemplar, p: usize| [(p % e.width) as i32, (p / e.width) as i32];
    let (search_j, search_k) = (
        PartnerSearch::new(&st[j].rows, len, dj.0, dj.1, options.pool),
        PartnerSearch::new(&st[k].cols, len, dk.0, dk.1, options.pool),
    );
    let mut triples = vec![[[0i32; 2]; 3]; ei.width * ei.height * n_t];
    triples.par_chunks_mut(n_t).enumerate().for_each_init(Scratch::default, |scratch, (p, out)| {
        // Column of plane i ↔ row of plane j; row of plane i ↔ column of plane k;
        // column of plane j ↔ row of plane k.
        let (col_i, row_i) =
            (&st[i].cols[p * len..(p + 1) * len], &st[i].rows[p * len..(p + 1) * len]);
        let qs = search_j.nearest(col_i, &st[j].rows, len, dj.0, dj.1, scratch);
        let rs = search_k.nearest(row_i, &st[k].cols, len, dk.0, dk.1, scratch);
        let mut scored: Vec<(f32, usize, usize)> = Vec::with_capacity(qs.len() * rs.len());
        for &(eq, q) in &qs {
            for &(er, r) in &rs {
                let e3 =
                    dist2(&st[j].cols[q * len..(q + 1) * len], &st[k].rows[r * len..(r + 1) * len]);
                scored.push((wij * eq + wik * er + wjk * e3, q, r));
            }
        }
        scored.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        for (slot, s) in out.iter_mut().enumerate() {
            let (_, q, r) = scored[slot.min(scored.len() - 1)];
            let mut t = [[0i32; 2]; 3];
            t[i] = coord(ei, p);
            t[j] = coord(ej, q);
            t[k] = coord(ek, r);
            *s = t;
        }
    });
    CandidateTriples { plane, width: ei.width, height: ei.height, n_t, triples }
}

#[cfg(test)]
mod layout_tests {
    use super::*;

    /// Sticks of a deterministic pseudo-random `w × h` "exemplar" (`len` floats each).
    fn random_sticks(w: usize, h: usize, len: usize, salt: &str) -> Vec<f32> {
        (0..w * h * len).map(|i| fieldtex_core::rng::hash_unit(3, salt, i as u64) as f32).collect()
    }

    #[test]
    fn the_transposed_pool_scan_gives_the_scalar_scans_partners_and_distances() {
        let (w, h, len) = (37, 29, 15);
        let sticks = random_sticks(w, h, len, "sticks");
        let queries = random_sticks(23, 1, len, "queries");
        let pool = pool(w, h, 64);
        assert!(pool.1 > 1);
        let pooled = pool_sticks(&sticks, len, &pool.0);
        let mut scratch = Scratch::default();
        for query in queries.chunks_exact(len) {
            let got = nearest(query, &sticks, &pooled, len, &pool, w, h, &mut scratch);
            // The scalar reference: the pool by `dist2`, then the cells around its hits.
            let mut coarse = Vec::new();
            for &q in &pool.0 {
                keep(&mut coarse, dist2(query, &sticks[q * len..(q + 1) * len]), q);
            }
            let mut cells = Vec::new();
            let s = pool.1 as i64;
            for &(_, q) in &coarse {
                for dy in -(s / 2)..s - s / 2 {
                    for dx in -(s / 2)..s - s / 2 {
                        let x = ((q % w) as i64 + dx).rem_euclid(w as i64) as usize;
                        let y = ((q / w) as i64 + dy).rem_euclid(h as i64) as usize;
                        cells.push(y * w + x);
                    }
                }
            }
            cells.sort_unstable();
            cells.dedup();
            let mut want = Vec::new();
            for q in cells {
                keep(&mut want, dist2(query, &sticks[q * len..(q + 1) * len]), q);
            }
            assert_eq!(got.len(), K1);
            let bits =
                |v: &[(f32, usize)]| v.iter().map(|(d, q)| (d.to_bits(), *q)).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&want));
        }
    }

    /// Large exemplars search their partners in a kd-tree: on smooth sticks (a blurred
    /// random image, like real neighbourhoods) its `K₁` partners are about as near as
    /// the exhaustive ones and no farther than the pool search's.
    #[test]
    fn large_exemplars_find_near_partners_in_a_tree() {
        let (w, h, len) = (160, 160, 15);
        // Sticks: 15 consecutive values of a smooth periodic signal plus noise.
        let f = |x: usize, y: usize, k: usize| {
            let (x, y) = (x as f32, (y + k) as f32);
            (0.13 * x + 0.07 * y).sin()
                + (0.05 * x - 0.11 * y).cos()
                + 0.1
                    * fieldtex_core::rng::hash_unit(9, "s", (y as usize * w + x as usize) as u64)
                        as f32
        };
        let sticks: Vec<f32> =
            (0..w * h).flat_map(|p| (0..len).map(move |k| f(p % w, p / w, k))).collect();
        let search = PartnerSearch::new(&sticks, len, w, h, 1024);
        assert!(matches!(search, PartnerSearch::Tree(_)));
        let pool_search = {
            let pool = pool(w, h, 1024);
            PartnerSearch::Pool { pooled: pool_sticks(&sticks, len, &pool.0), pool }
        };
        let mut scratch = Scratch::default();
        let (mut tree_sum, mut pool_sum, mut exact_sum) = (0.0f64, 0.0f64, 0.0f64);
        for q in (0..w * h).step_by(397) {
            let query: Vec<f32> =
                (0..len).map(|k| f((q * 7) % w, (q / w + 3) % h, k) + 0.05).collect();
            let t = search.nearest(&query, &sticks, len, w, h, &mut scratch);
            let p = pool_search.nearest(&query, &sticks, len, w, h, &mut scratch);
            let mut all: Vec<f32> = sticks.chunks_exact(len).map(|c| dist2(&query, c)).collect();
            all.sort_by(f32::total_cmp);
            assert_eq!(t.len(), K1);
            tree_sum += t.iter().map(|v| v.0 as f64).sum::<f64>();
            pool_sum += p.iter().map(|v| v.0 as f64).sum::<f64>();
            exact_sum += all[..K1].iter().map(|&v| v as f64).sum::<f64>();
        }
        eprintln!("K1 distance sums: exact {exact_sum:.3}, tree {tree_sum:.3}, pool {pool_sum:.3}");
        assert!(tree_sum <= 1.5 * exact_sum, "tree {tree_sum}, exact {exact_sum}");
        assert!(tree_sum <= 1.05 * pool_sum, "tree {tree_sum}, pool {pool_sum}");
    }

    #[test]
    fn candidate_heads_hold_each_pixels_first_k_triples() {
        let (w, h, n_t) = (11, 7, 5);
        let triples: Vec<Triple> = (0..w * h * n_t)
            .map(|i| {
                let v = |s: &str, m: usize| {
                    (fieldtex_core::rng::hash_unit(5, s, i as u64) * m as f64) as i32
                };
                [[v("a", w), v("b", h)], [v("c", w), v("d", h)], [v("e", w), v("f", h)]]
            })
            .collect();
        let table = CandidateTriples { plane: 0, width: w, height: h, n_t, triples };
        let heads = CandidateHeads::new(&table, 3);
        for y in -8..16 {
            for x in -12..24 {
                for kk in 0..3 {
                    assert_eq!(heads.get(x, y, kk), *table.get(x, y, kk), "({x}, {y}) #{kk}");
                }
            }
        }
    }
}
