//! Evaluation of a requested subset of finest-level samples by the parallel engine
//! ([`crate::synthesize_subset`]): the window property of Lefebvre & Hoppe 2005 (§3.4,
//! "spatially deterministic" synthesis: a sample's value depends only on a bounded
//! neighbourhood at each coarser level), the base of paper E's on-demand synthesis.
//!
//! **Dependency sets.** One level's corrections are a fixed sequence of steps
//! (`passes × subpass classes`); the step of class `C` rewrites the samples of `C` from
//! the current values of their neighbours (8 in 2-D, 26 in 3-D) and themselves. Walking the steps
//! backwards from the set `N` needed after the last step, the samples a step must
//! rewrite are `N ∩ C`, and before it `N ∪ nbrs(N ∩ C)` must be right. What is needed
//! before the first step is what upsampling must produce, and upsampling reads one
//! parent per child, so the parent level's needed set is the parents of that set. The
//! initialisation level (the coarsest, a few samples) is computed whole: its flip
//! combing is a global procedure.
//!
//! Forward, each step rewrites exactly its planned samples with the engine's own
//! correction, whose inputs are then all current: the requested samples get the same
//! bits as in a full synthesis (tested). The level tables (neighbours, Jacobians) are
//! still tabulated whole per level — they are closed-form per sample for the domains
//! here, so a lattice that computes them on demand can drop that too.

use crate::level_tables::{LevelTables, NONE};

/// Per level (index = level, finest 0), the samples upsampling must produce and, per
/// correction step (pass-major, then class), the samples that step rewrites.
pub(crate) struct SubsetPlan {
    pub(crate) start: Vec<Vec<bool>>,
    pub(crate) steps: Vec<Vec<Vec<bool>>>,
}

impl SubsetPlan {
    /// The plan for `requested` finest samples over `tables[level]` (levels `0..L`,
    /// the initialisation level of `n_init` samples excluded), `passes(level)`
    /// correction passes each.
    pub(crate) fn new<const D: usize, const S: usize>(
        tables: &[LevelTables<D, S>],
        n_init: usize,
        passes: impl Fn(usize) -> usize,
        requested: &[usize],
    ) -> Self {
        let levels = tables.len();
        let mut start = vec![Vec::new(); levels];
        let mut steps = vec![Vec::new(); levels];
        let mut needed = vec![false; tables.first().map_or(0, |t| t.nbr.len())];
        for &r in requested {
            if r < needed.len() {
                needed[r] = true;
            }
        }
        for level in 0..levels {
            let t = &tables[level];
            let mut class_of = vec![0usize; t.nbr.len()];
            for (c, class) in t.classes.iter().enumerate() {
                for &p in class {
                    class_of[p as usize] = c;
                }
            }
            let n_steps = passes(level) * t.classes.len();
            let mut level_steps = vec![Vec::new(); n_steps];
            for step in (0..n_steps).rev() {
                let c = step % t.classes.len();
                let rewrite: Vec<bool> =
                    (0..needed.len()).map(|p| needed[p] && class_of[p] == c).collect();
                for (p, _) in rewrite.iter().enumerate().filter(|(_, r)| **r) {
                    for &q in &t.nbr[p] {
                        if q != NONE {
                            needed[q as usize] = true;
                        }
                    }
                }
                level_steps[step] = rewrite;
            }
            steps[level] = level_steps;
            let n_parent = tables.get(level + 1).map_or(n_init, |pt| pt.nbr.len());
            let mut parents = vec![false; n_parent];
            for (i, _) in needed.iter().enumerate().filter(|(_, n)| **n) {
                parents[t.parent[i].0 as usize] = true;
            }
            start[level] = std::mem::replace(&mut needed, parents);
        }
        Self { start, steps }
    }

    /// Samples computed per level (upsampled ones), finest first.
    pub(crate) fn evaluated(&self) -> Vec<usize> {
        self.start.iter().map(|s| s.iter().filter(|&&b| b).count()).collect()
    }
}
