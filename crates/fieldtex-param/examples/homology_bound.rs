//! How long the cut of a closed surface's handles must be (issue 13's seam target on
//! fertility): `homology_bound MESH [ROOTS=400] [ATLAS_SEAM]`.
//!
//! Prints the total edge length of the shortest homology basis found by pooling the
//! greedy loop systems (Erickson & Whittlesey 2005) of `ROOTS` evenly spaced base
//! vertices (`homology_loops::shortest_homology_basis`), the shortest single loop
//! system (loops through one base point plus their shared stems), both in mesh units
//! and in √area, and, with `ATLAS_SEAM` (the 3-D seam length of `fieldtex atlas` on the
//! mesh), their ratio to it. Any layout whose charts are disks or cylinders without
//! handles cuts every handle, so its seams hold `2g` loops spanning the homology; the
//! basis is the shortest such set of cycles found here (an estimate of that length, not
//! a proven lower bound of a cut graph, whose cycles may share edges).

mod common;

use fieldtex_mesh::Topology;
use fieldtex_param::conformal::homology_loops::{shortest_homology_basis, shortest_loop_system};
use fieldtex_param::conformal::tree_cotree::tree_cotree;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first() else {
        eprintln!("usage: homology_bound MESH [ROOTS=400] [ATLAS_SEAM]");
        std::process::exit(2);
    };
    let n_roots: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(400);
    let atlas: Option<f64> = args.get(2).and_then(|s| s.parse().ok());
    let mesh = match common::repaired_mesh(path) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
    let tc = tree_cotree(&topo);
    let g2 = tc.generators.len();
    let cocycles: Vec<Vec<f64>> =
        tc.generators.iter().map(|&g| tc.dual_loop_form(&topo, g)).collect();
    let area: f64 = (0..mesh.n_triangles())
        .map(|f| {
            let p = mesh.triangle_positions(f);
            0.5 * fieldtex_core::vec3::norm(fieldtex_core::vec3::cross(
                fieldtex_core::vec3::sub(p[1], p[0]),
                fieldtex_core::vec3::sub(p[2], p[0]),
            ))
        })
        .sum();
    let nv = mesh.n_vertices() as u32;
    let step = (nv as usize / n_roots.max(1)).max(1);
    let roots: Vec<u32> = (0..nv).step_by(step).collect();
    let show = |name: &str, len: f64| {
        let rel = atlas.map_or(String::new(), |a| format!(", {:.3}× the atlas's seams", len / a));
        println!("{path}: {name} {len:.4} ({:.3} √area{rel})", len / area.sqrt());
    };
    println!("{path}: {g2} homology generators (genus {}), {} base vertices", g2 / 2, roots.len());
    if let Some(b) = shortest_homology_basis(&mesh.positions, &topo, &cocycles, &roots) {
        show("shortest homology basis (pooled loops)", b.length);
        let each: Vec<String> = b.loops.iter().map(|l| format!("{:.1}", l.1)).collect();
        println!("{path}: loop lengths [{}]", each.join(", "));
    }
    if let Some(s) = shortest_loop_system(&mesh.positions, &topo, &roots) {
        show("shortest loop system (one base point, stems counted once)", s.length);
    }
}
