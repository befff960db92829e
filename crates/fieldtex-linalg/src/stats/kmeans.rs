//! k-means clustering (Lloyd 1982) with k-means++ seeding (Arthur & Vassilvitskii 2007).
//!
//! Points are row-major `N × dim`. Seeding picks the first centre uniformly and each next
//! one with probability proportional to the squared distance to the nearest chosen
//! centre, drawing from `hash_unit(seed, "kmeans++", k)`. Lloyd iterations assign every
//! point to its nearest centre (parallel, one slot per point; ties go to the lowest
//! index) and move each centre to the mean of its points (sums in point order). An empty
//! cluster keeps its centre. Iteration stops when no label changes or after
//! `max_iterations`. Deterministic for any thread count.

use super::STATS_CHUNK;
use crate::LinalgError;
use fieldtex_core::rng::hash_unit;
use rayon::prelude::*;

/// Options of [`kmeans`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KMeansOptions {
    /// Number of clusters (clamped to the number of points). Default 50 (paper B §5.2).
    pub k: usize,
    /// Lloyd iterations at most. Default 30.
    pub max_iterations: usize,
    pub seed: u64,
}

impl Default for KMeansOptions {
    fn default() -> Self {
        Self { k: 50, max_iterations: 30, seed: 0 }
    }
}

/// The result of [`kmeans`].
#[derive(Debug, Clone, PartialEq)]
pub struct KMeans {
    pub dim: usize,
    /// `k × dim` centres, row-major.
    pub centers: Vec<f64>,
    /// `N` labels.
    pub labels: Vec<u32>,
    /// Lloyd iterations run.
    pub iterations: usize,
    /// Mean squared distance of the points to their centres.
    pub mean_squared_error: f64,
}

impl KMeans {
    pub fn k(&self) -> usize {
        self.centers.len() / self.dim
    }

    /// Index of the centre nearest to `x` (`dim` entries) and its squared distance.
    pub fn nearest(&self, x: &[f64]) -> (usize, f64) {
        nearest(&self.centers, self.dim, x)
    }
}

fn nearest(centers: &[f64], dim: usize, x: &[f64]) -> (usize, f64) {
    let mut best = (0, f64::INFINITY);
    for (c, row) in centers.chunks_exact(dim).enumerate() {
        let d2: f64 = row.iter().zip(x).map(|(a, b)| (a - b) * (a - b)).sum();
        if d2 < best.1 {
            best = (c, d2);
        }
    }
    best
}

