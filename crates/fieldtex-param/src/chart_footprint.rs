//! Chart footprints for packing: the texels a chart covers at a given scale, as a
//! bitmap, with quarter turns and growth by a disk (the gutter).
//!
//! Rasterisation is conservative ([`crate::raster`]) with a small margin, so that every
//! texel the texel map later covers is reserved here. Rows are bottom-up (y up), bit
//! `x` of row `y` is texel `(x, y)`.

use crate::raster::triangle_row_spans;

/// Covered texels of one chart: `w × h` bits, rows of `stride` words.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub(crate) struct Footprint {
    pub w: i64,
    pub h: i64,
    stride: usize,
    bits: Vec<u64>,
}

/// A footprint grown by the gutter, as spans per row: row `k` is footprint row
/// `y0 + k` (its spans are `spans[start[k]..start[k + 1]]`, one allocation for all
/// rows); `need[k]` is the length of its longest span; `by_need` lists the rows from
/// the widest to the narrowest (ties by row).
#[derive(Debug, Clone, Default)]
pub(crate) struct Grown {
    pub y0: i64,
    spans: Vec<(i64, i64)>,
    start: Vec<u32>,
    pub need: Vec<i64>,
    pub by_need: Vec<u32>,
}

impl Grown {
    /// Number of rows.
    pub fn n_rows(&self) -> usize {
        self.need.len()
    }

    /// Spans of row `k`.
    pub fn row(&self, k: usize) -> &[(i64, i64)] {
        &self.spans[self.start[k] as usize..self.start[k + 1] as usize]
    }
}

/// Sets bits `a..=b` of a row.
fn set_bits(row: &mut [u64], a: usize, b: usize) {
    let (wa, wb) = (a / 64, b / 64);
    let lo = !0u64 << (a % 64);
    let hi = !0u64 >> (63 - b % 64);
    if wa == wb {
        row[wa] |= lo & hi;
    } else {
        row[wa] |= lo;
        for w in &mut row[wa + 1..wb] {
            *w = !0;
        }
        row[wb] |= hi;
    }
}

/// Appends the runs of set bits of `row` (first `w` bits) as inclusive spans, shifted
/// by `shift`.
fn row_runs(row: &[u64], w: usize, shift: i64, out: &mut Vec<(i64, i64)>) {
    let mut x = 0usize;
    while x < w {
        // Next set bit at or after x.
        let mut wi = x / 64;
        let mut word = row[wi] & (!0u64 << (x % 64));
        while word == 0 {
            wi += 1;
            if wi >= row.len() {
                return;
            }
            word = row[wi];
        }
        let start = wi * 64 + word.trailing_zeros() as usize;
        if start >= w {
            return;
        }
        // Next clear bit after start.
        let mut wi = start / 64;
        let mut word = !row[wi] & (!0u64 << (start % 64));
        while word == 0 {
            wi += 1;
            if wi >= row.len() {
                break;
            }
            word = !row[wi];
        }
        let end =
            if wi >= row.len() { w } else { (wi * 64 + word.trailing_zeros() as usize).min(w) };
        out.push((start as i64 + shift, end as i64 - 1 + shift));
        x = end;
    }
}

impl Footprint {
    fn empty(w: i64, h: i64) -> Self {
        let stride = (w as usize).div_ceil(64);
        Self { w, h, stride, bits: vec![0; stride * h as usize] }
    }

    /// A single texel.
    pub fn single() -> Self {
        Self { w: 1, h: 1, stride: 1, bits: vec![1] }
    }

    fn row(&self, y: i64) -> &[u64] {
        &self.bits[y as usize * self.stride..(y as usize + 1) * self.stride]
    }

    /// Rasterises the triangles of `points` mapped by `p ↦ (p − origin)·scale + inset`;
    /// `None` when the footprint would be wider or taller than `max_size` (tests only:
    /// the packer maps the points itself and sizes with [`Self::extent`]).
    #[cfg(test)]
    pub fn rasterize(
        points: &[[f64; 2]],
        triangles: &[[u32; 3]],
        origin: [f64; 2],
        scale: f64,
        inset: f64,
        eps: f64,
        max_size: i64,
    ) -> Option<Self> {
        let pts: Vec<[f64; 2]> = points
            .iter()
            .map(|p| [(p[0] - origin[0]) * scale + inset, (p[1] - origin[1]) * scale + inset])
            .collect();
        let (w, h) = Self::extent(&pts, triangles, eps, max_size)?;
        Some(Self::rasterize_texels(&pts, triangles, w, h, eps))
    }

