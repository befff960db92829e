//! Free space of the packer ([`crate::packing`]): occupied spans per atlas row (of
//! cells), the longest free run of each row, and the lowest-then-leftmost offset where
//! a grown footprint fits. Rows whose longest free run is shorter than a footprint row
//! are skipped at once; otherwise the feasible offsets are narrowed by interval
//! subtraction, row by row, starting at the row that blocked the previous offset.

use crate::chart_footprint::{Footprint, Grown};

fn merge_spans(spans: &mut Vec<(i64, i64)>) {
    spans.sort_unstable();
    let mut out: Vec<(i64, i64)> = Vec::with_capacity(spans.len());
    for &(a, b) in spans.iter() {
        match out.last_mut() {
            Some(last) if a <= last.1 + 1 => last.1 = last.1.max(b),
            _ => out.push((a, b)),
        }
    }
    *spans = out;
}

/// Occupied spans per atlas row and the longest free run of each row.
pub(crate) struct Grid {
    /// Width in cells (the atlas side over the cell size).
    size: i64,
    /// Height in cells: twice the atlas, so that a failed fit still measures how tall
    /// the packing would be.
    pub height: i64,
    gutter: i64,
    margin: i64,
    rows: Vec<Vec<(i64, i64)>>,
    max_free: Vec<i64>,
}

impl Grid {
    /// `gutter`: how far (whole cells) a grown footprint may reach past the sides;
    /// `margin`: free cells kept along the border.
    pub fn new(size: i64, height: i64, gutter: i64, margin: i64) -> Self {
        let free = size + 2 * gutter;
        Self {
            size,
            height,
            gutter,
            margin,
            rows: vec![Vec::new(); height as usize],
            max_free: vec![free; height as usize],
        }
    }

    fn update_free(&mut self, y: usize) {
        let lo = -self.gutter;
        let hi = self.size - 1 + self.gutter;
        let mut cur = lo;
        let mut best = 0;
        for &(a, b) in &self.rows[y] {
            best = best.max(a - cur);
            cur = cur.max(b + 1);
        }
        best = best.max(hi + 1 - cur);
        self.max_free[y] = best;
    }

    /// Rows an offset of a footprint `fh` texels tall may take, at least `oy_min` and at
    /// most `oy_max`.
    pub fn offset_rows(&self, fh: i64, oy_min: i64, oy_max: i64) -> (i64, i64) {
        (self.margin.max(oy_min), (self.height - self.margin - fh).min(oy_max))
    }

    /// Lowest-then-leftmost offset where `grown` (of a `fw × fh` footprint) fits, with
    /// the offset's row between `oy_min` and `oy_max`.
    pub fn find(
        &self,
        grown: &Grown,
        fw: i64,
        fh: i64,
        oy_min: i64,
        oy_max: i64,
    ) -> Option<(i64, i64)> {
        let (ox_lo, ox_hi) = (self.margin, self.size - self.margin - fw);
        let (oy_lo, oy_hi) = self.offset_rows(fh, oy_min, oy_max);
        if ox_lo > ox_hi || oy_lo > oy_hi {
            return None;
        }
        let nrows = grown.n_rows() as i64;
        let mut feasible: Vec<(i64, i64)> = Vec::with_capacity(16);
        let mut scratch: Vec<(i64, i64)> = Vec::with_capacity(16);
        // Atlas row where the last test failed: the obstacle there usually blocks the
        // next offset too, one chart row lower.
        let mut hint_y = i64::MIN;
        let mut oy = oy_lo - 1;
        'oy: loop {
            oy += 1;
            if oy > oy_hi {
                break;
            }
            feasible.clear();
            feasible.push((ox_lo, ox_hi));
            // Rows in any order give the same set; start at the last obstacle.
            let r0 = hint_y - (oy + grown.y0);
            let first = if (0..nrows).contains(&r0) { Some(r0) } else { None };
            // Then the widest rows: in a fragmented atlas they are the likeliest to fail.
            let widest = grown.by_need.iter().map(|&r| r as i64).filter(|&r| Some(r) != first);
            for r in first.into_iter().chain(widest) {
                let y = oy + grown.y0 + r;
                if y < 0 || y >= self.height {
                    continue;
                }
                let need = grown.need[r as usize];
                if need > self.max_free[y as usize] {
                    // Skip to the next offset where this row has a long enough run.
                    let mut y2 = y + 1;
                    while y2 < self.height && need > self.max_free[y2 as usize] {
                        y2 += 1;
                    }
                    oy += y2 - y - 1;
                    hint_y = y2;
                    continue 'oy;
                }
                let occ = &self.rows[y as usize];
                if occ.is_empty() {
                    continue;
                }
                for &(a, b) in grown.row(r as usize) {
                    // Offsets where span [a, b] meets occupied span [p, q]: [p - b, q - a].
                    scratch.clear();
                    for &(s, e) in &feasible {
                        let mut cur = s;
                        let start = occ.partition_point(|&(_, q)| q - a < s);
                        for &(p, q) in &occ[start..] {
                            let (fs, fe) = (p - b, q - a);
                            if fs > e {
                                break;
                            }
                            if fs > cur {
                                scratch.push((cur, fs - 1));
                            }
                            cur = cur.max(fe + 1);
                            if cur > e {
                                break;
                            }
                        }
                        if cur <= e {
                            scratch.push((cur, e));
                        }
                    }
                    std::mem::swap(&mut feasible, &mut scratch);
                    if feasible.is_empty() {
                        hint_y = y;
                        continue 'oy;
                    }
                }
            }
            return Some((feasible[0].0, oy));
        }
        None
    }

    pub fn place(&mut self, f: &Footprint, ox: i64, oy: i64) {
        for r in 0..f.h {
            let y = (oy + r) as usize;
            let before = self.rows[y].len();
            f.row_spans(r, ox, &mut self.rows[y]);
            if self.rows[y].len() > before {
                merge_spans(&mut self.rows[y]);
                self.update_free(y);
            }
        }
    }
}