/// Clusters `points` (`N × dim`, module docs). Errors on empty or non-finite input.
pub fn kmeans(points: &[f64], dim: usize, options: &KMeansOptions) -> Result<KMeans, LinalgError> {
    if dim == 0 || points.is_empty() || !points.len().is_multiple_of(dim) {
        return Err(LinalgError::Dimension {
            what: "k-means points (a non-empty multiple of dim)",
            expected: dim.max(1),
            found: points.len(),
        });
    }
    if let Some(index) = points.iter().position(|v| !v.is_finite()) {
        return Err(LinalgError::NonFinite { what: "k-means point", index });
    }
    let n = points.len() / dim;
    let k = options.k.clamp(1, n);
    let row = |i: usize| &points[i * dim..(i + 1) * dim];
    // k-means++ seeding.
    let first = ((hash_unit(options.seed, "kmeans++", 0) * n as f64) as usize).min(n - 1);
    let mut centers: Vec<f64> = row(first).to_vec();
    let mut d2: Vec<f64> =
        (0..n).into_par_iter().map(|i| nearest(&centers, dim, row(i)).1).collect();
    for c in 1..k {
        let chunk_sums: Vec<f64> =
            d2.par_chunks(STATS_CHUNK).map(|s| s.iter().sum::<f64>()).collect();
        let total: f64 = chunk_sums.iter().sum();
        let pick = if total > 0.0 {
            let mut target = hash_unit(options.seed, "kmeans++", c as u64) * total;
            let mut chosen = n - 1;
            'outer: for (ci, s) in chunk_sums.iter().enumerate() {
                if target >= *s {
                    target -= s;
                    continue;
                }
                for i in ci * STATS_CHUNK..((ci + 1) * STATS_CHUNK).min(n) {
                    if target < d2[i] {
                        chosen = i;
                        break 'outer;
                    }
                    target -= d2[i];
                }
            }
            chosen
        } else {
            // All points coincide with centres: duplicate the first centre's point.
            first
        };
        let new = row(pick).to_vec();
        d2.par_iter_mut().enumerate().for_each(|(i, d)| {
            let e: f64 = new.iter().zip(row(i)).map(|(a, b)| (a - b) * (a - b)).sum();
            if e < *d {
                *d = e;
            }
        });
        centers.extend_from_slice(&new);
    }
    // Lloyd iterations.
    let mut labels = vec![u32::MAX; n];
    let mut iterations = 0;
    for _ in 0..options.max_iterations.max(1) {
        iterations += 1;
        let new_labels: Vec<u32> =
            (0..n).into_par_iter().map(|i| nearest(&centers, dim, row(i)).0 as u32).collect();
        let changed = new_labels != labels;
        labels = new_labels;
        if !changed {
            break;
        }
        let mut sums = vec![0.0; k * dim];
        let mut counts = vec![0usize; k];
        for (i, &l) in labels.iter().enumerate() {
            let l = l as usize;
            counts[l] += 1;
            for (s, v) in sums[l * dim..(l + 1) * dim].iter_mut().zip(row(i)) {
                *s += v;
            }
        }
        for c in 0..k {
            if counts[c] > 0 {
                for j in 0..dim {
                    centers[c * dim + j] = sums[c * dim + j] / counts[c] as f64;
                }
            }
        }
    }
    let errs: Vec<f64> = labels
        .par_chunks(STATS_CHUNK)
        .enumerate()
        .map(|(ci, ls)| {
            ls.iter()
                .enumerate()
                .map(|(j, &l)| {
                    let i = ci * STATS_CHUNK + j;
                    let c = &centers[l as usize * dim..(l as usize + 1) * dim];
                    c.iter().zip(row(i)).map(|(a, b)| (a - b) * (a - b)).sum::<f64>()
                })
                .sum()
        })
        .collect();
    let mean_squared_error = errs.iter().sum::<f64>() / n as f64;
    Ok(KMeans { dim, centers, labels, iterations, mean_squared_error })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::hashed_normal;

    #[test]
    fn kmeans_finds_separated_blobs() {
        let blobs = [[0.0, 0.0], [10.0, 0.0], [0.0, 10.0], [10.0, 10.0]];
        let mut pts = Vec::new();
        for i in 0..4000u64 {
            let b = blobs[(i % 4) as usize];
            pts.push(b[0] + 0.3 * hashed_normal(1, "x", i));
            pts.push(b[1] + 0.3 * hashed_normal(1, "y", i));
        }
        let r = kmeans(&pts, 2, &KMeansOptions { k: 4, max_iterations: 50, seed: 3 }).unwrap();
        // Every blob maps to a single cluster and clusters are distinct.
        let mut of_blob = [u32::MAX; 4];
        for (i, &l) in r.labels.iter().enumerate() {
            let b = i % 4;
            if of_blob[b] == u32::MAX {
                of_blob[b] = l;
            }
            assert_eq!(of_blob[b], l);
        }
        let mut s = of_blob.to_vec();
        s.sort();
        s.dedup();
        assert_eq!(s.len(), 4);
        assert!((r.mean_squared_error - 2.0 * 0.09).abs() < 0.02, "{}", r.mean_squared_error);
    }

    #[test]
    fn kmeans_same_result_for_one_and_two_threads() {
        let pts: Vec<f64> = (0..30_000u64).map(|i| hashed_normal(5, "p", i)).collect();
        let opts = KMeansOptions { k: 20, max_iterations: 10, seed: 1 };
        let run = |t| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .unwrap()
                .install(|| kmeans(&pts, 3, &opts).unwrap())
        };
        assert_eq!(run(1), run(2));
    }

    #[test]
    fn kmeans_handles_fewer_points_than_clusters() {
        let r = kmeans(&[1.0, 1.0, 1.0], 1, &KMeansOptions::default()).unwrap();
        assert_eq!(r.k(), 3);
        assert!(r.labels.iter().all(|&l| (l as usize) < 3));
        assert!(kmeans(&[], 2, &KMeansOptions::default()).is_err());
    }
}
