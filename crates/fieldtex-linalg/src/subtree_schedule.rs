//! Two-worker schedule of a supernodal backward substitution over disjoint subtrees of
//! the supernodal elimination tree ("subtree-to-processor mapping": George, Liu & Ng
//! 1989, "Communication results for parallel sparse Cholesky factorization"; Geist &
//! Ng 1989, "Task scheduling for parallel sparse Cholesky factorization", the
//! bin-packing of subtrees used here).
//!
//! In `Lᵀ x = y` supernode `s` reads `x` only at its pattern rows, all of them columns
//! of its ancestors, and writes only its own columns. So once every ancestor of a
//! subtree is solved, the subtree can be solved on its own; two subtrees with no
//! ancestor relation never touch each other's columns. The schedule splits the tree
//! into a *top* (solved first, sequentially, from the root down) and disjoint subtrees
//! below it, packed into two bins of about equal work; each bin is then solved by one
//! worker, its supernodes in decreasing order (ancestors before descendants).
//!
//! Every supernode does the same operations in the same order as in the sequential
//! pass, on the same (final) inputs: the result is bit for bit the sequential one, for
//! any thread count.
//!
//! Why: the backward pass streams the whole factor (on the 128² field-design grid,
//! 2.3M entries, 18.7 MB) and is memory-latency bound on one core; a second core
//! doubles the misses in flight. The schedule depends only on the factor's structure,
//! which updates and downdates keep, so it is built once per analysis.

/// Supernodes of the top and of the two bins, each in decreasing order.
#[derive(Debug, Clone, Default)]
pub(crate) struct SubtreeSchedule {
    pub(crate) top: Vec<u32>,
    pub(crate) bins: [Vec<u32>; 2],
}

/// Below this many stored entries in all the backward pass runs sequentially (the
/// hand-over to a second worker costs more than it saves).
const MIN_ENTRIES: usize = 1 << 18;
/// Splits of the largest remaining subtree tried (the best is kept).
const MAX_SPLITS: usize = 256;

impl SubtreeSchedule {
    /// Schedule for supernodes `s` with `cost[s]` stored entries and parent supernode
    /// `parent[s]` (`u32::MAX` for a root; `parent[s] > s`). `None` when the factor is
    /// too small to gain from two workers or no split balances the work.
    pub(crate) fn build(cost: &[usize], parent: &[u32]) -> Option<Self> {
        let nsn = cost.len();
        let total: usize = cost.iter().sum();
        if total < MIN_ENTRIES {
            return None;
        }
        let mut sub = cost.to_vec();
        let mut children: Vec<Vec<u32>> = vec![Vec::new(); nsn];
        let mut roots = Vec::new();
        for s in 0..nsn {
            match parent[s] {
                u32::MAX => roots.push(s as u32),
                p => {
                    debug_assert!(p as usize > s, "parent after child");
                    sub[p as usize] += sub[s];
                    children[p as usize].push(s as u32);
                }
            }
        }
        // split the heaviest subtree (its root goes to the top) while the estimate of
        // the parallel time `top + max(bin)` improves somewhere within MAX_SPLITS
        let mut candidates = roots;
        let mut top_cost = 0usize;
        let mut best: Option<(usize, Vec<u32>, [Vec<u32>; 2])> = None;
        let mut top_list = Vec::new();
        for _ in 0..MAX_SPLITS {
            candidates.sort_by_key(|&s| (std::cmp::Reverse(sub[s as usize]), s));
            // longest-processing-time packing into two bins
            let (mut load, mut assign) = ([0usize; 2], Vec::with_capacity(candidates.len()));
            for &s in &candidates {
                let b = usize::from(load[1] < load[0]);
                load[b] += sub[s as usize];
                assign.push(b);
            }
            let time = top_cost + load[0].max(load[1]);
            if best.as_ref().is_none_or(|b| time < b.0) && load[0].min(load[1]) > 0 {
                best = Some((time, top_list.clone(), pack(&candidates, &assign)));
            }
            let Some(&heaviest) = candidates.first() else { break };
            // small enough subtrees pack evenly already (and many roots, e.g. of a
            // block-diagonal matrix, are not re-sorted over and over)
            if children[heaviest as usize].is_empty() || sub[heaviest as usize] * 16 <= total {
                break;
            }
            candidates.remove(0);
            top_cost += cost[heaviest as usize];
            top_list.push(heaviest);
            candidates.extend_from_slice(&children[heaviest as usize]);
        }
        let (time, mut top, owner) = best?;
        // worth it only if the estimate is clearly below the sequential time
        if time * 10 > total * 8 {
            return None;
        }
        top.sort_unstable_by(|a, b| b.cmp(a));
        // every supernode below the top belongs to the bin of its subtree's root
        let mut bin_of = vec![u8::MAX; nsn];
        for (b, list) in owner.iter().enumerate() {
            for &s in list {
                bin_of[s as usize] = b as u8;
            }
        }
        for &s in &top {
            bin_of[s as usize] = 2;
        }
        // parents come after children: a top-down sweep gives each its root's bin
        for s in (0..nsn).rev() {
            if bin_of[s] == u8::MAX {
                bin_of[s] = bin_of[parent[s] as usize];
                debug_assert!(bin_of[s] < 2, "a subtree root's descendant inherits its bin");
            }
        }
        let mut bins = [Vec::new(), Vec::new()];
        for s in (0..nsn).rev() {
            if bin_of[s] < 2 {
                bins[bin_of[s] as usize].push(s as u32);
            }
        }
        Some(Self { top, bins })
    }
}

