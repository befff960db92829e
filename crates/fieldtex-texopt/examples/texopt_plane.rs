//! Texture optimisation on a plane: writes a PNG of the carriers (laid out as an image)
//! and prints timings.
//!
//! `cargo run --release -p fieldtex-texopt --example texopt_plane -- [SIZE] [EXEMPLAR]
//! [FIELD_ANGLE_DEG] [OUT.png]` (defaults: 256, stripes, 30°, /tmp/texopt_plane.png).

use fieldtex_core::NoProgress;
use fieldtex_mesh::primitives::grid;
use fieldtex_texopt::{SurfaceDomain, TexOptOptions, optimise};
use std::path::{Path, PathBuf};
use std::time::Instant;

// The plane tests' helpers (exemplar reading, orientation measurement).
#[path = "../tests/common/mod.rs"]
mod common;
use common::{dominant_orientation, line_angle_difference, luma};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let size: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(256);
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/exemplars");
    let exemplar_path =
        args.get(2).map(PathBuf::from).unwrap_or_else(|| data.join("stripes_Fabric071.png"));
    let angle_deg: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(30.0);
    let out =
        args.get(4).map(PathBuf::from).unwrap_or_else(|| PathBuf::from("/tmp/texopt_plane.png"));
    let exemplar = common::load_image(&exemplar_path);

    let t0 = Instant::now();
    let n = size - 1;
    let mesh = grid(n, n, n as f64, n as f64);
    let a = angle_deg.to_radians();
    let field = vec![[a.cos(), a.sin(), 0.0]; mesh.positions.len()];
    let (domain, vertices, warnings) = SurfaceDomain::at_vertices(&mesh, &field).expect("domain");
    let t_domain = t0.elapsed().as_secs_f64();
    let options = TexOptOptions::default().with_pixel_size(1.0);
    let t1 = Instant::now();
    let result = optimise(&domain, &exemplar, &options, None, &NoProgress).expect("optimise");
    let t_opt = t1.elapsed().as_secs_f64();

    // Carrier of vertex (i, j) → image pixel (i, size-1-j) (world y up, image y down).
    let mut img = image::RgbaImage::new(size as u32, size as u32);
    let mut luma_img = vec![0.0f32; size * size];
    for (c, &v) in vertices.iter().enumerate() {
        let (i, j) = (v as usize % size, v as usize / size);
        let col = result.colors[c];
        let px = col.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8);
        img.put_pixel(i as u32, (size - 1 - j) as u32, image::Rgba(px));
        luma_img[(size - 1 - j) * size + i] = luma(col);
    }
    img.save(&out).expect("write png");
    // The same carriers coloured by their source coordinate (nearest exemplar pixel).
    let mut src_img = image::RgbaImage::new(size as u32, size as u32);
    for (c, &v) in vertices.iter().enumerate() {
        let (i, j) = (v as usize % size, v as usize / size);
        let [x, y] = result.source[c];
        let col = exemplar
            .get((x as usize).min(exemplar.width - 1), (y as usize).min(exemplar.height - 1));
        src_img.put_pixel(
            i as u32,
            (size - 1 - j) as u32,
            image::Rgba(col.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8)),
        );
    }
    src_img.save(out.with_extension("source.png")).expect("write png");
    let (ex_angle, _) =
        dominant_orientation(&exemplar.luminance(), exemplar.width, exemplar.height)
            .unwrap_or((0.0, 0.0));
    let (got, coh) = dominant_orientation(&luma_img, size, size).unwrap_or((f64::NAN, 0.0));
    // Image y is down: a world angle a appears as -a in the image; exemplar lines at
    // ex_angle follow the field.
    let expected = (-a + ex_angle).rem_euclid(std::f64::consts::PI);
    println!(
        "carriers {} | domain {:.3} s | optimise {:.3} s | orientation error {:.2}° (coherence {:.2}) | warnings {}",
        domain.len(),
        t_domain,
        t_opt,
        line_angle_difference(got, expected).to_degrees(),
        coh,
        warnings.len() + result.warnings.len()
    );
    for l in &result.levels {
        println!(
            "  w={:>2} samples {:>7} iterations {} energy {:?} changed {:?} {:.3} s",
            l.patch_size,
            l.samples,
            l.iterations,
            l.energy.iter().map(|e| format!("{e:.1}")).collect::<Vec<_>>(),
            l.changed,
            l.seconds
        );
    }
    println!("wrote {}", out.display());
}