    /// Width and height of the footprint of `triangles` over points already in texel
    /// units (as [`Self::rasterize`] sizes it); `None` beyond `max_size` or non-finite.
    pub fn extent(
        pts: &[[f64; 2]],
        triangles: &[[u32; 3]],
        eps: f64,
        max_size: i64,
    ) -> Option<(i64, i64)> {
        let mut hi = [0.0f64; 2];
        for t in triangles {
            for &i in t {
                let p = pts[i as usize];
                hi = [hi[0].max(p[0]), hi[1].max(p[1])];
            }
        }
        if !(hi[0].is_finite() && hi[1].is_finite()) {
            return None;
        }
        let w = ((hi[0] + eps).floor() as i64 + 1).max(1);
        let h = ((hi[1] + eps).floor() as i64 + 1).max(1);
        (w <= max_size && h <= max_size).then_some((w, h))
    }

    /// Rasterises triangles whose points are already in texel units into a `w × h`
    /// footprint (coverage outside it is clamped to the border texels).
    pub fn rasterize_texels(
        pts: &[[f64; 2]],
        triangles: &[[u32; 3]],
        w: i64,
        h: i64,
        eps: f64,
    ) -> Self {
        let mut f = Self::empty(w, h);
        let stride = f.stride;
        for t in triangles {
            let tri = [pts[t[0] as usize], pts[t[1] as usize], pts[t[2] as usize]];
            triangle_row_spans(tri, eps, |r, a, b| {
                let r = r.clamp(0, h - 1) as usize;
                let (a, b) = (a.clamp(0, w - 1) as usize, b.clamp(0, w - 1) as usize);
                if a <= b {
                    set_bits(&mut f.bits[r * stride..(r + 1) * stride], a, b);
                }
            });
        }
        if f.bits.iter().all(|&x| x == 0) {
            f.bits[0] = 1; // a chart always reserves at least one texel
        }
        f
    }

    /// The footprint of a region given by its outline: `segments` (index pairs into
    /// `pts`, texel units) are the boundary edges of a set of triangles without
    /// overlaps (a flip-free chart whose boundary does not cross itself). A texel
    /// meets the closed region exactly when it meets the outline or lies inside, so the
    /// result equals [`Self::rasterize_texels`] of the triangles, at a cost that grows
    /// with the outline instead of the triangle count: the segments are rasterised as
    /// degenerate triangles and the inside is filled between crossings of the texel-row
    /// centre lines (even–odd rule).
    pub fn rasterize_outline(
        pts: &[[f64; 2]],
        segments: &[[u32; 2]],
        w: i64,
        h: i64,
        eps: f64,
        crossings: &mut Vec<(i64, f64)>,
    ) -> Self {
        let mut f = Self::empty(w, h);
        let stride = f.stride;
        crossings.clear();
        for s in segments {
            let (p, q) = (pts[s[0] as usize], pts[s[1] as usize]);
            triangle_row_spans([p, q, q], eps, |r, a, b| {
                let r = r.clamp(0, h - 1) as usize;
                let (a, b) = (a.clamp(0, w - 1) as usize, b.clamp(0, w - 1) as usize);
                if a <= b {
                    set_bits(&mut f.bits[r * stride..(r + 1) * stride], a, b);
                }
            });
            if p[1] == q[1] || !(p[1].is_finite() && q[1].is_finite()) {
                continue;
            }
            let (lo, hi) = if p[1] < q[1] { (p, q) } else { (q, p) };
            let dxdy = (hi[0] - lo[0]) / (hi[1] - lo[1]);
            // Rows whose centre line y = r + ½ satisfies lo.y ≤ y < hi.y.
            let r0 = (lo[1] - 0.5).ceil() as i64;
            let r1 = (hi[1] - 0.5).ceil() as i64;
            for r in r0.max(0)..r1.min(h) {
                let y = r as f64 + 0.5;
                crossings.push((r, lo[0] + (y - lo[1]) * dxdy));
            }
        }
        crossings.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
        // Closed outlines cross every centre line an even number of times (the count
        // depends only on comparisons of corner heights); pair them within each row.
        let mut i = 0;
        while i < crossings.len() {
            let r = crossings[i].0;
            let mut j = i;
            while j < crossings.len() && crossings[j].0 == r {
                j += 1;
            }
            let row = &mut f.bits[r as usize * stride..(r as usize + 1) * stride];
            for pair in crossings[i..j].chunks_exact(2) {
                // Texels whose centre c + ½ lies in [x0, x1].
                let a = ((pair[0].1 - 0.5).ceil() as i64).max(0);
                let b = ((pair[1].1 - 0.5).floor() as i64).min(w - 1);
                if a <= b {
                    set_bits(row, a as usize, b as usize);
                }
            }
            i = j;
        }
        if f.bits.iter().all(|&x| x == 0) {
            f.bits[0] = 1;
        }
        f
    }