/// The bins' root lists from the packing.
fn pack(candidates: &[u32], assign: &[usize]) -> [Vec<u32>; 2] {
    let mut out = [Vec::new(), Vec::new()];
    for (&s, &b) in candidates.iter().zip(assign) {
        out[b].push(s);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A balanced binary tree of `levels` levels in postorder: every supernode is in
    /// exactly one list, lists are decreasing, the bins hold disjoint subtrees (no
    /// supernode of one bin is an ancestor of one of the other), the top holds every
    /// ancestor of a bin's supernode that is not in its bin, and the bins are balanced.
    #[test]
    fn schedule_covers_the_tree_with_disjoint_balanced_subtrees() {
        fn build(levels: u32, parent: &mut Vec<u32>, cost: &mut Vec<usize>) -> u32 {
            if levels == 1 {
                parent.push(u32::MAX);
                cost.push(1000);
                return (parent.len() - 1) as u32;
            }
            let a = build(levels - 1, parent, cost);
            let b = build(levels - 1, parent, cost);
            parent.push(u32::MAX);
            cost.push(1000 * levels as usize * levels as usize);
            let me = (parent.len() - 1) as u32;
            parent[a as usize] = me;
            parent[b as usize] = me;
            me
        }
        let (mut parent, mut cost) = (Vec::new(), Vec::new());
        build(9, &mut parent, &mut cost);
        let nsn = parent.len();
        let s = SubtreeSchedule::build(&cost, &parent).expect("a schedule");
        let mut seen = vec![0u8; nsn];
        for (k, list) in [&s.top, &s.bins[0], &s.bins[1]].into_iter().enumerate() {
            assert!(list.windows(2).all(|w| w[0] > w[1]), "decreasing");
            for &x in list {
                assert_eq!(seen[x as usize], 0, "once only");
                seen[x as usize] = k as u8 + 1;
            }
        }
        assert!(seen.iter().all(|&v| v > 0), "every supernode scheduled");
        for x in 0..nsn {
            let mut p = parent[x];
            while p != u32::MAX {
                let (me, up) = (seen[x], seen[p as usize]);
                if me == 1 {
                    assert_eq!(up, 1, "an ancestor of a top supernode is in the top");
                } else {
                    assert!(up == me || up == 1, "bins hold disjoint subtrees");
                }
                p = parent[p as usize];
            }
        }
        let load = |b: usize| s.bins[b].iter().map(|&x| cost[x as usize]).sum::<usize>();
        let (l0, l1) = (load(0), load(1));
        assert!(l0.abs_diff(l1) * 10 < l0 + l1, "balanced: {l0} vs {l1}");
        assert!(SubtreeSchedule::build(&cost[..3], &[2, 2, u32::MAX]).is_none(), "too small");
    }
}
