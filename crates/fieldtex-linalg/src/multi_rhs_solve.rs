//! Blocked solves `A X = B` with `k` right-hand sides in one pass over the factor.
//!
//! The right-hand sides of a block are stored column-major (`n × k`, column `c` at
//! `c·n .. (c+1)·n`). One forward and one backward triangular solve run over the factor
//! with all `k` columns at once (faer's supernodal/simplicial solve with a `k`-column
//! right-hand side under `Par::Seq` for a factor never updated; own supernodal loops,
//! `crate::supernodal_solve`, for an updated factor still in faer's supernodal layout —
//! 0.7–0.8× the time of faer's on the refined horse; own simplicial loops with `k`
//! interleaved columns once fill has moved the factor out of faer's layout), so the factor — the dominant
//! memory traffic of a solve — is read once instead of `k` times. The residual check of
//! every column (`‖A x − b‖ / ‖b‖`, see [`crate::CholeskyOptions`]) is computed with one
//! sparse matrix–block product; iterative refinement runs, again blocked, on the columns
//! that need it. Blocks hold at most [`MAX_BLOCK`] columns; more right-hand sides are
//! split into fixed blocks that run in parallel (deterministic for any thread count).
//!
//! Not implemented: supernodal blocking of the own simplicial loops (used only after
//! fill); parallel triangular solves (subtrees of the elimination tree).

use rayon::prelude::*;

use crate::LinalgError;
use crate::cholesky::{Cholesky, norm2};

/// Most right-hand sides solved together in one pass over the factor.
pub const MAX_BLOCK: usize = 8;

/// Output columns of `A X` per parallel task.
const ROW_CHUNK: usize = 2048;

fn exceeds(r: f64, tol: f64) -> bool {
    r.is_nan() || r > tol
}

impl Cholesky {
    /// Solves `A X = B` for several right-hand sides, [`MAX_BLOCK`] at a time in one pass
    /// over the factor (blocks in parallel); every column gets the residual check and
    /// refinement of [`Cholesky::solve`]. Fails if any column fails.
    /// [`Cholesky::last_residual`] gets the largest residual.
    pub fn solve_many(&self, b: &[Vec<f64>]) -> Result<Vec<Vec<f64>>, LinalgError> {
        let n = self.size();
        let mut out: Vec<Vec<f64>> = b.iter().map(|_| vec![0.0; n]).collect();
        {
            let bs: Vec<&[f64]> = b.iter().map(Vec::as_slice).collect();
            let mut xs: Vec<&mut [f64]> = out.iter_mut().map(Vec::as_mut_slice).collect();
            self.solve_many_into(&bs, &mut xs)?;
        }
        Ok(out)
    }

    /// As [`Cholesky::solve_many`], writing column `c` of the solution into `x[c]`
    /// (each of length `n`; `x.len() == b.len()`). Returns the largest relative residual
    /// (also stored for [`Cholesky::last_residual`]). On error `x` holds unspecified
    /// values.
    pub fn solve_many_into(&self, b: &[&[f64]], x: &mut [&mut [f64]]) -> Result<f64, LinalgError> {
        let n = self.size();
        LinalgError::check_len("number of solution buffers", b.len(), x.len())?;
        for (bi, xi) in b.iter().zip(x.iter()) {
            for len in [bi.len(), xi.len()] {
                LinalgError::check_len("right-hand side or solution buffer", n, len)?;
            }
        }
        let results: Vec<Result<f64, LinalgError>> = b
            .par_chunks(MAX_BLOCK)
            .zip(x.par_chunks_mut(MAX_BLOCK))
            .map(|(bb, xb)| {
                let k = bb.len();
                let mut packed = Vec::with_capacity(n * k);
                for col in bb {
                    packed.extend_from_slice(col);
                }
                let (sol, rel) = self.solve_block(&packed, k)?;
                for (c, xc) in xb.iter_mut().enumerate() {
                    xc.copy_from_slice(&sol[c * n..(c + 1) * n]);
                }
                Ok(rel.iter().fold(0.0f64, |m, &r| m.max(r)))
            })
            .collect();
        let mut worst = 0.0f64;
        for r in results {
            worst = worst.max(r?);
        }
        self.store_last_residual(worst);
        Ok(worst)
    }

