//! Single-linkage clustering of image points within a radius (the merge step of
//! singularity and phase-defect detection), on the mesh crate's union-find.

use fieldtex_mesh::UnionFind;

/// Single-linkage clusters of points sorted by `y` (scan order), linking points at most
/// `radius` apart: each point's cluster label, labels numbered by first appearance, and
/// the number of clusters. Used by `singularities` and `phase_defects`.
pub(crate) fn single_linkage_labels(points: &[[f64; 2]], radius: f64) -> (Vec<usize>, usize) {
    let n = points.len();
    let mut sets = UnionFind::new(n);
    // Points are sorted by y, so only a window needs checking.
    for i in 0..n {
        for j in i + 1..n {
            let (dx, dy) = (points[j][0] - points[i][0], points[j][1] - points[i][1]);
            if dy > radius {
                break;
            }
            if dx * dx + dy * dy <= radius * radius {
                sets.union(i, j);
            }
        }
    }
    let mut label_of_root = vec![usize::MAX; n];
    let mut count = 0;
    let labels = (0..n)
        .map(|i| {
            let r = sets.find(i);
            if label_of_root[r] == usize::MAX {
                label_of_root[r] = count;
                count += 1;
            }
            label_of_root[r]
        })
        .collect();
    (labels, count)
}
