//! Quality probe of the orientation-guided synthesis on fields written by
//! `fieldtex orient` (paper D §4 targets of issue 3).
//!
//! `cargo run --release -p fieldtex-synth --example orient_probe -- EXEMPLAR.png
//!  [DIR…] [--const DEG…] [--ideal DEG…] [--prerotate DEG… [--residual R] [--copy-scale F]] [--tileable | --detect-tileable] [--margin-divisor D] [--wrap-metric | --no-wrap-metric] [--both] [--no-rosy-fix] [--free-flips]
//!  [--no-comb] [--nearest] [--no-snap] [--integrated-init] [--no-trapezoid] [--warp | --no-warp]
//!  [--passes N] [--finest-passes N] [--coarse-passes N] [--jitter X] [--unjittered N] [--k K] [--no-own]
//!  [--seed S] [--stride N] [--runs R] [--png DIR] [--scan N] [--radius R] [--analysis-k K]
//!  [--no-metrics]`
//!
//! Each `DIR` holds `field.npy` (H × W × 2) and `report.json` (its
//! `metrics.designed_singularities`), e.g. `out/orient-bench/<exemplar>-<preset>`.
//! Per case it prints the synthesis time (median of `--runs`), the guided coherence
//! (`fieldtex_eval::guided_coherence`, stride `--stride`, default 8 like the report),
//! the orientation error (against the field turned by the exemplar's dominant stripe
//! direction, as `fieldtex orient` reports it, and raw), the phase-defect count, the count within 3 periods of the
//! designed singularities (as `fieldtex orient`) and the count a uniform density of
//! the image's defects would put there (`bg`), and the coordinate coherence of
//! neighbour pairs, the effective-frame seams (`(−1)^I J` turning by more than 90°
//! between neighbours) and the flipped share. `--const DEG` adds a constant-field
//! case (no singularities); `--ideal DEG` scores the exemplar itself rotated to a
//! constant field (the resampling floor of the metric; with `--png DIR` also written as
//! `ideal-DEG.png` and its field `ideal-DEG.npy`). `--prerotate DEG` scores a constant
//! design at DEG + `--residual` (default 0) synthesised against the exemplar pre-rotated
//! by DEG (`fieldtex_synth::synthesize_rotated`, a copy `--copy-scale` × the exemplar's
//! size); `--tileable` analyses the exemplar as tileable, `--detect-tileable` does so
//! when `fieldtex_synth::exemplar_tiling` finds that it tiles; `--margin-divisor D`
//! caps a non-tileable exemplar's border margin at `min(W, H) / D` (default 8). The guided coherence
//! searches the exemplar's patches toroidally only when that test finds that it tiles
//! (the rule of `fieldtex orient` / `eval`); `--wrap-metric` / `--no-wrap-metric`
//! force wrapping on / off. `--both` runs with and without the 2-RoSy fix. `--png DIR`
//! writes the texture, the texture with the defects marked (red: within 3 periods of a
//! designed singularity), 3× crops around the singularities and the flip map.

use std::path::{Path, PathBuf};
use std::time::Instant;

use fieldtex_core::{Image, NoProgress};
use fieldtex_eval as ev;
use fieldtex_synth::{
    AnalysisOptions, ExemplarAnalysis, ImageDomain, SynthesisOptions, synthesize,
};

fn num<T: std::str::FromStr>(v: Option<String>, what: &str) -> T {
    v.and_then(|s| s.parse().ok()).unwrap_or_else(|| panic!("{what} needs a number"))
}

struct Case {
    name: String,
    n: usize,
    field: Vec<f32>,
    sings: Vec<[f64; 2]>,
}

