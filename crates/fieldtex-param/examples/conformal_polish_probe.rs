//! Conformal polish probe (issue 13): `cargo run --release -p fieldtex-param --example
//! conformal_polish_probe -- [--weight W]... MESH...`.
//!
//! Repairs each mesh, runs [`global_conformal`] and, for every component with a slit
//! cylinder or a patch layout, polishes a copy of its map at each data weight (default:
//! [`POLISH_WEIGHT`]) regardless of the threshold, printing the mean `σ1/σ2` away from
//! singularities and over all non-slit faces, the log-area std and the folds before and
//! after, and the time.

use fieldtex_param::conformal::conformal_polish::{POLISH_WEIGHT, PolishOptions};
use fieldtex_param::conformal::global_conformal;
use std::time::Instant;

fn main() -> Result<(), String> {
    let mut weights = Vec::new();
    let mut meshes = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--weight" {
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
        let mesh =
            fieldtex_io::read_mesh(std::path::Path::new(&path)).map_err(|e| e.to_string())?.mesh;
        let mesh = fieldtex_mesh::repair(&mesh, &Default::default()).mesh;
        let (comps, _) =
            global_conformal(&mesh, &fieldtex_core::NoProgress).map_err(|e| e.to_string())?;
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
            }
        }
    }
    Ok(())
}
