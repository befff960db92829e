//! Scattered-data interpolation between surface sample sets (Shepard 1968, with a
//! Gaussian kernel): the value at a query point is the normalised Gaussian-weighted
//! mean of the source samples within `2.5 σ`, keeping only samples whose normal agrees
//! with the query's (`n·n' > 0.3`), so values do not leak across thin sheets. A query
//! with no such neighbour widens the radius (×2, up to 3 times), then drops the normal
//! test; as a last resort it takes the nearest sample of a brute-force scan of the
//! candidates in the widest cell block.
//!
//! The weights are built once as a sparse `#queries × #sources` matrix (CSR, rows sum to
//! one) and applied to any number of value channels. Deterministic: neighbours come in
//! the grid's fixed order and each row is computed independently.

use fieldtex_core::vec3::{V3, dot};
use fieldtex_texopt::UniformGrid;
use rayon::prelude::*;

/// Row-normalised interpolation weights from a source sample set to query points.
#[derive(Debug, Clone, PartialEq)]
pub struct Interpolator {
    /// `#queries + 1` row starts into `entries`.
    offsets: Vec<u32>,
    /// `(source index, weight)`; each row's weights sum to one.
    entries: Vec<(u32, f32)>,
    n_sources: usize,
}

impl Interpolator {
    /// Gaussian weights of standard deviation `sigma` from (`src_pos`, `src_nrm`) to
    /// (`q_pos`, `q_nrm`), module docs. `src_pos` must not be empty.
    pub fn gaussian(
        src_pos: &[V3],
        src_nrm: &[V3],
        q_pos: &[V3],
        q_nrm: &[V3],
        sigma: f64,
    ) -> Self {
        assert!(!src_pos.is_empty(), "Interpolator::gaussian needs source samples");
        let radius = 2.5 * sigma;
        let grid = UniformGrid::new(src_pos, radius);
        let rows: Vec<Vec<(u32, f32)>> = q_pos
            .par_iter()
            .zip(q_nrm.par_iter())
            .map(|(&p, &n)| {
                let mut row = Vec::new();
                for attempt in 0..5 {
                    let (r, use_normals) = match attempt {
                        0 => (radius, true),
                        1 => (2.0 * radius, true),
                        2 => (4.0 * radius, true),
                        3 => (8.0 * radius, true),
                        _ => (8.0 * radius, false),
                    };
                    let s2 = 2.0 * (sigma * r / radius).powi(2);
                    let mut total = 0.0f64;
                    grid.for_each_within(src_pos, p, r, |i, d2| {
                        if use_normals && dot(src_nrm[i as usize], n) <= 0.3 {
                            return;
                        }
                        let w = (-d2 / s2).exp().max(1e-30);
                        total += w;
                        row.push((i, w as f32));
                    });
                    if total > 0.0 {
                        let inv = (1.0 / total) as f32;
                        row.iter_mut().for_each(|e| e.1 *= inv);
                        return row;
                    }
                    row.clear();
                }
                // Last resort: nearest candidate anywhere in the widest block, or sample 0.
                let mut best = (0u32, f64::INFINITY);
                grid.for_each_within(src_pos, p, 64.0 * radius, |i, d2| {
                    if d2 < best.1 {
                        best = (i, d2);
                    }
                });
                vec![(best.0, 1.0)]
            })
            .collect();
        let mut offsets = Vec::with_capacity(rows.len() + 1);
        offsets.push(0u32);
        let mut entries = Vec::with_capacity(rows.iter().map(Vec::len).sum());
        for r in rows {
            entries.extend(r);
            offsets.push(entries.len() as u32);
        }
        Self { offsets, entries, n_sources: src_pos.len() }
    }

    pub fn n_queries(&self) -> usize {
        self.offsets.len() - 1
    }

    pub fn n_sources(&self) -> usize {
        self.n_sources
    }

    /// The weights of query `q`.
    pub fn row(&self, q: usize) -> &[(u32, f32)] {
        &self.entries[self.offsets[q] as usize..self.offsets[q + 1] as usize]
    }

    /// Interpolates row-major `#sources × dim` values to `#queries × dim`.
    pub fn apply(&self, values: &[f64], dim: usize) -> Vec<f64> {
        assert_eq!(values.len(), self.n_sources * dim, "Interpolator::apply: wrong value count");
        let mut out = vec![0.0; self.n_queries() * dim];
        out.par_chunks_mut(dim).enumerate().for_each(|(q, o)| {
            for &(i, w) in self.row(q) {
                for k in 0..dim {
                    o[k] += w as f64 * values[i as usize * dim + k];
                }
            }
        });
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_linear_functions_on_a_grid_and_respects_normals() {
        let mut src = Vec::new();
        for i in 0..40 {
            for j in 0..40 {
                src.push([i as f64 * 0.1, j as f64 * 0.1, 0.0]);
            }
        }
        let nrm = vec![[0.0, 0.0, 1.0]; src.len()];
        let q = vec![[1.23, 2.07, 0.0], [2.5, 1.5, 0.0]];
        let qn = vec![[0.0, 0.0, 1.0]; 2];
        let it = Interpolator::gaussian(&src, &nrm, &q, &qn, 0.1);
        let vals: Vec<f64> = src.iter().map(|p| 2.0 * p[0] - p[1]).collect();
        let out = it.apply(&vals, 1);
        for (o, p) in out.iter().zip(&q) {
            assert!((o - (2.0 * p[0] - p[1])).abs() < 5e-3, "{o}");
        }
        // A query facing the other way falls back to dropping the normal test.
        let back = Interpolator::gaussian(&src, &nrm, &q[..1], &[[0.0, 0.0, -1.0]], 0.1);
        assert!(!back.row(0).is_empty());
        let s: f32 = back.row(0).iter().map(|e| e.1).sum();
        assert!((s - 1.0).abs() < 1e-5);
    }
}
