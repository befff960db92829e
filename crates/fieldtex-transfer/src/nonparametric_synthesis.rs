//! Non-parametric synthesis guided by the geometry (paper B §5.1): image analogies
//! (Hertzmann et al. 2001) on surface samples (Turk 2001), with Ashikhmin (2001)
//! coherence, coarse to fine over the sample pyramids.
//!
//! In image-analogies terms the source guidance is `A`, the source colour `A'`, the
//! target guidance `B` and the synthesised target colour `B'`. Per level `l`, coarsest
//! first:
//!
//! 1. **Neighbourhoods.** Every sample gets an `n × n` tangent-plane stencil (default
//!    5 × 5, [`crate::surface_stencils`]) in its own level and a 3 × 3 parent stencil in
//!    level `l + 1`. Its vector holds colour and guidance at every fine cell, then colour
//!    and guidance at every parent cell (absent at the coarsest level), each cell
//!    weighted by a Gaussian of its grid distance (σ = `n / 2` cells; parent cells weigh
//!    half as much in all). Colour is divided by the source colour's standard deviation
//!    at that level and guidance by the guidance's, times `guidance_weight` (default 1:
//!    "features and texture were given equal weights", §6.2). Source colours and
//!    guidance at level `l` are the Gaussian pyramid of the level-0 values.
//! 2. **Search space.** The source vectors of usable samples (not masked) are projected
//!    on their `pca_dims` (default 16) leading principal components, fitted on at most
//!    20 000 of them on a regular stride, and put in a kd-tree
//!    (`fieldtex_linalg::stats::KdTree`). This PCA + approximate kd-tree search stands in
//!    for the exact L2 search with the ANN library of the paper (both approximate).
//! 3. **Initialisation.** Coarsest level: every target sample takes the colour of the
//!    source sample whose *guidance-only* neighbourhood is nearest. Finer levels: each
//!    target sample starts from its parent's source match carried to the finer source
//!    level (its nearest finer source sample).
//! 4. **Passes** (default 2 per level). Every target sample compares (a) the
//!    approximate nearest source neighbourhood (best-bin-first, `max_checks` points,
//!    default 96) and (b) Ashikhmin's coherent candidates — for every stencil cell
//!    holding a target neighbour `q` at offset `o`, the source sample at offset `−o`
//!    from `q`'s current match — and keeps the coherent one when its squared distance
//!    is within `1 + 2^{−l} κ` times the search's (Hertzmann et al.'s rule with the
//!    coherence parameter κ, default 1.0 as in §6.2; `l = 0` is the finest level).
//!    It then copies the chosen source sample's level-`l` colour.
//!
//! Substitute: the paper (after Turk and Hertzmann et al.) synthesises samples one at a
//! time in a sweep order, comparing the causal half of each neighbourhood. Here every
//! pass recomputes all target samples at once from the previous pass's colours (full
//! neighbourhoods, as in the parallel synthesis of Lefebvre & Hoppe 2005), so the
//! result is identical for any thread count and the work is parallel.

use crate::TransferError;
use crate::parametric_synthesis::SynthesisInput;
use crate::surface_samples::{SamplePyramid, SampleSet};
use crate::surface_stencils::{Stencils, stencil_grid, stencils};
use fieldtex_linalg::Pca;
use fieldtex_linalg::stats::{KdScratch, KdTree};
use rayon::prelude::*;
use serde::Serialize;

/// Options of [`nonparametric_synthesis`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NonparametricOptions {
    /// Side of the tangent-plane neighbourhood (odd). Default 5.
    pub neighbourhood: usize,
    /// Ashikhmin coherence parameter κ. Default 1.0.
    pub coherence: f64,
    /// Passes per level. Default 2.
    pub passes: usize,
    /// Weight of the guidance relative to colour. Default 1.0.
    pub guidance_weight: f64,
    /// PCA dimensions of the search space. Default 16.
    pub pca_dims: usize,
    /// Points examined per approximate nearest-neighbour query. Default 96.
    pub max_checks: usize,
}

impl Default for NonparametricOptions {
    fn default() -> Self {
        Self {
            neighbourhood: 5,
            coherence: 1.0,
            passes: 2,
            guidance_weight: 1.0,
            pca_dims: 16,
            max_checks: 96,
        }
    }
}

