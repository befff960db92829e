//! Behaviour of the preview renderer on scenes with known answers.

use fieldtex_core::Image;
use fieldtex_core::image::srgb_to_linear;
use fieldtex_mesh::primitives::{grid, icosphere, torus};
use fieldtex_mesh::{CornerUvs, TriMesh};
use fieldtex_render::{
    FieldGlyphs, GlyphStyle, MarkerShape, Markers, Overlay, Polyline3, RenderOptions, Scene,
    Shading, render, scene_camera,
};

const BLACK: [f32; 4] = [0.0, 0.0, 0.0, 1.0];

fn coverage_sum(img: &Image) -> f64 {
    img.pixels.iter().map(|p| srgb_to_linear(p[0]) as f64).sum()
}

#[test]
fn sphere_covers_expected_fraction() {
    let mesh = icosphere(5);
    let scene = Scene::new(&mesh).with_base_color([1.0; 4]);
    let opts =
        RenderOptions::default().with_size(160).with_shading(Shading::Unlit).with_background(BLACK);
    let img = render(&scene, &opts);
    assert_eq!((img.width, img.height), (160, 160));
    let half_fov = (0.5 * opts.fov_deg).to_radians();
    let alpha = (half_fov.sin() / opts.margin).asin();
    let r_px = alpha.tan() / half_fov.tan() * 80.0;
    let expected = std::f64::consts::PI * r_px * r_px;
    let got = coverage_sum(&img);
    assert!((got - expected).abs() / expected < 0.01, "covered {got} px², expected {expected}");
}

/// 2×2 texture: top row red, green; bottom row blue, yellow.
fn quad_texture() -> Image {
    let mut t = Image::new(2, 2, [0.0; 4]);
    t.set(0, 0, [1.0, 0.0, 0.0, 1.0]);
    t.set(1, 0, [0.0, 1.0, 0.0, 1.0]);
    t.set(0, 1, [0.0, 0.0, 1.0, 1.0]);
    t.set(1, 1, [1.0, 1.0, 0.0, 1.0]);
    t
}

#[test]
fn textured_quad_front_view_keeps_uv_orientation() {
    let mut mesh = grid(1, 1, 1.0, 1.0);
    mesh.uvs = Some(CornerUvs {
        values: mesh.positions.iter().map(|p| [p[0], p[1]]).collect(),
        indices: mesh.triangles.clone(),
    });
    let tex = quad_texture();
    let scene = Scene::new(&mesh).with_texture(&tex);
    let opts =
        RenderOptions::default().with_size(128).with_view(0.0, 0.0).with_shading(Shading::Unlit);
    let img = render(&scene, &opts);
    let cam = scene_camera(&scene, &opts).unwrap();
    // (point on the quad, expected texel colour, expected image quadrant (right?, bottom?)).
    let cases = [
        ([0.25, 0.25, 0.0], [0.0, 0.0, 1.0], (false, true)),
        ([0.75, 0.25, 0.0], [1.0, 1.0, 0.0], (true, true)),
        ([0.25, 0.75, 0.0], [1.0, 0.0, 0.0], (false, false)),
        ([0.75, 0.75, 0.0], [0.0, 1.0, 0.0], (true, false)),
    ];
    for (p, want, (right, bottom)) in cases {
        let (s, _) = cam.project(p).unwrap();
        assert_eq!(s[0] > 64.0, right, "{p:?} projects to {s:?}");
        assert_eq!(s[1] > 64.0, bottom, "{p:?} projects to {s:?}");
        let c = img.get(s[0] as usize, s[1] as usize);
        for k in 0..3 {
            assert!((c[k] - want[k]).abs() < 0.02, "{p:?}: got {c:?}, want {want:?}");
        }
    }
}

fn busy_scene_mesh() -> TriMesh {
    let mut m = torus(1.0, 0.35, 48, 24);
    m.uvs = Some(CornerUvs {
        values: m.positions.iter().map(|p| [p[0] * 0.7, p[2] * 1.3]).collect(),
        indices: m.triangles.clone(),
    });
    m
}

#[test]
fn rendering_is_deterministic_across_thread_counts() {
    let mesh = busy_scene_mesh();
    let mut tex = Image::new(16, 16, [0.0; 4]);
    for (i, p) in tex.pixels.iter_mut().enumerate() {
        *p = [(i % 7) as f32 / 6.0, (i % 5) as f32 / 4.0, (i % 3) as f32 / 2.0, 1.0];
    }
    let pts: Vec<[f64; 3]> = mesh.positions.iter().step_by(17).copied().collect();
    let dirs: Vec<[f64; 3]> = pts.iter().map(|p| [-p[1], p[0], 0.0]).collect();
    let scene = Scene::new(&mesh)
        .with_texture(&tex)
        .with_overlay(Overlay::Polyline(Polyline3::new(mesh.positions[..24].to_vec()).closed(true)))
        .with_overlay(Overlay::Glyphs(
            FieldGlyphs::new(pts.clone(), dirs).with_style(GlyphStyle::Arrow),
        ))
        .with_overlay(Overlay::Markers(Markers::new(pts).with_shape(MarkerShape::Triangle)));
    let opts = RenderOptions::default()
        .with_size(150)
        .with_view(20.0, 50.0)
        .with_up(fieldtex_render::UpAxis::Z);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(&scene, &opts))
    };
    let a = run(1);
    let b = run(3);
    assert!(
        a.pixels.iter().zip(&b.pixels).all(|(x, y)| x.map(f32::to_bits) == y.map(f32::to_bits))
    );
    // Something was drawn.
    let bg = opts.background;
    assert!(a.pixels.iter().filter(|p| (p[0] - bg[0]).abs() > 0.05).count() > 1000);
}

