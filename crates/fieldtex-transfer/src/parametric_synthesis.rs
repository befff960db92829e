//! Parametric synthesis guided by the geometry (paper B §5.2): a constrained
//! Heeger & Bergen (1995) model over surface samples.
//!
//! 1. **Segmentation.** k-means (default 50 clusters, `fieldtex_linalg::stats::kmeans`)
//!    of the source guidance and, separately, of the target guidance. To bound the cost,
//!    k-means is fitted on at most 65 536 evenly strided samples; every sample is then
//!    labelled by its nearest centre.
//! 2. **Feathering** (§5.2.2). Each sample gets soft weights `exp(−|g − C_k|² / 2σ_k²)`
//!    over its `feather_clusters` (default 4) nearest centres, `σ_k²` the per-dimension
//!    variance of cluster `k`, normalised to sum to one (nearest centre alone when all
//!    underflow). Truncating to the nearest few centres is this implementation's choice;
//!    farther clusters' weights are negligible.
//! 3. **Colour space.** Colours are decorrelated by the PCA of the usable source colours
//!    (as H&B do) and synthesised per decorrelated channel.
//! 4. **Source model per cluster**: a weighted linear regression `y = A g + b` (ridge
//!    `1e-6`), and weighted quantile functions (128 quantiles) of every channel on every
//!    level of the Laplacian pyramid of the colours (`levels`, default 3) and of the
//!    colour values themselves. Masked samples have weight 0 (their colour is set to the
//!    mean before the pyramid is built, so bands next to a mask are slightly damped).
//! 5. **Target model per cluster**: the `neighbors` (default 4) nearest source centres
//!    in guidance space, weighted by reciprocal squared distance (Shepard), give the
//!    interpolated regression and the interpolated quantile functions (averaging inverse
//!    CDFs, after Matusik et al. 2005).
//! 6. **Initialisation** (§5.2.3): `Σ_j w_j (A_j g + b_j)` plus white Gaussian noise whose
//!    standard deviation per channel is `noise` (default 1) times the source's weighted
//!    regression residual (the texture detail the regression cannot explain).
//! 7. **Iterations** (default 3): decompose into the Laplacian pyramid; on every band
//!    and channel map each value through every target cluster's current distribution to
//!    its interpolated source distribution, `Q_j(P_j(v))`, and blend by the feathering
//!    weights; reconstruct; do the same for the colour values. Then back to RGB, clamped
//!    to `[0, 1]`.
//!
//! Deterministic: k-means and noise are seeded streams, every per-sample step writes its
//! own slot, per-cluster statistics are computed per cluster in a fixed order.

use crate::TransferError;
use crate::surface_samples::SamplePyramid;
use fieldtex_core::rng::{hash_unit, stream_seed};
use fieldtex_linalg::Pca;
use fieldtex_linalg::stats::{KMeansOptions, QuantileFunction, kmeans};
use rayon::prelude::*;
use serde::Serialize;

/// Options of [`parametric_synthesis`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParametricOptions {
    /// k-means clusters. Default 50.
    pub clusters: usize,
    /// H&B iterations. Default 3.
    pub iterations: usize,
    /// Nearest source clusters interpolated per target cluster. Default 4.
    pub neighbors: usize,
    /// Clusters per sample in the feathering. Default 4.
    pub feather_clusters: usize,
    /// Quantiles per distribution. Default 128.
    pub quantiles: usize,
    /// Initial noise in units of the source regression residual. Default 1.
    pub noise: f64,
}

impl Default for ParametricOptions {
    fn default() -> Self {
        Self {
            clusters: 50,
            iterations: 3,
            neighbors: 4,
            feather_clusters: 4,
            quantiles: 128,
            noise: 1.0,
        }
    }
}

/// What the engine did, for the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParametricStats {
    pub source_clusters: usize,
    pub target_clusters: usize,
    pub source_kmeans_iterations: usize,
    pub target_kmeans_iterations: usize,
    /// Fraction of the source colour variance (decorrelated space) explained by the
    /// per-cluster regressions.
    pub regression_r2: f64,
    /// Per-channel standard deviation of the initial noise (decorrelated space).
    pub noise_std: [f64; 3],
}

/// Inputs of both synthesis engines ([`parametric_synthesis`] and
/// [`crate::nonparametric_synthesis`]): level-0 values over the two pyramids.
pub struct SynthesisInput<'a> {
    pub source: &'a SamplePyramid,
    /// `#source × 3` guidance.
    pub source_guidance: &'a [f64],
    /// `#source × 3` RGB.
    pub source_colors: &'a [f64],
    /// Usable source samples.
    pub source_valid: &'a [bool],
    pub target: &'a SamplePyramid,
    /// `#target × 3` guidance.
    pub target_guidance: &'a [f64],
}

