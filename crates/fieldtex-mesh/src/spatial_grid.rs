//! The one uniform spatial grid of the workspace: radius and box queries over 3-D points
//! or axis-aligned boxes, built once ([`SpatialGrid`]) or filled point by point while it
//! is queried ([`IncrementalGrid`], the form dart throwing needs).
//!
//! Both forms address space the same way: cubic cells of side `cell` measured from an
//! origin, cell coordinates packed into 21 bits per axis, and an open-addressing hash
//! table from packed key to bucket, so memory follows the occupied cells, never the
//! bounding box.
//!
//! **[`SpatialGrid`]** (static). Items are entered in every cell their box overlaps as
//! `(cell key, item)` pairs, sorted by key then item; the table maps a key to its range
//! of that sorted array, and a one-hash Bloom filter (8 bits per table slot) rejects
//! empty cells without touching the table. A query visits the cells overlapping the
//! query box in lexicographic `(z, y, x)` order and reports, inside a cell, items by
//! increasing index, so results never depend on thread count or hash order. Cell
//! coordinates are clamped to `±2²⁰` around the origin; the cell is enlarged when the
//! items' bounding box would need more cells per axis. A box spanning more than 512
//! cells is kept in a short list reported first by every query, so a few huge items
//! among tiny ones cannot blow up memory. A box item is reported once per shared cell
//! (callers reduce with a minimum or deduplicate); a point item exactly once.
//!
//! **[`IncrementalGrid`]** (insertion). Cell → first point, with `next` links; the slot
//! is a *linear* function of the cell so the 27 neighbours of a cell fall on few cache
//! lines. Keys wrap at 21 bits: two far-apart cells sharing a key only cost a distance
//! test, never a wrong answer. It answers one question, "is an inserted point closer
//! than `r` to `p`" (cell side ≥ `r`), whose answer does not depend on visiting order.
//!
//! Users: texture optimisation's carrier and sample neighbourhoods, the facade's curve
//! band, curve-field constraint sampling (nearest vertex), curve endpoint joining and
//! feature coverage (boxes of segments), and the dart thrower ([`crate::dart_throwing`]).

use fieldtex_core::rng::mix64;
use fieldtex_core::vec3::{self, V3};
use rayon::prelude::*;

/// Cell coordinates are packed in 21 bits each (cells beyond ±2²⁰ are clamped; the
/// constructors choose `cell` so this never happens for real data).
const BITS: u32 = 21;
const OFFSET: i64 = 1 << (BITS - 1);
const MASK: u64 = (1 << BITS) - 1;
const EMPTY_KEY: u64 = u64::MAX;
/// Boxes covering more cells than this go to the list every query visits.
const MAX_ITEM_CELLS: i64 = 512;

/// Radius-neighbour and box-overlap index over a fixed set of points or boxes (module
/// docs).
#[derive(Debug, Clone)]
pub struct SpatialGrid {
    origin: V3,
    /// Upper corner of the bounding box of the gridded items (`origin` is the lower).
    upper: V3,
    cell: f64,
    /// Item indices sorted by (cell key, index).
    order: Vec<u32>,
    /// Open-addressing table: keys and `[start, end)` ranges into `order`.
    keys: Vec<u64>,
    ranges: Vec<[u32; 2]>,
    mask: usize,
    /// Occupancy bits by key hash (a one-hash Bloom filter, 8 bits per table slot), so
    /// empty cells are rejected without touching the table.
    occupied: Vec<u64>,
    occupied_mask: usize,
    /// Items too large for the cells, reported by every query.
    large: Vec<u32>,
    /// Whether any item is gridded at all.
    any: bool,
}

