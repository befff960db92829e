//! Chart packing: places flattened charts into a square atlas with gutters.
//!
//! Each chart is rasterised conservatively ([`crate::raster`]) at a trial scale
//! (texels per unit of chart coordinates) into a *footprint* (per texel row, the sorted
//! spans of covered texels); the footprint grown by a disk of radius `G` (the gutter)
//! must not meet any texel already covered by another chart. Charts go in order of
//! decreasing area, each at the lowest, then leftmost, position where it fits, trying
//! the four rotations by 90° and keeping the one whose top edge ends lowest (a
//! bottom-left fill on the real chart shapes rather than on their bounding boxes, in
//! the spirit of the "Tetris" packing of Lévy et al. 2002 §5 and of xatlas's bitmap
//! packer). Free space is kept as interval lists per row, so a position test costs
//! a few interval subtractions per chart row.
//!
//! The scale is the largest one (within [`PackingOptions::tolerance`]) at which every
//! chart fits: a search over the scale, evaluating three trial scales per round in
//! parallel. Results do not depend on the thread count.
//!
//! Conventions: atlas texel `(x, y)` has `x` to the right and `y` **up** (row 0 is the
//! bottom row, `v` ∈ `[0, 1/H]`). Gutter semantics: the centres of two texels covered by
//! different charts are more than `G` texels apart (Euclidean), and covered texels keep
//! `⌈G/2⌉` texels from the atlas border, so wrapping samplers do not bleed either.
//! Charts are only rotated, never mirrored (mirroring would flip triangles).

use crate::ParamError;
use crate::raster::triangle_row_spans;
use rayon::prelude::*;
use serde::Serialize;

/// A chart ready for packing: 2-D points in any unit and triangles indexing them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PackChart {
    pub points: Vec<[f64; 2]>,
    pub triangles: Vec<[u32; 3]>,
}

/// Options of [`pack_charts`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PackingOptions {
    /// Atlas width and height in texels. Default 1024.
    pub resolution: u32,
    /// Minimum free distance between charts, in texels. Default 4.
    pub gutter: u32,
    /// Try the four 90° rotations of every chart. Default true.
    pub rotate: bool,
    /// Relative precision of the scale search. Default 0.004.
    pub tolerance: f64,
}

impl Default for PackingOptions {
    fn default() -> Self {
        Self { resolution: 1024, gutter: 4, rotate: true, tolerance: 0.004 }
    }
}

/// Where one chart went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Texel offset of the chart's rotated footprint in the atlas.
    pub offset: [i64; 2],
    /// Number of 90° counter-clockwise rotations (0–3).
    pub rotation: u8,
    /// Minimum corner of the chart's points (subtracted before scaling).
    pub origin: [f64; 2],
    /// Width and height in texels of the unrotated footprint.
    pub size: [i64; 2],
}

/// The result of [`pack_charts`].
#[derive(Debug, Clone, PartialEq)]
pub struct Packing {
    pub resolution: u32,
    pub gutter: u32,
    /// Texels per unit of chart coordinates.
    pub texels_per_unit: f64,
    /// One placement per chart, in input order.
    pub placements: Vec<Placement>,
}

/// Offset of chart points inside their footprint, in texels (keeps columns ≥ 0).
const INSET: f64 = 0.5;
/// Rasterisation margin of the packer, in texels (covers rounding in later steps).
const PACK_EPS: f64 = 1e-3;

impl Packing {
    /// Atlas position in texels (x right, y up) of point `p` of chart `chart`.
    pub fn atlas_texel(&self, chart: usize, p: [f64; 2]) -> [f64; 2] {
        let pl = &self.placements[chart];
        let s = self.texels_per_unit;
        let mut q = [(p[0] - pl.origin[0]) * s + INSET, (p[1] - pl.origin[1]) * s + INSET];
        // Footprint (width, height) before each quarter turn; they swap every turn.
        let mut wh = pl.size;
        for _ in 0..pl.rotation {
            q = [wh[1] as f64 - q[1], q[0]];
            wh = [wh[1], wh[0]];
        }
        [q[0] + pl.offset[0] as f64, q[1] + pl.offset[1] as f64]
    }