const FIT_SAMPLES: usize = 65_536;

/// k-means on a strided subset, labels for all.
fn segment(g: &[f64], k: usize, seed: u64) -> Result<(Vec<f64>, usize), TransferError> {
    let n = g.len() / 3;
    let stride = n.div_ceil(FIT_SAMPLES).max(1);
    let fit: Vec<f64> =
        (0..n).step_by(stride).flat_map(|i| g[i * 3..i * 3 + 3].iter().copied()).collect();
    let km = kmeans(&fit, 3, &KMeansOptions { k, max_iterations: 30, seed })
        .map_err(|e| TransferError::numeric("k-means", e))?;
    Ok((km.centers, km.iterations))
}

/// Per-dimension variance of every cluster (hard labels, all samples), floored.
fn cluster_variances(g: &[f64], centers: &[f64]) -> Vec<f64> {
    let k = centers.len() / 3;
    let n = g.len() / 3;
    let labels: Vec<usize> =
        (0..n).into_par_iter().map(|i| nearest(centers, &g[i * 3..i * 3 + 3]).0).collect();
    let mut sum = vec![0.0; k];
    let mut cnt = vec![0usize; k];
    for i in 0..n {
        let c = labels[i];
        sum[c] += (0..3).map(|d| (g[i * 3 + d] - centers[c * 3 + d]).powi(2)).sum::<f64>();
        cnt[c] += 1;
    }
    let global: f64 = {
        let mut m = [0.0; 3];
        for i in 0..n {
            for d in 0..3 {
                m[d] += g[i * 3 + d] / n as f64;
            }
        }
        (0..n).map(|i| (0..3).map(|d| (g[i * 3 + d] - m[d]).powi(2)).sum::<f64>()).sum::<f64>()
            / (3 * n.max(1)) as f64
    };
    let floor = (1e-4 * global).max(1e-12);
    (0..k)
        .map(
            |c| {
                if cnt[c] > 0 {
                    (sum[c] / (3 * cnt[c]) as f64).max(floor)
                } else {
                    global.max(floor)
                }
            },
        )
        .collect()
}

fn nearest(centers: &[f64], x: &[f64]) -> (usize, f64) {
    let mut best = (0, f64::INFINITY);
    for (c, r) in centers.chunks_exact(3).enumerate() {
        let d2 = (r[0] - x[0]).powi(2) + (r[1] - x[1]).powi(2) + (r[2] - x[2]).powi(2);
        if d2 < best.1 {
            best = (c, d2);
        }
    }
    best
}

/// Feathering weights: `f` `(cluster, weight)` pairs per sample (weight 0 pads).
fn feather(g: &[f64], centers: &[f64], var: &[f64], f: usize) -> Vec<(u32, f64)> {
    let k = centers.len() / 3;
    let f = f.clamp(1, k);
    let n = g.len() / 3;
    let mut out = vec![(0u32, 0.0); n * f];
    out.par_chunks_mut(f).enumerate().for_each(|(i, row)| {
        let x = &g[i * 3..i * 3 + 3];
        let mut d: Vec<(f64, usize)> = centers
            .chunks_exact(3)
            .enumerate()
            .map(|(c, r)| {
                ((r[0] - x[0]).powi(2) + (r[1] - x[1]).powi(2) + (r[2] - x[2]).powi(2), c)
            })
            .collect();
        d.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut total = 0.0;
        for (slot, &(d2, c)) in row.iter_mut().zip(&d) {
            let w = (-d2 / (2.0 * var[c])).exp();
            *slot = (c as u32, w);
            total += w;
        }
        if total > 0.0 && total.is_finite() {
            row.iter_mut().for_each(|s| s.1 /= total);
        } else {
            row.iter_mut().for_each(|s| s.1 = 0.0);
            row[0].1 = 1.0;
        }
    });
    out
}

/// Members `(sample, weight)` of every cluster from feathering weights × `extra`.
fn members(fw: &[(u32, f64)], f: usize, k: usize, extra: Option<&[f64]>) -> Vec<Vec<(u32, f64)>> {
    let mut m = vec![Vec::new(); k];
    for (i, row) in fw.chunks_exact(f).enumerate() {
        let e = extra.map_or(1.0, |x| x[i]);
        for &(c, w) in row {
            if w * e > 0.0 {
                m[c as usize].push((i as u32, w * e));
            }
        }
    }
    m
}