impl NonparametricOptions {
    /// Checks the ranges (neighbourhood odd in 1..=9, passes in 1..=20, max_checks ≥ 1,
    /// coherence and guidance weight ≥ 0).
    pub fn validate(&self) -> Result<(), TransferError> {
        let n = self.neighbourhood;
        if n.is_multiple_of(2) || !(1..=9).contains(&n) {
            return Err(TransferError::InvalidOption {
                what: "neighbourhood",
                message: format!("must be odd, 1..=9, got {n}"),
            });
        }
        if self.passes == 0 || self.passes > 20 || self.max_checks == 0 || self.pca_dims == 0 {
            return Err(TransferError::InvalidOption {
                what: "non-parametric engine",
                message: "passes in 1..=20, max_checks ≥ 1, pca_dims ≥ 1".into(),
            });
        }
        if !(self.coherence >= 0.0
            && self.coherence.is_finite()
            && self.guidance_weight >= 0.0
            && self.guidance_weight.is_finite())
        {
            return Err(TransferError::InvalidOption {
                what: "coherence",
                message: format!(
                    "coherence and guidance weight must be finite and ≥ 0, got {} and {}",
                    self.coherence, self.guidance_weight
                ),
            });
        }
        Ok(())
    }
}

/// What one level did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NonparametricLevel {
    /// 0 = finest.
    pub level: usize,
    pub source_samples: usize,
    pub target_samples: usize,
    /// Length of a neighbourhood vector and of its PCA projection.
    pub vector_dims: usize,
    pub pca_dims: usize,
    /// Fraction of the source vectors' variance the projection keeps.
    pub pca_variance_kept: f64,
    /// Fraction of target samples that took a coherent candidate in the last pass.
    pub coherent_fraction: f64,
    /// Fraction of target samples whose source match changed in the last pass.
    pub changed_fraction: f64,
    /// Mean squared neighbourhood distance of the chosen matches (PCA space, last pass).
    pub mean_distance: f64,
}

/// What the engine did, for the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NonparametricStats {
    /// Coarsest first.
    pub levels: Vec<NonparametricLevel>,
}

const PCA_FIT: usize = 20_000;

/// One mesh's data at one level, as the vectors read it.
#[derive(Clone, Copy)]
struct Side<'a> {
    colour: &'a [f64],
    guidance: &'a [f64],
    fine: &'a Stencils,
    /// Parent colour, guidance and stencils (none at the coarsest level).
    parent: Option<(&'a [f64], &'a [f64], &'a Stencils)>,
}

/// Layout and weights of a neighbourhood vector.
#[derive(Clone)]
struct Layout {
    /// √weight per fine cell and per parent cell.
    fine_w: Vec<f64>,
    parent_w: Vec<f64>,
    colour_scale: f64,
    guidance_scale: f64,
    /// Guidance only (coarsest-level initialisation).
    guidance_only: bool,
    has_parent: bool,
}

impl Layout {
    fn dim(&self) -> usize {
        let per = if self.guidance_only { 3 } else { 6 };
        per * self.fine_w.len() + if self.has_parent { 6 * self.parent_w.len() } else { 0 }
    }

    fn fill(&self, side: &Side<'_>, i: usize, out: &mut [f32]) {
        let mut o = 0;
        let cells = side.fine.cells_of(i);
        for (c, &w) in cells.iter().zip(&self.fine_w) {
            let c = *c as usize;
            if !self.guidance_only {
                for k in 0..3 {
                    out[o] = (w * self.colour_scale * side.colour[c * 3 + k]) as f32;
                    o += 1;
                }
            }
            for k in 0..3 {
                out[o] = (w * self.guidance_scale * side.guidance[c * 3 + k]) as f32;
                o += 1;
            }
        }
        if self.has_parent {
            let (pc, pg, ps) = side.parent.expect("parent data at a non-coarsest level");
            for (c, &w) in ps.cells_of(i).iter().zip(&self.parent_w) {
                let c = *c as usize;
                for k in 0..3 {
                    out[o] = (w * self.colour_scale * pc[c * 3 + k]) as f32;
                    o += 1;
                }
                for k in 0..3 {
                    out[o] = (w * self.guidance_scale * pg[c * 3 + k]) as f32;
                    o += 1;
                }
            }
        }
    }
}