    /// Atlas UV in `[0, 1]²` (v up) of point `p` of chart `chart`.
    pub fn atlas_uv(&self, chart: usize, p: [f64; 2]) -> [f64; 2] {
        let t = self.atlas_texel(chart, p);
        let r = self.resolution as f64;
        [t[0] / r, t[1] / r]
    }
}

/// Row spans of covered texels, rows `0..h`, columns within `0..w`.
#[derive(Debug, Clone, Default)]
struct Footprint {
    w: i64,
    h: i64,
    rows: Vec<Vec<(i64, i64)>>,
}

/// A footprint grown by the gutter: rows start at `y0`; `need` is each row's widest span.
#[derive(Debug, Clone, Default)]
struct Grown {
    y0: i64,
    rows: Vec<Vec<(i64, i64)>>,
    need: Vec<i64>,
}

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

fn rasterize(chart: &PackChart, origin: [f64; 2], scale: f64) -> Footprint {
    let pts: Vec<[f64; 2]> = chart
        .points
        .iter()
        .map(|p| [(p[0] - origin[0]) * scale + INSET, (p[1] - origin[1]) * scale + INSET])
        .collect();
    let mut rows: Vec<Vec<(i64, i64)>> = Vec::new();
    let mut emit = |r: i64, a: i64, b: i64| {
        let r = r.max(0) as usize;
        if rows.len() <= r {
            rows.resize(r + 1, Vec::new());
        }
        rows[r].push((a.max(0), b.max(0)));
    };
    for t in &chart.triangles {
        let tri = [pts[t[0] as usize], pts[t[1] as usize], pts[t[2] as usize]];
        triangle_row_spans(tri, PACK_EPS, &mut emit);
    }
    if rows.is_empty() {
        rows.push(vec![(0, 0)]);
    }
    let mut w = 1;
    for r in rows.iter_mut() {
        merge_spans(r);
        if let Some(l) = r.last() {
            w = w.max(l.1 + 1);
        }
    }
    Footprint { w, h: rows.len() as i64, rows }
}

/// Rotates a footprint by 90° counter-clockwise: texel `(x, y)` → `(h − 1 − y, x)`.
fn rotate90(f: &Footprint) -> Footprint {
    let (w, h) = (f.w, f.h);
    let mut rows: Vec<Vec<(i64, i64)>> = vec![Vec::new(); w as usize];
    // New row x holds the old column x; the old row y becomes new column h-1-y.
    for y in (0..h).rev() {
        let nx = h - 1 - y;
        for &(a, b) in &f.rows[y as usize] {
            for x in a..=b {
                let row = &mut rows[x as usize];
                match row.last_mut() {
                    Some(last) if last.1 + 1 == nx => last.1 = nx,
                    _ => row.push((nx, nx)),
                }
            }
        }
    }
    Footprint { w: h, h: w, rows }
}

fn grow_footprint(f: &Footprint, g: i64) -> Grown {
    let ext: Vec<i64> =
        (0..=g).map(|d| (((g * g - d * d) as f64).sqrt() + 1e-9).floor() as i64).collect();
    let n = f.h + 2 * g;
    let mut rows = Vec::with_capacity(n as usize);
    let mut need = Vec::with_capacity(n as usize);
    for k in 0..n {
        let y = k - g;
        let mut spans = Vec::new();
        for d in -g..=g {
            let src = y + d;
            if src < 0 || src >= f.h {
                continue;
            }
            let e = ext[d.unsigned_abs() as usize];
            spans.extend(f.rows[src as usize].iter().map(|&(a, b)| (a - e, b + e)));
        }
        merge_spans(&mut spans);
        need.push(spans.iter().map(|&(a, b)| b - a + 1).max().unwrap_or(0));
        rows.push(spans);
    }
    Grown { y0: -g, rows, need }
}