/// Quantile functions of channel `ch` of `values` (`n × 3`) per cluster.
fn cluster_quantiles(
    values: &[f64],
    ch: usize,
    mem: &[Vec<(u32, f64)>],
    q: usize,
) -> Vec<Option<QuantileFunction>> {
    mem.par_iter()
        .map(|m| {
            let v: Vec<f64> = m.iter().map(|&(i, _)| values[i as usize * 3 + ch]).collect();
            let w: Vec<f64> = m.iter().map(|&(_, w)| w).collect();
            QuantileFunction::from_weighted(&v, &w, q)
        })
        .collect()
}

/// Solves the 4×4 SPD system `m x = r` for 3 right-hand sides (Cholesky).
fn solve4(m: &[[f64; 4]; 4], r: &[[f64; 3]; 4]) -> Option<[[f64; 3]; 4]> {
    let mut l = [[0.0f64; 4]; 4];
    for i in 0..4 {
        for j in 0..=i {
            let s: f64 = m[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            if i == j {
                if s <= 0.0 {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    let mut x = [[0.0; 3]; 4];
    for c in 0..3 {
        let mut y = [0.0; 4];
        for i in 0..4 {
            y[i] = (r[i][c] - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
        }
        for i in (0..4).rev() {
            x[i][c] = (y[i] - (i + 1..4).map(|k| l[k][i] * x[k][c]).sum::<f64>()) / l[i][i];
        }
    }
    Some(x)
}

/// Per-cluster weighted regression `[g 1] → y` (4 × 3 coefficients).
fn regressions(g: &[f64], y: &[f64], mem: &[Vec<(u32, f64)>]) -> Vec<Option<[[f64; 3]; 4]>> {
    mem.par_iter()
        .map(|m| {
            let mut a = [[0.0; 4]; 4];
            let mut r = [[0.0; 3]; 4];
            let mut wsum = 0.0;
            for &(i, w) in m {
                let i = i as usize;
                let x = [g[i * 3], g[i * 3 + 1], g[i * 3 + 2], 1.0];
                for p in 0..4 {
                    for q in 0..4 {
                        a[p][q] += w * x[p] * x[q];
                    }
                    for c in 0..3 {
                        r[p][c] += w * x[p] * y[i * 3 + c];
                    }
                }
                wsum += w;
            }
            if wsum <= 0.0 {
                return None;
            }
            let ridge = 1e-6 * (a[0][0] + a[1][1] + a[2][2]).max(1e-12) + 1e-9 * wsum;
            for p in 0..3 {
                a[p][p] += ridge;
            }
            a[3][3] += 1e-12 * wsum;
            solve4(&a, &r)
        })
        .collect()
}

fn eval_regression(c: &[[f64; 3]; 4], g: &[f64]) -> [f64; 3] {
    let mut o = [0.0; 3];
    for ch in 0..3 {
        o[ch] = c[0][ch] * g[0] + c[1][ch] * g[1] + c[2][ch] * g[2] + c[3][ch];
    }
    o
}

/// The source model interpolated for one target cluster.
struct TargetModel {
    regression: [[f64; 3]; 4],
    /// `[level or value][channel]`.
    quantiles: Vec<[QuantileFunction; 3]>,
}

/// Runs the engine (module docs); returns `#target × 3` RGB in `[0, 1]`.
pub fn parametric_synthesis(
    input: &SynthesisInput<'_>,
    options: &ParametricOptions,
    seed: u64,
) -> Result<(Vec<f64>, ParametricStats), TransferError> {
    if options.clusters == 0 || options.iterations > 100 || options.quantiles < 2 {
        return Err(TransferError::InvalidOption {
            what: "parametric engine",
            message: "clusters ≥ 1, iterations ≤ 100, quantiles ≥ 2".into(),
        });
    }
    let (sp, tp) = (input.source, input.target);
    let levels = sp.n_levels().min(tp.n_levels());
    let ns = sp.levels[0].len();
    let f = options.feather_clusters.max(1);
    // 3. Decorrelated colour space from the usable source colours.
    let valid_rows: Vec<usize> = (0..ns).filter(|&i| input.source_valid[i]).collect();
    if valid_rows.len() < 16 {
        return Err(TransferError::TooFewSamples { found: valid_rows.len(), needed: 16 });
    }
    let fit: Vec<f32> = valid_rows
        .iter()
        .flat_map(|&i| input.source_colors[i * 3..i * 3 + 3].iter().map(|&v| v as f32))
        .collect();
    let pca = Pca::fit(&fit, 3, 3).map_err(|e| TransferError::numeric("colour PCA", e))?;
    let to_dec = |c: &[f64]| -> [f64; 3] {
        let mut o = [0.0; 3];
        for k in 0..3 {
            o[k] = (0..3).map(|j| (c[j] - pca.mean[j]) * pca.components[k][j]).sum();
        }
        o
    };
    let mut ys = vec![0.0; ns * 3];
    let vfrac: Vec<f64> = input.source_valid.iter().map(|&v| if v { 1.0 } else { 0.0 }).collect();
    for i in 0..ns {
        if input.source_valid[i] {
            ys[i * 3..i * 3 + 3].copy_from_slice(&to_dec(&input.source_colors[i * 3..i * 3 + 3]));
        } // masked: the mean colour, i.e. 0 in the centred decorrelated space
    }
    // 1–2. Segmentation and feathering on every level.
    let k_req = options.clusters;
    let (cs, it_s) =
        segment(input.source_guidance, k_req, stream_seed(seed, "transfer-kmeans", 0))?;
    let (ct, it_t) =
        segment(input.target_guidance, k_req, stream_seed(seed, "transfer-kmeans", 1))?;
    let (ks, kt) = (cs.len() / 3, ct.len() / 3);
    let var_s = cluster_variances(input.source_guidance, &cs);
    let var_t = cluster_variances(input.target_guidance, &ct);
    let gs_levels = sp.gaussian(input.source_guidance, 3);
    let gt_levels = tp.gaussian(input.target_guidance, 3);
    let valid_levels = sp.gaussian(&vfrac, 1);
    let fs: Vec<Vec<(u32, f64)>> = gs_levels.iter().map(|g| feather(g, &cs, &var_s, f)).collect();
    let ft: Vec<Vec<(u32, f64)>> = gt_levels.iter().map(|g| feather(g, &ct, &var_t, f)).collect();
    let fs_eff = f.min(ks);
    let ft_eff = f.min(kt);
    let mem_s: Vec<Vec<Vec<(u32, f64)>>> =
        (0..levels).map(|l| members(&fs[l], fs_eff, ks, Some(&valid_levels[l]))).collect();
    let mem_t: Vec<Vec<Vec<(u32, f64)>>> =
        (0..levels).map(|l| members(&ft[l], ft_eff, kt, None)).collect();
    // 4. Source model.
    let reg_s = regressions(input.source_guidance, &ys, &mem_s[0]);
    let bands_s = sp.laplacian(&ys, 3);
    let q = options.quantiles;
    // quant_s[slot][channel][cluster]; slots: bands 0..levels, then values.
    let mut quant_s: Vec<[Vec<Option<QuantileFunction>>; 3]> = Vec::new();
    for l in 0..levels {
        quant_s.push(std::array::from_fn(|ch| cluster_quantiles(&bands_s[l], ch, &mem_s[l], q)));
    }
    quant_s.push(std::array::from_fn(|ch| cluster_quantiles(&ys, ch, &mem_s[0], q)));
    // Regression residual (noise level) and R².
    let mut res2 = [0.0; 3];
    let mut tot2 = [0.0; 3];
    let mut wsum = 0.0;
    for i in 0..ns {
        if !input.source_valid[i] {
            continue;
        }
        let g = &input.source_guidance[i * 3..i * 3 + 3];
        let mut pred = [0.0; 3];
        for &(c, w) in &fs[0][i * fs_eff..(i + 1) * fs_eff] {
            if let Some(r) = &reg_s[c as usize] {
                let p = eval_regression(r, g);
                for ch in 0..3 {
                    pred[ch] += w * p[ch];
                }
            }
        }
        for ch in 0..3 {
            res2[ch] += (ys[i * 3 + ch] - pred[ch]).powi(2);
            tot2[ch] += ys[i * 3 + ch].powi(2);
        }
        wsum += 1.0;
    }
    let noise_std: [f64; 3] = std::array::from_fn(|ch| options.noise * (res2[ch] / wsum).sqrt());
    let regression_r2 = 1.0 - res2.iter().sum::<f64>() / tot2.iter().sum::<f64>().max(1e-300);
    // 5. Target models by Shepard interpolation of the nearest source clusters.
    let usable: Vec<usize> = (0..ks)
        .filter(|&c| reg_s[c].is_some() && quant_s.iter().all(|s| s.iter().all(|v| v[c].is_some())))
        .collect();
    if usable.is_empty() {
        return Err(TransferError::TooFewSamples { found: valid_rows.len(), needed: 16 });
    }
    let models: Vec<TargetModel> = (0..kt)
        .map(|j| {
            let c = &ct[j * 3..j * 3 + 3];
            let mut d: Vec<(f64, usize)> = usable
                .iter()
                .map(|&k| ((0..3).map(|x| (cs[k * 3 + x] - c[x]).powi(2)).sum::<f64>(), k))
                .collect();
            d.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            d.truncate(options.neighbors.max(1));
            let w: Vec<(usize, f64)> = if d[0].0 < 1e-24 {
                vec![(d[0].1, 1.0)]
            } else {
                d.iter().map(|&(d2, k)| (k, 1.0 / d2)).collect()
            };
            let wt: f64 = w.iter().map(|x| x.1).sum();
            let mut regression = [[0.0; 3]; 4];
            for &(k, wk) in &w {
                let r = reg_s[k].as_ref().expect("usable");
                for p in 0..4 {
                    for ch in 0..3 {
                        regression[p][ch] += wk / wt * r[p][ch];
                    }
                }
            }
            let quantiles = quant_s
                .iter()
                .map(|slot| {
                    std::array::from_fn(|ch| {
                        let parts: Vec<(&QuantileFunction, f64)> = w
                            .iter()
                            .map(|&(k, wk)| (slot[ch][k].as_ref().expect("usable"), wk))
                            .collect();
                        QuantileFunction::mix(&parts).expect("positive weights")
                    })
                })
                .collect();
            TargetModel { regression, quantiles }
        })
        .collect();
    // 6. Initialisation.
    let nt = tp.levels[0].len();
    let noise_seed = stream_seed(seed, "transfer-noise", 0);
    let mut yt = vec![0.0; nt * 3];
    yt.par_chunks_mut(3).enumerate().for_each(|(i, o)| {
        let g = &input.target_guidance[i * 3..i * 3 + 3];
        for &(c, w) in &ft[0][i * ft_eff..(i + 1) * ft_eff] {
            let p = eval_regression(&models[c as usize].regression, g);
            for ch in 0..3 {
                o[ch] += w * p[ch];
            }
        }
        for ch in 0..3 {
            let idx = (i * 3 + ch) as u64;
            let u1 = hash_unit(noise_seed, "u1", idx).max(1e-300);
            let u2 = hash_unit(noise_seed, "u2", idx);
            let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
            o[ch] += noise_std[ch] * z;
        }
    });
    // 7. Constrained Heeger–Bergen iterations.
    let match_slot = |vals: &mut [f64], slot: usize, fw: &[(u32, f64)], mem: &[Vec<(u32, f64)>]| {
        for ch in 0..3 {
            let current = cluster_quantiles(vals, ch, mem, q);
            let mapped: Vec<f64> = (0..vals.len() / 3)
                .into_par_iter()
                .map(|i| {
                    let v = vals[i * 3 + ch];
                    let mut acc = 0.0;
                    let mut wsum = 0.0;
                    for &(c, w) in &fw[i * ft_eff..(i + 1) * ft_eff] {
                        if w <= 0.0 {
                            continue;
                        }
                        if let Some(p) = &current[c as usize] {
                            acc += w * models[c as usize].quantiles[slot][ch].eval(p.cdf(v));
                            wsum += w;
                        }
                    }
                    if wsum > 0.0 { acc / wsum } else { v }
                })
                .collect();
            for (i, m) in mapped.into_iter().enumerate() {
                vals[i * 3 + ch] = m;
            }
        }
    };
    for _ in 0..options.iterations {
        let mut bands = tp.laplacian(&yt, 3);
        for (l, band) in bands.iter_mut().enumerate().take(levels) {
            match_slot(band, l, &ft[l], &mem_t[l]);
        }
        yt = tp.reconstruct(&bands, 3);
        match_slot(&mut yt, levels, &ft[0], &mem_t[0]);
    }
    // Back to RGB.
    let mut rgb = vec![0.0; nt * 3];
    rgb.par_chunks_mut(3).enumerate().for_each(|(i, o)| {
        for j in 0..3 {
            let v = pca.mean[j] + (0..3).map(|k| yt[i * 3 + k] * pca.components[k][j]).sum::<f64>();
            o[j] = v.clamp(0.0, 1.0);
        }
    });
    Ok((
        rgb,
        ParametricStats {
            source_clusters: ks,
            target_clusters: kt,
            source_kmeans_iterations: it_s,
            target_kmeans_iterations: it_t,
            regression_r2,
            noise_std,
        },
    ))
}
