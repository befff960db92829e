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
use rayon::prelude::*;

const K1: usize = 8;

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

    /// Asks the CPU to fetch pixel `(x, y)`'s first candidates ahead of [`Self::get`]
    /// (no effect on results).
    #[inline]
    pub fn prefetch(&self, x: i32, y: i32) {
        let pixel = wrapped(y, self.height) * self.width + wrapped(x, self.width);
        crate::prefetch::prefetch_read(&self.triples[pixel * self.n_t]);
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

/// The `K₁` pixels whose `stick(q)` is nearest `query`: the best of the pool, then the
/// best of the full-resolution `stride × stride` cells around those (module docs).
fn nearest(
    query: &[f32],
    sticks: &[f32],
    len: usize,
    pool: &(Vec<usize>, usize),
    w: usize,
    hgt: usize,
) -> Vec<(f32, usize)> {
    let (pool, stride) = (&pool.0, pool.1);
    let mut coarse: Vec<(f32, usize)> = Vec::with_capacity(K1 + 1);
    for &q in pool {
        keep(&mut coarse, dist2(query, &sticks[q * len..(q + 1) * len]), q);
    }
    if stride <= 1 {
        return coarse;
    }
    let mut cells: Vec<usize> = Vec::with_capacity(coarse.len() * stride * stride);
    let lo = -((stride / 2) as i64);
    let hi = lo + stride as i64;
    for &(_, q) in &coarse {
        let (qx, qy) = ((q % w) as i64, (q / w) as i64);
        for dy in lo..hi {
            for dx in lo..hi {
                let x = (qx + dx).rem_euclid(w as i64) as usize;
                let y = (qy + dy).rem_euclid(hgt as i64) as usize;
                cells.push(y * w + x);
            }
        }
    }
    cells.sort_unstable();
    cells.dedup();
    let mut best: Vec<(f32, usize)> = Vec::with_capacity(K1 + 1);
    for q in cells {
        keep(&mut best, dist2(query, &sticks[q * len..(q + 1) * len]), q);
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
    let pool_j = pool(ej.width, ej.height, options.pool);
    let pool_k = pool(ek.width, ek.height, options.pool);
    let (dj, dk) = ((ej.width, ej.height), (ek.width, ek.height));
    let len = st[0].len;
    let n_t = options.triples;
    // Stick pairs weighted by the product of their planes' weights (the partner
    // searches themselves are unweighted, so a zero-weight plane still gets sensible
    // coordinates).
    let w = options.plane_weights;
    let (wij, wik, wjk) = (w[i] * w[j], w[i] * w[k], w[j] * w[k]);
    let coord = |e: &PlaneExemplar, p: usize| [(p % e.width) as i32, (p / e.width) as i32];
    let mut triples = vec![[[0i32; 2]; 3]; ei.width * ei.height * n_t];
    triples.par_chunks_mut(n_t).enumerate().for_each(|(p, out)| {
        // Column of plane i ↔ row of plane j; row of plane i ↔ column of plane k;
        // column of plane j ↔ row of plane k.
        let qs =
            nearest(&st[i].cols[p * len..(p + 1) * len], &st[j].rows, len, &pool_j, dj.0, dj.1);
        let rs =
            nearest(&st[i].rows[p * len..(p + 1) * len], &st[k].cols, len, &pool_k, dk.0, dk.1);
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
