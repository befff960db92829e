//! Fidelity benchmark of `fieldtex transfer` on a known answer (issue 14).
//!
//! The source colour is a known function of geometry plus noise: a scalar
//! `s = 0.55·accessibility + 0.30·height + 0.15·(1 − 2·solid_angle(0.05·diag))`
//! (accessibility = unoccluded fraction of the sphere, 128 rays; height along y in
//! `[0, 1]`; solid angle by the mesh crate's analytic computation), mapped to a brown
//! palette, plus white noise (σ = 0.03) per texel. Colours are stored one texel per
//! triangle (each triangle's colour at its centroid). The same function, without noise,
//! is evaluated on each target and written as `reference.obj`; every transfer is then
//! scored with `fieldtex::transfer_fidelity_files` (Pearson r of luma at 100K points).
//!
//! Configurations: CCA with the three `--match` settings and the PCA ablation on the
//! parametric engine, then the non-parametric engine with CCA + multiscale and CCA +
//! none. `--engines parametric|nonparametric|all` (default all) selects.
//!
//! `--with-weighted` adds the parametric runs with `cca-weighted` guidance (canonical
//! variates weighted by their correlations). `--mask-below H` masks the source texels
//! of triangles whose normalised height is below `H` (an incomplete source, like the
//! half-scanned bagel of paper B Fig. 8): the case feature matching is meant for.
//!
//! Usage: `transfer_fidelity OUT_DIR SOURCE_MESH TARGET_MESH... [--samples N] [--engines E]
//! [--mask-below H] [--with-weighted]`
//! Prints one line per (target, configuration): r, wall seconds.

use fieldtex::crates::{core::Image, io, mesh};
use fieldtex::{NoProgress, TransferCommandOptions};
use fieldtex_core::rng::hash_unit;
use mesh::{CornerUvs, TriMesh};
use std::path::{Path, PathBuf};
use std::time::Instant;

fn ground_truth(m: &TriMesh) -> Vec<f64> {
    let bbox = m.bounding_box().expect("non-empty");
    let diag = bbox.diagonal();
    let normals = mesh::face_normals(m);
    let pts: Vec<mesh::OrientedPoint> = (0..m.n_triangles())
        .map(|f| {
            let [a, b, c] = m.triangle_positions(f);
            let p = [
                (a[0] + b[0] + c[0]) / 3.0,
                (a[1] + b[1] + c[1]) / 3.0,
                (a[2] + b[2] + c[2]) / 3.0,
            ];
            mesh::OrientedPoint { position: p, normal: normals[f] }
        })
        .collect();
    let bvh = mesh::Bvh::build(m).expect("bvh");
    let ao = mesh::directional_occlusion_sh(
        &bvh,
        &pts,
        &mesh::DirectionalOcclusionOptions {
            directions: 128,
            epsilon: 1e-4 * diag,
            seed: 99,
            ..Default::default()
        },
    );
    let positions: Vec<[f64; 3]> = pts.iter().map(|p| p.position).collect();
    let sa = mesh::solid_angle_curvature(m, &positions, &[0.05 * diag]).expect("solid angle");
    let span = (bbox.max[1] - bbox.min[1]).max(1e-12);
    (0..pts.len())
        .map(|i| {
            let access = ao[i][0] / (2.0 * std::f64::consts::PI.sqrt());
            let h = (pts[i].position[1] - bbox.min[1]) / span;
            (0.55 * access + 0.30 * h + 0.15 * (1.0 - 2.0 * sa[i])).clamp(0.0, 1.0)
        })
        .collect()
}

fn palette(s: f64) -> [f32; 3] {
    [(0.15 + 0.75 * s) as f32, (0.12 + 0.55 * s) as f32, (0.08 + 0.35 * s) as f32]
}

/// One texel per triangle, colour `palette(s) + noise`.
fn textured(m: &TriMesh, s: &[f64], noise: f64) -> (TriMesh, Image) {
    let nf = m.n_triangles();
    let w = (nf as f64).sqrt().ceil() as usize;
    let h = nf.div_ceil(w);
    let mut img = Image::new(w, h, [0.5, 0.5, 0.5, 1.0]);
    let mut values = Vec::with_capacity(nf);
    for (t, &st) in s.iter().enumerate().take(nf) {
        let mut c = palette(st);
        for (k, ck) in c.iter_mut().enumerate() {
            let u1 = hash_unit(5, "bench-noise", (3 * t + k) as u64).max(1e-300);
            let u2 = hash_unit(6, "bench-noise", (3 * t + k) as u64);
            let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
            *ck = (*ck as f64 + noise * z).clamp(0.0, 1.0) as f32;
        }
        let (x, y) = (t % w, t / w);
        img.set(x, y, [c[0], c[1], c[2], 1.0]);
        values.push([(x as f64 + 0.5) / w as f64, 1.0 - (y as f64 + 0.5) / h as f64]);
    }
    let mut out = TriMesh::new(m.positions.clone(), m.triangles.clone());
    out.uvs = Some(CornerUvs { values, indices: (0..nf as u32).map(|t| [t, t, t]).collect() });
    (out, img)
}