fn load_case(dir: &Path) -> Case {
    let (shape, field) = fieldtex_io::read_npy_f32(&dir.join("field.npy"))
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    assert!(shape.len() == 3 && shape[0] == shape[1] && shape[2] == 2, "{shape:?}");
    let text = std::fs::read_to_string(dir.join("report.json")).expect("report.json");
    let r: serde_json::Value = serde_json::from_str(&text).expect("report.json parses");
    let sings = r["metrics"]["designed_singularities"]
        .as_array()
        .map(|a| a.iter().map(|s| [s["x"].as_f64().unwrap(), s["y"].as_f64().unwrap()]).collect())
        .unwrap_or_default();
    let name = dir.file_name().unwrap().to_string_lossy().to_string();
    Case { name, n: shape[0], field, sings }
}

/// Stripe ends a texture of period `t` must have near the singularities when its
/// stripes follow the field: stripes along the unit line field `d` with a constant
/// period need a phase `φ` with `∇φ = (2π/t) d⊥`, which exists only where
/// `curl d⊥ = div d = 0`; the net number of stripe ends in a region is
/// `∫ div d dA / t`. Summed here as `∫ |div d| dA / t` over the annuli `1.5 t ≤ r ≤ 3 t`
/// around the designed singularities (the phase-defect metric skips the inner 1.5 t),
/// with `d` of each neighbour sign-aligned to the centre's (a line field).
fn required_dislocations(case: &Case, t: f64) -> f64 {
    let n = case.n;
    let v = |x: usize, y: usize| {
        let i = 2 * (y * n + x);
        [case.field[i] as f64, case.field[i + 1] as f64]
    };
    let mut sum = 0.0;
    for y in 1..n - 1 {
        for x in 1..n - 1 {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            let inside = case.sings.iter().any(|s| {
                let r2 = (px - s[0]).powi(2) + (py - s[1]).powi(2);
                r2 <= 9.0 * t * t && r2 >= 2.25 * t * t
            });
            if !inside {
                continue;
            }
            let c = v(x, y);
            let al = |w: [f64; 2]| if w[0] * c[0] + w[1] * c[1] < 0.0 { [-w[0], -w[1]] } else { w };
            let (e, wv, s, nn) =
                (al(v(x + 1, y)), al(v(x - 1, y)), al(v(x, y + 1)), al(v(x, y - 1)));
            sum += (0.5 * (e[0] - wv[0]) + 0.5 * (s[1] - nn[1])).abs();
        }
    }
    sum / t
}

