//! Dart throwing: the one Poisson-disk acceptance rule of the workspace, with a
//! multi-resolution (nested sets) mode.
//!
//! Cook (1986, "Stochastic sampling in computer graphics"): candidates are visited in a
//! fixed order and a candidate is accepted when no accepted sample lies closer than `r`
//! (Euclidean distance, tested exactly through an [`IncrementalGrid`] with cells of side
//! `r`). Every pair of accepted samples is at least `r` apart, and every candidate lies
//! within `r` of a sample (maximality over the candidates). The order carries all the
//! randomness and all the priorities (curves first, say), so the result is a pure
//! function of the order: deterministic for any thread count.
//!
//! **Nested sets** ([`nested_dart_throwing`]): for radii `r₀ > r₁ > …` level `k` starts
//! from level `k − 1`'s samples and adds candidates in order at spacing `r_k`. So
//! `S₀ ⊂ S₁ ⊂ …`, each level lists its parent's samples first (a prefix), and level
//! `k` is `r_k`-separated and maximal over the candidates at `r_k` — the coarse-to-fine
//! sample hierarchies of multi-resolution surface synthesis (e.g. paper B's pyramid of
//! surface samples) without a separate pass per level.
//!
//! Users: [`crate::poisson_disk_sampling`] (streamed random surface candidates) and
//! texture optimisation's sample set (carriers ordered by curve priority).

use crate::spatial_grid::IncrementalGrid;
use fieldtex_core::vec3::V3;

/// Sequential dart throwing at one radius (module docs).
#[derive(Debug, Clone)]
pub struct DartThrower {
    grid: IncrementalGrid,
    r2: f64,
}

impl DartThrower {
    /// A thrower with minimum distance `radius` (> 0, finite), cells measured from
    /// `origin`, sized for about `expected` samples.
    pub fn new(origin: V3, radius: f64, expected: usize) -> Self {
        Self { grid: IncrementalGrid::new(origin, radius, expected), r2: radius * radius }
    }

    /// Accepts `p` when no accepted sample lies closer than the radius; returns whether
    /// it did.
    #[inline]
    pub fn offer(&mut self, p: V3) -> bool {
        if self.grid.has_neighbour(p, self.r2) {
            return false;
        }
        self.grid.insert(p);
        true
    }

    /// Accepts `p` without the distance test (the samples of a coarser level, which are
    /// farther apart than this radius already).
    pub fn seed(&mut self, p: V3) {
        self.grid.insert(p);
    }

    /// The accepted samples, in acceptance order.
    pub fn samples(&self) -> &[V3] {
        self.grid.points()
    }
}

/// Indices (into `positions`) of the candidates `order` accepted at spacing `radius`, in
/// acceptance order. A non-positive or non-finite radius accepts every candidate.
pub fn dart_throwing(positions: &[V3], order: &[u32], radius: f64) -> Vec<u32> {
    nested_dart_throwing(positions, order, &[radius]).pop().unwrap_or_default()
}

/// Nested sample sets for decreasing `radii` (module docs): `out[k]` holds the indices
/// accepted at `radii[k]`, with `out[k − 1]` as its prefix. Radii that do not decrease
/// are used as given (the sets stay nested; the separation of level `k` is then the
/// smallest radius so far). A non-positive or non-finite radius accepts every
/// candidate not yet accepted.
pub fn nested_dart_throwing(positions: &[V3], order: &[u32], radii: &[f64]) -> Vec<Vec<u32>> {
    let mut out: Vec<Vec<u32>> = Vec::with_capacity(radii.len());
    let mut taken = vec![false; positions.len()];
    let mut accepted: Vec<u32> = Vec::new();
    for &r in radii {
        if !(r.is_finite() && r > 0.0) {
            for &c in order {
                if !std::mem::replace(&mut taken[c as usize], true) {
                    accepted.push(c);
                }
            }
            out.push(accepted.clone());
            continue;
        }
        let mut thrower = DartThrower::new([0.0; 3], r, accepted.len().max(order.len() / 8));
        for &c in &accepted {
            thrower.seed(positions[c as usize]);
        }
        for &c in order {
            if !taken[c as usize] && thrower.offer(positions[c as usize]) {
                taken[c as usize] = true;
                accepted.push(c);
            }
        }
        out.push(accepted.clone());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_core::vec3;

    fn cloud(n: u64) -> Vec<V3> {
        (0..n)
            .map(|i| {
                let u = |s: &str| fieldtex_core::rng::hash_unit(9, s, i);
                [u("x") * 4.0, u("y") * 4.0, u("z") * 0.5]
            })
            .collect()
    }

    #[test]
    fn single_level_is_separated_and_maximal() {
        let pts = cloud(3000);
        let order: Vec<u32> = (0..pts.len() as u32).rev().collect();
        let s = dart_throwing(&pts, &order, 0.3);
        assert!(s.len() > 20);
        for (i, &a) in s.iter().enumerate() {
            for &b in &s[i + 1..] {
                assert!(vec3::norm(vec3::sub(pts[a as usize], pts[b as usize])) >= 0.3);
            }
        }
        for p in &pts {
            assert!(s.iter().any(|&a| vec3::norm(vec3::sub(pts[a as usize], *p)) < 0.3));
        }
        // The first candidate in order is always accepted.
        assert_eq!(s[0], order[0]);
    }

    #[test]
    fn nested_levels_are_prefixes_and_each_level_is_separated() {
        let pts = cloud(3000);
        let order: Vec<u32> = (0..pts.len() as u32).collect();
        let radii = [0.8, 0.4, 0.2];
        let levels = nested_dart_throwing(&pts, &order, &radii);
        assert_eq!(levels.len(), 3);
        for k in 0..3 {
            if k > 0 {
                assert!(levels[k].len() > levels[k - 1].len());
                assert_eq!(&levels[k][..levels[k - 1].len()], &levels[k - 1][..]);
            }
            let s = &levels[k];
            for (i, &a) in s.iter().enumerate() {
                for &b in &s[i + 1..] {
                    let d = vec3::norm(vec3::sub(pts[a as usize], pts[b as usize]));
                    assert!(d >= radii[k], "level {k}: {d}");
                }
            }
        }
        // Level 0 alone equals a single-level throw.
        assert_eq!(levels[0], dart_throwing(&pts, &order, 0.8));
    }

    #[test]
    fn zero_radius_takes_every_candidate_once() {
        let pts = cloud(10);
        let order = [3u32, 1, 3, 2];
        assert_eq!(dart_throwing(&pts, &order, 0.0), vec![3, 1, 2]);
    }
}
