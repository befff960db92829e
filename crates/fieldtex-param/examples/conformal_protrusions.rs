//! Protrusion probe for genus-0 meshes (issue 13):
//! `cargo run --release -p fieldtex-param --example conformal_protrusions -- MESH...`.
//!
//! Repairs each mesh, runs [`global_conformal`], and for every genus-0 component prints
//! the compressed regions of the two-point slit cylinder (tip vertex, log area scale
//! below the median), the tips that qualify for a slit (rim length in `√area`, slit
//! length in vertices) and what `global_conformal` chose, with the log-area std; for
//! genus ≥ 1 components (which the pipeline keeps on the paper's map) what protrusion
//! slits would give.

#[path = "common/mod.rs"]
mod common;

use fieldtex_param::conformal::global_conformal;
use fieldtex_param::conformal::protrusion_slits::{
    ProtrusionChoice, compressed_tips, protrusion_map, protrusion_tips,
};
use fieldtex_param::conformal::slit_cylinder::slit_cylinder;
use std::time::Instant;

fn main() -> Result<(), String> {
    for path in std::env::args().skip(1) {
        let mesh = common::repaired_mesh(&path)?;
        let scale = fieldtex_mesh::areas::total_area(&mesh).sqrt();
        let t = Instant::now();
        let (comps, _) =
            global_conformal(&mesh, &fieldtex_core::NoProgress).map_err(|e| e.to_string())?;
        let secs = t.elapsed().as_secs_f64();
        for c in comps.iter().filter(|c| c.genus >= 1 && c.has_uv()) {
            let tips = compressed_tips(&c.local_mesh, c.faces.len(), &c.map);
            println!(
                "{path}: component {} genus {} {:?}: {} compressed regions {:?}",
                c.component,
                c.genus,
                c.method,
                tips.len(),
                tips
            );
            // What slits would give (the pipeline keeps genus ≥ 1 on the paper's map).
            if c.double_cover_genus.is_none() {
                match protrusion_map(
                    &c.local_mesh,
                    c.faces.len(),
                    c.genus,
                    [None, None],
                    &Default::default(),
                ) {
                    Ok(ProtrusionChoice::Slits { cut, map, .. }) => println!(
                        "  with slits at {:?}: log-area std {:.3} (plain {:.3}), {} zero points",
                        cut.tips,
                        map.1,
                        map.2,
                        map.0.zero_points.len()
                    ),
                    Ok(_) => println!("  slits would not lower the log-area std"),
                    Err(e) => println!("  {e}"),
                }
            }
        }
        for c in comps.iter().filter(|c| c.genus == 0) {
            let n = c.faces.len();
            println!("{path}: component {} ({n} faces), {:?}, {secs:.2} s", c.component, c.method);
            if let Some(p) = &c.protrusion_slits {
                println!(
                    "  protrusion tips {:?}: log-area std {:.3} (two-point cylinder {:.3}), double cover genus {:?}",
                    p.tips, p.log_area_std, p.cylinder_log_area_std, c.double_cover_genus
                );
            }
            // Details for cylinder components (their local mesh is the capped mesh).
            if c.double_cover_genus.is_some() {
                continue;
            }
            if let Ok(cyl) = slit_cylinder(&c.local_mesh, [None, None]) {
                for (t, s) in compressed_tips(&c.local_mesh, n, &cyl) {
                    println!("  compressed tip {t}: log area scale {s:.2} below the median");
                }
                let (tips, paths, rims) = protrusion_tips(&c.local_mesh, n, &cyl);
                for ((t, r), p) in tips.iter().zip(&rims).zip(&paths) {
                    println!("  slit at {t}: rim {:.4} √area, {} vertices", r / scale, p.len());
                }
            }
        }
    }
    Ok(())
}
