//! Protrusion probe for genus-0 meshes (issue 13):
//! `cargo run --release -p fieldtex-param --example conformal_protrusions -- MESH...`.
//!
//! Repairs each mesh, runs [`global_conformal`], and for every genus-0 component prints
//! the compressed regions of the two-point slit cylinder (tip vertex, log area scale
//! below the median), the tips that qualify for a slit (rim length in `√area`, slit
//! length in vertices) and what `global_conformal` chose, with the log-area std.

use fieldtex_param::conformal::global_conformal;
use fieldtex_param::conformal::protrusion_slits::{compressed_tips, protrusion_tips};
use fieldtex_param::conformal::slit_cylinder::slit_cylinder;
use std::time::Instant;

fn main() -> Result<(), String> {
    for path in std::env::args().skip(1) {
        let mesh =
            fieldtex_io::read_mesh(std::path::Path::new(&path)).map_err(|e| e.to_string())?.mesh;
        let mesh = fieldtex_mesh::repair(&mesh, &Default::default()).mesh;
        let scale = fieldtex_mesh::areas::total_area(&mesh).sqrt();
        let t = Instant::now();
        let (comps, _) =
            global_conformal(&mesh, &fieldtex_core::NoProgress).map_err(|e| e.to_string())?;
        let secs = t.elapsed().as_secs_f64();
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
