//! Chart packing: places flattened charts into a square atlas with gutters.
//!
//! Each chart is rasterised conservatively (module `chart_footprint`) at a trial
//! scale (texels per unit of chart coordinates) into a *footprint* bitmap; the
//! footprint grown by a disk of radius `G` (the gutter) must not meet any texel already
//! covered by another chart. Charts go in order of decreasing area, each at the lowest,
//! then leftmost, position where it fits, trying the four rotations by 90° and keeping
//! the one whose top edge ends lowest (a bottom-left fill on the real chart shapes
//! rather than on their bounding boxes, in the spirit of the "Tetris" packing of Lévy
//! et al. 2002 §5 and of xatlas's bitmap packer). Free space is kept as interval lists
//! per row, so a position test costs a few interval subtractions per chart row; rows
//! whose longest free run is too short are skipped at once.
//!
//! **Cells.** Placement works on a grid of `k × k`-texel cells
//! ([`PackingOptions::cell`]; `k = 2` for the default 1024² atlas): a chart reserves
//! every cell that one of its texels touches, and the gutter test uses the radius
//! `(G + (k − 1)·√2) / k` cells, since two texels in cells `a` and `b` are at least
//! `k·|a − b| − (k − 1)·√2` texels apart. Placements are exact in texels; the cost of a
//! trial drops with the number of cell rows, at the price of up to a cell of extra
//! space around each chart. Charts without overlaps are rasterised from their outline
//! (boundary segments plus an even–odd fill between crossings of the row centres),
//! which equals the union of their triangles' coverage at a cost that grows with the
//! boundary, not the triangle count.
//!
//! The scale is the largest one (within [`PackingOptions::tolerance`]) at which every
//! chart fits. Each trial packs into a grid twice as tall as the atlas and reports the
//! height it used; the height grows roughly like the square of the scale, which gives
//! the next guess, and the bracket between the best fitting and the smallest failing
//! scale is then narrowed with three trial scales per round, evaluated in parallel
//! (module `packing_scale_search`).
//! The search runs first on cells twice as large (a quarter of the work per trial)
//! and then, from just above the scale found there, for at most three rounds on the
//! final cells; the coarse packing is valid as it stands and is kept if no finer one
//! fits. Results do not depend on the thread count.
//!
//! **Few charts** (at most 16 at 1024²: [`SMALL_INPUT_CHART_SIDE`]; atlases of 512²
//! texels or more): each trial rasterises and grows a few large footprints, and the
//! waste of a coarse cell along a chart's outline is small against the chart's area,
//! so the trials run on a coarser working raster. The final cells are four times as
//! large, at most 1/128 of the atlas side (8×8 texels at 1024²), the bracket runs on
//! cells of 1/64 of the atlas side (16 texels at 1024²) to a relative precision of
//! 3 % (1 % elsewhere), and the final search stops after two rounds. This costs a few points of packing efficiency (numbers in
//! `docs/perf/atlas.md`).
//!
//! **Packing efficiency** (reported by the atlas) is the charts' UV triangle area in
//! texels over the atlas area; gutters and the conservative coverage of boundary
//! texels count as waste.
//!
//! Conventions: atlas texel `(x, y)` has `x` to the right and `y` **up** (row 0 is the
//! bottom row, `v` ∈ `[0, 1/H]`). Gutter semantics: the centres of two texels covered by
//! different charts are more than `G` texels apart (Euclidean), and covered texels keep
//! `⌈G/2⌉` texels from the atlas border, so wrapping samplers do not bleed either.
//! Charts are only rotated, never mirrored (mirroring would flip triangles).

use crate::ParamError;
use crate::chart_footprint::{Footprint, Grown};
use crate::packing_grid::Grid;
use crate::packing_scale_search::{Search, SearchState, search_scale};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// A chart ready for packing: 2-D points in any unit and triangles indexing them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PackChart {
    pub points: Vec<[f64; 2]>,
    pub triangles: Vec<[u32; 3]>,
    /// The triangles do not overlap (no flips, a boundary that does not cross itself),
    /// so the chart can be rasterised from its outline (faster for large charts).
    /// `false` rasterises every triangle. Default false.
    pub simple_outline: bool,
}