/// √ of normalised Gaussian weights over an `n × n` grid (σ = n / 2 cells), scaled so
/// that the weights sum to `total`.
fn cell_weights(n: usize, total: f64) -> Vec<f64> {
    let h = (n / 2) as f64;
    let s2 = 2.0 * (n as f64 / 2.0).powi(2);
    let w: Vec<f64> = (0..n * n)
        .map(|c| {
            let (a, b) = ((c % n) as f64 - h, (c / n) as f64 - h);
            (-(a * a + b * b) / s2).exp()
        })
        .collect();
    let sum: f64 = w.iter().sum();
    w.iter().map(|v| (total * v / sum).sqrt()).collect()
}

/// Root mean square deviation (over 3 channels) of the rows in `rows`.
fn rms_spread(values: &[f64], rows: &[u32]) -> f64 {
    let n = rows.len().max(1) as f64;
    let mut m = [0.0; 3];
    for &i in rows {
        for k in 0..3 {
            m[k] += values[i as usize * 3 + k] / n;
        }
    }
    let mut v = 0.0;
    for &i in rows {
        for k in 0..3 {
            v += (values[i as usize * 3 + k] - m[k]).powi(2);
        }
    }
    (v / (3.0 * n)).sqrt().max(1e-6)
}

/// Source search space: projected vectors of the usable samples and their kd-tree.
struct SearchSpace {
    pca: Pca,
    /// Usable source samples (tree row → sample).
    rows: Vec<u32>,
    /// Sample → tree row (`u32::MAX`: not a candidate).
    row_of: Vec<u32>,
    tree: KdTree,
    variance_kept: f64,
}

fn vectors(layout: &Layout, side: &Side<'_>, ids: &[u32]) -> Vec<f32> {
    let d = layout.dim();
    let mut out = vec![0.0f32; ids.len() * d];
    out.par_chunks_mut(d).zip(ids.par_iter()).for_each(|(o, &i)| layout.fill(side, i as usize, o));
    out
}

fn project(pca: &Pca, layout: &Layout, side: &Side<'_>, n: usize) -> Vec<f32> {
    let (d, k) = (layout.dim(), pca.k());
    let mut out = vec![0.0f32; n * k];
    out.par_chunks_mut(k).enumerate().for_each_init(
        || vec![0.0f32; d],
        |buf, (i, o)| {
            layout.fill(side, i, buf);
            pca.project(buf, o);
        },
    );
    out
}

fn search_space(
    layout: &Layout,
    side: &Side<'_>,
    usable: &[u32],
    n_source: usize,
    pca_dims: usize,
) -> Result<SearchSpace, TransferError> {
    let d = layout.dim();
    let stride = usable.len().div_ceil(PCA_FIT).max(1);
    let fit_ids: Vec<u32> = usable.iter().step_by(stride).copied().collect();
    let fit = vectors(layout, side, &fit_ids);
    let k = pca_dims.clamp(1, d);
    let pca = Pca::fit(&fit, d, k).map_err(|e| TransferError::numeric("neighbourhood PCA", e))?;
    // Total variance of the fit vectors (for the kept fraction).
    let nf = fit_ids.len().max(1) as f64;
    let mut mean = vec![0.0f64; d];
    for r in fit.chunks_exact(d) {
        for (m, v) in mean.iter_mut().zip(r) {
            *m += *v as f64 / nf;
        }
    }
    let mut total = 0.0;
    for r in fit.chunks_exact(d) {
        for (m, v) in mean.iter().zip(r) {
            total += (*v as f64 - m).powi(2) / nf;
        }
    }
    let kept: f64 = pca.variances.iter().sum();
    let mut proj = vec![0.0f32; usable.len() * k];
    proj.par_chunks_mut(k).zip(usable.par_iter()).for_each_init(
        || vec![0.0f32; d],
        |buf, (o, &i)| {
            layout.fill(side, i as usize, buf);
            pca.project(buf, o);
        },
    );
    let mut row_of = vec![u32::MAX; n_source];
    for (r, &i) in usable.iter().enumerate() {
        row_of[i as usize] = r as u32;
    }
    Ok(SearchSpace {
        pca,
        rows: usable.to_vec(),
        row_of,
        tree: KdTree::build(&proj, k),
        variance_kept: if total > 0.0 { (kept / total).min(1.0) } else { 1.0 },
    })
}

