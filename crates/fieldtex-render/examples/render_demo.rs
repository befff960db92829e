//! Renders a few demo scenes to PNG files for eyeballing:
//! `cargo run --release -p fieldtex-render --example render_demo -- OUT_DIR`.

use fieldtex_core::Image;
use fieldtex_mesh::CornerUvs;
use fieldtex_mesh::primitives::{icosphere, torus};
use fieldtex_render::{
    FieldGlyphs, GlyphStyle, ImageOverlay, ImageOverlayOptions, Marker2, MarkerShape, Markers,
    Overlay, Polyline3, RenderOptions, Scene, Shading, UpAxis, orientation_glyphs, render,
    render_image_overlay,
};

fn save(img: &Image, path: &std::path::Path) {
    let buf: Vec<u8> = img
        .pixels
        .iter()
        .flat_map(|p| p.map(|v| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8))
        .collect();
    image::save_buffer(path, &buf, img.width as u32, img.height as u32, image::ColorType::Rgba8)
        .expect("write png");
}

fn checker(n: usize, cells: usize) -> Image {
    let mut t = Image::new(n, n, [0.0; 4]);
    for y in 0..n {
        for x in 0..n {
            let c = ((x * cells / n) + (y * cells / n)) % 2;
            let shade = if c == 0 { 0.9 } else { 0.25 };
            t.set(
                x,
                y,
                [
                    shade,
                    shade * (y as f32 / n as f32),
                    0.5 * shade + 0.3 * (x as f32 / n as f32),
                    1.0,
                ],
            );
        }
    }
    t
}

fn main() {
    let out =
        std::path::PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "render-demo".into()));
    std::fs::create_dir_all(&out).expect("create output dir");

    let sphere = icosphere(4);
    let t0 = std::time::Instant::now();
    let img = render(&Scene::new(&sphere), &RenderOptions::default());
    println!("sphere 800px: {:.1} ms", t0.elapsed().as_secs_f64() * 1e3);
    save(&img, &out.join("sphere.png"));
    save(
        &render(
            &Scene::new(&sphere),
            &RenderOptions::default().with_shading(Shading::Flat).with_size(300),
        ),
        &out.join("sphere_flat.png"),
    );

    let mut tor = torus(1.0, 0.4, 96, 48);
    let uv: Vec<[f64; 2]> = (0..96)
        .flat_map(|i| (0..48).map(move |j| [i as f64 / 96.0 * 4.0, j as f64 / 48.0]))
        .collect();
    tor.uvs = Some(CornerUvs { values: uv, indices: tor.triangles.clone() });
    let tex = checker(256, 8);
    let ring: Vec<[f64; 3]> = (0..200)
        .map(|i| {
            let a = i as f64 / 200.0 * std::f64::consts::TAU;
            [1.4 * a.cos(), 1.4 * a.sin(), 0.0]
        })
        .collect();
    let pts: Vec<[f64; 3]> = tor.positions.iter().step_by(23).copied().collect();
    let dirs: Vec<[f64; 3]> = pts.iter().map(|p| [-p[1], p[0], 0.0]).collect();
    let scene = Scene::new(&tor)
        .with_texture(&tex)
        .with_overlay(Overlay::Polyline(Polyline3::new(ring).closed(true).with_width(3.0)))
        .with_overlay(Overlay::Glyphs(
            FieldGlyphs::new(pts.clone(), dirs).with_style(GlyphStyle::Arrow),
        ))
        .with_overlay(Overlay::Markers(
            Markers::new(pts[..5].to_vec()).with_shape(MarkerShape::Triangle),
        ));
    let t0 = std::time::Instant::now();
    let img = render(&scene, &RenderOptions::default().with_up(UpAxis::Z));
    println!("torus 800px with overlays: {:.1} ms", t0.elapsed().as_secs_f64() * 1e3);
    save(&img, &out.join("torus.png"));
    let mut crop = Image::new(600, 600, [0.0; 4]);
    for y in 0..600 {
        for x in 0..600 {
            crop.set(x, y, img.get(560 + x / 3, 330 + y / 3));
        }
    }
    save(&crop, &out.join("torus_crop.png"));

    // Texture preview with a field and markers.
    let (w, h) = (128usize, 128usize);
    let mut field = vec![0f32; w * h * 2];
    let mut stripes = Image::new(w, h, [0.0; 4]);
    for y in 0..h {
        for x in 0..w {
            let a = 0.5 * ((y as f64 - 64.0).atan2(x as f64 - 64.0));
            field[2 * (y * w + x)] = a.cos() as f32;
            field[2 * (y * w + x) + 1] = a.sin() as f32;
            let v = (0.5 + 0.5 * (x as f64 * 0.6).sin()) as f32;
            stripes.set(x, y, [v, v, v, 1.0]);
        }
    }
    let overlay = ImageOverlay {
        polylines: orientation_glyphs(&field, w, h, 8, 6.0, [0.1, 0.3, 0.9, 1.0], 1.5),
        markers: vec![Marker2::new([64.0, 64.0]).with_radius(8.0)],
    };
    let img =
        render_image_overlay(&stripes, &overlay, &ImageOverlayOptions { scale: 4, smooth: false });
    save(&img, &out.join("texture_overlay.png"));
}