    /// Solves `A X = B` for one column-major block `b` (`n × k`): returns `X` (column-major)
    /// and the relative residual of every column, after the residual check and refinement
    /// of the module docs.
    pub(crate) fn solve_block(
        &self,
        b: &[f64],
        k: usize,
    ) -> Result<(Vec<f64>, Vec<f64>), LinalgError> {
        let n = self.size();
        debug_assert_eq!(b.len(), n * k);
        if let Some(index) = b.iter().position(|v| !v.is_finite()) {
            return Err(LinalgError::NonFinite {
                what: "right-hand side",
                index: index % n.max(1),
            });
        }
        let b_norm: Vec<f64> = (0..k).map(|c| norm2(&b[c * n..(c + 1) * n])).collect();
        let mut x = b.to_vec();
        self.raw_solve_block_in_place(&mut x, k);
        let mut r = self.residual_block(&x, b, k);
        let rel_of = |r: &[f64], c: usize, nb: f64| norm2(&r[c * n..(c + 1) * n]) / nb;
        let mut rel: Vec<f64> =
            (0..k).map(|c| if b_norm[c] == 0.0 { 0.0 } else { rel_of(&r, c, b_norm[c]) }).collect();
        // zero right-hand sides are solved exactly (x = 0) and never refined
        let mut done: Vec<bool> = b_norm.iter().map(|&nb| nb == 0.0).collect();
        // After a downdate the factor carries an absolute error ~ε·(removed weight); one
        // refinement step against the exact matrix removes it from the solution even when
        // the residual already looks small.
        let opts = self.options();
        let forced = usize::from(self.downdated && opts.refine_after_downdate);
        let max_steps = opts.max_refinement_steps.max(forced);
        let mut steps = 0;
        while steps < max_steps {
            let active: Vec<usize> = (0..k)
                .filter(|&c| {
                    !done[c]
                        && rel[c].is_finite()
                        && (steps < forced || exceeds(rel[c], opts.refine_above))
                })
                .collect();
            if active.is_empty() {
                break;
            }
            for c in (0..k).filter(|c| !active.contains(c)) {
                done[c] = true;
            }
            let m = active.len();
            let mut d = Vec::with_capacity(n * m);
            let mut bb = Vec::with_capacity(n * m);
            for &c in &active {
                d.extend_from_slice(&r[c * n..(c + 1) * n]);
                bb.extend_from_slice(&b[c * n..(c + 1) * n]);
            }
            self.raw_solve_block_in_place(&mut d, m);
            for (t, &c) in active.iter().enumerate() {
                for (dv, xv) in d[t * n..(t + 1) * n].iter_mut().zip(&x[c * n..(c + 1) * n]) {
                    *dv += xv;
                }
            }
            let r_new = self.residual_block(&d, &bb, m);
            steps += 1;
            for (t, &c) in active.iter().enumerate() {
                let rel_new = rel_of(&r_new, t, b_norm[c]);
                let accept = if steps <= forced { rel_new.is_finite() } else { rel_new < rel[c] };
                if !accept {
                    done[c] = true;
                    continue;
                }
                x[c * n..(c + 1) * n].copy_from_slice(&d[t * n..(t + 1) * n]);
                r[c * n..(c + 1) * n].copy_from_slice(&r_new[t * n..(t + 1) * n]);
                rel[c] = rel_new;
            }
        }
        for c in 0..k {
            if exceeds(rel[c], opts.residual_tolerance)
                || x[c * n..(c + 1) * n].iter().any(|v| !v.is_finite())
            {
                return Err(LinalgError::SolveFailed {
                    size: n,
                    residual: rel[c],
                    tolerance: opts.residual_tolerance,
                });
            }
        }
        Ok((x, rel))
    }

    /// `R = B − A X` for a column-major block with the current matrix (extra rank-1
    /// terms included), in one pass over `A` (symmetric, so `Aᵀ X`: column-parallel, each
    /// output a fixed-order dot product, the order of the single-vector product).
    pub(crate) fn residual_block(&self, x: &[f64], b: &[f64], k: usize) -> Vec<f64> {
        let n = self.size();
        let (cp, ri, va) = (self.matrix.col_ptr(), self.matrix.row_idx(), self.matrix.values());
        // row-major A X (n × k)
        let mut ax = vec![0.0f64; n * k];
        if k == 1 {
            // one right-hand side: the same sums in the same order, without the block loop
            ax.par_chunks_mut(ROW_CHUNK).enumerate().for_each(|(chunk, out)| {
                let j0 = chunk * ROW_CHUNK;
                for (o, v) in out.iter_mut().enumerate() {
                    let (p0, p1) = (cp[j0 + o], cp[j0 + o + 1]);
                    let mut t = 0.0;
                    for (&i, &a) in ri[p0..p1].iter().zip(&va[p0..p1]) {
                        t += a * x[i];
                    }
                    *v = t;
                }
            });
        } else {
            ax.par_chunks_mut(ROW_CHUNK * k).enumerate().for_each(|(chunk, out)| {
                let mut s = [0.0f64; MAX_BLOCK];
                for (o, row) in out.chunks_mut(k).enumerate() {
                    let j = chunk * ROW_CHUNK + o;
                    if k <= MAX_BLOCK {
                        s[..k].fill(0.0);
                        for p in cp[j]..cp[j + 1] {
                            let (i, v) = (ri[p], va[p]);
                            for (c, sc) in s[..k].iter_mut().enumerate() {
                                *sc += v * x[c * n + i];
                            }
                        }
                        row.copy_from_slice(&s[..k]);
                    } else {
                        for (c, rc) in row.iter_mut().enumerate() {
                            let mut t = 0.0;
                            for p in cp[j]..cp[j + 1] {
                                t += va[p] * x[c * n + ri[p]];
                            }
                            *rc = t;
                        }
                    }
                }
            });
        }
        for (w, sign) in &self.extra_terms {
            for c in 0..k {
                let d: f64 = w.iter().map(|&(i, v)| v * x[c * n + i]).sum();
                for &(i, v) in w {
                    ax[i * k + c] += sign * v * d;
                }
            }
        }
        let mut r = vec![0.0f64; n * k];
        for c in 0..k {
            for i in 0..n {
                r[c * n + i] = b[c * n + i] - ax[i * k + c];
            }
        }
        r
    }
}
