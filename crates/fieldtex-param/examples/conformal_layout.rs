//! Patch-layout probe for closed genus ≥ 2 meshes (issue 13):
//! `cargo run --release -p fieldtex-param --example conformal_layout -- MESH.obj GENUS
//! [TRAJECTORY_LENGTH] [PIECE_SIDE] [MERGE: 0|1] [LOOPS: 0|1] [SPANNING: 0|1]`.
//!
//! Runs [`holomorphic_map_with`] on a plain `v`/`f` triangle OBJ and prints the patch
//! count, small patches, folded faces, the 3-D seam length (edges whose two faces
//! disagree on a corner) relative to `√area`, the packing efficiency (UV area over the
//! packed bounding box) and the layout time. The seam length is split into the part on
//! snapped critical trajectories, on shortest homology loops (not trajectories) and
//! elsewhere (fronts where a patch met itself, overlap-guard and folded-face charts). No texture, no metrics of the pipeline:
//! a quick way to compare layout choices before running `bench/conformal_bench.sh`.

use fieldtex_core::vec3;
use fieldtex_mesh::{Topology, TriMesh};
use fieldtex_param::conformal::holomorphic_map::{
    HOMOLOGY_LOOPS, LayoutOptions, PIECE_SIDE, SPANNING_CUT, TRAJECTORY_LENGTH,
    holomorphic_map_with,
};
use fieldtex_param::conformal::periodic_uv::signed_area;
use std::time::Instant;

fn load_mesh(path: &str) -> Result<TriMesh, String> {
    fieldtex_io::read_mesh(std::path::Path::new(path)).map(|l| l.mesh).map_err(|e| e.to_string())
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args.first().ok_or("usage: conformal_layout MESH.obj GENUS [TRAJ] [PIECE]")?;
    let genus: usize = args.get(1).and_then(|s| s.parse().ok()).ok_or("GENUS")?;
    let traj = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(TRAJECTORY_LENGTH);
    let piece = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(PIECE_SIDE);
    let merge = args.get(4).is_none_or(|s| s != "0");
    let loops = args.get(5).map_or(HOMOLOGY_LOOPS, |s| s != "0");
    let mesh = load_mesh(path)?;
    let nf = mesh.n_triangles();
    let t = Instant::now();
    let spanning = args.get(6).map_or(SPANNING_CUT, |s| s != "0");
    let options = LayoutOptions {
        trajectory_length: traj,
        piece_side: piece,
        merge,
        homology_loops: loops,
        spanning_cut: spanning,
    };
    let map = holomorphic_map_with(&mesh, genus, nf, &options).map_err(|e| e.to_string())?;
    let secs = t.elapsed().as_secs_f64();
    let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
    let uv = |f: usize, v: u32| map.corner[f][(0..3).find(|&k| mesh.triangles[f][k] == v).unwrap()];
    let (mut seam, mut area, mut uv_area) = (0.0, 0.0, 0.0);
    let (mut on_traj, mut on_loop) = (0.0, 0.0);
    let flag = |v: &[bool], e: usize| v.get(e).is_some_and(|&c| c);
    let mut n_seam = 0;
    for e in 0..topo.n_edges() {
        let fs = topo.edge_faces(e);
        if fs.len() != 2 {
            continue;
        }
        let [a, b] = topo.edges[e];
        let (f, g) = (fs[0] as usize, fs[1] as usize);
        let d = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).abs() + (p[1] - q[1]).abs();
        if d(uv(f, a), uv(g, a)) + d(uv(f, b), uv(g, b)) > 1e-9 {
            n_seam += 1;
            let len = vec3::norm(vec3::sub(mesh.positions[b as usize], mesh.positions[a as usize]));
            seam += len;
            if flag(&map.trajectory_cut, e) {
                on_traj += len;
            } else if flag(&map.loop_cut, e) {
                on_loop += len;
            }
        }
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    let mut flipped = 0;
    for f in 0..nf {
        let p = mesh.triangle_positions(f);
        area += 0.5 * vec3::norm(vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0])));
        let s = signed_area(&map.corner[f]);
        flipped += usize::from(s <= 0.0);
        uv_area += s.abs();
        for q in &map.corner[f] {
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
    }
    let n_patches = map.patch.iter().map(|&p| p as usize + 1).max().unwrap_or(0);
    println!(
        "LAYOUT traj {traj} piece {piece} merge {merge} loops {loops}: patches {n_patches} (merges {}) small {} \
         folded {} flipped {flipped} \
         seam edges {n_seam} length {seam:.4} = {:.3} sqrt(area) (trajectories {:.3}, loops {:.3}, \
         elsewhere {:.3}); packing {:.3}; {secs:.2} s",
        map.patch_merges,
        map.small_patches,
        map.folded_faces,
        seam / area.sqrt(),
        on_traj / area.sqrt(),
        on_loop / area.sqrt(),
        (seam - on_traj - on_loop) / area.sqrt(),
        uv_area / ((hi[0] - lo[0]) * (hi[1] - lo[1])),
    );
    Ok(())
}
