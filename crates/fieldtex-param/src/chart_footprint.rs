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
/// `y0 + k`; `need[k]` is the length of its longest span; `by_need` lists the rows
/// from the widest to the narrowest (ties by row).
#[derive(Debug, Clone, Default)]
pub(crate) struct Grown {
    pub y0: i64,
    pub rows: Vec<Vec<(i64, i64)>>,
    pub need: Vec<i64>,
    pub by_need: Vec<u32>,
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
    /// `None` when the footprint would be wider or taller than `max_size`.
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
        if w > max_size || h > max_size {
            return None;
        }
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
        Some(f)
    }

    /// Quarter turn counter-clockwise: texel `(x, y)` → `(h − 1 − y, x)`.
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

    /// The footprint grown by a disk of radius `g` texels (centre distances ≤ `g`).
    pub fn grow(&self, g: i64) -> Grown {
        let ext: Vec<i64> =
            (0..=g).map(|d| (((g * g - d * d) as f64).sqrt() + 1e-9).floor() as i64).collect();
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
            rows: Vec::with_capacity(n),
            need: Vec::with_capacity(n),
            by_need: Vec::new(),
        };
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
            let mut row = Vec::new();
            row_runs(&acc, wg, -g, &mut row);
            grown.need.push(row.iter().map(|&(a, b)| b - a + 1).max().unwrap_or(0));
            grown.rows.push(row);
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
        let rot: Vec<[f64; 2]> = pts.iter().map(|p| [-p[1], p[0]]).collect();
        let g = Footprint::rasterize(&rot, &tris, [-1.0, 0.0], 2.0, 0.5, 1e-3, 100).unwrap();
        assert_eq!(g, r);
        assert_eq!(r.rotate90().rotate90().rotate90(), f);
    }

    #[test]
    fn growth_is_a_disk() {
        // A single texel grown by 2: rows -2..=2 with half-widths 0, 1, 2, 1, 0.
        let f = Footprint::rasterize(&[[0.2, 0.2]; 3], &[[0, 1, 2]], [0.0, 0.0], 1.0, 0.0, 0.0, 10)
            .unwrap();
        assert_eq!((f.w, f.h), (1, 1));
        let g = f.grow(2);
        assert_eq!(g.y0, -2);
        assert_eq!(
            g.rows,
            vec![vec![(0, 0)], vec![(-1, 1)], vec![(-2, 2)], vec![(-1, 1)], vec![(0, 0)]]
        );
        assert_eq!(g.need, vec![1, 3, 5, 3, 1]);
    }
}
