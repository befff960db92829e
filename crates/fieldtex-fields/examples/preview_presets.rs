//! Renders every fingerprint preset's orientation field as a line-integral-convolution
//! picture with the detected singularities marked (red: +1/2, blue: −1/2).
//!
//! `cargo run --release -p fieldtex-fields --example preview_presets -- OUT_DIR [SIZE]`

use fieldtex_fields::Symmetry;
use fieldtex_fields::orientation_field::{detect_pixel_singularities, sample_plane};
use fieldtex_fields::presets::{PRESET_NAMES, preset};

fn lic(field: &[[f32; 2]], w: usize, h: usize) -> Vec<u8> {
    // White noise from a fixed hash, then streamline averages of ±L steps.
    let noise: Vec<f32> = (0..w * h)
        .map(|i| {
            let mut x = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            x ^= x >> 29;
            x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
            x ^= x >> 32;
            (x % 1000) as f32 / 1000.0
        })
        .collect();
    let at = |x: f32, y: f32| -> Option<usize> {
        if x < 0.0 || y < 0.0 || x >= w as f32 || y >= h as f32 {
            None
        } else {
            Some(y as usize * w + x as usize)
        }
    };
    let mut out = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut sum = noise[y * w + x];
            let mut cnt = 1.0;
            for dir in [1.0f32, -1.0] {
                let (mut px, mut py) = (x as f32 + 0.5, y as f32 + 0.5);
                let mut prev = [field[y * w + x][0] * dir, field[y * w + x][1] * dir];
                for _ in 0..12 {
                    let Some(i) = at(px, py) else { break };
                    let mut v = field[i];
                    if v[0] * prev[0] + v[1] * prev[1] < 0.0 {
                        v = [-v[0], -v[1]];
                    }
                    prev = v;
                    px += v[0];
                    py += v[1];
                    let Some(j) = at(px, py) else { break };
                    sum += noise[j];
                    cnt += 1.0;
                }
            }
            let m = sum / cnt;
            out[y * w + x] = ((m - 0.5) * 4.0 * 255.0 + 128.0).clamp(0.0, 255.0) as u8;
        }
    }
    out
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out =
        std::path::PathBuf::from(args.get(1).map(String::as_str).unwrap_or("preset-previews"));
    let size: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(512);
    std::fs::create_dir_all(&out).unwrap();
    for name in PRESET_NAMES {
        let d = preset(name, size as f64, size as f64, 128).unwrap();
        let mut design = d.build(None).unwrap();
        let f = design.solve().unwrap();
        let px = sample_plane(&design, &f, size, size).unwrap();
        let sing = detect_pixel_singularities(&px, size, size, Symmetry::Orientation, 6.0).unwrap();
        let gray = lic(&px, size, size);
        let mut img = image::RgbImage::new(size as u32, size as u32);
        for (i, g) in gray.iter().enumerate() {
            img.put_pixel((i % size) as u32, (i / size) as u32, image::Rgb([*g, *g, *g]));
        }
        for s in &sing {
            let c = if s.index > 0.0 { [255, 0, 0] } else { [0, 80, 255] };
            for dy in -3i32..=3 {
                for dx in -3i32..=3 {
                    let (x, y) = (s.position[0] as i32 + dx, s.position[1] as i32 + dy);
                    if x >= 0 && y >= 0 && (x as usize) < size && (y as usize) < size {
                        img.put_pixel(x as u32, y as u32, image::Rgb(c));
                    }
                }
            }
        }
        for s in &d.singularities {
            let (x, y) = (s.x.unwrap() as i32, s.y.unwrap() as i32);
            for k in -6i32..=6 {
                for (xx, yy) in [(x + k, y), (x, y + k)] {
                    if xx >= 0 && yy >= 0 && (xx as usize) < size && (yy as usize) < size {
                        img.put_pixel(xx as u32, yy as u32, image::Rgb([0, 200, 0]));
                    }
                }
            }
        }
        img.save(out.join(format!("{name}.png"))).unwrap();
        println!(
            "{name}: designed {:?}",
            d.singularities
                .iter()
                .map(|s| (s.kind.name(), s.x.unwrap(), s.y.unwrap(), s.angle))
                .collect::<Vec<_>>()
        );
        println!(
            "{name}: found {:?}",
            sing.iter().map(|s| (s.index, s.position[0], s.position[1])).collect::<Vec<_>>()
        );
    }
}