fn dist2(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// Nearest sample of `set` to every point of `pts` (the stencil centre rule: normal
/// agreement, centre fallback to index 0 of nothing is near).
fn nearest_in(set: &SampleSet, pts: &SampleSet) -> Vec<u32> {
    let grid = stencil_grid(set);
    stencils(&pts.positions, &pts.normals, set, &grid, 1, 0).cells
}

/// Runs the engine (module docs); returns `#target × 3` RGB in `[0, 1]`.
///
/// `up` is the up axis index (0, 1, 2) that orients the stencils.
pub fn nonparametric_synthesis(
    input: &SynthesisInput<'_>,
    up: usize,
    options: &NonparametricOptions,
) -> Result<(Vec<f64>, NonparametricStats), TransferError> {
    options.validate()?;
    let n = options.neighbourhood;
    let (sp, tp) = (input.source, input.target);
    let levels = sp.n_levels().min(tp.n_levels());
    let ns = sp.levels[0].len();
    // Masked samples carry the mean usable colour (they are never candidates).
    let valid_ids: Vec<u32> = (0..ns as u32).filter(|&i| input.source_valid[i as usize]).collect();
    if valid_ids.len() < 16 {
        return Err(TransferError::TooFewSamples { found: valid_ids.len(), needed: 16 });
    }
    let mut mean = [0.0; 3];
    for &i in &valid_ids {
        for k in 0..3 {
            mean[k] += input.source_colors[i as usize * 3 + k] / valid_ids.len() as f64;
        }
    }
    let filled: Vec<f64> = (0..ns * 3)
        .map(|j| if input.source_valid[j / 3] { input.source_colors[j] } else { mean[j % 3] })
        .collect();
    let vfrac: Vec<f64> = input.source_valid.iter().map(|&v| f64::from(u8::from(v))).collect();
    let cs = sp.gaussian(&filled, 3);
    let gs = sp.gaussian(input.source_guidance, 3);
    let vs = sp.gaussian(&vfrac, 1);
    let gt = tp.gaussian(input.target_guidance, 3);
    // Stencils per level, parent stencils per non-coarsest level.
    let sgrid: Vec<_> = sp.levels[..levels].iter().map(stencil_grid).collect();
    let tgrid: Vec<_> = tp.levels[..levels].iter().map(stencil_grid).collect();
    let own = |p: &SamplePyramid, g: &[fieldtex_texopt::UniformGrid], l: usize, size: usize| {
        let set = &p.levels[l];
        stencils(&set.positions, &set.normals, set, &g[l], size, up)
    };
    let parent = |p: &SamplePyramid, g: &[fieldtex_texopt::UniformGrid], l: usize| {
        let (fine, coarse) = (&p.levels[l], &p.levels[l + 1]);
        stencils(&fine.positions, &fine.normals, coarse, &g[l + 1], 3, up)
    };
    let fine_w = cell_weights(n, 1.0);
    let parent_w = cell_weights(3, 0.5);
    let mut stats = Vec::new();
    // Per target sample: source match (level `l` index) and colour of the last level.
    let mut prev_match: Vec<u32> = Vec::new();
    let mut prev_colour: Vec<f64> = Vec::new();
    for l in (0..levels).rev() {
        let s_st = own(sp, &sgrid, l, n);
        let t_st = own(tp, &tgrid, l, n);
        let coarsest = l + 1 == levels;
        let (s_par, t_par) = if coarsest {
            (None, None)
        } else {
            (Some(parent(sp, &sgrid, l)), Some(parent(tp, &tgrid, l)))
        };
        let usable: Vec<u32> =
            (0..sp.levels[l].len() as u32).filter(|&i| vs[l][i as usize] > 0.5).collect();
        let usable =
            if usable.len() >= 16 { usable } else { (0..sp.levels[l].len() as u32).collect() };
        let colour_scale = 1.0 / rms_spread(&cs[l], &usable);
        let guidance_scale = options.guidance_weight / rms_spread(&gs[l], &usable);
        let layout = Layout {
            fine_w: fine_w.clone(),
            parent_w: parent_w.clone(),
            colour_scale,
            guidance_scale,
            guidance_only: false,
            has_parent: !coarsest,
        };
        let nt = tp.levels[l].len();
        let s_parent_colour = if coarsest { None } else { Some(cs[l + 1].as_slice()) };
        let src_side = Side {
            colour: &cs[l],
            guidance: &gs[l],
            fine: &s_st,
            parent: s_parent_colour
                .map(|c| (c, gs[l + 1].as_slice(), s_par.as_ref().expect("parent stencils"))),
        };
        // Initial matches.
        let mut matches: Vec<u32> = if coarsest {
            let g_layout = Layout { guidance_only: true, has_parent: false, ..layout.clone() };
            let src_g = Side { parent: None, ..src_side };
            let space =
                search_space(&g_layout, &src_g, &usable, sp.levels[l].len(), options.pca_dims)?;
            let tgt_g = Side { colour: &[], guidance: &gt[l], fine: &t_st, parent: None };
            let q = project(&space.pca, &g_layout, &tgt_g, nt);
            let k = space.pca.k();
            q.par_chunks(k)
                .map_init(KdScratch::default, |sc, qv| {
                    let (r, _) = space.tree.nearest(qv, options.max_checks, sc).expect("non-empty");
                    space.rows[r]
                })
                .collect()
        } else {
            // Parent's match carried to this level's nearest source sample.
            let child = nearest_in(&sp.levels[l], &sp.levels[l + 1]);
            let tp_centre = t_par.as_ref().expect("parent stencils");
            (0..nt).map(|j| child[prev_match[tp_centre.cells_of(j)[4] as usize] as usize]).collect()
        };
        let space =
            search_space(&layout, &src_side, &usable, sp.levels[l].len(), options.pca_dims)?;
        let k = space.pca.k();
        let copy = |m: &[u32]| -> Vec<f64> {
            m.iter()
                .flat_map(|&s| {
                    let b = s as usize * 3;
                    [cs[l][b], cs[l][b + 1], cs[l][b + 2]]
                })
                .collect()
        };
        let mut colour = copy(&matches);
        let factor = 1.0 + options.coherence * 0.5f64.powi(l as i32);
        let mut last = (0.0, 0.0, 0.0);
        for _pass in 0..options.passes {
            let tgt_side = Side {
                colour: &colour,
                guidance: &gt[l],
                fine: &t_st,
                parent: if coarsest {
                    None
                } else {
                    Some((prev_colour.as_slice(), gt[l + 1].as_slice(), t_par.as_ref().expect("p")))
                },
            };
            let q = project(&space.pca, &layout, &tgt_side, nt);
            let chosen: Vec<(u32, bool, f32)> = (0..nt)
                .into_par_iter()
                .map_init(KdScratch::default, |sc, j| {
                    let qv = &q[j * k..(j + 1) * k];
                    let (r, d_ann) =
                        space.tree.nearest(qv, options.max_checks, sc).expect("non-empty");
                    let ann = space.rows[r];
                    let mut coh = (u32::MAX, f32::INFINITY);
                    let cells = t_st.cells_of(j);
                    for (c, &nb) in cells.iter().enumerate() {
                        if nb as usize == j {
                            continue;
                        }
                        let cand = s_st.cells_of(matches[nb as usize] as usize)[s_st.mirror(c)];
                        let row = space.row_of[cand as usize];
                        if row == u32::MAX {
                            continue;
                        }
                        let d = dist2(space.tree.point(row as usize), qv);
                        if d < coh.1 || (d == coh.1 && cand < coh.0) {
                            coh = (cand, d);
                        }
                    }
                    if coh.0 != u32::MAX && (coh.1 as f64) <= d_ann as f64 * factor {
                        (coh.0, true, coh.1)
                    } else {
                        (ann, false, d_ann)
                    }
                })
                .collect();
            let changed = chosen.iter().zip(&matches).filter(|(c, m)| c.0 != **m).count();
            let coherent = chosen.iter().filter(|c| c.1).count();
            let dsum: f64 = chosen.iter().map(|c| c.2 as f64).sum();
            last = (
                coherent as f64 / nt.max(1) as f64,
                changed as f64 / nt.max(1) as f64,
                dsum / nt.max(1) as f64,
            );
            matches = chosen.into_iter().map(|c| c.0).collect();
            colour = copy(&matches);
        }
        stats.push(NonparametricLevel {
            level: l,
            source_samples: sp.levels[l].len(),
            target_samples: nt,
            vector_dims: layout.dim(),
            pca_dims: k,
            pca_variance_kept: space.variance_kept,
            coherent_fraction: last.0,
            changed_fraction: last.1,
            mean_distance: last.2,
        });
        prev_match = matches;
        prev_colour = colour;
    }
    let rgb = prev_colour.iter().map(|v| v.clamp(0.0, 1.0)).collect();
    Ok((rgb, NonparametricStats { levels: stats }))
}
