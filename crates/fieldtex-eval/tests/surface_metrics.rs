//! Surface metrics with known answers: a striped plane, a field turned by a known
//! angle, and constructed curve samples for feature coverage.

use fieldtex_eval::{
    CurveSample, EvalError, FeatureCoverageOptions, ImageView, SurfaceOrientationOptions,
    feature_line_coverage, surface_orientation_error,
};
use fieldtex_mesh::{CornerUvs, TriMesh, primitives};

const SIDE: usize = 256;

/// `SIDE²` grey stripes of period 12 px running at `angle_deg` in image coordinates
/// (x right, y down).
fn stripes(angle_deg: f64) -> Vec<f32> {
    let a = angle_deg.to_radians();
    let (nx, ny) = (-a.sin(), a.cos()); // across the stripes
    let mut out = Vec::with_capacity(SIDE * SIDE);
    for y in 0..SIDE {
        for x in 0..SIDE {
            let s = nx * x as f64 + ny * y as f64;
            out.push((0.5 + 0.4 * (2.0 * std::f64::consts::PI * s / 12.0).cos()) as f32);
        }
    }
    out
}

/// A 2 × 2 plane (z = 0, normal +z) with UV = position / 2: the texture covers it once.
fn plane() -> (TriMesh, CornerUvs) {
    let mesh = primitives::grid(24, 24, 2.0, 2.0);
    let values = mesh.positions.iter().map(|p| [p[0] / 2.0, p[1] / 2.0]).collect();
    let uvs = CornerUvs { values, indices: mesh.triangles.clone() };
    (mesh, uvs)
}

fn field(mesh: &TriMesh, angle_deg: f64) -> Vec<[f64; 3]> {
    let a = angle_deg.to_radians();
    vec![[a.cos(), a.sin(), 0.0]; mesh.n_vertices()]
}

#[test]
fn striped_plane_gives_the_known_error() {
    let (mesh, uvs) = plane();
    for &texture_angle in &[0.0, 20.0, 65.0] {
        let data = stripes(texture_angle);
        let tex = ImageView::new(&data, SIDE, SIDE, 1).unwrap();
        let options = SurfaceOrientationOptions {
            n_samples: 60,
            exemplar_angle_deg: texture_angle,
            ..Default::default()
        };
        // Field along the texture's x axis: the texture shows exactly the exemplar angle.
        let r = surface_orientation_error(&mesh, &uvs, &tex, &field(&mesh, 0.0), &options).unwrap();
        assert!(r.n_samples >= 20, "{r:?}");
        assert!(r.mean_deg < 1.0, "texture {texture_angle}°: {r:?}");
        assert!(r.p90_deg < 1.0, "{r:?}");
        assert!((r.texel_size - 2.0 / SIDE as f64).abs() < 1e-9);
        assert!(r.mean_coherence > 0.9, "{r:?}");
        // Field turned by 30° (counter-clockwise seen from +z): error 30°.
        let r =
            surface_orientation_error(&mesh, &uvs, &tex, &field(&mesh, 30.0), &options).unwrap();
        assert!((r.mean_deg - 30.0).abs() < 1.0, "texture {texture_angle}°: {r:?}");
        assert!((r.median_deg - 30.0).abs() < 1.0, "{r:?}");
        // A sign-flipping (2-RoSy) field measures the same.
        let mut flipped = field(&mesh, 30.0);
        flipped.iter_mut().step_by(3).for_each(|v| *v = [-v[0], -v[1], -v[2]]);
        let rf = surface_orientation_error(&mesh, &uvs, &tex, &flipped, &options).unwrap();
        assert!((rf.mean_deg - 30.0).abs() < 1.0, "flipped: {rf:?}");
    }
    // Perpendicular field: 90°.
    let data = stripes(0.0);
    let tex = ImageView::new(&data, SIDE, SIDE, 1).unwrap();
    let options = SurfaceOrientationOptions { n_samples: 60, ..Default::default() };
    let r = surface_orientation_error(&mesh, &uvs, &tex, &field(&mesh, 90.0), &options).unwrap();
    assert!(r.mean_deg > 89.0, "{r:?}");
}

#[test]
fn orientation_on_a_curved_surface_follows_the_texture() {
    // A cylinder-like bent strip: the grid bent around the y axis (radius 2), UVs as on
    // the plane; stripes along the texture's x wrap around the bend, so a field along
    // the bend direction (dP/dx) measures ~0 error.
    let (mut mesh, uvs) = plane();
    let mut f = Vec::new();
    for p in mesh.positions.iter_mut() {
        let a = p[0] / 2.0;
        *p = [2.0 * a.sin(), p[1], 2.0 * (1.0 - a.cos())];
        f.push([a.cos(), 0.0, a.sin()]);
    }
    let data = stripes(0.0);
    let tex = ImageView::new(&data, SIDE, SIDE, 1).unwrap();
    let options = SurfaceOrientationOptions { n_samples: 60, ..Default::default() };
    let r = surface_orientation_error(&mesh, &uvs, &tex, &f, &options).unwrap();
    assert!(r.n_samples >= 20, "{r:?}");
    assert!(r.mean_deg < 2.0, "{r:?}");
}

