//! Speed of the 12 transfer descriptors on one mesh (issue 14: < 20 s at 512K samples):
//! times the level-0 sampling, the directional occlusion on the descriptor point set and
//! the whole `compute_descriptors` call (analytic solid angle on per-radius point sets
//! included), and measures the solid angle's interpolation error against exact values
//! at every 128th level-0 sample.
//!
//! Usage: `bench_descriptors MESH [--samples N] [--runs R]`; prints medians (wall ms).

use fieldtex::NoProgress;
use fieldtex::crates::{io, mesh, transfer};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn j_min(v: &[f64], k: usize) -> f64 {
    v.iter().skip(k).step_by(4).copied().fold(f64::INFINITY, f64::min)
}

fn j_max(v: &[f64], k: usize) -> f64 {
    v.iter().skip(k).step_by(4).copied().fold(f64::NEG_INFINITY, f64::max)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("usage: bench_descriptors MESH [--samples N] [--runs R]");
    let mut samples = 512_000usize;
    let mut runs = 3usize;
    let mut i = 2;
    while i + 1 < args.len() {
        match args[i].as_str() {
            "--samples" => samples = args[i + 1].parse().expect("--samples N"),
            "--runs" => runs = args[i + 1].parse().expect("--runs R"),
            other => panic!("unknown option {other}"),
        }
        i += 2;
    }
    let m = io::read_mesh(std::path::Path::new(path)).expect("read mesh").mesh;
    let opts = transfer::DescriptorOptions::default();
    let diag = m.bounding_box().expect("non-empty").diagonal();
    let radii: Vec<f64> = opts.radii.iter().map(|r| r * diag).collect();
    let mut w = Vec::new();
    let (mut ts, mut tdo, mut tall) = (vec![], vec![], vec![]);
    for run in 0..runs {
        let t0 = Instant::now();
        let level0 = transfer::sample_surface(&m, samples, run as u64, "mesh", &mut w).unwrap();
        ts.push(t0.elapsed().as_secs_f64() * 1e3);
        let coarse = transfer::sample_surface(&m, opts.samples, 7, "mesh", &mut w).unwrap();
        let bvh = mesh::Bvh::build(&m).unwrap();
        let pts: Vec<mesh::OrientedPoint> = coarse
            .positions
            .iter()
            .zip(&coarse.face_normals)
            .map(|(&position, &normal)| mesh::OrientedPoint { position, normal })
            .collect();
        let t0 = Instant::now();
        let sh = mesh::directional_occlusion_sh(
            &bvh,
            &pts,
            &mesh::DirectionalOcclusionOptions { epsilon: 1e-4 * diag, ..Default::default() },
        );
        tdo.push(t0.elapsed().as_secs_f64() * 1e3);
        let t0 = Instant::now();
        let d = transfer::compute_descriptors(&m, &level0, &opts, 1, "mesh", &NoProgress, &mut w)
            .unwrap();
        tall.push(t0.elapsed().as_secs_f64() * 1e3);
        assert_eq!(d.len(), level0.len() * transfer::N_DESCRIPTORS);
        if run == 0 {
            // Accuracy of the per-radius evaluation sets: exact values at every 128th
            // level-0 sample against the interpolated descriptor columns.
            let idx: Vec<usize> = (0..level0.len()).step_by(128).collect();
            let pts: Vec<[f64; 3]> = idx.iter().map(|&i| level0.positions[i]).collect();
            let exact = mesh::solid_angle_curvature(&m, &pts, &radii).unwrap();
            for k in 0..4 {
                let errs: Vec<f64> = idx
                    .iter()
                    .enumerate()
                    .map(|(j, &i)| {
                        (d[i * transfer::N_DESCRIPTORS + 4 + k] - exact[j * 4 + k]).abs()
                    })
                    .collect();
                let mean = errs.iter().sum::<f64>() / errs.len() as f64;
                let (lo, hi) = (j_min(&exact, k), j_max(&exact, k));
                println!(
                    "radius {:.2} diag: |interpolated - exact| mean {mean:.4}, max {:.4} \
                     at {} points (exact values span {lo:.3}..{hi:.3})",
                    opts.radii[k],
                    errs.iter().copied().fold(0.0, f64::max),
                    errs.len()
                );
            }
        }
        assert_eq!(sh.len(), coarse.len());
    }
    // Spacing statistics of the nested sample pyramid (docs/transfer.md, "Samples"):
    // nearest-neighbour distance over the level's Poisson radius.
    let pyr =
        transfer::SamplePyramid::build(&m, samples, 3, 1, "mesh", &NoProgress, &mut w).unwrap();
    for (l, set) in pyr.levels.iter().enumerate() {
        let grid = mesh::SpatialGrid::new(&set.positions, set.spacing);
        let nn: Vec<f64> = (0..set.len())
            .map(|i| {
                let mut best = f64::INFINITY;
                grid.for_each_within(
                    &set.positions,
                    set.positions[i],
                    3.0 * set.spacing,
                    |j, d2| {
                        if j as usize != i {
                            best = best.min(d2.sqrt());
                        }
                    },
                );
                best / set.spacing
            })
            .collect();
        let finite: Vec<f64> = nn.iter().copied().filter(|x| x.is_finite()).collect();
        let mean = finite.iter().sum::<f64>() / finite.len() as f64;
        let sd =
            (finite.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / finite.len() as f64).sqrt();
        println!(
            "level {l}: {} samples, nearest neighbour / radius: min {:.3}, mean {mean:.3}, \
             coefficient of variation {:.3}, none within 3 radii: {}",
            set.len(),
            finite.iter().copied().fold(f64::INFINITY, f64::min),
            sd / mean,
            nn.len() - finite.len()
        );
    }
    println!(
        "{path}: {} triangles, {samples} samples; medians of {runs} (wall ms): sampling {:.0}, \
         occlusion ({} points) {:.0}, compute_descriptors (all 12) {:.0}",
        m.n_triangles(),
        median(ts),
        opts.samples,
        median(tdo),
        median(tall)
    );
}