impl SpatialGrid {
    /// A grid over `points` (item `i` is `points[i]`) with cells of side `cell` (> 0,
    /// finite; otherwise the bounding-box extent). Non-finite coordinates are clamped to
    /// border cells, so such points are still reported to nearby queries' callers, who
    /// test distances.
    pub fn new(points: &[V3], cell: f64) -> Self {
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
        let mut grid = Self::empty(lo, hi, cell);
        let mut keyed: Vec<(u64, u32)> = points
            .par_iter()
            .enumerate()
            .map(|(i, p)| (grid.key_of(grid.cell_of(*p)), i as u32))
            .collect();
        keyed.par_sort_unstable();
        grid.fill(&keyed);
        grid.any = !points.is_empty();
        grid
    }

    /// A grid over the boxes `(min, max)` (item `i` is `boxes[i]`; a point is a box with
    /// `min == max`) with cells of side `cell`. Boxes with a non-finite corner are left
    /// out (never reported).
    pub fn from_boxes(boxes: &[(V3, V3)], cell: f64) -> Self {
        let finite = |(a, b): &(V3, V3)| vec3::is_finite(*a) && vec3::is_finite(*b);
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for (a, b) in boxes.iter().filter(|b| finite(b)) {
            for k in 0..3 {
                lo[k] = lo[k].min(a[k]);
                hi[k] = hi[k].max(b[k]);
            }
        }
        if lo[0] > hi[0] {
            return Self::empty([0.0; 3], [0.0; 3], cell);
        }
        let mut grid = Self::empty(lo, hi, cell);
        let mut keyed: Vec<(u64, u32)> = Vec::with_capacity(boxes.len());
        for (i, b) in boxes.iter().enumerate() {
            if !finite(b) {
                continue;
            }
            let (c0, c1) = (grid.cell_of(b.0), grid.cell_of(b.1));
            let span: i64 = (0..3).map(|k| c1[k] - c0[k] + 1).product();
            if span > MAX_ITEM_CELLS {
                grid.large.push(i as u32);
                continue;
            }
            for z in c0[2]..=c1[2] {
                for y in c0[1]..=c1[1] {
                    for x in c0[0]..=c1[0] {
                        keyed.push((grid.key_of([x, y, z]), i as u32));
                    }
                }
            }
        }
        keyed.par_sort_unstable();
        grid.fill(&keyed);
        grid.any = true;
        grid
    }