fn main() {
    let mut args = std::env::args().skip(1);
    let exemplar = PathBuf::from(args.next().expect("EXEMPLAR.png"));
    let mut dirs = Vec::new();
    let mut opts = SynthesisOptions { seed: 1, ..Default::default() };
    let (mut both, mut stride, mut runs) = (false, 8usize, 1usize);
    let mut png: Option<PathBuf> = None;
    let mut aopts = AnalysisOptions::default();
    let mut no_metrics = false;
    let mut ideal: Vec<f32> = Vec::new();
    let mut consts: Vec<f32> = Vec::new();
    let mut prerotate: Vec<f32> = Vec::new();
    let mut residual = 0.0f32;
    let mut copy_scale = 1.0f32;
    let mut wrap_metric: Option<bool> = None;
    let mut detect_tileable = false;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--both" => both = true,
            "--no-metrics" => no_metrics = true,
            "--no-comb" => opts.comb_flips = false,
            "--no-snap" => opts.snap_coordinates = false,
            "--integrated-init" => opts.integrated_init = true,
            "--integrated-trust" => opts.integrated_trust = num(args.next(), &a),
            "--integrated-free" => opts.integrated_free_levels = num(args.next(), &a),
            "--ideal" => ideal.push(num::<f32>(args.next(), &a)),
            "--scan" => aopts.coherence_scan = num(args.next(), &a),
            "--radius" => aopts.coherence_radius = num(args.next(), &a),
            "--analysis-k" => aopts.k = num(args.next(), &a),
            "--nearest" => opts.color_filter = fieldtex_synth::ColorFilter::Nearest,
            "--free-flips" => opts.keep_flips = false,
            "--const" => consts.push(num::<f32>(args.next(), &a)),
            "--prerotate" => prerotate.push(num::<f32>(args.next(), &a)),
            "--residual" => residual = num(args.next(), &a),
            "--copy-scale" => copy_scale = num(args.next(), &a),
            "--tileable" => aopts.tileable = true,
            "--no-wrap-metric" => wrap_metric = Some(false),
            "--wrap-metric" => wrap_metric = Some(true),
            "--detect-tileable" => detect_tileable = true,
            "--margin-divisor" => aopts.margin_divisor = num(args.next(), &a),
            "--no-rosy-fix" => opts.rosy_fix = false,
            "--coarse-passes" => opts.coarse_passes = Some(num(args.next(), &a)),
            "--no-trapezoid" => opts.trapezoid_frames = false,
            "--warp" => opts.warped_corners = true,
            "--no-warp" => opts.warped_corners = false,
            "--passes" => opts.correction_passes = num(args.next(), &a),
            "--finest-passes" => opts.finest_passes = Some(num(args.next(), &a)),
            "--jitter" => opts.jitter = num(args.next(), &a),
            "--unjittered" => opts.unjittered_levels = num(args.next(), &a),
            "--k" => opts.k = num(args.next(), &a),
            "--no-own" => opts.own_candidates = false,
            "--seed" => opts.seed = num(args.next(), &a),
            "--stride" => stride = num(args.next(), &a),
            "--runs" => runs = num(args.next(), &a),
            "--png" => png = args.next().map(PathBuf::from),
            _ => dirs.push(PathBuf::from(a)),
        }
    }
    let ex: Image = fieldtex_io::read_image(&exemplar).expect("exemplar");
    let tiling = fieldtex_synth::exemplar_tiling(&ex);
    let wrap_exemplar = wrap_metric.unwrap_or(tiling.tiles);
    aopts.tileable |= detect_tileable && tiling.tiles;
    println!(
        "wrap-jump ratio x {:.2} y {:.2} (tiles: {}); metric wraps: {wrap_exemplar}; analysis \
         tileable: {}",
        tiling.jump_ratio[0], tiling.jump_ratio[1], tiling.tiles, aopts.tileable
    );
    let t0 = Instant::now();
    let analysis = ExemplarAnalysis::new(&ex, &aopts, &NoProgress).unwrap();
    println!(
        "analysis_ms={:.0} explained={:?}",
        t0.elapsed().as_secs_f64() * 1e3,
        (0..analysis.level_count())
            .map(|c| (analysis.level(c).explained_variance * 100.0).round())
            .collect::<Vec<_>>()
    );
    let eb = ev::rgb_buffer(&ex);
    let ev_ex = ev::ImageView::new(&eb, ex.width, ex.height, 3).unwrap();
    let ex_angle = ev::dominant_orientation(&ev_ex).map_or(0.0, |a| a.0);
    // Resampling floor: the exemplar itself rotated to a constant field at each angle
    // of `--ideal` (coordinates an exact rotation of the output grid, cubic colours),
    // scored like a synthesis result.
    for &deg in &ideal {
        let n = 512usize;
        let (sn, cs) = deg.to_radians().sin_cos();
        let mut img = Image { width: n, height: n, pixels: Vec::with_capacity(n * n) };
        for y in 0..n {
            for x in 0..n {
                let (px, py) = (x as f32 + 0.5 - 256.0, y as f32 + 0.5 - 256.0);
                // J = [d; d⊥]: exemplar x along d = (cos, sin).
                let u = [
                    cs * px + sn * py + 1000.0 * ex.width as f32,
                    -sn * px + cs * py + 1000.0 * ex.height as f32,
                ];
                let u = [u[0].rem_euclid(ex.width as f32), u[1].rem_euclid(ex.height as f32)];
                img.pixels.push(fieldtex_synth::color_lookup(&analysis, u, opts.color_filter));
            }
        }
        let field: Vec<f32> = (0..n * n).flat_map(|_| [cs, sn]).collect();
        let ob = ev::rgb_buffer(&img);
        let out = ev::ImageView::new(&ob, n, n, 3).unwrap();
        let fv = ev::FieldView::new(&field, n, n).unwrap();
        let gopts = ev::GuidedCoherenceOptions { stride, wrap_exemplar, ..Default::default() };
        let gc = ev::guided_coherence(&out, &ev_ex, &fv, &gopts).unwrap();
        println!("ideal rotated copy {deg:5.1}°: gc={:.6} (median {:.6})", gc.mean, gc.median);
        if let Some(dir) = &png {
            // The copy itself and its field, for scoring with `fieldtex eval` (the
            // approximate search of orient's reports).
            std::fs::create_dir_all(dir).unwrap();
            fieldtex_io::write_png(&dir.join(format!("ideal-{deg}.png")), &img).unwrap();
            fieldtex_io::write_npy_f32(&dir.join(format!("ideal-{deg}.npy")), &[n, n, 2], &field)
                .unwrap();
        }
    }
    // A constant field at DEG + `--residual` synthesised against the exemplar
    // pre-rotated by DEG (`synthesize_rotated`): at residual 0 coherent patches copy
    // the copy's pixels exactly. Scored against the original exemplar.
    for &deg in &prerotate {
        let n = 512usize;
        // The design's field is at DEG + residual; the copy is turned by DEG.
        let (ts, tc) = (deg + residual).to_radians().sin_cos();
        let field: Vec<f32> = (0..n * n).flat_map(|_| [tc, ts]).collect();
        let dom = ImageDomain::from_direction_field(n, n, &field, 1.0).unwrap();
        let t = Instant::now();
        let res = fieldtex_synth::synthesize_rotated(
            &analysis,
            &aopts,
            &dom,
            deg.to_radians(),
            copy_scale,
            &opts,
            &NoProgress,
        )
        .unwrap();
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let ob = ev::rgb_buffer(&res.colors);
        let out = ev::ImageView::new(&ob, n, n, 3).unwrap();
        let fv = ev::FieldView::new(&field, n, n).unwrap();
        let gopts = ev::GuidedCoherenceOptions { stride, wrap_exemplar, ..Default::default() };
        let gc = ev::guided_coherence(&out, &ev_ex, &fv, &gopts).unwrap();
        println!(
            "prerotated copy {deg:5.1}° + {residual}°: syn_ms={ms:.0} gc={:.6} (median {:.6})",
            gc.mean, gc.median
        );
        if let Some(dir) = &png {
            std::fs::create_dir_all(dir).unwrap();
            fieldtex_io::write_png(&dir.join(format!("prerot-{deg}.png")), &res.colors).unwrap();
        }
    }
    let fixes: Vec<bool> = if both { vec![true, false] } else { vec![opts.rosy_fix] };
    let mut cases: Vec<Case> = consts
        .iter()
        .map(|&deg| {
            let n = 512;
            let (sn, cs) = deg.to_radians().sin_cos();
            Case {
                name: format!("const{deg}"),
                n,
                field: (0..n * n).flat_map(|_| [cs, sn]).collect(),
                sings: Vec::new(),
            }
        })
        .collect();
    cases.extend(dirs.iter().map(|d| load_case(d)));
    for case in &cases {
        for &fix in &fixes {
            let o = SynthesisOptions { rosy_fix: fix, ..opts.clone() };
            let dom = ImageDomain::from_direction_field(case.n, case.n, &case.field, 1.0).unwrap();
            let mut times = Vec::new();
            let mut res = None;
            for _ in 0..runs.max(1) {
                let t = Instant::now();
                res = Some(synthesize(&analysis, &dom, &o, &NoProgress).unwrap());
                times.push(t.elapsed().as_secs_f64() * 1e3);
            }
            times.sort_by(f64::total_cmp);
            let min_ms = times[0];
            let res = res.unwrap();
            if no_metrics {
                println!(
                    "{:44} fix={} syn_ms={:6.0} min_ms={min_ms:6.0} levels_ms={:?}",
                    case.name,
                    fix as u8,
                    times[times.len() / 2],
                    res.level_timings_ms.iter().map(|t| t.round()).collect::<Vec<_>>()
                );
                continue;
            }
            // Coordinate coherence of horizontal/vertical neighbour pairs: S[q] − S[p] within
            // 0.5 px of the effective frame's offset F(p) δ, F = (−1)^I J; split by whether
            // the representative vectors jump (J(p)·J(q) < 0) between p and q.
            let (mut coh, mut tot, mut jcoh, mut jtot, mut seams) =
                (0usize, 0usize, 0usize, 0usize, 0usize);
            let (ew, eh) = (ex.width as f32, ex.height as f32);
            for y in 0..case.n - 1 {
                for x in 0..case.n - 1 {
                    let p = y * case.n + x;
                    let jp = dom.jacobian[p];
                    let fp = if res.flips[p] { jp.map(|v| -v) } else { jp };
                    for (q, d) in [(p + 1, [1.0f32, 0.0]), (p + case.n, [0.0, 1.0])] {
                        let jq = dom.jacobian[q];
                        let fq = if res.flips[q] { jq.map(|v| -v) } else { jq };
                        let jump = jp[0] * jq[0] + jp[1] * jq[1] < 0.0;
                        if fp[0] * fq[0] + fp[1] * fq[1] < 0.0 {
                            seams += 1;
                        }
                        let off = [fp[0] * d[0] + fp[1] * d[1], fp[2] * d[0] + fp[3] * d[1]];
                        let mut e = [
                            res.coords[q][0] - res.coords[p][0] - off[0],
                            res.coords[q][1] - res.coords[p][1] - off[1],
                        ];
                        e[0] -= (e[0] / ew).round() * ew;
                        e[1] -= (e[1] / eh).round() * eh;
                        let ok = e[0].abs() < 0.5 && e[1].abs() < 0.5;
                        tot += 1;
                        coh += ok as usize;
                        if jump {
                            jtot += 1;
                            jcoh += ok as usize;
                        }
                    }
                }
            }
            println!(
                "  coherent pairs {:.1}%, across representative jumps {:.1}% of {jtot}, effective-frame seams {seams}, flipped samples {:.1}%",
                100.0 * coh as f64 / tot as f64,
                100.0 * jcoh as f64 / jtot.max(1) as f64,
                100.0 * res.flips.iter().filter(|&&f| f).count() as f64 / res.flips.len() as f64
            );
            let ob = ev::rgb_buffer(&res.colors);
            let out = ev::ImageView::new(&ob, case.n, case.n, 3).unwrap();
            let fv = ev::FieldView::new(&case.field, case.n, case.n).unwrap();
            let gopts = ev::GuidedCoherenceOptions { stride, wrap_exemplar, ..Default::default() };
            let gc = ev::guided_coherence(&out, &ev_ex, &fv, &gopts).unwrap();
            let oe_raw = ev::orientation_error(
                &out,
                &ev::OrientationReference::Field(fv),
                &ev::OrientationErrorOptions::default(),
            )
            .unwrap();
            // As `fieldtex orient` reports it: against the field turned by the
            // exemplar's own dominant stripe direction.
            let oe_opts =
                ev::OrientationErrorOptions { exemplar_angle_deg: ex_angle, ..Default::default() };
            let oe = ev::orientation_error(&out, &ev::OrientationReference::Field(fv), &oe_opts)
                .unwrap();
            let pd = ev::phase_defects(&out, &ev::PhaseDefectOptions::default()).unwrap();
            let r = 3.0 * pd.period_px;
            let near = ev::count_defects_near(&pd.defects, &case.sings, r);
            let disc = std::f64::consts::PI * r * r * case.sings.len() as f64;
            let bg = pd.count as f64 * disc / pd.evaluated_pixels.max(1) as f64;
            let need = required_dislocations(case, pd.period_px);
            println!(
                "{:44} fix={} syn_ms={:6.0} gc={:.6} (median {:.6}, p95 {:.6}) oe={:5.2} (raw {:5.2}) defects={:4} near={:3} bg={:5.1} need={:4.1} T={:.1}",
                case.name,
                fix as u8,
                times[times.len() / 2],
                gc.mean,
                gc.median,
                gc.p95,
                oe.mean_error_deg,
                oe_raw.mean_error_deg,
                pd.count,
                near,
                bg,
                need,
                pd.period_px
            );
            if let Some(dir) = &png {
                std::fs::create_dir_all(dir).unwrap();
                let p =
                    dir.join(format!("{}-{}.png", case.name, if fix { "fix" } else { "nofix" }));
                fieldtex_io::write_png(&p, &res.colors).unwrap();
                // Defects marked: red near a designed singularity, green elsewhere;
                // designed singularities as blue squares.
                let mut m = res.colors.clone();
                let mut dot = |x: f64, y: f64, c: [f32; 4], r: i64| {
                    for dy in -r..=r {
                        for dx in -r..=r {
                            let (px, py) = (x as i64 + dx, y as i64 + dy);
                            if px >= 0
                                && py >= 0
                                && (px as usize) < m.width
                                && (py as usize) < m.height
                                && (dx.abs() == r || dy.abs() == r)
                            {
                                m.pixels[py as usize * m.width + px as usize] = c;
                            }
                        }
                    }
                };
                for d in &pd.defects {
                    let near = case
                        .sings
                        .iter()
                        .any(|s| (d.x - s[0]).powi(2) + (d.y - s[1]).powi(2) <= r * r);
                    dot(
                        d.x,
                        d.y,
                        if near { [1.0, 0.0, 0.0, 1.0] } else { [0.0, 0.8, 0.0, 1.0] },
                        3,
                    );
                }
                for s in &case.sings {
                    dot(s[0], s[1], [0.0, 0.3, 1.0, 1.0], 5);
                    dot(s[0], s[1], [0.0, 0.3, 1.0, 1.0], r as i64);
                }
                let tag = if fix { "fix" } else { "nofix" };
                let fimg = Image {
                    width: case.n,
                    height: case.n,
                    pixels: (0..case.n * case.n)
                        .map(|i| {
                            let j = dom.jacobian[i];
                            let a = j[1].atan2(j[0]);
                            let g = 0.35 + 0.3 * a.cos();
                            if res.flips[i] { [1.0, g, g, 1.0] } else { [g, g, 1.0, 1.0] }
                        })
                        .collect(),
                };
                fieldtex_io::write_png(&dir.join(format!("{}-{tag}-flips.png", case.name)), &fimg)
                    .unwrap();
                let p = dir.join(format!("{}-{tag}-marked.png", case.name));
                fieldtex_io::write_png(&p, &m).unwrap();
                // Crops of 96² around each singularity, magnified 3×, side by side.
                let (cs, mag) = (96usize, 3usize);
                let cw = cs * mag * case.sings.len().max(1);
                let mut crop =
                    Image { width: cw, height: cs * mag, pixels: vec![[1.0; 4]; cw * cs * mag] };
                for (si, s) in case.sings.iter().enumerate() {
                    for y in 0..cs * mag {
                        for x in 0..cs * mag {
                            let sx = (s[0] as i64 - cs as i64 / 2 + (x / mag) as i64)
                                .clamp(0, m.width as i64 - 1);
                            let sy = (s[1] as i64 - cs as i64 / 2 + (y / mag) as i64)
                                .clamp(0, m.height as i64 - 1);
                            crop.pixels[y * cw + si * cs * mag + x] =
                                res.colors.pixels[sy as usize * m.width + sx as usize];
                        }
                    }
                }
                fieldtex_io::write_png(&dir.join(format!("{}-{tag}-crops.png", case.name)), &crop)
                    .unwrap();
            }
        }
    }
}