/// Occupied spans per atlas row and the longest free run of each row.
struct Grid {
    size: i64,
    gutter: i64,
    margin: i64,
    rows: Vec<Vec<(i64, i64)>>,
    max_free: Vec<i64>,
}

impl Grid {
    fn new(size: i64, gutter: i64) -> Self {
        let margin = (gutter + 1) / 2;
        let free = size + 2 * gutter;
        Self {
            size,
            gutter,
            margin,
            rows: vec![Vec::new(); size as usize],
            max_free: vec![free; size as usize],
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

    /// Lowest-then-leftmost offset where `grown` (of a `fw × fh` footprint) fits.
    fn find(&self, grown: &Grown, fw: i64, fh: i64) -> Option<(i64, i64)> {
        let (ox_lo, ox_hi) = (self.margin, self.size - self.margin - fw);
        let (oy_lo, oy_hi) = (self.margin, self.size - self.margin - fh);
        if ox_lo > ox_hi || oy_lo > oy_hi {
            return None;
        }
        let nrows = grown.rows.len() as i64;
        let mut feasible: Vec<(i64, i64)> = Vec::new();
        let mut scratch: Vec<(i64, i64)> = Vec::new();
        let mut hint = 0i64;
        'oy: for oy in oy_lo..=oy_hi {
            // Quick reject on the longest free run, starting where the last one failed.
            for k in 0..nrows {
                let r = (hint + k) % nrows;
                let y = oy + grown.y0 + r;
                if y >= 0 && y < self.size && grown.need[r as usize] > self.max_free[y as usize] {
                    hint = r;
                    continue 'oy;
                }
            }
            feasible.clear();
            feasible.push((ox_lo, ox_hi));
            for r in 0..nrows {
                let y = oy + grown.y0 + r;
                if y < 0 || y >= self.size {
                    continue;
                }
                let occ = &self.rows[y as usize];
                if occ.is_empty() {
                    continue;
                }
                for &(a, b) in &grown.rows[r as usize] {
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
                        hint = r;
                        continue 'oy;
                    }
                }
            }
            return Some((feasible[0].0, oy));
        }
        None
    }

    fn place(&mut self, f: &Footprint, ox: i64, oy: i64) {
        for (r, spans) in f.rows.iter().enumerate() {
            if spans.is_empty() {
                continue;
            }
            let y = (oy + r as i64) as usize;
            self.rows[y].extend(spans.iter().map(|&(a, b)| (a + ox, b + ox)));
            merge_spans(&mut self.rows[y]);
            self.update_free(y);
        }
    }
}

/// Packs all charts at scale `scale`; `None` when one does not fit.
fn try_pack(
    charts: &[PackChart],
    origins: &[[f64; 2]],
    order: &[usize],
    scale: f64,
    opts: &PackingOptions,
) -> Option<Vec<Placement>> {
    let g = opts.gutter as i64;
    let size = opts.resolution as i64;
    let rots = if opts.rotate { 4 } else { 1 };
    let mut grid = Grid::new(size, g);
    let mut out = vec![
        Placement { offset: [0, 0], rotation: 0, origin: [0.0; 2], size: [0, 0] };
        charts.len()
    ];
    for &c in order {
        let base = rasterize(&charts[c], origins[c], scale);
        if base.w > size || base.h > size {
            return None;
        }
        let mut best: Option<((i64, i64, i64, u8), Footprint)> = None;
        let mut fp = base.clone();
        for k in 0..rots {
            if k > 0 {
                fp = rotate90(&fp);
            }
            let grown = grow_footprint(&fp, g);
            if let Some((ox, oy)) = grid.find(&grown, fp.w, fp.h) {
                let key = (oy + fp.h, oy, ox, k as u8);
                if best.as_ref().is_none_or(|(bk, _)| key < *bk) {
                    best = Some((key, fp.clone()));
                }
            }
        }
        let ((_, oy, ox, k), f) = best?;
        grid.place(&f, ox, oy);
        out[c] =
            Placement { offset: [ox, oy], rotation: k, origin: origins[c], size: [base.w, base.h] };
    }
    Some(out)
}