    /// Quarter turn counter-clockwise: texel `(x, y)` → `(h − 1 − y, x)` (the packer
    /// rasterises rotated points instead; this is the test oracle).
    #[cfg(test)]
    pub fn rotate90(&self) -> Self {
        let mut out = Self::empty(self.h, self.w);
        let mut spans = Vec::new();
        for y in 0..self.h {
            spans.clear();
            row_runs(self.row(y), self.w as usize, 0, &mut spans);
            let nx = (self.h - 1 - y) as usize;
            for &(a, b) in &spans {
                for x in a..=b {
                    out.bits[x as usize * out.stride + nx / 64] |= 1u64 << (nx % 64);
                }
            }
        }
        out
    }

    /// Appends the spans of row `y` shifted by `shift`.
    pub fn row_spans(&self, y: i64, shift: i64, out: &mut Vec<(i64, i64)>) {
        row_runs(self.row(y), self.w as usize, shift, out);
    }

    /// The footprint grown by a disk of radius `radius` texels (centre distances
    /// ≤ `radius`; the radius need not be a whole number).
    pub fn grow(&self, radius: f64) -> Grown {
        let radius = radius.max(0.0);
        let g = (radius + 1e-9).floor() as i64;
        let ext: Vec<i64> = (0..=g)
            .map(|d| ((radius * radius - (d * d) as f64).max(0.0).sqrt() + 1e-9).floor() as i64)
            .collect();
        let wg = (self.w + 2 * g) as usize;
        let sg = wg.div_ceil(64);
        // Horizontally grown rows, one set per distinct extension.
        let mut exts: Vec<i64> = ext.clone();
        exts.sort_unstable();
        exts.dedup();
        let h = self.h as usize;
        let mut hrows: Vec<Vec<u64>> = vec![vec![0u64; sg * h]; exts.len()];
        let mut spans = Vec::new();
        for y in 0..h {
            spans.clear();
            self.row_spans(y as i64, 0, &mut spans);
            for (k, &e) in exts.iter().enumerate() {
                let row = &mut hrows[k][y * sg..(y + 1) * sg];
                for &(a, b) in &spans {
                    set_bits(row, (a - e + g) as usize, (b + e + g) as usize);
                }
            }
        }
        let which: Vec<usize> =
            ext.iter().map(|e| exts.binary_search(e).expect("listed")).collect();
        let n = h + 2 * g as usize;
        let mut grown = Grown {
            y0: -g,
            spans: Vec::with_capacity(2 * n),
            start: Vec::with_capacity(n + 1),
            need: Vec::with_capacity(n),
            by_need: Vec::new(),
        };
        grown.start.push(0);
        let mut acc = vec![0u64; sg];
        for k in 0..n as i64 {
            let y = k - g;
            acc.fill(0);
            for d in -g..=g {
                let src = y + d;
                if src < 0 || src >= self.h {
                    continue;
                }
                let hr = &hrows[which[d.unsigned_abs() as usize]];
                for (a, &b) in acc.iter_mut().zip(&hr[src as usize * sg..(src as usize + 1) * sg]) {
                    *a |= b;
                }
            }
            let first = grown.spans.len();
            row_runs(&acc, wg, -g, &mut grown.spans);
            let row = &grown.spans[first..];
            grown.need.push(row.iter().map(|&(a, b)| b - a + 1).max().unwrap_or(0));
            grown.start.push(grown.spans.len() as u32);
        }
        grown.by_need = (0..n as u32).collect();
        grown.by_need.sort_by_key(|&r| (std::cmp::Reverse(grown.need[r as usize]), r));
        grown
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_and_ranges() {
        let mut row = vec![0u64; 3];
        set_bits(&mut row, 3, 70);
        set_bits(&mut row, 130, 130);
        set_bits(&mut row, 72, 72);
        let mut out = Vec::new();
        row_runs(&row, 140, 0, &mut out);
        assert_eq!(out, vec![(3, 70), (72, 72), (130, 130)]);
        out.clear();
        row_runs(&row, 130, 10, &mut out);
        assert_eq!(out, vec![(13, 80), (82, 82)]);
    }

    #[test]
    fn rotation_matches_rasterised_rotation() {
        let pts = [[0.0, 0.0], [3.0, 0.0], [0.0, 1.0]];
        let tris = [[0u32, 1, 2]];
        let f = Footprint::rasterize(&pts, &tris, [0.0, 0.0], 2.0, 0.5, 1e-3, 100).unwrap();
        let r = f.rotate90();
        assert_eq!((r.w, r.h), (f.h, f.w));
        // The packer's way: rasterise the turned points `q ↦ (h − q_y, q_x)`.
        let q: Vec<[f64; 2]> = pts.iter().map(|p| [p[0] * 2.0 + 0.5, p[1] * 2.0 + 0.5]).collect();
        let turned: Vec<[f64; 2]> = q.iter().map(|p| [f.h as f64 - p[1], p[0]]).collect();
        assert_eq!(Footprint::rasterize_texels(&turned, &tris, f.h, f.w, 1e-3), r);
        let rot: Vec<[f64; 2]> = pts.iter().map(|p| [-p[1], p[0]]).collect();
        let g = Footprint::rasterize(&rot, &tris, [-1.0, 0.0], 2.0, 0.5, 1e-3, 100).unwrap();
        assert_eq!(g, r);
        assert_eq!(r.rotate90().rotate90().rotate90(), f);
    }

    #[test]
    fn outline_fill_equals_triangle_union() {
        // A fan around a centre with a wiggly, non-convex rim (a flip-free disk).
        let n = 23;
        let mut pts = vec![[20.3, 19.7]];
        for k in 0..n {
            let a = k as f64 / n as f64 * std::f64::consts::TAU;
            let r = 12.0 + 6.0 * (3.0 * a).sin() + if k % 2 == 0 { 2.5 } else { 0.0 };
            pts.push([20.3 + r * a.cos(), 19.7 + r * a.sin()]);
        }
        let tris: Vec<[u32; 3]> =
            (0..n as u32).map(|k| [0, 1 + k, 1 + (k + 1) % n as u32]).collect();
        let mut segs = Vec::new();
        for t in &tris {
            segs.push([t[1], t[2]]);
        }
        let mut scratch = Vec::new();
        for eps in [0.0, 1e-3] {
            let a = Footprint::rasterize_texels(&pts, &tris, 42, 41, eps);
            let b = Footprint::rasterize_outline(&pts, &segs, 42, 41, eps, &mut scratch);
            assert_eq!(a, b, "eps {eps}");
        }
    }

    #[test]
    fn growth_is_a_disk() {
        // A single texel grown by 2: rows -2..=2 with half-widths 0, 1, 2, 1, 0.
        let f = Footprint::rasterize(&[[0.2, 0.2]; 3], &[[0, 1, 2]], [0.0, 0.0], 1.0, 0.0, 0.0, 10)
            .unwrap();
        assert_eq!((f.w, f.h), (1, 1));
        let g = f.grow(2.0);
        assert_eq!(g.y0, -2);
        let rows: Vec<Vec<(i64, i64)>> = (0..g.n_rows()).map(|k| g.row(k).to_vec()).collect();
        assert_eq!(
            rows,
            vec![vec![(0, 0)], vec![(-1, 1)], vec![(-2, 2)], vec![(-1, 1)], vec![(0, 0)]]
        );
        assert_eq!(g.need, vec![1, 3, 5, 3, 1]);
    }
}
