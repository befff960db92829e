//! Poisson-disk sampling of a triangle mesh surface with a true minimum distance.
//!
//! Dart throwing (Cook 1986, "Stochastic sampling in computer graphics"; on surfaces e.g.
//! Cline, Jeschke, White, Razdan & Wonka 2009): a fixed, dense sequence of uniform
//! candidates (area-weighted triangle choice through Walker's alias table, uniform
//! barycentric coordinates) is scanned
//! in order and a candidate is accepted when no accepted sample lies closer than `r`
//! (Euclidean distance in space, checked exactly through a hash grid with cells of side
//! `r`). So **every pair of samples is at least `r` apart**, and with the default
//! candidate density the set is close to maximal (few gaps wider than `2r`).
//!
//! Candidates come in fixed chunks of 4096, chunk `k` drawn from
//! `fieldtex_core::stream(seed, "poisson-disk-candidates", k)`; chunks are generated in
//! parallel and accepted sequentially, so the output is identical for any thread count.
//! The number of candidates is `candidate_factor · 0.7 · A / r²` (`0.7 A / r²` is about
//! the size of a maximal set on area `A`), capped at
//! [`PoissonDiskOptions::max_candidates`] with a warning.
//!
//! With [`PoissonDiskOptions::target_count`] instead of a radius, `r` is estimated from
//! the area and corrected a few times from the counts obtained; the result is within a
//! few percent of the target, never exact (truncating would leave holes).
//!
//! Not implemented: geodesic (on-surface) distances, Yuksel's (2015) sample elimination.

use crate::areas::triangle_area;
use crate::{MeshError, TriMesh};
use fieldtex_core::Warning;
use fieldtex_core::vec3::{self, V3};
use rand::RngExt;
use rayon::prelude::*;

/// Options of [`poisson_disk_sampling`]; give `radius` or `target_count`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoissonDiskOptions {
    /// Minimum Euclidean distance between samples. Default `None`.
    pub radius: Option<f64>,
    /// Approximate number of samples wanted, used when `radius` is `None`. Default `None`.
    pub target_count: Option<usize>,
    /// Seed of the candidate streams. Default 0.
    pub seed: u64,
    /// Candidates per expected sample. Default 16 (more: closer to maximal, slower).
    pub candidate_factor: f64,
    /// Upper bound on candidates (time guard; memory stays bounded anyway). Default 20
    /// million (a few seconds).
    pub max_candidates: usize,
}

impl Default for PoissonDiskOptions {
    fn default() -> Self {
        Self {
            radius: None,
            target_count: None,
            seed: 0,
            candidate_factor: 16.0,
            max_candidates: 20_000_000,
        }
    }
}

/// A point on the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceSample {
    pub position: V3,
    pub triangle: u32,
    pub barycentric: [f64; 3],
}

/// Samples and the radius they respect.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PoissonDiskSamples {
    pub samples: Vec<SurfaceSample>,
    /// The minimum distance guaranteed between any two samples.
    pub radius: f64,
}

const CHUNK: usize = 4096;
const CHUNKS_PER_BATCH: usize = 32;

/// Open-addressing hash grid of accepted samples: cell → first sample, `next` links.
///
/// Cell coordinates are packed into 21 bits each (wrapping; points of far-apart cells
/// that share a key only cost a distance test, never a wrong answer), and the slot is a
/// *linear* function of the cell so that the 27 neighbours of a cell fall on few cache
/// lines.
struct HashGrid {
    origin: V3,
    inv_cell: f64,
    /// `(packed cell key, first sample)`; `EMPTY` heads mark free slots.
    slots: Vec<(u64, u32)>,
    mask: usize,
    next: Vec<u32>,
    points: Vec<V3>,
    used: usize,
}

const EMPTY: u32 = u32::MAX;
const KEY_BITS: u32 = 21;
const KEY_MASK: i64 = (1 << KEY_BITS) - 1;

/// The 27 cell offsets, the cell itself first, then `x` fastest.
const NEIGHBOUR_ORDER: [[i64; 3]; 27] = {
    let mut out = [[0i64; 3]; 27];
    let mut k = 1;
    let mut i = 0;
    while i < 27 {
        let d = [(i % 3) as i64 - 1, ((i / 3) % 3) as i64 - 1, (i / 9) as i64 - 1];
        if !(d[0] == 0 && d[1] == 0 && d[2] == 0) {
            out[k] = d;
            k += 1;
        }
        i += 1;
    }
    out
};

impl HashGrid {
    fn new(origin: V3, cell: f64, expected: usize) -> Self {
        let cap = (2 * expected.max(16)).next_power_of_two();
        Self {
            origin,
            inv_cell: 1.0 / cell,
            slots: vec![(0, EMPTY); cap],
            mask: cap - 1,
            next: Vec::new(),
            points: Vec::new(),
            used: 0,
        }
    }

    #[inline]
    fn cell(&self, p: V3) -> [i64; 3] {
        [0, 1, 2].map(|k| ((p[k] - self.origin[k]) * self.inv_cell).floor() as i64)
    }

