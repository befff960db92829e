//! Conformal polish probe (issue 13): `cargo run --release -p fieldtex-param --example
//! conformal_polish_probe -- [--weight W]... MESH...`.
//!
//! Repairs each mesh, runs `fieldtex_param::conformal::global_conformal` and, for every component with a slit
//! cylinder or a patch layout, polishes a copy of its map at each data weight (default:
//! [`POLISH_WEIGHT`]) regardless of the threshold, printing the mean `σ1/σ2` away from
//! singularities and over all non-slit faces, the log-area std and the folds before and
//! after, and the time. `--histogram` adds, for the polished map, the area-weighted
//! 50th / 90th / 99th percentiles of `σ1/σ2` away from singularities and the share of
//! the excess `σ1/σ2 − 1` carried by the worst 5 % of that area.

#[path = "common/mod.rs"]
mod common;

use fieldtex_param::conformal::conformal_polish::{POLISH_WEIGHT, PolishOptions};
use std::time::Instant;

fn main() -> Result<(), String> {
    let mut weights = Vec::new();
    let mut meshes = Vec::new();
    let mut histogram = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--histogram" {
            histogram = true;
        } else if a == "--weight" {
            let w = args.next().and_then(|w| w.parse().ok()).ok_or("--weight needs a number")?;
            weights.push(w);
        } else {
            meshes.push(a);
        }
    }
    if weights.is_empty() {
        weights.push(POLISH_WEIGHT);
    }
    for path in meshes {
        let (_, comps) = common::mapped(&path)?;
        for c in &comps {
            for &weight in &weights {
                let mut p = c.clone();
                let t = Instant::now();
                let Some(s) = p.polish_conformal(&PolishOptions { weight, above: 0.0 }) else {
                    continue;
                };
                println!(
                    "{path} component {} {:?} weight {weight:e}: {} charts ({} kept), applied {}; \
                     away {:.4} -> {:.4}, all {:.4} -> {:.4}, log-area std {:.3} -> {:.3}, \
                     folds {} -> {}, {:.2} s",
                    c.component,
                    c.method,
                    s.charts,
                    s.charts_kept,
                    s.applied,
                    s.away_before,
                    s.away_after,
                    s.before.angle_mean,
                    s.after.angle_mean,
                    s.before.log_area_std,
                    s.after.log_area_std,
                    s.before.flipped,
                    s.after.flipped,
                    t.elapsed().as_secs_f64()
                );
                if histogram {
                    print_histogram(&p);
                }
            }
        }
    }
    Ok(())
}

/// Area-weighted percentiles of `σ1/σ2` away from singularities and the share of the
/// excess carried by the worst 5 % of the area.
fn print_histogram(c: &fieldtex_param::conformal::ConformalComponent) {
    let mut rows: Vec<(f64, f64)> = (0..c.faces.len())
        .filter(|&f| !c.near_singularity[f])
        .filter_map(|f| {
            let (s1, s2, _, a3) = fieldtex_param::distortion::triangle_jacobian(
                c.local_mesh.triangle_positions(f),
                c.corner_uv[f],
                0.0,
            )?;
            let r = s1 / s2;
            r.is_finite().then_some((r, a3))
        })
        .collect();
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = rows.iter().map(|r| r.1).sum();
    let excess: f64 = rows.iter().map(|r| r.1 * (r.0 - 1.0)).sum();
    let pct = |q: f64| {
        let mut acc = 0.0;
        for r in &rows {
            acc += r.1;
            if acc >= q * total {
                return r.0;
            }
        }
        f64::NAN
    };
    let (mut acc, mut top) = (0.0, 0.0);
    for r in rows.iter().rev() {
        if acc >= 0.05 * total {
            break;
        }
        acc += r.1;
        top += r.1 * (r.0 - 1.0);
    }
    println!(
        "    σ1/σ2 away: p50 {:.4} p90 {:.4} p99 {:.4}; worst 5 % of the area carries {:.0} % of the excess",
        pct(0.5),
        pct(0.9),
        pct(0.99),
        100.0 * top / excess.max(f64::MIN_POSITIVE)
    );
}