    /// A grid without items over the bounding box `lo..hi` (its cell size is fixed here).
    fn empty(lo: V3, hi: V3, cell: f64) -> Self {
        let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0f64, f64::max);
        let mut cell = if cell.is_finite() && cell > 0.0 { cell } else { extent.max(1.0) };
        cell = cell.max(extent / (OFFSET as f64 - 2.0));
        Self {
            origin: lo,
            upper: hi,
            cell,
            order: Vec::new(),
            keys: Vec::new(),
            ranges: Vec::new(),
            mask: 0,
            occupied: Vec::new(),
            occupied_mask: 0,
            large: Vec::new(),
            any: false,
        }
    }

    /// Builds the table from `(key, item)` pairs sorted by key.
    fn fill(&mut self, keyed: &[(u64, u32)]) {
        let mut n_cells = 0usize;
        for i in 0..keyed.len() {
            if i == 0 || keyed[i].0 != keyed[i - 1].0 {
                n_cells += 1;
            }
        }
        let cap = (2 * n_cells).next_power_of_two().max(16);
        self.keys = vec![EMPTY_KEY; cap];
        self.ranges = vec![[0, 0]; cap];
        self.mask = cap - 1;
        self.occupied = vec![0u64; cap / 8];
        self.occupied_mask = cap * 8 - 1;
        self.order = keyed.iter().map(|&(_, i)| i).collect();
        let mut start = 0;
        while start < keyed.len() {
            let key = keyed[start].0;
            let mut end = start + 1;
            while end < keyed.len() && keyed[end].0 == key {
                end += 1;
            }
            let hash = mix64(key) as usize;
            let bit = (hash >> 20) & self.occupied_mask;
            self.occupied[bit >> 6] |= 1 << (bit & 63);
            let mut slot = hash & self.mask;
            while self.keys[slot] != EMPTY_KEY {
                slot = (slot + 1) & self.mask;
            }
            self.keys[slot] = key;
            self.ranges[slot] = [start as u32, end as u32];
            start = end;
        }
    }

    /// Side of a cell.
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// Bounding box `(min, max)` of the gridded items, `None` when there are none.
    pub fn bounds(&self) -> Option<(V3, V3)> {
        self.any.then_some((self.origin, self.upper))
    }

    #[inline]
    fn cell_of(&self, p: V3) -> [i64; 3] {
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
            if k == EMPTY_KEY {
                return &[];
            }
            slot = (slot + 1) & self.mask;
        }
    }

    /// Calls `f(item)` for every item in the cells that intersect the box `lo..hi` (and
    /// every oversized item). Deterministic order, see the module docs.
    #[inline]
    pub fn for_each_in_box(&self, lo: V3, hi: V3, mut f: impl FnMut(u32)) {
        self.large.iter().for_each(|&i| f(i));
        if self.order.is_empty() {
            return;
        }
        let lo = self.cell_of(lo);
        let hi = self.cell_of(hi);
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

    /// Calls `f(item)` for every item in the cells that intersect the cube of half-side
    /// `radius` around `p` (a superset of the items within `radius`; the caller tests
    /// the distance it needs). Deterministic order, see the module docs.
    #[inline]
    pub fn for_each_candidate(&self, p: V3, radius: f64, f: impl FnMut(u32)) {
        self.for_each_in_box(
            [p[0] - radius, p[1] - radius, p[2] - radius],
            [p[0] + radius, p[1] + radius, p[2] + radius],
            f,
        );
    }

    /// Calls `f(index, squared distance)` for every point of a point grid within
    /// `radius` of `p` (`points` are the ones the grid was built over).
    #[inline]
    pub fn for_each_within(&self, points: &[V3], p: V3, radius: f64, mut f: impl FnMut(u32, f64)) {
        let r2 = radius * radius;
        self.for_each_candidate(p, radius, |i| {
            let q = points[i as usize];
            let d2 = (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2);
            if d2 <= r2 {
                f(i, d2);
            }
        });
    }

    /// The point of a point grid nearest to `p` within `radius` (ties: lower index) with
    /// its squared distance.
    pub fn nearest_within(&self, points: &[V3], p: V3, radius: f64) -> Option<(u32, f64)> {
        let mut best: Option<(f64, u32)> = None;
        self.for_each_within(points, p, radius, |i, d2| {
            if best.is_none_or(|b| (d2, i) < b) {
                best = Some((d2, i));
            }
        });
        best.map(|(d2, i)| (i, d2))
    }

    /// Parameter range `[t0, t1] ⊂ [0, 1]` of the segment `a → b` inside the items'
    /// bounding box grown by `margin` (slab method), or `None` when it misses the box or
    /// the grid is empty.
    pub fn clip_segment(&self, a: V3, b: V3, margin: f64) -> Option<(f64, f64)> {
        let (lo, hi) = self.bounds()?;
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for k in 0..3 {
            let (lo, hi) = (lo[k] - margin, hi[k] + margin);
            let d = b[k] - a[k];
            if d == 0.0 {
                if a[k] < lo || a[k] > hi {
                    return None;
                }
                continue;
            }
            let (u, v) = ((lo - a[k]) / d, (hi - a[k]) / d);
            t0 = t0.max(u.min(v));
            t1 = t1.min(u.max(v));
        }
        (t0 <= t1).then_some((t0, t1))
    }
}

/// Point grid filled while it is queried: "is an inserted point closer than `r`?"
/// (module docs).
#[derive(Debug, Clone)]
pub struct IncrementalGrid {
    origin: V3,
    inv_cell: f64,
    /// `(packed cell key, first point)`; `NO_POINT` heads mark free slots.
    slots: Vec<(u64, u32)>,
    mask: usize,
    next: Vec<u32>,
    points: Vec<V3>,
    used: usize,
}