    #[inline]
    fn key(c: [i64; 3]) -> u64 {
        ((c[0] & KEY_MASK) | (c[1] & KEY_MASK) << KEY_BITS | (c[2] & KEY_MASK) << (2 * KEY_BITS))
            as u64
    }

    /// Slot of cell `c`: the one holding its key, or the free slot where it would go.
    #[inline]
    fn slot(&self, c: [i64; 3]) -> usize {
        let key = Self::key(c);
        let h = (c[0] as u64)
            .wrapping_add((c[1] as u64).wrapping_mul(0x9E37_79B1))
            .wrapping_add((c[2] as u64).wrapping_mul(0x85EB_CA77_C2B2_AE63));
        let mut i = h as usize & self.mask;
        while self.slots[i].1 != EMPTY && self.slots[i].0 != key {
            i = (i + 1) & self.mask;
        }
        i
    }

    /// Whether an accepted sample lies closer than `sqrt(r2)` to `p`.
    fn has_neighbour(&self, p: V3, r2: f64) -> bool {
        let c = self.cell(p);
        // Own cell first: near saturation most candidates are rejected there.
        NEIGHBOUR_ORDER.iter().any(|d| {
            let mut s = self.slots[self.slot([c[0] + d[0], c[1] + d[1], c[2] + d[2]])].1;
            while s != EMPTY {
                if vec3::norm2(vec3::sub(self.points[s as usize], p)) < r2 {
                    return true;
                }
                s = self.next[s as usize];
            }
            false
        })
    }

    fn insert(&mut self, p: V3) {
        if 2 * (self.used + 1) > self.slots.len() {
            self.grow();
        }
        let c = self.cell(p);
        let i = self.slot(c);
        if self.slots[i].1 == EMPTY {
            self.slots[i].0 = Self::key(c);
            self.used += 1;
        }
        self.next.push(self.slots[i].1);
        self.slots[i].1 = self.points.len() as u32;
        self.points.push(p);
    }

    fn grow(&mut self) {
        let old = std::mem::replace(&mut self.slots, vec![(0, EMPTY); 2 * self.mask + 2]);
        self.mask = self.slots.len() - 1;
        for (_, head) in old {
            if head != EMPTY {
                // Any point of the bucket gives its cell.
                let i = self.slot(self.cell(self.points[head as usize]));
                self.slots[i] = (Self::key(self.cell(self.points[head as usize])), head);
            }
        }
    }
}

/// Walker's alias table (Vose's construction): `O(1)` area-weighted triangle choice.
struct AliasTable {
    prob: Vec<f64>,
    alias: Vec<u32>,
}

impl AliasTable {
    /// Table for non-negative `weights` with a positive sum (deterministic).
    fn new(weights: &[f64], total: f64) -> Self {
        let n = weights.len();
        let mut prob: Vec<f64> = weights.iter().map(|w| w * n as f64 / total).collect();
        let mut alias: Vec<u32> = (0..n as u32).collect();
        let (mut small, mut large): (Vec<u32>, Vec<u32>) =
            (0..n as u32).partition(|&i| prob[i as usize] < 1.0);
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            alias[s as usize] = l;
            prob[l as usize] -= 1.0 - prob[s as usize];
            if prob[l as usize] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // Leftovers (rounding): keep their own index with certainty, unless they have no
        // area at all (then defer to a triangle that has some).
        let fallback = weights.iter().position(|&w| w > 0.0).unwrap_or(0) as u32;
        for i in small.into_iter().chain(large) {
            if weights[i as usize] > 0.0 {
                prob[i as usize] = 1.0;
            } else {
                prob[i as usize] = 0.0;
                alias[i as usize] = fallback;
            }
        }
        Self { prob, alias }
    }

    #[inline]
    fn pick(&self, u: f64, v: f64) -> usize {
        let n = self.prob.len();
        let i = ((u * n as f64) as usize).min(n - 1);
        if v < self.prob[i] { i } else { self.alias[i] as usize }
    }
}