/// The edges of `triangles` used by one triangle only (in its direction).
fn outline_segments(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(3 * triangles.len());
    for t in triangles {
        for k in 0..3 {
            edges.push((t[k], t[(k + 1) % 3]));
        }
    }
    let mut keys: Vec<(u32, u32)> = edges.iter().map(|&(a, b)| (a.min(b), a.max(b))).collect();
    keys.sort_unstable();
    edges
        .into_iter()
        .filter(|&(a, b)| {
            let k = (a.min(b), a.max(b));
            let i = keys.partition_point(|x| *x < k);
            keys.get(i + 1) != Some(&k)
        })
        .map(|(a, b)| [a, b])
        .collect()
}

/// Options of [`pack_charts`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PackingOptions {
    /// Atlas width and height in texels. Default 1024.
    pub resolution: u32,
    /// Minimum free distance between charts, in texels. Default 4.
    pub gutter: u32,
    /// Try the four 90° rotations of every chart. Default true.
    pub rotate: bool,
    /// Relative precision of the scale search. Default 0.004.
    pub tolerance: f64,
    /// Texels per side of a packing cell (charts are placed on a grid of
    /// `cell × cell`-texel cells; see the module docs); 0 picks it from the resolution:
    /// 1 up to 512 texels, 2 up to 2048, 4 above. Default 0.
    pub cell: u32,
}

impl Default for PackingOptions {
    fn default() -> Self {
        Self { resolution: 1024, gutter: 4, rotate: true, tolerance: 0.004, cell: 0 }
    }
}