const NO_POINT: u32 = u32::MAX;
const KEY_MASK: i64 = (1 << BITS) - 1;

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

impl IncrementalGrid {
    /// An empty grid with cells of side `cell` from `origin`, sized for about
    /// `expected` points (it grows as needed). Neighbour tests with radius `r` need
    /// `r ≤ cell`.
    pub fn new(origin: V3, cell: f64, expected: usize) -> Self {
        let cap = (2 * expected.max(16)).next_power_of_two();
        Self {
            origin,
            inv_cell: 1.0 / cell,
            slots: vec![(0, NO_POINT); cap],
            mask: cap - 1,
            next: Vec::new(),
            points: Vec::new(),
            used: 0,
        }
    }

    /// The inserted points, in insertion order.
    pub fn points(&self) -> &[V3] {
        &self.points
    }

    #[inline]
    fn cell(&self, p: V3) -> [i64; 3] {
        [0, 1, 2].map(|k| ((p[k] - self.origin[k]) * self.inv_cell).floor() as i64)
    }

    #[inline]
    fn key(c: [i64; 3]) -> u64 {
        ((c[0] & KEY_MASK) | (c[1] & KEY_MASK) << BITS | (c[2] & KEY_MASK) << (2 * BITS)) as u64
    }

    /// Slot of cell `c`: the one holding its key, or the free slot where it would go.
    #[inline]
    fn slot(&self, c: [i64; 3]) -> usize {
        let key = Self::key(c);
        let h = (c[0] as u64)
            .wrapping_add((c[1] as u64).wrapping_mul(0x9E37_79B1))
            .wrapping_add((c[2] as u64).wrapping_mul(0x85EB_CA77_C2B2_AE63));
        let mut i = h as usize & self.mask;
        while self.slots[i].1 != NO_POINT && self.slots[i].0 != key {
            i = (i + 1) & self.mask;
        }
        i
    }

    /// Whether an inserted point lies closer than `sqrt(r2)` to `p` (`r ≤ cell`).
    pub fn has_neighbour(&self, p: V3, r2: f64) -> bool {
        let c = self.cell(p);
        // Own cell first: near saturation most candidates are rejected there.
        NEIGHBOUR_ORDER.iter().any(|d| {
            let mut s = self.slots[self.slot([c[0] + d[0], c[1] + d[1], c[2] + d[2]])].1;
            while s != NO_POINT {
                if vec3::norm2(vec3::sub(self.points[s as usize], p)) < r2 {
                    return true;
                }
                s = self.next[s as usize];
            }
            false
        })
    }

    /// Inserts `p` (its index is the number of points inserted before).
    pub fn insert(&mut self, p: V3) {
        if 2 * (self.used + 1) > self.slots.len() {
            self.grow();
        }
        let c = self.cell(p);
        let i = self.slot(c);
        if self.slots[i].1 == NO_POINT {
            self.slots[i].0 = Self::key(c);
            self.used += 1;
        }
        self.next.push(self.slots[i].1);
        self.slots[i].1 = self.points.len() as u32;
        self.points.push(p);
    }