/// One dart-throwing pass with radius `r` over `n_candidates` candidates.
fn throw(
    mesh: &TriMesh,
    table: &AliasTable,
    total: f64,
    r: f64,
    n_candidates: usize,
    seed: u64,
) -> Vec<SurfaceSample> {
    let origin = mesh.bounding_box().map_or([0.0; 3], |b| b.min);
    let expected = (0.7 * total / (r * r)).min(n_candidates as f64) as usize;
    let mut grid = HashGrid::new(origin, r, expected);
    let mut samples = Vec::with_capacity(expected);
    let n_chunks = n_candidates.div_ceil(CHUNK);
    let r2 = r * r;
    let generate = |batch: usize| -> Vec<Vec<SurfaceSample>> {
        (batch..(batch + CHUNKS_PER_BATCH).min(n_chunks))
            .into_par_iter()
            .map(|k| {
                let mut rng = fieldtex_core::stream(seed, "poisson-disk-candidates", k as u64);
                let len = CHUNK.min(n_candidates - k * CHUNK);
                (0..len)
                    .map(|_| {
                        let (a, a2): (f64, f64) = (rng.random(), rng.random());
                        let (b, c): (f64, f64) = (rng.random(), rng.random());
                        let f = table.pick(a, a2);
                        let s = b.sqrt();
                        let bary = [1.0 - s, s * (1.0 - c), s * c];
                        let p = mesh.triangle_positions(f);
                        let pos = (0..3)
                            .fold([0.0; 3], |acc, i| vec3::add(acc, vec3::scale(p[i], bary[i])));
                        SurfaceSample { position: pos, triangle: f as u32, barycentric: bary }
                    })
                    .collect()
            })
            .collect()
    };
    // Accept batch k while batch k + 1 is generated (acceptance is sequential).
    let mut current = generate(0);
    let mut batch = 0;
    while batch < n_chunks {
        let next_batch = batch + CHUNKS_PER_BATCH;
        let cands = std::mem::take(&mut current);
        let (grid, samples) = (&mut grid, &mut samples);
        let ((), next) = rayon::join(
            move || {
                for cand in cands.into_iter().flatten() {
                    if !grid.has_neighbour(cand.position, r2) {
                        grid.insert(cand.position);
                        samples.push(cand);
                    }
                }
            },
            || if next_batch < n_chunks { generate(next_batch) } else { Vec::new() },
        );
        current = next;
        batch = next_batch;
    }
    samples
}

/// Poisson-disk samples of the surface (module docs). Errors on bad options or indices;
/// a mesh without area gives no samples and a warning.
pub fn poisson_disk_sampling(
    mesh: &TriMesh,
    options: &PoissonDiskOptions,
) -> Result<(PoissonDiskSamples, Vec<Warning>), MeshError> {
    crate::checks::check_indices(mesh)?;
    let bad = |found: String| MeshError::Precondition {
        operation: "Poisson-disk sampling",
        requirement: "a positive finite radius or a positive target count",
        found,
    };
    let mut warnings = Vec::new();
    // Area CDF over triangles with finite corners.
    let areas: Vec<f64> = (0..mesh.n_triangles())
        .into_par_iter()
        .with_min_len(4096)
        .map(|f| {
            let p = mesh.triangle_positions(f);
            if p.iter().all(|q| vec3::is_finite(*q)) {
                triangle_area(p[0], p[1], p[2])
            } else {
                0.0
            }
        })
        .collect();
    let total: f64 = areas.iter().sum();
    let radius_for = |count: usize| (0.7 * total / count as f64).sqrt();
    let mut r = match (options.radius, options.target_count) {
        (Some(r), _) if r > 0.0 && r.is_finite() => r,
        (Some(r), _) => return Err(bad(format!("radius {r}"))),
        (None, Some(n)) if n > 0 => radius_for(n),
        (None, n) => return Err(bad(format!("no radius and target count {n:?}"))),
    };
    if !(total > 0.0 && total.is_finite()) {
        warnings.push(Warning::new(
            "sampling-no-area",
            "the mesh has no triangle with positive finite area; no samples were drawn",
        ));
        return Ok((PoissonDiskSamples { samples: Vec::new(), radius: r }, warnings));
    }
    let factor = if options.candidate_factor > 0.0 { options.candidate_factor } else { 16.0 };
    let candidates_for = |r: f64, warnings: &mut Vec<Warning>| {
        let want = factor * 0.7 * total / (r * r);
        if want > options.max_candidates as f64 {
            warnings.push(Warning::new(
                "sampling-candidates-capped",
                format!(
                    "radius {r:e} would need {want:.3e} candidates; capped at {}, so the \
                     samples keep their minimum distance but may leave gaps",
                    options.max_candidates
                ),
            ));
        }
        (want.ceil() as usize).clamp(1, options.max_candidates.max(1))
    };
    let table = AliasTable::new(&areas, total);
    let mut samples = throw(mesh, &table, total, r, candidates_for(r, &mut warnings), options.seed);
    if options.radius.is_none() {
        let target = options.target_count.unwrap_or(1) as f64;
        for _ in 0..4 {
            let ratio = samples.len().max(1) as f64 / target;
            if (ratio - 1.0).abs() < 0.02 {
                break;
            }
            r *= ratio.sqrt();
            samples = throw(mesh, &table, total, r, candidates_for(r, &mut warnings), options.seed);
        }
    }
    Ok((PoissonDiskSamples { samples, radius: r }, warnings))
}

#[cfg(test)]
#[test]
fn alias_table_reproduces_the_weights() {
    let w = [0.0, 1.0, 3.0, 0.0, 4.0, 2.0];
    let table = AliasTable::new(&w, 10.0);
    let mut counts = [0usize; 6];
    let n = 200;
    for i in 0..n {
        for j in 0..n {
            counts[table.pick((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64)] += 1;
        }
    }
    for k in 0..6 {
        let p = counts[k] as f64 / (n * n) as f64;
        assert!((p - w[k] / 10.0).abs() < 0.01, "{k}: {p}");
    }
    assert_eq!(counts[0] + counts[3], 0);
}

#[cfg(test)]
#[path = "poisson_disk_sampling_tests.rs"]
mod tests;
