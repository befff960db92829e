//! Diagnosis of the feature-size CV of a `fieldtex conformal` result (issue 13,
//! session 13): where on the surface the variance of the measured period lives.
//!
//! `cargo run --release -p fieldtex --example conformal_feature_diag -- DIR [centre]`
//! reads `DIR/model.glb` and `DIR/report.json` (the exemplar levels and `τ_ref`) and
//! prints, area-weighted over triangles:
//! - the CV as `eval` measures it (per-texel `λ`; with `centre`, the centre triangle's
//!   `λ` of sessions 10–12), and its variance split by quantiles of the surface
//!   length per texel `λ`, by how much of each triangle's measuring window lies in its
//!   own chart, and by window size;
//! - the CV the quilting's level choice *predicts* if the texture followed its levels
//!   exactly (surface period `∝ s/τ` per texel, `s` the level of the last quilting patch
//!   over it, chosen like `image_quilting::patch_tau`), against the per-texel nearest
//!   level (quantisation alone) and the exact scale (clamping alone);
//! - the measured period in texels against that level (`period / s`, which should be
//!   constant).
//!
//! `-- --response EXEMPLAR [PATCH]` prints, per scale, the period the measure reads on
//! the resampled exemplar and on a flat canvas quilted from it.
//!
//! Assumes the texture holds one geometry image at its top (one component).

use fieldtex_eval::feature_size::{feature_size_per_triangle, triangle_texel_scale};
use std::path::PathBuf;

/// `--response EXEMPLAR PATCH`: for each scale, the period in texels the measure reads
/// on the resampled exemplar and on a flat 512² canvas quilted from it (uniform `τ`).
fn response(exemplar: &str, patch: usize) {
    let ex = fieldtex_io::read_image(std::path::Path::new(exemplar)).unwrap();
    let measure = |im: &fieldtex_core::Image| {
        let mut mesh = fieldtex_mesh::primitives::grid(16, 16, 1.0, 1.0);
        let values: Vec<[f64; 2]> = mesh.positions.iter().map(|p| [p[0], p[1]]).collect();
        mesh.uvs = Some(fieldtex_mesh::CornerUvs { values, indices: mesh.triangles.clone() });
        let r =
            fieldtex_eval::feature_size::feature_size_variation(&mesh, im, 24, true, true).unwrap();
        (r.mean_period * im.width as f64, r.cv_texels)
    };
    for s in [0.78, 1.0, 1.29, 1.65, 2.12, 2.72, 3.49, 4.48, 5.75, 8.0, 12.0] {
        let lv = fieldtex_synth::exemplar_scales::resample(&ex, s);
        let (n, w) = (512usize, 512usize);
        let tau = vec![1.0f32; n * w];
        let level_for = |_: f64| 0usize;
        let partners = |_: usize, _: usize, _: &mut Vec<(usize, usize)>| {};
        let target = fieldtex_synth::QuiltTarget {
            width: w,
            height: n,
            tau: &tau,
            level_for: &level_for,
            partners: &partners,
        };
        let o = fieldtex_synth::QuiltingOptions {
            patch_size: patch,
            overlap: (patch / 5).max(2),
            ..Default::default()
        };
        let (q, _) = fieldtex_synth::quilt(
            std::slice::from_ref(&lv),
            &target,
            &o,
            &fieldtex_core::NoProgress,
        );
        let (pe, _) = measure(&lv);
        let (pq, cq) = measure(&q);
        println!(
            "scale {s:5.2}: exemplar {pe:6.1} texels ({:.2}/scale), quilted {pq:6.1} ({:.2}/scale, CV {cq:.3})",
            pe / s,
            pq / s
        );
    }
}

