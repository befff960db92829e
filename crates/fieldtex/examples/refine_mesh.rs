//! Writes a mesh refined by midpoint subdivision (each level ×4 triangles), for
//! benchmarks on large inputs.
//!
//! `cargo run --release -p fieldtex --example refine_mesh -- IN OUT.obj [LEVELS=1]`

use fieldtex::crates::{io, mesh};
use std::path::PathBuf;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        eprintln!("usage: refine_mesh IN OUT.obj [LEVELS]");
        std::process::exit(2);
    }
    let levels: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let loaded = match io::read_mesh(&PathBuf::from(&args[0])) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let mut m = mesh::TriMesh::new(loaded.mesh.positions, loaded.mesh.triangles);
    for _ in 0..levels {
        m = mesh::primitives::subdivide_midpoint(&m);
    }
    if let Err(e) = io::write_obj(&PathBuf::from(&args[1]), &m, None) {
        eprintln!("{e}");
        std::process::exit(2);
    }
    println!("{} vertices, {} triangles", m.n_vertices(), m.n_triangles());
}