fn assert_background(img: &Image, size: usize, bg: [f32; 4]) {
    assert_eq!((img.width, img.height), (size, size));
    for p in &img.pixels {
        for k in 0..4 {
            assert!((p[k] - bg[k]).abs() < 1e-3, "pixel {p:?} is not background {bg:?}");
        }
    }
}

#[test]
fn degenerate_meshes_give_background() {
    let opts = RenderOptions::default().with_size(40);
    let bg = opts.background;
    let empty = TriMesh::default();
    assert_background(&render(&Scene::new(&empty), &opts), 40, bg);

    let nan = TriMesh::new(
        vec![[f64::NAN; 3], [0.0, f64::INFINITY, 0.0], [1.0, 0.0, f64::NAN]],
        vec![[0, 1, 2]],
    );
    assert_background(&render(&Scene::new(&nan), &opts), 40, bg);

    let point = TriMesh::new(vec![[2.0, 2.0, 2.0]; 3], vec![[0, 1, 2], [2, 1, 0]]);
    assert_background(&render(&Scene::new(&point), &opts), 40, bg);

    let bad_index = TriMesh::new(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 7], [u32::MAX, 0, 1]],
    );
    assert_background(&render(&Scene::new(&bad_index), &opts), 40, bg);

    let collinear = TriMesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], vec![[0, 1, 2]]);
    assert_background(&render(&Scene::new(&collinear), &opts), 40, bg);

    // Broken attributes and silly options: no panic.
    let mut odd = grid(3, 3, 1.0, 1.0);
    odd.uvs = Some(CornerUvs { values: vec![[f64::NAN, 0.0]], indices: vec![[0, 5, 9]] });
    odd.vertex_colors = Some(vec![[1.0; 4]; 2]);
    let tex = Image::new(0, 0, [0.0; 4]);
    let silly = RenderOptions {
        size: 0,
        fov_deg: f64::NAN,
        supersample: 99,
        view: (f64::INFINITY, 400.0),
        ..Default::default()
    };
    let img = render(&Scene::new(&odd).with_texture(&tex), &silly);
    assert_eq!((img.width, img.height), (1, 1));
    let img = render(&Scene::new(&odd).with_texture(&tex), &RenderOptions::default().with_size(32));
    assert_eq!(img.pixels.len(), 32 * 32);
}

#[test]
fn partially_broken_mesh_still_renders_valid_part() {
    let mut mesh = icosphere(2);
    mesh.positions[0] = [f64::NAN, 0.0, 0.0];
    mesh.triangles.push([0, 1, 9999]);
    let opts = RenderOptions::default().with_size(64);
    let img = render(&Scene::new(&mesh), &opts);
    assert!(img.pixels.iter().all(|p| p.iter().all(|v| v.is_finite())));
    let bg = opts.background;
    assert!(img.pixels.iter().filter(|p| (p[0] - bg[0]).abs() > 0.05).count() > 500);
}

#[test]
fn overlay_lines_respect_depth() {
    let mesh = icosphere(4);
    let red = [1.0, 0.0, 0.0, 1.0];
    let front: Vec<[f64; 3]> = (0..=20)
        .map(|i| {
            let x = -0.4 + 0.04 * i as f64;
            [x, 0.0, (1.0 - x * x).sqrt()]
        })
        .collect();
    let back: Vec<[f64; 3]> = front.iter().map(|p| [p[0], 0.3, -p[2]]).collect();
    let scene = Scene::new(&mesh)
        .with_overlay(Overlay::Polyline(Polyline3::new(front).with_color(red).with_width(3.0)))
        .with_overlay(Overlay::Polyline(
            Polyline3::new(back.clone()).with_color(red).with_width(3.0),
        ))
        .with_overlay(Overlay::Markers(
            Markers::new(vec![[0.0, -0.5, -0.9]])
                .with_color([0.0, 0.0, 1.0, 1.0])
                .with_depth_test(false),
        ));
    let opts = RenderOptions::default().with_size(120).with_view(0.0, 0.0);
    let img = render(&scene, &opts);
    let cam = scene_camera(&scene, &opts).unwrap();
    let is_red = |c: [f32; 4]| c[0] > 0.8 && c[1] < 0.2 && c[2] < 0.2;
    let (s, _) = cam.project([0.0, 0.0, 1.0]).unwrap();
    assert!(is_red(img.get(s[0] as usize, s[1] as usize)), "front line hidden");
    let (s, _) = cam.project([0.0, 0.3, -1.0]).unwrap();
    assert!(!is_red(img.get(s[0] as usize, s[1] as usize)), "back line shows through");
    let (s, _) = cam.project([0.0, -0.5, -0.9]).unwrap();
    let c = img.get(s[0] as usize, s[1] as usize);
    assert!(c[2] > 0.8 && c[0] < 0.2, "marker without depth test hidden: {c:?}");
}

#[test]
fn vertex_colors_and_flat_shading() {
    let mut mesh = icosphere(2);
    mesh.vertex_colors = Some(vec![[0.0, 0.8, 0.0, 1.0]; mesh.positions.len()]);
    let opts = RenderOptions::default().with_size(64).with_view(0.0, 0.0);
    let img = render(&Scene::new(&mesh), &opts.clone().with_shading(Shading::Unlit));
    let c = img.get(32, 32);
    assert!((c[1] - 0.8).abs() < 0.01 && c[0] < 0.01, "{c:?}");
    let lit =
        render(&Scene::new(&mesh).with_vertex_colors(false), &opts.with_shading(Shading::Flat));
    let c = lit.get(32, 32);
    assert!((c[0] - c[1]).abs() < 0.05, "base colour is grey: {c:?}");
}