    fn grow(&mut self) {
        let old = std::mem::replace(&mut self.slots, vec![(0, NO_POINT); 2 * self.mask + 2]);
        self.mask = self.slots.len() - 1;
        for (_, head) in old {
            if head != NO_POINT {
                // Any point of the bucket gives its cell.
                let c = self.cell(self.points[head as usize]);
                let i = self.slot(c);
                self.slots[i] = (Self::key(c), head);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud(n: u64) -> Vec<V3> {
        (0..n)
            .map(|i| {
                let u = |s: &str| fieldtex_core::rng::hash_unit(3, s, i);
                [u("x") * 10.0 - 5.0, u("y") * 3.0, u("z") * 0.1]
            })
            .collect()
    }

    fn brute(pts: &[V3], p: V3, r: f64) -> Vec<u32> {
        (0..pts.len() as u32)
            .filter(|&i| vec3::norm2(vec3::sub(pts[i as usize], p)) <= r * r)
            .collect()
    }

    #[test]
    fn radius_query_matches_brute_force() {
        let pts = cloud(500);
        let grid = SpatialGrid::new(&pts, 0.7);
        for q in 0..50 {
            let p = pts[q * 7];
            let mut got = Vec::new();
            grid.for_each_within(&pts, p, 0.9, |i, _| got.push(i));
            got.sort_unstable();
            assert_eq!(got, brute(&pts, p, 0.9));
            let want = brute(&pts, p, 0.9)
                .into_iter()
                .min_by(|&a, &b| {
                    let d = |i: u32| vec3::norm2(vec3::sub(pts[i as usize], p));
                    d(a).total_cmp(&d(b)).then(a.cmp(&b))
                })
                .map(|i| i as usize);
            assert_eq!(grid.nearest_within(&pts, p, 0.9).map(|(i, _)| i as usize), want);
        }
    }

    #[test]
    fn box_grid_reports_every_overlapping_box_and_huge_ones_once_listed() {
        let boxes = vec![([0.0; 3], [0.01; 3]), ([-1e3; 3], [1e3; 3]), ([5.0; 3], [5.01; 3])];
        let g = SpatialGrid::from_boxes(&boxes, 0.01);
        assert!(g.order.len() <= 16, "{} entries", g.order.len());
        assert_eq!(g.large, vec![1]);
        let mut found = Vec::new();
        g.for_each_in_box([4.99; 3], [5.02; 3], |i| found.push(i));
        found.sort_unstable();
        found.dedup();
        assert_eq!(found, vec![1, 2]);
        // Far outside the items: only the huge box.
        let mut far = Vec::new();
        g.for_each_in_box([-50.0; 3], [-49.0; 3], |i| far.push(i));
        assert_eq!(far, vec![1]);
    }

    #[test]
    fn empty_degenerate_and_non_finite_inputs() {
        let grid = SpatialGrid::new(&[], 1.0);
        grid.for_each_candidate([0.0; 3], 1.0, |_| panic!("no points"));
        assert!(grid.bounds().is_none());
        let grid = SpatialGrid::new(&[[1.0, 1.0, 1.0]; 3], 0.0);
        let mut n = 0;
        grid.for_each_within(&[[1.0, 1.0, 1.0]; 3], [1.0; 3], 0.5, |_, _| n += 1);
        assert_eq!(n, 3);
        let g = SpatialGrid::from_boxes(&[([f64::NAN; 3], [0.0; 3])], 1.0);
        assert!(g.bounds().is_none());
        g.for_each_in_box([-1e9; 3], [1e9; 3], |_| panic!("non-finite boxes are left out"));
    }

    #[test]
    fn segment_clipping_to_the_item_box() {
        let g = SpatialGrid::new(&[[0.0; 3], [1.0, 1.0, 1.0]], 0.5);
        let (t0, t1) = g.clip_segment([-1.0, 0.5, 0.5], [3.0, 0.5, 0.5], 0.0).unwrap();
        assert!((t0 - 0.25).abs() < 1e-12 && (t1 - 0.5).abs() < 1e-12);
        assert!(g.clip_segment([-1.0, 5.0, 0.5], [3.0, 5.0, 0.5], 0.1).is_none());
    }

    #[test]
    fn incremental_grid_answers_like_brute_force() {
        let pts = cloud(400);
        let mut g = IncrementalGrid::new([-5.0, 0.0, 0.0], 0.3, 4);
        for (i, &p) in pts.iter().enumerate() {
            let want = pts[..i].iter().any(|&q| vec3::norm2(vec3::sub(q, p)) < 0.09);
            assert_eq!(g.has_neighbour(p, 0.09), want, "point {i}");
            g.insert(p);
        }
        assert_eq!(g.points().len(), pts.len());
    }
}