fn main() {
    if std::env::args().nth(1).as_deref() == Some("--response") {
        let patch = std::env::args().nth(3).map_or(40, |s| s.parse().unwrap());
        return response(&std::env::args().nth(2).unwrap(), patch);
    }
    let dir = PathBuf::from(std::env::args().nth(1).expect("DIR"));
    let patch = 40usize;
    let loaded = fieldtex_io::read_mesh(&dir.join("model.glb")).expect("model.glb");
    let mesh = loaded.mesh;
    let tex = loaded.base_color.expect("texture");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap();
    let lv = &report["metrics"]["exemplar_levels"];
    let scales: Vec<f64> =
        lv["scales"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let tau_ref = lv["tau_reference"].as_f64().unwrap();
    println!("levels {scales:.3?} tau_ref {tau_ref:.4e}");
    let (w, h) = (tex.width, tex.height);
    let uvs = mesh.uvs.as_ref().unwrap();
    // Charts: faces sharing a UV index.
    let nf = mesh.n_triangles();
    let mut sets = fieldtex_mesh::UnionFind::new(nf);
    let mut first = vec![usize::MAX; uvs.values.len()];
    for f in 0..nf {
        for &u in &uvs.indices[f] {
            let u = u as usize;
            if first[u] == usize::MAX {
                first[u] = f;
            } else {
                sets.union(f, first[u]);
            }
        }
    }
    let chart: Vec<usize> = (0..nf).map(|f| sets.find(f)).collect();
    let map = fieldtex_param::build_texel_map(&mesh, w, h, 0).unwrap();
    let owner: Vec<i64> = map.entries.iter().map(|e| e.map_or(-1, |e| e.triangle as i64)).collect();
    let per_texel = std::env::args().nth(2).as_deref() != Some("centre");
    let rows = feature_size_per_triangle(&mesh, &tex, 24, true, per_texel).unwrap();
    // Per-face λ from the rows' computation (recomputed for faces without a row).
    let lam: Vec<f64> = (0..nf).map(|f| triangle_texel_scale(&mesh, uvs, f, w, h).2).collect();
    let tau: Vec<f64> =
        owner.iter().map(|&o| if o >= 0 { 1.0 / lam[o as usize] } else { f64::NAN }).collect();
    // Quilting patches as `quilt` places them.
    let b = patch;
    let step = b - (b / 5).max(2).min(b / 2);
    let positions = |len: usize| -> Vec<usize> {
        if len <= b {
            return vec![0];
        }
        let mut v: Vec<usize> = (0..).map(|k| k * step).take_while(|&p| p + b < len).collect();
        v.push(len - b);
        v
    };
    let nearest = |t: f64| -> f64 {
        let r = (t / tau_ref).ln();
        *scales.iter().min_by(|a, b| (a.ln() - r).abs().total_cmp(&(b.ln() - r).abs())).unwrap()
    };
    let mut level = vec![f64::NAN; w * h];
    let mut patch_spread: Vec<(f64, f64)> = Vec::new(); // (max/min τ in patch, surface weight)
    for &y0 in &positions(h) {
        for &x0 in &positions(w) {
            let (mut num, mut den, mut tmin, mut tmax, mut sw) =
                (0.0, 0.0, f64::INFINITY, 0.0f64, 0.0);
            for y in y0..(y0 + b).min(h) {
                for x in x0..(x0 + b).min(w) {
                    let t = tau[y * w + x];
                    if t.is_finite() && t > 0.0 {
                        let wt = t.powi(-4);
                        num += wt * t;
                        den += wt;
                        tmin = tmin.min(t);
                        tmax = tmax.max(t);
                        sw += t.powi(-2);
                    }
                }
            }
            if den <= 0.0 {
                continue;
            }
            patch_spread.push((tmax / tmin, sw));
            let s = nearest(num / den);
            for y in y0..(y0 + b).min(h) {
                for x in x0..(x0 + b).min(w) {
                    level[y * w + x] = s;
                }
            }
        }
    }
    // Predicted CVs over texels (weight = surface area of a texel, λ² = τ⁻²).
    let cv = |vals: &mut dyn Iterator<Item = (f64, f64)>| {
        let (mut sw, mut s1, mut s2) = (0.0, 0.0, 0.0);
        for (v, wt) in vals {
            if v.is_finite() && wt.is_finite() {
                sw += wt;
                s1 += wt * v;
                s2 += wt * v * v;
            }
        }
        let m = s1 / sw;
        (s2 / sw - m * m).max(0.0).sqrt() / m
    };
    let lo = scales[0];
    let hi = *scales.last().unwrap();
    println!(
        "predicted CV of the surface period over texels: patch levels {:.3}, per-texel nearest level {:.3}, per-texel exact clamped scale {:.3}, one level (no multiscale) {:.3}",
        cv(&mut (0..w * h).map(|i| (level[i] / tau[i], tau[i].powi(-2)))),
        cv(&mut (0..w * h).map(|i| (nearest(tau[i]) / tau[i], tau[i].powi(-2)))),
        cv(&mut (0..w * h).map(|i| ((tau[i] / tau_ref).clamp(lo, hi) / tau[i], tau[i].powi(-2)))),
        cv(&mut (0..w * h).map(|i| (1.0 / tau[i], tau[i].powi(-2)))),
    );
    patch_spread.sort_by(|a, b| a.0.total_cmp(&b.0));
    let tot: f64 = patch_spread.iter().map(|p| p.1).sum();
    let mut acc = 0.0;
    print!("patch τ max/min (surface-weighted quantiles):");
    let mut qs = [0.25, 0.5, 0.75, 0.9, 0.99].into_iter().peekable();
    for p in &patch_spread {
        acc += p.1;
        while let Some(&q) = qs.peek() {
            if acc >= q * tot {
                print!(" q{:.0} {:.2}", q * 100.0, p.0);
                qs.next();
            } else {
                break;
            }
        }
    }
    println!();
    // Per-triangle table.
    struct Row {
        period: f64,
        ptex: f64,
        lambda: f64,
        area: f64,
        own: f64,
        empty: f64,
        s: f64,
        r: i64,
    }
    let mut tri: Vec<Row> = Vec::new();
    for (f, r) in rows.iter().enumerate() {
        let Some(r) = r else { continue };
        let (cx, cy, hs) = (r.centre[0], r.centre[1], r.half_side);
        let n = (2 * hs + 1).min(w as i64);
        let x0 = (cx - hs).clamp(0, w as i64 - n);
        let n2 = (2 * hs + 1).min(h as i64);
        let y0 = (cy - hs).clamp(0, h as i64 - n2);
        let (mut own, mut empty, mut all) = (0.0, 0.0, 0.0);
        for y in y0..y0 + n2 {
            for x in x0..x0 + n {
                let o = owner[(y as usize) * w + x as usize];
                all += 1.0;
                if o < 0 {
                    empty += 1.0;
                } else if chart[o as usize] == chart[f] {
                    own += 1.0;
                }
            }
        }
        let s = level[(cy as usize) * w + cx as usize];
        tri.push(Row {
            period: r.period,
            ptex: r.period_texels,
            lambda: r.lambda,
            area: r.area,
            own: own / all,
            empty: empty / all,
            s,
            r: hs,
        });
    }
    let sw: f64 = tri.iter().map(|t| t.area).sum();
    let m: f64 = tri.iter().map(|t| t.area * t.period).sum::<f64>() / sw;
    let var: f64 = tri.iter().map(|t| t.area * (t.period - m).powi(2)).sum::<f64>() / sw;
    println!(
        "measured CV {:.3} over {} triangles, mean period {:.4e}; charts {}",
        var.sqrt() / m,
        tri.len(),
        m,
        {
            let mut c = chart.clone();
            c.sort();
            c.dedup();
            c.len()
        }
    );
    let table = |name: &str, key: &dyn Fn(&Row) -> f64, edges: &[f64]| {
        println!(
            "by {name}: bin | area % | var share % | mean period/mean | mean texels | mean texels/level | mean level | mean λ"
        );
        for k in 0..edges.len() - 1 {
            let sel: Vec<&Row> =
                tri.iter().filter(|t| key(t) >= edges[k] && key(t) < edges[k + 1]).collect();
            let a: f64 = sel.iter().map(|t| t.area).sum();
            if a <= 0.0 {
                continue;
            }
            let v: f64 = sel.iter().map(|t| t.area * (t.period - m).powi(2)).sum::<f64>();
            let mean = |g: &dyn Fn(&Row) -> f64| sel.iter().map(|t| t.area * g(t)).sum::<f64>() / a;
            println!(
                "  [{:.3e}, {:.3e}) | {:5.1} | {:5.1} | {:.2} | {:.1} | {:.2} | {:.2} | {:.3e}",
                edges[k],
                edges[k + 1],
                100.0 * a / sw,
                100.0 * v / (var * sw),
                mean(&|t| t.period) / m,
                mean(&|t| t.ptex),
                mean(&|t| t.ptex / t.s),
                mean(&|t| t.s),
                mean(&|t| t.lambda),
            );
        }
    };
    // λ deciles (area-weighted).
    let mut by_l: Vec<(f64, f64)> = tri.iter().map(|t| (t.lambda, t.area)).collect();
    by_l.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut edges = vec![0.0];
    let mut acc = 0.0;
    let qs = [
        0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.98, 0.99, 0.995, 0.998, 0.999, 0.9995,
    ];
    let mut k = 0;
    for (l, a) in &by_l {
        acc += a;
        if k < qs.len() && acc >= qs[k] * sw {
            edges.push(*l);
            k += 1;
        }
    }
    edges.push(f64::INFINITY);
    table("λ decile", &|t| t.lambda, &edges);
    table("own-chart share of window", &|t| t.own, &[0.0, 0.25, 0.5, 0.75, 0.9, 1.01]);
    table("empty share of window", &|t| t.empty, &[0.0, 1e-9, 0.1, 0.25, 0.5, 1.01]);
    table("window half-side", &|t| t.r as f64, &[0.0, 13.0, 20.0, 30.0, 50.0, 1e9]);
}
