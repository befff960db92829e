//! Benchmark of paper A §4 (greedy curve orientation + harmonic diffusion with rank-1
//! updates) against arbitrary orientations.
//!
//! ```text
//! cargo run --release -p fieldtex-fields --example bench_orientation -- \
//!     [MESH.obj|.ply] [--refine] [--curves C.obj | --sharp] [--seeds 20] [--runs 3]
//!     [--crest-before-refine] [--batch 0.9] [--name NAME]
//! ```
//! Default mesh: `shared/data/meshes/fandisk.obj`. Curves: the polylines (`l` elements)
//! of `--curves`; with `--sharp`, plain sharp-edge chains (dihedral angle > 30°, broken
//! at turns > 60°, more than 3 edges; a private stand-in kept for comparison); otherwise
//! every crest line of `fieldtex_features::crest_lines` with default options (timed
//! separately, not part of the orientation time). `--crest-before-refine` detects the
//! curves on the input mesh and orients them on the refined one (midpoint subdivision
//! does not change the shape, but its flat triangles add spurious curvature extrema).
//!
//! Prints `BENCH orient_<name>_{greedy,arbitrary}_{singularities,dirichlet} value=..`
//! (arbitrary: median over the seeds), `BENCH orient_<name>_total median_ms=..` (whole
//! greedy procedure, median over runs), `..._update_ms` (rank-1 updates of one step,
//! median over steps), `..._refactor_ms` (numeric refactorisation of the final `L + P`
//! with the kept symbolic analysis, median of 3), the same for the batched greedy
//! (`--batch τ`, default 0.9; 0 skips it) as `..._batched_*`, and `INFO` lines.

use std::path::{Path, PathBuf};
use std::time::Instant;

use fieldtex_core::NoProgress;
use fieldtex_core::vec3::{self, V3};
use fieldtex_fields::{
    CurveOrientationOptions, OrientationMode, orient_curves, surface_field_metrics,
};
use fieldtex_mesh::primitives::subdivide_midpoint;
use fieldtex_mesh::{Topology, TriMesh, face_normals};

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) }
}

/// Chains of edges whose dihedral angle exceeds `min_angle_deg`, broken at vertices of
/// sharp-degree ≠ 2 and at turns sharper than `max_turn_deg`, kept if ≥ `min_edges` long.
/// Runs `f` `runs` times (at least once); the wall times in ms and the last result.
fn timed_runs<T>(runs: usize, mut f: impl FnMut() -> T) -> (Vec<f64>, T) {
    let mut totals = Vec::new();
    let mut last = None;
    for _ in 0..runs.max(1) {
        let t0 = Instant::now();
        let r = f();
        totals.push(1e3 * t0.elapsed().as_secs_f64());
        last = Some(r);
    }
    (totals, last.expect("at least one run"))
}

