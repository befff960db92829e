//! The scale search of the chart packer (module `packing`): the largest scale at which
//! every chart fits, bracketed by trial packings three at a time, in parallel. Each trial's packing height grows roughly
//! like the square of the scale, which gives the next guess; results do not depend on
//! the thread count.

use crate::packing::{CellGrid, INSET, PackChart, PackingOptions, Placement, Trial, try_pack};
use rayon::prelude::*;

/// The inputs every trial of a scale search packs.
#[derive(Clone, Copy)]
pub(crate) struct Search<'a> {
    pub(crate) charts: &'a [PackChart],
    pub(crate) outlines: &'a [Option<Vec<[u32; 2]>>],
    pub(crate) origins: &'a [[f64; 2]],
    pub(crate) order: &'a [usize],
    pub(crate) options: &'a PackingOptions,
}

/// The best packing found so far.
pub(crate) struct Found {
    pub(crate) scale: f64,
    pub(crate) placements: Vec<Placement>,
    pub(crate) inset: f64,
}

/// Scale search state: `lo` fits, `hi` does not (or is the upper bound).
pub(crate) struct SearchState {
    pub(crate) lo: Option<Found>,
    pub(crate) hi: f64,
    pub(crate) guess: f64,
}

/// Narrows the scale on `cells` until `hi ≤ lo·(1 + tol)` or `max_rounds` rounds.
/// Each trial's packing height h(s) ∝ s² roughly, so `s·√(limit / h)` estimates the
/// best scale.
pub(crate) fn search_scale(
    search: &Search,
    cells: CellGrid,
    st: &mut SearchState,
    tol: f64,
    max_rounds: usize,
) {
    let Search { charts, outlines, origins, order, options } = *search;
    let limit = (cells.size - cells.margin) as f64;
    let upper = st.hi;
    for _round in 0..max_rounds {
        let lo_s = st.lo.as_ref().map_or(0.0, |l| l.scale);
        if st.lo.is_some() && st.hi <= lo_s * (1.0 + tol) {
            break;
        }
        let trials: Vec<f64> = if st.lo.is_some() && st.hi <= lo_s * 1.05 {
            let r = st.hi / lo_s;
            (1..=3).map(|k| lo_s * r.powf(k as f64 / 4.0)).collect()
        } else {
            let c = st.guess.min(st.hi / (1.0 + 0.25 * tol)).max(lo_s * (1.0 + 0.25 * tol));
            [c, c * 0.99, c * 0.98].into_iter().filter(|&t| t > lo_s && t < st.hi).collect()
        };
        if trials.is_empty() {
            break;
        }
        let run = |&t: &f64| try_pack(charts, outlines, origins, order, t, options, cells);
        let results: Vec<Option<Trial>> = trials.par_iter().map(run).collect();
        let mut estimate: Option<f64> = None;
        let mut smallest_failed: Option<f64> = None;
        for (&t, r) in trials.iter().zip(results) {
            match r {
                Some(trial) if trial.top as f64 <= limit => {
                    if t > st.lo.as_ref().map_or(0.0, |l| l.scale) {
                        let est = t * (limit / trial.top.max(1) as f64).sqrt();
                        estimate = Some(estimate.map_or(est, |e: f64| e.max(est)));
                        st.lo = Some(Found {
                            scale: t,
                            placements: trial.placements,
                            inset: cells.k as f64 * INSET,
                        });
                    }
                }
                Some(trial) => {
                    st.hi = st.hi.min(t);
                    if st.lo.is_none() {
                        let est = t * (limit / trial.top as f64).sqrt() * 0.995;
                        estimate = Some(estimate.map_or(est, |e: f64| e.min(est)));
                    }
                }
                None => {
                    st.hi = st.hi.min(t);
                    smallest_failed = Some(smallest_failed.map_or(t, |m: f64| m.min(t)));
                }
            }
        }
        st.guess = match (estimate, smallest_failed) {
            (Some(e), _) => e,
            (None, Some(m)) => m * 0.6,
            (None, None) => st.guess,
        };
        if st.lo.is_none() && st.guess < upper * 1e-9 {
            return;
        }
    }
}
