//! Matrices shared by the unit tests.

use crate::SparseMatrix;

/// 5-point Laplacian of a `side × side` grid graph plus a penalty `1e8` on every
/// `every`-th node (symmetric positive definite).
pub(crate) fn penalised_grid(side: usize, every: usize) -> SparseMatrix {
    let n = side * side;
    let mut t = Vec::new();
    for y in 0..side {
        for x in 0..side {
            let i = y * side + x;
            for j in [(x + 1 < side).then(|| i + 1), (y + 1 < side).then(|| i + side)]
                .into_iter()
                .flatten()
            {
                t.extend([(i, i, 1.0), (j, j, 1.0), (i, j, -1.0), (j, i, -1.0)]);
            }
            if i.is_multiple_of(every) {
                t.push((i, i, 1e8));
            }
        }
    }
    SparseMatrix::from_triplets(n, n, &t).unwrap()
}