fn load(path: &Path) -> TriMesh {
    let l = io::read_mesh(path).expect("read mesh");
    mesh::repair(&l.mesh, &mesh::RepairOptions::default()).mesh
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut samples = 200_000usize;
    let mut engines = "all".to_string();
    let mut mask_below: Option<f64> = None;
    let mut weighted = false;
    let mut pos = Vec::new();
    let mut i = 0;
    while i < args.len() {
        if args[i] == "--samples" {
            samples = args[i + 1].parse().expect("--samples N");
            i += 2;
        } else if args[i] == "--with-weighted" {
            weighted = true;
            i += 1;
        } else if args[i] == "--mask-below" {
            mask_below = Some(args[i + 1].parse().expect("--mask-below H"));
            i += 2;
        } else if args[i] == "--engines" {
            engines = args[i + 1].clone();
            i += 2;
        } else {
            pos.push(args[i].clone());
            i += 1;
        }
    }
    assert!(pos.len() >= 3, "usage: transfer_fidelity OUT SOURCE TARGET... [--samples N]");
    let out = PathBuf::from(&pos[0]);
    std::fs::create_dir_all(&out).expect("out dir");
    let src = load(Path::new(&pos[1]));
    let (src_tex_mesh, src_tex) = textured(&src, &ground_truth(&src), 0.03);
    let src_path = out.join("source.obj");
    io::write_obj(&src_path, &src_tex_mesh, Some(&src_tex)).expect("write source");
    let mask_path = mask_below.map(|hmin| {
        // Texel t belongs to triangle t (see `textured`); white = ignored.
        let bbox = src.bounding_box().expect("non-empty");
        let span = (bbox.max[1] - bbox.min[1]).max(1e-12);
        let mut mask = Image::new(src_tex.width, src_tex.height, [0.0, 0.0, 0.0, 1.0]);
        for t in 0..src.n_triangles() {
            let [a, b, c] = src.triangle_positions(t);
            let h = ((a[1] + b[1] + c[1]) / 3.0 - bbox.min[1]) / span;
            if h < hmin {
                mask.set(t % src_tex.width, t / src_tex.width, [1.0; 4]);
            }
        }
        let p = out.join("source-mask.png");
        io::write_png(&p, &mask).expect("write mask");
        p
    });
    let configs: Vec<(&str, &str, &str)> = [
        ("cca", "multiscale", "parametric"),
        ("cca", "marginals", "parametric"),
        ("cca", "none", "parametric"),
        ("pca", "multiscale", "parametric"),
        ("cca", "multiscale", "nonparametric"),
        ("cca", "none", "nonparametric"),
        ("cca-weighted", "multiscale", "parametric"),
        ("cca-weighted", "marginals", "parametric"),
        ("cca-weighted", "none", "parametric"),
    ]
    .into_iter()
    .filter(|c| (engines == "all" || engines == c.2) && (weighted || c.0 != "cca-weighted"))
    .collect();
    for tpath in &pos[2..] {
        let name = Path::new(tpath).file_stem().unwrap().to_string_lossy().to_string();
        let tgt = load(Path::new(tpath));
        let (ref_mesh, ref_tex) = textured(&tgt, &ground_truth(&tgt), 0.0);
        let dir = out.join(&name);
        std::fs::create_dir_all(&dir).expect("dir");
        let ref_path = dir.join("reference.obj");
        io::write_obj(&ref_path, &ref_mesh, Some(&ref_tex)).expect("write reference");
        let tgt_path = dir.join("target.obj");
        io::write_obj(&tgt_path, &tgt, None).expect("write target");
        for &(reduce, matching, engine) in &configs {
            let mut opts = TransferCommandOptions {
                source: src_path.clone(),
                target: tgt_path.clone(),
                mask: mask_path.clone(),
                ..Default::default()
            };
            opts.transfer.samples = samples;
            opts.transfer.reduction =
                fieldtex::pipelines_transfer::parse_reduction(reduce).unwrap();
            opts.transfer.matching =
                fieldtex::pipelines_transfer::parse_match_mode(matching).unwrap();
            opts.transfer.engine = fieldtex::pipelines_transfer::parse_engine(engine).unwrap();
            let run_dir = dir.join(format!("{engine}-{reduce}-{matching}"));
            let t0 = Instant::now();
            fieldtex::transfer_files(&run_dir, &opts, &NoProgress).expect("transfer");
            let secs = t0.elapsed().as_secs_f64();
            let f = fieldtex::transfer_fidelity_files(
                &run_dir.join("model.glb"),
                &ref_path,
                100_000,
                3,
            )
            .expect("fidelity");
            println!(
                "FIDELITY source={} target={name} engine={engine} reduce={reduce} match={matching} samples={samples} mask_below={mask_below:?} r_luma={:.3} r_rgb=[{:.3},{:.3},{:.3}] wall_s={secs:.1}",
                Path::new(&pos[1]).file_stem().unwrap().to_string_lossy(),
                f.pearson_luma,
                f.pearson_rgb[0],
                f.pearson_rgb[1],
                f.pearson_rgb[2],
            );
        }
    }
}