#[test]
fn bad_inputs_are_errors() {
    let (mesh, uvs) = plane();
    let data = stripes(0.0);
    let tex = ImageView::new(&data, SIDE, SIDE, 1).unwrap();
    let o = SurfaceOrientationOptions::default();
    let short = vec![[1.0, 0.0, 0.0]; 3];
    assert!(matches!(
        surface_orientation_error(&mesh, &uvs, &tex, &short, &o),
        Err(EvalError::InvalidOption { name: "field", .. })
    ));
    let mut bad_uvs = uvs.clone();
    bad_uvs.indices[5] = [0, 1, 99_999];
    assert!(matches!(
        surface_orientation_error(&mesh, &bad_uvs, &tex, &field(&mesh, 0.0), &o),
        Err(EvalError::InvalidOption { name: "corner_uvs", .. })
    ));
    let bad = SurfaceOrientationOptions { patch_size: 3, ..Default::default() };
    assert!(surface_orientation_error(&mesh, &uvs, &tex, &field(&mesh, 0.0), &bad).is_err());
    // A zero field: nothing measured, NaN, no panic.
    let zero = vec![[0.0; 3]; mesh.n_vertices()];
    let r = surface_orientation_error(&mesh, &uvs, &tex, &zero, &o).unwrap();
    assert_eq!(r.n_samples, 0);
    assert!(r.mean_deg.is_nan());
}

#[test]
fn same_result_for_any_thread_count() {
    let (mesh, uvs) = plane();
    let data = stripes(20.0);
    let tex = ImageView::new(&data, SIDE, SIDE, 1).unwrap();
    let o = SurfaceOrientationOptions { n_samples: 40, ..Default::default() };
    let run = |threads| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| {
            surface_orientation_error(&mesh, &uvs, &tex, &field(&mesh, 10.0), &o).unwrap()
        })
    };
    assert_eq!(run(1), run(3));
}

/// 10 × 8 distance map to the vertical line x = 2 (toroidal).
fn vertical_line_distance() -> Vec<f32> {
    let (w, h) = (10usize, 8usize);
    (0..w * h)
        .map(|i| {
            let d = ((i % w) as i64 - 2).rem_euclid(10);
            d.min(10 - d) as f32
        })
        .collect()
}

#[test]
fn coverage_counts_length_near_feature_lines() {
    let d = vertical_line_distance();
    let o = FeatureCoverageOptions::default();
    let samples = [
        CurveSample { exemplar_xy: [2.0, 3.0], length: 1.0 }, // on the line
        CurveSample { exemplar_xy: [2.9, 5.0], length: 2.0 }, // 0.9 px away
        CurveSample { exemplar_xy: [5.0, 1.0], length: 3.0 }, // 3 px away
        CurveSample { exemplar_xy: [11.5, 1.0], length: 1.5 }, // wraps to x = 1.5: 0.5 px
        CurveSample { exemplar_xy: [f64::NAN, 1.0], length: 1.0 },
    ];
    let r = feature_line_coverage(&samples, &d, 10, 8, &o).unwrap();
    assert_eq!(r.n_samples, 4);
    assert_eq!(r.n_skipped, 1);
    assert_eq!(r.total_length, 7.5);
    assert_eq!(r.covered_length, 4.5);
    assert!((r.fraction - 0.6).abs() < 1e-12);
    // Stricter tolerance: the 0.9 px point is no longer covered.
    let strict = FeatureCoverageOptions { tolerance_px: 0.6, ..o.clone() };
    let r = feature_line_coverage(&samples, &d, 10, 8, &strict).unwrap();
    assert_eq!(r.covered_length, 2.5);
    // Not toroidal: the wrapped point is outside and skipped.
    let flat = FeatureCoverageOptions { toroidal: false, ..o.clone() };
    let r = feature_line_coverage(&samples, &d, 10, 8, &flat).unwrap();
    assert_eq!((r.n_samples, r.n_skipped), (3, 2));
    assert_eq!(r.covered_length, 3.0);
    // No feature line at all: nothing covered, no NaN from infinities.
    let inf = vec![f32::INFINITY; 80];
    let r = feature_line_coverage(&samples, &inf, 10, 8, &o).unwrap();
    assert_eq!(r.fraction, 0.0);
    // Shape errors.
    assert!(feature_line_coverage(&samples, &d, 9, 8, &o).is_err());
    assert!(feature_line_coverage(&[], &d, 10, 8, &o).unwrap().fraction.is_nan());
}