impl PackingOptions {
    /// The cell size in texels actually used (module docs).
    pub fn cell_texels(&self) -> u32 {
        match self.cell {
            0 if self.resolution <= 512 => 1,
            0 if self.resolution <= 2048 => 2,
            0 => 4,
            c => c.clamp(1, (self.resolution / 8).max(1)),
        }
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
    /// Offset in texels of chart points inside their footprint (half a cell).
    pub inset: f64,
}

/// Inputs whose charts would be at least this many texels wide on average (the atlas
/// side over the square root of the chart count: at most 16 charts at 1024²) pack on
/// the coarser cells of the small-input shortcut (module docs).
pub const SMALL_INPUT_CHART_SIDE: f64 = 256.0;

/// Relative precision of the coarse bracket of the small-input shortcut (the final
/// cells then refine it; 0.01 elsewhere).
const SMALL_INPUT_COARSE_TOLERANCE: f64 = 0.03;

/// Footprints of at most this many cells are remembered per shape within a trial (the
/// lowest row still worth testing; this only skips rows that cannot fit, so results
/// are the same with or without it).
const SHAPE_CACHE_CELLS: i64 = 4096;

/// Offset of chart points inside their footprint, in texels (keeps columns ≥ 0).
pub(crate) const INSET: f64 = 0.5;
/// Rasterisation margin of the packer, in texels (covers rounding in later steps).
const PACK_EPS: f64 = 1e-3;

impl Packing {
    /// Atlas position in texels (x right, y up) of point `p` of chart `chart`.
    pub fn atlas_texel(&self, chart: usize, p: [f64; 2]) -> [f64; 2] {
        let pl = &self.placements[chart];
        let s = self.texels_per_unit;
        let mut q =
            [(p[0] - pl.origin[0]) * s + self.inset, (p[1] - pl.origin[1]) * s + self.inset];
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

/// A packing at one scale: placements and the top row used (exclusive).
pub(crate) struct Trial {
    pub(crate) placements: Vec<Placement>,
    pub(crate) top: i64,
}

/// The packing grid of one trial: `k × k`-texel cells.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CellGrid {
    /// Texels per cell side.
    pub(crate) k: i64,
    /// Cells per atlas side.
    pub(crate) size: i64,
    /// Gutter radius in cells (see the module docs).
    gutter: f64,
    /// Free cells along the border.
    pub(crate) margin: i64,
}

impl CellGrid {
    fn new(opts: &PackingOptions, k: i64) -> Self {
        let g = opts.gutter as f64;
        // Two texels in cells `a` and `b` are at least k·|a − b| − (k − 1)·√2 apart.
        let gutter =
            if k == 1 { g } else { (g + (k - 1) as f64 * std::f64::consts::SQRT_2) / k as f64 };
        let margin = (opts.gutter as i64 + 1) / 2;
        Self { k, size: opts.resolution as i64 / k, gutter, margin: (margin + k - 1) / k }
    }
}

/// Packs all charts at scale `scale` (texels per unit) into a grid twice as tall as
/// the atlas; `None` when a chart is wider than the atlas or the grid overflows.
pub(crate) fn try_pack(
    charts: &[PackChart],
    outlines: &[Option<Vec<[u32; 2]>>],
    origins: &[[f64; 2]],
    order: &[usize],
    scale: f64,
    opts: &PackingOptions,
    cells: CellGrid,
) -> Option<Trial> {
    let size = cells.size;
    let rots = if opts.rotate { 4 } else { 1 };
    let gi = (cells.gutter + 1e-9).floor() as i64;
    let mut grid = Grid::new(size, 2 * size, gi, cells.margin);
    let mut out = vec![
        Placement { offset: [0, 0], rotation: 0, origin: [0.0; 2], size: [0, 0] };
        charts.len()
    ];
    let cell_scale = scale / cells.k as f64;
    let mut top = 0;
    // Occupancy only grows, so a footprint that did not fit below some row never will:
    // remember, per footprint shape, the lowest row still worth testing. Every chart
    // contains a cell of its bottom row, so no chart fits below the lowest row where a
    // single grown cell fits (`floor`).
    let mut lowest: HashMap<Footprint, (std::rc::Rc<Grown>, i64)> = HashMap::new();
    let probe = Footprint::single();
    let probe_grown = probe.grow(cells.gutter);
    let mut floor = 0;
    let mut pts: Vec<[f64; 2]> = Vec::new();
    let mut crossings = Vec::new();
    for &c in order {
        let ch = &charts[c];
        pts.clear();
        pts.extend(ch.points.iter().map(|p| {
            [
                (p[0] - origins[c][0]) * cell_scale + INSET,
                (p[1] - origins[c][1]) * cell_scale + INSET,
            ]
        }));
        let mut raster = |pts: &[[f64; 2]], w: i64, h: i64| match &outlines[c] {
            Some(seg) => Footprint::rasterize_outline(pts, seg, w, h, PACK_EPS, &mut crossings),
            None => Footprint::rasterize_texels(pts, &ch.triangles, w, h, PACK_EPS),
        };
        let (w, h) = Footprint::extent(&pts, &ch.triangles, PACK_EPS, size)?;
        let base = raster(&pts, w, h);
        let mut best: Option<((i64, i64, i64, u8), Footprint)> = None;
        let mut fp = base.clone();
        for k in 0..rots {
            if k > 0 {
                // Quarter turn of the points, as `Packing::atlas_texel` does it.
                let h = fp.h as f64;
                for q in pts.iter_mut() {
                    *q = [h - q[1], q[0]];
                }
                fp = raster(&pts, fp.h, fp.w);
            }
            // Only rows that could beat the best top edge so far.
            let oy_max = best.as_ref().map_or(i64::MAX, |(bk, _)| bk.0 - fp.h);
            // Large footprints rarely repeat and cost to hash: only small ones are kept.
            let cached = fp.w * fp.h <= SHAPE_CACHE_CELLS;
            let (grown, seen) = match lowest.get(&fp).filter(|_| cached) {
                Some((gr, row)) => (gr.clone(), *row),
                None => (std::rc::Rc::new(fp.grow(cells.gutter)), 0),
            };
            let oy_min = floor.max(seen);
            let (lo, hi) = grid.offset_rows(fp.h, oy_min, oy_max);
            let found = grid.find(&grown, fp.w, fp.h, oy_min, oy_max);
            let next = match found {
                Some((_, oy)) => oy,
                None if lo <= hi => hi + 1,
                None => seen,
            };
            if cached {
                lowest.insert(fp.clone(), (grown, next));
            }
            if let Some((ox, oy)) = found {
                let key = (oy + fp.h, oy, ox, k as u8);
                if best.as_ref().is_none_or(|(bk, _)| key < *bk) {
                    best = Some((key, fp.clone()));
                }
            }
        }
        let ((t, oy, ox, k), f) = best?;
        grid.place(&f, ox, oy);
        top = top.max(t);
        floor = grid.find(&probe_grown, 1, 1, floor, i64::MAX).map_or(grid.height, |(_, y)| y);
        let kk = cells.k;
        out[c] = Placement {
            offset: [kk * ox, kk * oy],
            rotation: k,
            origin: origins[c],
            size: [kk * base.w, kk * base.h],
        };
    }
    Some(Trial { placements: out, top })
}

/// Packs `charts` into a `resolution²` atlas at the largest scale that fits (module
/// docs). Charts with no triangles get a placement and reserve one texel.
pub fn pack_charts(charts: &[PackChart], options: &PackingOptions) -> Result<Packing, ParamError> {
    if options.resolution < 8 || options.resolution > 16384 {
        return Err(ParamError::InvalidOption {
            name: "resolution",
            value: options.resolution.to_string(),
            reason: "the atlas resolution must be between 8 and 16384 texels",
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
        let mut a = 0.0;
        for t in &ch.triangles {
            let [p, q, r] = t.map(|i| ch.points[i as usize]);
            for v in [p, q, r] {
                lo = [lo[0].min(v[0]), lo[1].min(v[1])];
                hi = [hi[0].max(v[0]), hi[1].max(v[1])];
            }
            a += 0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])).abs();
        }
        if !(lo[0].is_finite() && lo[1].is_finite() && hi[0].is_finite() && hi[1].is_finite()) {
            lo = [0.0; 2];
            hi = [0.0; 2];
        }
        extent = extent.max(hi[0] - lo[0]).max(hi[1] - lo[1]);
        origins.push(lo);
        areas.push(if a.is_finite() { a } else { 0.0 });
    }
    let mut order: Vec<usize> = (0..charts.len()).collect();
    order.sort_by(|&a, &b| areas[b].total_cmp(&areas[a]).then(a.cmp(&b)));
    let res = options.resolution as f64;
    let total: f64 = areas.iter().sum();
    // Upper bound: no chart larger than the atlas, no more than full coverage.
    let mut upper = if total > 0.0 { (res * res / total).sqrt() } else { f64::INFINITY };
    if extent > 0.0 {
        upper = upper.min(res / extent);
    }
    if !upper.is_finite() {
        upper = 1.0;
    }
    let tol = options.tolerance.clamp(1e-6, 0.5);
    let fail = |s: f64| ParamError::PackingFailed {
        charts: charts.len(),
        resolution: options.resolution,
        gutter: options.gutter,
        texels_per_unit: s,
    };
    let fine = CellGrid::new(options, options.cell_texels() as i64);
    let outlines: Vec<Option<Vec<[u32; 2]>>> = charts
        .par_iter()
        .map(|ch| ch.simple_outline.then(|| outline_segments(&ch.triangles)))
        .collect();
    let mut state = SearchState { lo: None, hi: upper * (1.0 + 1e-9), guess: 0.8 * upper };
    // Coarse to fine: the scale is first bracketed on cells twice as large (a quarter
    // of the work per trial); its packing is valid as it stands, so it is kept as the
    // fallback, and the search then goes on at full precision on the final cells from
    // just above it, for a few rounds at most.
    // Small inputs: the packer's trials dominate the atlas's time, so they run on a
    // coarser working raster (module docs).
    let side = options.resolution as f64 / (charts.len().max(1) as f64).sqrt();
    let small = side >= SMALL_INPUT_CHART_SIDE && options.resolution >= 512;
    let (coarse_k, fine, fine_rounds) = if small {
        let k = (4 * fine.k).min(options.resolution as i64 / 128);
        ((options.resolution as i64 / 64).max(2 * k), CellGrid::new(options, k), 2)
    } else {
        (2 * fine.k, fine, 3)
    };
    let coarse_tol = if small { SMALL_INPUT_COARSE_TOLERANCE } else { 0.01 };
    // Stages: (cells, tolerance, round limit). Each later stage restarts the bracket
    // from just above the scale the previous one found.
    let stages: Vec<(CellGrid, f64, usize)> = if options.resolution as i64 / coarse_k >= 64 {
        vec![(CellGrid::new(options, coarse_k), tol.max(coarse_tol), 40), (fine, tol, fine_rounds)]
    } else {
        vec![(fine, tol, 40)]
    };
    for (k, &(cells, stage_tol, rounds)) in stages.iter().enumerate() {
        if k > 0
            && let Some(lo) = &state.lo
        {
            state.hi = upper * (1.0 + 1e-9);
            state.guess = lo.scale * 1.03;
        }
        let search =
            Search { charts, outlines: &outlines, origins: &origins, order: &order, options };
        search_scale(&search, cells, &mut state, stage_tol, rounds);
    }
    let Some(found) = state.lo else { return Err(fail(state.guess)) };
    if found.scale < upper * 1e-9 {
        return Err(fail(found.scale));
    }
    Ok(Packing {
        resolution: options.resolution,
        gutter: options.gutter,
        texels_per_unit: found.scale,
        placements: found.placements,
        inset: found.inset,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::triangle_row_spans;

    fn square(side: f64) -> PackChart {
        PackChart {
            points: vec![[0.0, 0.0], [side, 0.0], [side, side], [0.0, side]],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            simple_outline: side > 2.5,
        }
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
