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
//! [`poisson_disk_sampling_nested`] gives nested sets for decreasing radii (the
//! multi-resolution mode of [`crate::dart_throwing`]).
//!
//! Not implemented: geodesic (on-surface) distances, Yuksel's (2015) sample elimination.

use crate::areas::triangle_area;
use crate::dart_throwing::DartThrower;
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

/// One dart-throwing pass with radius `r` over `n_candidates` candidates, starting from
/// the accepted `seeds` (not repeated in the result).
fn throw(
    mesh: &TriMesh,
    table: &AliasTable,
    total: f64,
    r: f64,
    n_candidates: usize,
    seed: u64,
    seeds: &[SurfaceSample],
) -> Vec<SurfaceSample> {
    let origin = mesh.bounding_box().map_or([0.0; 3], |b| b.min);
    let expected = (0.7 * total / (r * r)).min(n_candidates as f64) as usize;
    let mut thrower = DartThrower::new(origin, r, expected + seeds.len());
    for s in seeds {
        thrower.seed(s.position);
    }
    let mut samples = Vec::with_capacity(expected);
    let n_chunks = n_candidates.div_ceil(CHUNK);
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
        let (thrower, samples) = (&mut thrower, &mut samples);
        let ((), next) = rayon::join(
            move || {
                for cand in cands.into_iter().flatten() {
                    if thrower.offer(cand.position) {
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
    let (areas, total) = triangle_weights(mesh);
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
    let candidates_for =
        |r: f64, warnings: &mut Vec<Warning>| candidate_count(options, total, r, warnings);
    let table = AliasTable::new(&areas, total);
    let mut samples =
        throw(mesh, &table, total, r, candidates_for(r, &mut warnings), options.seed, &[]);
    if options.radius.is_none() {
        let target = options.target_count.unwrap_or(1) as f64;
        for _ in 0..4 {
            let ratio = samples.len().max(1) as f64 / target;
            if (ratio - 1.0).abs() < 0.02 {
                break;
            }
            r *= ratio.sqrt();
            samples =
                throw(mesh, &table, total, r, candidates_for(r, &mut warnings), options.seed, &[]);
        }
    }
    Ok((PoissonDiskSamples { samples, radius: r }, warnings))
}

/// Nested Poisson-disk sample sets of the surface for strictly decreasing `radii`
/// (multi-resolution mode, [`crate::dart_throwing`]): level `k` keeps every sample of
/// level `k − 1` as its prefix and adds darts at spacing `radii[k]`, so each level is
/// `radii[k]`-separated and close to maximal. `options.radius` and
/// `options.target_count` are ignored; seed, candidate factor and cap apply per level.
/// Errors on bad indices or radii; a mesh without area gives empty levels and a warning.
pub fn poisson_disk_sampling_nested(
    mesh: &TriMesh,
    radii: &[f64],
    options: &PoissonDiskOptions,
) -> Result<(Vec<PoissonDiskSamples>, Vec<Warning>), MeshError> {
    crate::checks::check_indices(mesh)?;
    let decreasing = radii.windows(2).all(|w| w[1] < w[0]);
    if radii.is_empty() || !decreasing || radii.iter().any(|r| !(r.is_finite() && *r > 0.0)) {
        return Err(MeshError::Precondition {
            operation: "nested Poisson-disk sampling",
            requirement: "one or more positive finite radii, strictly decreasing",
            found: format!("{radii:?}"),
        });
    }
    let mut warnings = Vec::new();
    let (areas, total) = triangle_weights(mesh);
    if !(total > 0.0 && total.is_finite()) {
        warnings.push(Warning::new(
            "sampling-no-area",
            "the mesh has no triangle with positive finite area; no samples were drawn",
        ));
        let empty = |&r: &f64| PoissonDiskSamples { samples: Vec::new(), radius: r };
        return Ok((radii.iter().map(empty).collect(), warnings));
    }
    let table = AliasTable::new(&areas, total);
    let mut levels: Vec<PoissonDiskSamples> = Vec::with_capacity(radii.len());
    let mut samples: Vec<SurfaceSample> = Vec::new();
    for &r in radii {
        let n = candidate_count(options, total, r, &mut warnings);
        let added = throw(mesh, &table, total, r, n, options.seed, &samples);
        samples.extend(added);
        levels.push(PoissonDiskSamples { samples: samples.clone(), radius: r });
    }
    Ok((levels, warnings))
}

/// Triangle areas (zero for triangles with a non-finite corner) and their sum.
fn triangle_weights(mesh: &TriMesh) -> (Vec<f64>, f64) {
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
    (areas, total)
}

/// Number of candidates for radius `r` on area `total` (module docs), with a warning
/// when the cap cuts it.
fn candidate_count(
    options: &PoissonDiskOptions,
    total: f64,
    r: f64,
    warnings: &mut Vec<Warning>,
) -> usize {
    let factor = if options.candidate_factor > 0.0 { options.candidate_factor } else { 16.0 };
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
