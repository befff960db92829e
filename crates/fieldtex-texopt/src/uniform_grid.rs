//! A uniform hash grid over 3-D points for radius-neighbour queries.
//!
//! Points are bucketed into cubic cells of side `cell`; the cells are stored as one
//! index array sorted by (cell key, point index) plus an open-addressing table from
//! cell key to its range. A query visits the `3 × 3 × 3` block of cells around the query
//! point when `radius ≤ cell` (larger radii visit more cells) and reports points in a
//! fixed order: cells in lexicographic `(z, y, x)` order, points by increasing index
//! inside a cell. So results never depend on thread count or hash order.

use fieldtex_core::rng::mix64;
use rayon::prelude::*;

/// Cell coordinates are packed in 21 bits each (cells beyond ±2²⁰ are clamped; the
/// caller chooses `cell` so this never happens for real data, see [`UniformGrid::new`]).
const BITS: u32 = 21;
const OFFSET: i64 = 1 << (BITS - 1);
const MASK: u64 = (1 << BITS) - 1;
const EMPTY: u64 = u64::MAX;

/// Radius-neighbour index over a fixed point set.
#[derive(Debug, Clone)]
pub struct UniformGrid {
    origin: [f64; 3],
    cell: f64,
    /// Point indices sorted by (cell key, index).
    order: Vec<u32>,
    /// Open-addressing table: keys and `[start, end)` ranges into `order`.
    keys: Vec<u64>,
    ranges: Vec<[u32; 2]>,
    mask: usize,
    /// Occupancy bits by key hash (a one-hash Bloom filter, 8 bits per table slot), so
    /// empty cells are rejected without touching the table.
    occupied: Vec<u64>,
    occupied_mask: usize,
}

impl UniformGrid {
    /// Builds the grid over `points` with cells of side `cell` (> 0, finite). The cell is
    /// enlarged when the bounding box would need more than 2²⁰ cells per axis.
    pub fn new(points: &[[f64; 3]], cell: f64) -> Self {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in points {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if points.is_empty() {
            lo = [0.0; 3];
            hi = [0.0; 3];
        }
        let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0f64, f64::max);
        let mut cell = if cell.is_finite() && cell > 0.0 { cell } else { extent.max(1.0) };
        cell = cell.max(extent / (OFFSET as f64 - 2.0));
        let mut grid = Self {
            origin: lo,
            cell,
            order: Vec::new(),
            keys: Vec::new(),
            ranges: Vec::new(),
            mask: 0,
            occupied: Vec::new(),
            occupied_mask: 0,
        };
        let mut keyed: Vec<(u64, u32)> = points
            .par_iter()
            .enumerate()
            .map(|(i, p)| (grid.key_of(grid.cell_of(*p)), i as u32))
            .collect();
        keyed.par_sort_unstable();
        let mut n_cells = 0usize;
        for i in 0..keyed.len() {
            if i == 0 || keyed[i].0 != keyed[i - 1].0 {
                n_cells += 1;
            }
        }
        let cap = (2 * n_cells).next_power_of_two().max(16);
        grid.keys = vec![EMPTY; cap];
        grid.ranges = vec![[0, 0]; cap];
        grid.mask = cap - 1;
        grid.occupied = vec![0u64; cap / 8];
        grid.occupied_mask = cap * 8 - 1;
        grid.order = keyed.iter().map(|&(_, i)| i).collect();
        let mut start = 0;
        while start < keyed.len() {
            let key = keyed[start].0;
            let mut end = start + 1;
            while end < keyed.len() && keyed[end].0 == key {
                end += 1;
            }
            let hash = mix64(key) as usize;
            let bit = (hash >> 20) & grid.occupied_mask;
            grid.occupied[bit >> 6] |= 1 << (bit & 63);
            let mut slot = hash & grid.mask;
            while grid.keys[slot] != EMPTY {
                slot = (slot + 1) & grid.mask;
            }
            grid.keys[slot] = key;
            grid.ranges[slot] = [start as u32, end as u32];
            start = end;
        }
        grid
    }