/// Packs `charts` into a `resolution²` atlas at the largest scale that fits (module
/// docs). Charts with no triangles get a placement but occupy nothing.
pub fn pack_charts(charts: &[PackChart], options: &PackingOptions) -> Result<Packing, ParamError> {
    if options.resolution < 8 || options.resolution > 32768 {
        return Err(ParamError::InvalidOption {
            name: "resolution",
            value: options.resolution.to_string(),
            reason: "the atlas resolution must be between 8 and 32768 texels",
        });
    }
    if options.gutter as u64 * 4 >= options.resolution as u64 {
        return Err(ParamError::InvalidOption {
            name: "gutter",
            value: options.gutter.to_string(),
            reason: "the gutter must be less than a quarter of the resolution",
        });
    }
    let mut origins = Vec::with_capacity(charts.len());
    let mut areas = Vec::with_capacity(charts.len());
    let mut extent = 0.0f64;
    for ch in charts {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for t in &ch.triangles {
            for &i in t {
                let p = ch.points[i as usize];
                for k in 0..2 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
        if !lo[0].is_finite() {
            lo = [0.0; 2];
            hi = [0.0; 2];
        }
        extent = extent.max(hi[0] - lo[0]).max(hi[1] - lo[1]);
        origins.push(lo);
        let mut a = 0.0;
        for t in &ch.triangles {
            let [p, q, r] =
                [ch.points[t[0] as usize], ch.points[t[1] as usize], ch.points[t[2] as usize]];
            a += 0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])).abs();
        }
        areas.push(a);
    }
    let mut order: Vec<usize> = (0..charts.len()).collect();
    order.sort_by(|&a, &b| areas[b].total_cmp(&areas[a]).then(a.cmp(&b)));
    let res = options.resolution as f64;
    let total: f64 = areas.iter().sum();
    // Upper bound: no chart larger than the atlas, no more than full coverage.
    let mut hi = if total > 0.0 { (res * res / total).sqrt() } else { f64::INFINITY };
    if extent > 0.0 {
        hi = hi.min(res / extent);
    }
    if !hi.is_finite() {
        hi = 1.0;
    }
    let fail = |s: f64| ParamError::PackingFailed {
        charts: charts.len(),
        resolution: options.resolution,
        gutter: options.gutter,
        texels_per_unit: s,
    };
    // Find a scale that fits, shrinking geometrically.
    let mut lo_fit: Option<(f64, Vec<Placement>)> = None;
    let mut s = hi * 0.8;
    for _ in 0..60 {
        let trials: Vec<f64> = vec![s, s * 0.85, s * 0.72];
        let results: Vec<Option<Vec<Placement>>> =
            trials.par_iter().map(|&t| try_pack(charts, &origins, &order, t, options)).collect();
        let mut found = false;
        for (t, r) in trials.iter().zip(results) {
            if let Some(p) = r {
                lo_fit = Some((*t, p));
                found = true;
                break;
            }
            hi = hi.min(*t);
        }
        if found {
            break;
        }
        s *= 0.6;
        if s < 1e-300 {
            break;
        }
    }
    let Some((mut lo, mut best)) = lo_fit else { return Err(fail(s)) };
    // Refine between lo (fits) and hi (does not, or the upper bound).
    let tol = options.tolerance.clamp(1e-6, 0.5);
    for _ in 0..20 {
        if hi / lo <= 1.0 + tol {
            break;
        }
        let r = hi / lo;
        let trials: Vec<f64> = (1..=3).map(|k| lo * r.powf(k as f64 / 4.0)).collect();
        let results: Vec<Option<Vec<Placement>>> =
            trials.par_iter().map(|&t| try_pack(charts, &origins, &order, t, options)).collect();
        let mut new_hi = hi;
        for (t, r) in trials.iter().zip(results) {
            match r {
                Some(p) => {
                    if *t > lo && *t < new_hi {
                        lo = *t;
                        best = p;
                    }
                }
                None => {
                    if *t > lo {
                        new_hi = new_hi.min(*t);
                    }
                }
            }
        }
        hi = new_hi;
    }
    Ok(Packing {
        resolution: options.resolution,
        gutter: options.gutter,
        texels_per_unit: lo,
        placements: best,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(side: f64) -> PackChart {
        PackChart {
            points: vec![[0.0, 0.0], [side, 0.0], [side, side], [0.0, side]],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    #[test]
    fn rotation_matches_geometry() {
        let ch = PackChart {
            points: vec![[0.0, 0.0], [3.0, 0.0], [0.0, 1.0]],
            triangles: vec![[0, 1, 2]],
        };
        let f = rasterize(&ch, [0.0, 0.0], 2.0);
        let r = rotate90(&f);
        assert_eq!((r.w, r.h), (f.h, f.w));
        // Rasterising the rotated geometry gives the rotated footprint.
        let rot = PackChart {
            points: ch.points.iter().map(|p| [-p[1], p[0]]).collect(),
            triangles: ch.triangles.clone(),
        };
        let g = rasterize(&rot, [-1.0, 0.0], 2.0);
        assert_eq!(g.rows, r.rows);
    }

    #[test]
    fn squares_pack_without_overlap() {
        let charts: Vec<PackChart> = (0..20).map(|i| square(1.0 + (i % 5) as f64)).collect();
        let opts = PackingOptions { resolution: 256, gutter: 2, ..Default::default() };
        let p = pack_charts(&charts, &opts).unwrap();
        let n = opts.resolution as usize;
        let mut owner = vec![usize::MAX; n * n];
        let mut covered = 0.0;
        for (c, ch) in charts.iter().enumerate() {
            let pts: Vec<[f64; 2]> = ch.points.iter().map(|&q| p.atlas_texel(c, q)).collect();
            for t in &ch.triangles {
                let tri = [pts[t[0] as usize], pts[t[1] as usize], pts[t[2] as usize]];
                covered += 0.5
                    * ((tri[1][0] - tri[0][0]) * (tri[2][1] - tri[0][1])
                        - (tri[1][1] - tri[0][1]) * (tri[2][0] - tri[0][0]));
                triangle_row_spans(tri, 0.0, |r, a, b| {
                    assert!(r >= 1 && (r as usize) < n - 1, "row {r} in the border margin");
                    for x in a..=b {
                        assert!(x >= 1 && (x as usize) < n - 1);
                        let o = &mut owner[r as usize * n + x as usize];
                        assert!(
                            *o == usize::MAX || *o == c,
                            "texel ({x}, {r}) covered by two charts"
                        );
                        *o = c;
                    }
                });
            }
        }
        // Rotation keeps orientation: covered area is positive.
        let eff = covered / (n * n) as f64;
        assert!(eff > 0.5, "efficiency {eff}");
        // Gutter: no texel of chart a within distance 2 of a texel of chart b.
        for y in 0..n {
            for x in 0..n {
                let o = owner[y * n + x];
                if o == usize::MAX {
                    continue;
                }
                for dy in -2i64..=2 {
                    for dx in -2i64..=2 {
                        if dx * dx + dy * dy > 4 {
                            continue;
                        }
                        let (xx, yy) = (x as i64 + dx, y as i64 + dy);
                        if xx < 0 || yy < 0 || xx >= n as i64 || yy >= n as i64 {
                            continue;
                        }
                        let o2 = owner[yy as usize * n + xx as usize];
                        assert!(o2 == usize::MAX || o2 == o);
                    }
                }
            }
        }
    }

    #[test]
    fn too_many_charts_is_an_error() {
        let charts: Vec<PackChart> = (0..400).map(|_| square(1.0)).collect();
        let opts = PackingOptions { resolution: 16, gutter: 3, ..Default::default() };
        assert!(matches!(pack_charts(&charts, &opts), Err(ParamError::PackingFailed { .. })));
    }
}
