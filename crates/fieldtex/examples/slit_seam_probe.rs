//! Seam colour jump on the slits of a protrusion-slit layout against the other seams
//! (issue 13): `cargo run --release -p fieldtex --example slit_seam_probe -- MESH
//! OUT/model.glb`, where `OUT` is a `fieldtex conformal --mesh MESH` output.
//!
//! Recomputes the map of MESH (repaired as the pipeline does) for its slit paths, reads
//! the GLB back (vertices welded by the default repair), and prints
//! [`fieldtex_eval::seam_metrics::seam_metrics_where`] for the seam edges on a slit and
//! for the rest.

use fieldtex_eval::seam_metrics::seam_metrics_where;
use std::collections::HashSet;

fn key(p: [f64; 3]) -> [u32; 3] {
    p.map(|x| (x as f32).to_bits())
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [mesh_path, glb_path] = args.as_slice() else {
        return Err("usage: slit_seam_probe MESH MODEL.glb".into());
    };
    let read = |p: &str| fieldtex_io::read_mesh(std::path::Path::new(p)).map_err(|e| e.to_string());
    let input = fieldtex_mesh::repair(&read(mesh_path)?.mesh, &Default::default()).mesh;
    let (comps, _) =
        fieldtex_param::conformal::global_conformal(&input, &fieldtex_core::NoProgress)
            .map_err(|e| e.to_string())?;
    let mut slit_edges: HashSet<([u32; 3], [u32; 3])> = HashSet::new();
    for c in &comps {
        for path in c.protrusion_slits.iter().flat_map(|p| &p.slit_paths) {
            for w in path.windows(2) {
                let (a, b) =
                    (key(input.positions[w[0] as usize]), key(input.positions[w[1] as usize]));
                slit_edges.insert((a, b));
                slit_edges.insert((b, a));
            }
        }
    }
    let loaded = read(glb_path)?;
    let tex = loaded.base_color.ok_or("the GLB has no texture")?;
    let glb = fieldtex_mesh::repair(&loaded.mesh, &Default::default()).mesh;
    let on_slit = |[a, b]: [u32; 2]| {
        slit_edges.contains(&(key(glb.positions[a as usize]), key(glb.positions[b as usize])))
    };
    let slit = seam_metrics_where(&glb, &tex, &on_slit).ok_or("no UVs")?;
    let rest = seam_metrics_where(&glb, &tex, &|e| !on_slit(e)).ok_or("no UVs")?;
    println!("slit edges in the input: {}", slit_edges.len() / 2);
    println!(
        "on slits:  {} seam edges, jump {:.4}, ratio {:.2}",
        slit.seam_edges, slit.seam_colour_jump, slit.ratio
    );
    println!(
        "elsewhere: {} seam edges, jump {:.4}, ratio {:.2}",
        rest.seam_edges, rest.seam_colour_jump, rest.ratio
    );
    Ok(())
}