    /// Side of a cell.
    pub fn cell(&self) -> f64 {
        self.cell
    }

    #[inline]
    fn cell_of(&self, p: [f64; 3]) -> [i64; 3] {
        let c = |k: usize| {
            (((p[k] - self.origin[k]) / self.cell).floor() as i64).clamp(-OFFSET + 1, OFFSET - 2)
        };
        [c(0), c(1), c(2)]
    }

    #[inline]
    fn key_of(&self, c: [i64; 3]) -> u64 {
        let pack = |v: i64| ((v + OFFSET) as u64) & MASK;
        pack(c[0]) | (pack(c[1]) << BITS) | (pack(c[2]) << (2 * BITS))
    }

    #[inline]
    fn lookup(&self, key: u64) -> &[u32] {
        let hash = mix64(key) as usize;
        let bit = (hash >> 20) & self.occupied_mask;
        if self.occupied[bit >> 6] & (1 << (bit & 63)) == 0 {
            return &[];
        }
        let mut slot = hash & self.mask;
        loop {
            let k = self.keys[slot];
            if k == key {
                let [s, e] = self.ranges[slot];
                return &self.order[s as usize..e as usize];
            }
            if k == EMPTY {
                return &[];
            }
            slot = (slot + 1) & self.mask;
        }
    }

    /// Calls `f(index)` for every point in the cells that intersect the cube of half-side
    /// `radius` around `p` (a superset of the points within `radius`; the caller tests
    /// the distance it needs). Deterministic order, see the module docs.
    #[inline]
    pub fn for_each_candidate(&self, p: [f64; 3], radius: f64, mut f: impl FnMut(u32)) {
        if self.order.is_empty() {
            return;
        }
        let lo = self.cell_of([p[0] - radius, p[1] - radius, p[2] - radius]);
        let hi = self.cell_of([p[0] + radius, p[1] + radius, p[2] + radius]);
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    for &i in self.lookup(self.key_of([x, y, z])) {
                        f(i);
                    }
                }
            }
        }
    }

    /// Calls `f(index, squared distance)` for every point within `radius` of `p`.
    #[inline]
    pub fn for_each_within(
        &self,
        points: &[[f64; 3]],
        p: [f64; 3],
        radius: f64,
        mut f: impl FnMut(u32, f64),
    ) {
        let r2 = radius * radius;
        self.for_each_candidate(p, radius, |i| {
            let q = points[i as usize];
            let d2 = (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2);
            if d2 <= r2 {
                f(i, d2);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radius_query_matches_brute_force() {
        let pts: Vec<[f64; 3]> = (0..500)
            .map(|i| {
                let u = |s: &str| fieldtex_core::rng::hash_unit(3, s, i);
                [u("x") * 10.0 - 5.0, u("y") * 3.0, u("z") * 0.1]
            })
            .collect();
        let grid = UniformGrid::new(&pts, 0.7);
        for q in 0..50 {
            let p = pts[q * 7];
            let mut got = Vec::new();
            grid.for_each_within(&pts, p, 0.9, |i, _| got.push(i));
            got.sort_unstable();
            let want: Vec<u32> = (0..pts.len() as u32)
                .filter(|&i| {
                    let d = pts[i as usize];
                    (d[0] - p[0]).powi(2) + (d[1] - p[1]).powi(2) + (d[2] - p[2]).powi(2) <= 0.81
                })
                .collect();
            assert_eq!(got, want);
        }
    }

    #[test]
    fn empty_and_degenerate_inputs() {
        let grid = UniformGrid::new(&[], 1.0);
        grid.for_each_candidate([0.0; 3], 1.0, |_| panic!("no points"));
        let grid = UniformGrid::new(&[[1.0, 1.0, 1.0]; 3], 0.0);
        let mut n = 0;
        grid.for_each_within(&[[1.0, 1.0, 1.0]; 3], [1.0; 3], 0.5, |_, _| n += 1);
        assert_eq!(n, 3);
    }
}