fn sharp_edge_chains(
    mesh: &TriMesh,
    min_angle_deg: f64,
    max_turn_deg: f64,
    min_edges: usize,
) -> Vec<Vec<V3>> {
    let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
    let fnorm = face_normals(mesh);
    let cos_min = min_angle_deg.to_radians().cos();
    let sharp: Vec<bool> = (0..topo.n_edges())
        .map(|e| {
            let f = topo.edge_faces(e);
            let [a, b] = topo.edges[e];
            f.len() == 2 && a != b && {
                let (n0, n1) = (fnorm[f[0] as usize], fnorm[f[1] as usize]);
                n0 != [0.0; 3] && n1 != [0.0; 3] && vec3::dot(n0, n1) < cos_min
            }
        })
        .collect();
    let mut adj: Vec<Vec<(u32, usize)>> = vec![Vec::new(); mesh.n_vertices()];
    for (e, &[a, b]) in topo.edges.iter().enumerate() {
        if sharp[e] {
            adj[a as usize].push((b, e));
            adj[b as usize].push((a, e));
        }
    }
    let mut used = vec![false; topo.n_edges()];
    let mut chains: Vec<Vec<u32>> = Vec::new();
    let mut walk = |start: u32, used: &mut Vec<bool>| {
        while let Some(&(next, e)) = adj[start as usize].iter().find(|(_, e)| !used[*e]) {
            used[e] = true;
            let mut chain = vec![start, next];
            let mut cur = next;
            while adj[cur as usize].len() == 2 {
                let Some(&(n, e2)) = adj[cur as usize].iter().find(|(_, e)| !used[*e]) else {
                    break;
                };
                used[e2] = true;
                chain.push(n);
                cur = n;
            }
            chains.push(chain);
        }
    };
    for v in 0..mesh.n_vertices() as u32 {
        if !adj[v as usize].is_empty() && adj[v as usize].len() != 2 {
            walk(v, &mut used);
        }
    }
    for v in 0..mesh.n_vertices() as u32 {
        walk(v, &mut used); // closed loops
    }
    let cos_turn = max_turn_deg.to_radians().cos();
    let p = &mesh.positions;
    let mut out = Vec::new();
    for chain in chains {
        let mut piece = vec![chain[0]];
        for k in 1..chain.len() {
            piece.push(chain[k]);
            if k + 1 < chain.len() {
                let d0 = vec3::normalize(vec3::sub(p[chain[k] as usize], p[chain[k - 1] as usize]));
                let d1 = vec3::normalize(vec3::sub(p[chain[k + 1] as usize], p[chain[k] as usize]));
                if let (Some(d0), Some(d1)) = (d0, d1)
                    && vec3::dot(d0, d1) < cos_turn
                {
                    out.push(std::mem::replace(&mut piece, vec![chain[k]]));
                }
            }
        }
        out.push(piece);
    }
    out.into_iter()
        .filter(|c| c.len() > min_edges)
        .map(|c| c.iter().map(|&v| p[v as usize]).collect())
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut mesh_path: Option<PathBuf> = None;
    let (mut refine, mut curves_path, mut seeds, mut runs, mut name) =
        (false, None, 20u64, 3, None);
    let mut sharp = false;
    let mut crest_before_refine = false;
    let mut batch = 0.9;
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--refine" => refine = true,
            "--sharp" => sharp = true,
            "--crest-before-refine" => crest_before_refine = true,
            "--curves" => {
                i += 1;
                curves_path = Some(PathBuf::from(&args[i]));
            }
            "--seeds" => {
                i += 1;
                seeds = args[i].parse().expect("--seeds N");
            }
            "--runs" => {
                i += 1;
                runs = args[i].parse().expect("--runs N");
            }
            "--batch" => {
                i += 1;
                batch = args[i].parse().expect("--batch TAU (0 disables)");
            }
            "--name" => {
                i += 1;
                name = Some(args[i].clone());
            }
            a => mesh_path = Some(PathBuf::from(a)),
        }
        i += 1;
    }
    let mesh_path = mesh_path.unwrap_or_else(|| {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/meshes/fandisk.obj")
    });
    let mut name = name.unwrap_or_else(|| {
        mesh_path.file_stem().map_or("mesh".into(), |s| s.to_string_lossy().replace('-', "_"))
    });
    let mut mesh = fieldtex_io::read_mesh(&mesh_path).expect("read mesh").mesh;
    let detect = |mesh: &TriMesh| {
        let t_curves = Instant::now();
        let (curves, source) = match &curves_path {
            Some(p) => (fieldtex_io::read_obj_polylines(p).expect("read curves"), "file"),
            None if sharp => (sharp_edge_chains(mesh, 30.0, 60.0, 3), "sharp-edge chains"),
            None => {
                let crest = fieldtex_features::crest_lines(
                    mesh,
                    &fieldtex_features::CrestOptions::default(),
                )
                .expect("crest lines");
                (crest.lines.into_iter().map(|l| l.points).collect(), "crest lines")
            }
        };
        (curves, source, 1e3 * t_curves.elapsed().as_secs_f64())
    };
    let mut detected = None;
    if refine {
        if crest_before_refine {
            detected = Some(detect(&mesh));
            name.push_str("_coarse_crest");
        }
        mesh = subdivide_midpoint(&mesh);
        name.push_str("_refined");
    }
    let (curves, source, curves_ms) = detected.unwrap_or_else(|| detect(&mesh));
    println!(
        "INFO mesh={name} vertices={} triangles={} curves={} ({source}, {curves_ms:.0} ms) threads={}",
        mesh.n_vertices(),
        mesh.n_triangles(),
        curves.len(),
        rayon::current_num_threads()
    );

    // Greedy: `runs` timed runs; metrics from the last.
    let options = CurveOrientationOptions::default();
    let (totals, r) = timed_runs(runs, || {
        orient_curves(&mesh, &curves, &options, &NoProgress).expect("greedy orientation")
    });
    let t_metrics = Instant::now();
    let m =
        surface_field_metrics(&mesh, &r.field.vectors, &r.solver.constraints()).expect("metrics");
    let metrics_ms = 1e3 * t_metrics.elapsed().as_secs_f64();
    let steps = &r.steps;
    let later: Vec<_> =
        steps.iter().filter(|s| s.factor_ms == 0.0 && s.new_constraints > 0).collect();
    let update_ms = median(later.iter().map(|s| s.update_ms).collect());
    let per_rank1 = later.iter().map(|s| s.update_ms).sum::<f64>()
        / later.iter().map(|s| s.new_constraints).sum::<usize>().max(1) as f64;
    let solve_ms = median(steps.iter().map(|s| s.solve_ms).collect());
    let factor_ms: f64 = steps.iter().map(|s| s.factor_ms).sum();
    let constrained = r.solver.constraints().len();
    let sum_update: f64 = steps.iter().map(|s| s.update_ms).sum();
    let sum_solve: f64 = steps.iter().map(|s| s.solve_ms).sum();
    println!(
        "INFO greedy_breakdown_ms total={:.0} factor={factor_ms:.0} updates={sum_update:.0} solves={sum_solve:.0} other={:.0}",
        r.total_ms,
        r.total_ms - factor_ms - sum_update - sum_solve
    );
    let mut refactor = Vec::new();
    let mut rel_diff = 0.0f64;
    for _ in 0..3 {
        let (fresh, secs) = r.solver.refactored_solution().expect("refactor");
        refactor.push(1e3 * secs);
        let scale = fresh.iter().map(|v| vec3::norm(*v)).fold(0.0, f64::max).max(1e-300);
        for (a, b) in r.solver.raw_solution().iter().zip(&fresh) {
            rel_diff = rel_diff.max(vec3::norm(vec3::sub(*a, *b)) / scale);
        }
    }
    let refactor_ms = median(refactor);
    let chi = m.euler_characteristic;
    println!(
        "INFO steps={} constrained_vertices={constrained} first_factor_ms={factor_ms:.1} solve_median_ms={solve_ms:.2} \
         rank1_update_ms={per_rank1:.3} max_residual={:.1e} updated_vs_refactored_rel_diff={rel_diff:.1e}",
        steps.len(),
        steps.iter().map(|s| s.residual).fold(0.0, f64::max)
    );
    println!(
        "INFO greedy index_sum={} chi={chi} undetermined_faces={} alignment_mean_deg={:.3} dirichlet_ambient={:.4} metrics_ms={metrics_ms:.1}",
        m.index_sum, m.undetermined_faces, m.alignment.mean_deg, m.dirichlet_energy_ambient
    );
    let mut ratios: Vec<f64> = later.iter().map(|s| refactor_ms / s.update_ms.max(1e-9)).collect();
    ratios.sort_by(f64::total_cmp);
    if !ratios.is_empty() {
        println!(
            "INFO refactor_over_step_update min={:.1} median={:.1} refactor_over_rank1={:.0} steps_below_10x={} max_step_update_ms={:.1}",
            ratios[0],
            median(ratios.clone()),
            refactor_ms / per_rank1.max(1e-9),
            ratios.iter().filter(|&&x| x < 10.0).count(),
            later.iter().map(|s| s.update_ms).fold(0.0, f64::max)
        );
    }

    // Batched greedy (not in the paper): same measures, and agreement with the exact one.
    if batch > 0.0 {
        let o = CurveOrientationOptions { batch_consistency: Some(batch), ..Default::default() };
        let (totals, b) = timed_runs(runs, || {
            orient_curves(&mesh, &curves, &o, &NoProgress).expect("batched greedy")
        });
        let mb = surface_field_metrics(&mesh, &b.field.vectors, &b.solver.constraints())
            .expect("metrics");
        let same = b.signs.iter().zip(&r.signs).filter(|(x, y)| x == y).count();
        let rounds = b.steps.last().map_or(0, |s| s.round + 1);
        println!(
            "INFO batched tau={batch} rounds={rounds} same_signs={same}/{} index_sum={}",
            b.signs.len(),
            mb.index_sum
        );
        println!("BENCH orient_{name}_batched_singularities value={}", mb.singularities.len());
        println!("BENCH orient_{name}_batched_dirichlet value={:.4}", mb.dirichlet_energy);
        println!("BENCH orient_{name}_batched_total median_ms={:.1}", median(totals));
    }

    // Arbitrary orientations: median over seeds.
    let (mut sing, mut dir) = (Vec::new(), Vec::new());
    for seed in 0..seeds {
        let o = CurveOrientationOptions {
            mode: OrientationMode::Arbitrary { seed },
            ..Default::default()
        };
        let a = orient_curves(&mesh, &curves, &o, &NoProgress).expect("arbitrary orientation");
        let ma = surface_field_metrics(&mesh, &a.field.vectors, &a.solver.constraints())
            .expect("metrics");
        sing.push(ma.singularities.len() as f64);
        dir.push(ma.dirichlet_energy);
    }
    let worst = sing.iter().copied().fold(0.0, f64::max);
    println!("INFO arbitrary seeds={seeds} worst_singularities={worst}");
    println!("BENCH orient_{name}_greedy_singularities value={}", m.singularities.len());
    println!("BENCH orient_{name}_arbitrary_singularities value={}", median(sing));
    println!("BENCH orient_{name}_greedy_dirichlet value={:.4}", m.dirichlet_energy);
    println!("BENCH orient_{name}_arbitrary_dirichlet value={:.4}", median(dir));
    println!("BENCH orient_{name}_total median_ms={:.1}", median(totals));
    println!("BENCH orient_{name}_update_ms median_ms={update_ms:.3}");
    println!("BENCH orient_{name}_refactor_ms median_ms={refactor_ms:.1}");
}
