//! End-to-end tests of `fieldtex solid`: outputs, the cut image against the volume
//! slice, closed cut meshes, determinism across thread counts, and clear errors.

use std::path::{Path, PathBuf};
use std::process::Output;

mod common;
use common::shared;

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("fieldtex-cli-solid", name)
}

/// `solid --mesh MESH --exemplar EXEMPLAR --out OUT EXTRA…`.
fn solid(mesh: &Path, exemplar: &Path, out: &Path, extra: &[&str]) -> Output {
    let limit = std::time::Duration::from_secs(900);
    common::run_on_mesh("solid", mesh, exemplar, out, extra, limit)
}

/// `solid` on the shared torus at a small size (`resolution` voxels along the longest
/// side, a 128² atlas, 3 levels, 6-voxel blocks) with `exemplar`, then `extra`.
fn small_torus(exemplar: &Path, out: &Path, resolution: &str, extra: &[&str]) -> Output {
    let small =
        ["--resolution", resolution, "--atlas-size", "128", "--levels", "3", "--block", "6"];
    solid(&shared().join("meshes/torus.obj"), exemplar, out, &[&small[..], extra].concat())
}

fn woodgrain() -> PathBuf {
    shared().join("exemplars/woodgrain_Wood022.png")
}

const SKETCH: &str = r#"{"curves": [
  {"points": [[1.25, 0.2, 0], [0.9, 0.2, 0.9], [0, 0.2, 1.25], [-0.9, 0.2, 0.9]], "axis": "x"},
  {"points": [[-1.0, 0.0, -0.5], [1.0, 0.0, -0.5]], "plane": {"point": [0, 0, 0], "normal": [0, 1, 0]}, "axis": "y"}
]}"#;

/// Runs the torus (axis y) at a small resolution with a y cut through the voxel
/// centres of slice `k`.
fn torus_run(dir: &Path, threads: &str, k: usize, more: &[&str]) -> Output {
    let sketch = dir.join("sketch.json");
    std::fs::write(&sketch, SKETCH).unwrap();
    // The grid: longest side 2.5 (x, z), 40 voxels, spacing 0.0625; y extent 0.5
    // → 8 voxels, origin y = −0.21875.
    let y = -0.21875 + 0.0625 * k as f64;
    let cut = format!("0,{y},0,0,1,0");
    let out = dir.join("out");
    let sketch = sketch.to_str().unwrap();
    let extra =
        ["--sketch", sketch, "--cut", &cut, "--volume", "--keep", "--threads", threads, "--quiet"];
    small_torus(&woodgrain(), &out, "40", &[&extra[..], more].concat())
}

fn weld_closed(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> bool {
    use std::collections::HashMap;
    let mut ids: HashMap<[u64; 3], u32> = HashMap::new();
    let map: Vec<u32> = positions
        .iter()
        .map(|p| {
            let key = p.map(f64::to_bits);
            let n = ids.len() as u32;
            *ids.entry(key).or_insert(n)
        })
        .collect();
    let mut half: HashMap<(u32, u32), usize> = HashMap::new();
    for t in triangles {
        let t = t.map(|v| map[v as usize]);
        for e in 0..3 {
            *half.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
        }
    }
    half.iter().all(|(&(a, b), &c)| c == 1 && half.get(&(b, a)) == Some(&1))
}

/// Asserts that `cut-1.png` of the torus run in `out` equals slice `k` (along y) of
/// `volume.nrrd` where opaque, with enough of both; returns the volume.
fn cut_equals_volume_slice(out: &Path, k: usize) -> fieldtex::crates::io::RgbVolume {
    let vol = fieldtex::crates::io::decode_nrrd_rgb(
        &std::fs::read(out.join("volume.nrrd")).unwrap(),
        "volume",
    )
    .unwrap();
    let [nx, ny, nz] = vol.sizes;
    assert_eq!((nx, ny, nz), (40, 8, 40));
    let img = fieldtex::crates::io::read_image(&out.join("cut-1.png")).unwrap();
    // Columns run along x, rows along z.
    assert_eq!((img.width, img.height), (nx, nz));
    let (mut opaque, mut transparent) = (0, 0);
    for z in 0..nz {
        for x in 0..nx {
            let p = img.get(x, z).map(|v| (v * 255.0).round() as u8);
            if p[3] == 0 {
                transparent += 1;
                continue;
            }
            opaque += 1;
            let i = 3 * (x + nx * (k + ny * z));
            assert_eq!(&p[..3], &vol.data[i..i + 3], "pixel ({x}, {z})");
        }
    }
    assert!(opaque > 100 && transparent > 100, "opaque {opaque}, transparent {transparent}");
    vol
}

#[test]
fn solid_outputs_cut_slice_and_determinism() {
    let d1 = tmp("torus-1");
    let o = torus_run(&d1, "1", 4, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = d1.join("out");
    for f in [
        "model.glb",
        "preview.png",
        "report.json",
        "cut-1.glb",
        "cut-1.png",
        "volume.nrrd",
        "frames.ply",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let err = report["metrics"]["frame_field"]["alignment_error_max_deg"].as_f64().unwrap();
    assert!(err <= 5.0, "frame-field alignment error {err}°");
    assert_eq!(report["metrics"]["cuts"][0]["grid_slice"], true);
    // The cut image equals the volume's slice where opaque.
    let vol = cut_equals_volume_slice(&out, 4);
    // The solid is textured, not flat: the red channel varies (woodgrain's own standard
    // deviation is 7.2; an earlier version that averaged three incompatible planes gave 1.1).
    let red: Vec<f64> = vol.data.iter().step_by(3).map(|&v| v as f64).collect();
    let mean = red.iter().sum::<f64>() / red.len() as f64;
    let std = (red.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / red.len() as f64).sqrt();
    assert!(std > 2.5, "volume red std {std}");
    // The cut mesh of the closed torus is closed.
    let cut = fieldtex::crates::io::read_mesh(&out.join("cut-1.glb")).unwrap().mesh;
    assert!(weld_closed(&cut.positions, &cut.triangles), "cut-1.glb is not closed");
    // Two threads: the same bytes.
    let d2 = tmp("torus-2");
    let o = torus_run(&d2, "2", 4, &[]);
    assert!(o.status.success());
    for f in ["model.glb", "cut-1.png", "volume.nrrd", "frames.ply"] {
        assert_eq!(
            std::fs::read(out.join(f)).unwrap(),
            std::fs::read(d2.join("out").join(f)).unwrap(),
            "{f} differs"
        );
    }
}

#[test]
fn bad_sketches_name_the_curve_and_point() {
    let d = tmp("bad");
    let sketch = d.join("s.json");
    std::fs::write(
        &sketch,
        r#"{"curves": [{"points": [[0,0,0],[1,0,0]]}, {"points": [[0,0,0]]}]}"#,
    )
    .unwrap();
    let torus = shared().join("meshes/torus.obj");
    let out = d.join("out");
    // The torus with the sketch file as it is now.
    let solid_run =
        || solid(&torus, &woodgrain(), &out, &["--sketch", sketch.to_str().unwrap(), "--quiet"]);
    let o = solid_run();
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("curve 1") && e.contains("s.json"), "{e}");
    std::fs::write(&sketch, r#"{"curves": [{"points": [[0,0,0],[1,0,"x"]]}]}"#).unwrap();
    let o = solid_run();
    assert_eq!(o.status.code(), Some(2));
}

/// `--interior`: a second exemplar below a depth. The cut image still equals the
/// volume's slice byte for byte (both regions on demand), voxels near the surface keep
/// the outer solid, and deep voxels change.
#[test]
fn interior_region_fills_the_deep_voxels() {
    let run_one = |name: &str, interior: bool| {
        let dir = tmp(name);
        let out = dir.join("out");
        let stripes = shared().join("exemplars/stripes_Fabric071.png");
        let mut extra = vec!["--cut=0,0.03125,0,0,1,0", "--volume", "--quiet"];
        if interior {
            extra.extend(["--interior", stripes.to_str().unwrap(), "--interior-depth", "0.12"]);
        }
        let o = small_torus(&woodgrain(), &out, "40", &extra);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        out
    };
    let plain = run_one("interior-off", false);
    let two = run_one("interior-on", true);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(two.join("report.json")).unwrap()).unwrap();
    assert!(report["metrics"]["interior"]["depth"].as_f64().unwrap() > 0.0);
    let read_vol = |d: &Path| {
        fieldtex::crates::io::decode_nrrd_rgb(&std::fs::read(d.join("volume.nrrd")).unwrap(), "v")
            .unwrap()
    };
    let (va, vb) = (read_vol(&plain), read_vol(&two));
    let img = fieldtex::crates::io::read_image(&two.join("cut-1.png")).unwrap();
    let [nx, _, nz] = vb.sizes;
    // Slice y = 0.03125: voxel index (0.03125 + 0.21875) / 0.0625 = 4.
    let at = |v: &fieldtex::crates::io::RgbVolume, x: usize, z: usize| {
        let i = 3 * (x + nx * (4 + vb.sizes[1] * z));
        [v.data[i], v.data[i + 1], v.data[i + 2]]
    };
    let (mut opaque, mut changed) = (0, 0);
    for z in 0..nz {
        for x in 0..nx {
            let p = img.get(x, z).map(|v| (v * 255.0).round() as u8);
            if p[3] == 0 {
                continue;
            }
            opaque += 1;
            assert_eq!([p[0], p[1], p[2]], at(&vb, x, z), "cut ≠ volume at ({x}, {z})");
            if at(&va, x, z) != at(&vb, x, z) {
                changed += 1;
            }
        }
    }
    assert!(opaque > 100, "{opaque} opaque pixels");
    assert!(changed > 0 && changed < opaque, "{changed} of {opaque} slice voxels changed");
}

/// `--feature-mask`: a mask the size of the exemplar is used (the report names the
/// channel); a mask of another size is a clear error (exit 2) naming the mask.
#[test]
fn feature_mask_is_used_and_a_wrong_size_is_an_error() {
    use fieldtex::crates::io::{read_image, write_png};
    let d = tmp("feature-mask");
    let bricks = shared().join("exemplars/bricks_Bricks012.png");
    let img = read_image(&bricks).unwrap();
    // A mask from the exemplar's darkest quarter (its mortar), and one of another size.
    let mut lum: Vec<f32> = img.pixels.iter().map(|p| p[0] + p[1] + p[2]).collect();
    lum.sort_by(f32::total_cmp);
    let cut = lum[lum.len() / 4];
    let mut mask = img.clone();
    for p in &mut mask.pixels {
        let m = if p[0] + p[1] + p[2] <= cut { 1.0 } else { 0.0 };
        *p = [m, m, m, 1.0];
    }
    let good = d.join("mask.png");
    write_png(&good, &mask).unwrap();
    let bad = d.join("small.png");
    write_png(&bad, &fieldtex::Image::new(20, 20, [1.0; 4])).unwrap();
    let solid_run = |mask: &Path, out: &Path| {
        small_torus(&bricks, out, "32", &["--feature-mask", mask.to_str().unwrap(), "--quiet"])
    };
    let o = solid_run(&bad, &d.join("bad"));
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("small.png") && e.contains("feature mask"), "{e}");
    let out = d.join("good");
    let o = solid_run(&good, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = std::fs::read_to_string(out.join("report.json")).unwrap();
    assert!(report.contains("--feature-mask: the mask"), "the notes name the feature channel");
}

/// `--integrated-init`: the cut still equals the volume's slice byte for byte (on-demand
/// equality with the new start), two threads give the same bytes, and the solid differs
/// from the default start.
#[test]
fn integrated_init_keeps_cut_equality_and_determinism() {
    let d1 = tmp("torus-int-1");
    let d2 = tmp("torus-int-2");
    for (d, threads) in [(&d1, "1"), (&d2, "2")] {
        let o = torus_run(d, threads, 4, &["--integrated-init"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let out = d1.join("out");
    cut_equals_volume_slice(&out, 4);
    for f in ["model.glb", "cut-1.png", "volume.nrrd"] {
        assert_eq!(
            std::fs::read(out.join(f)).unwrap(),
            std::fs::read(d2.join("out").join(f)).unwrap(),
            "{f} differs"
        );
    }
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["options"]["synthesis"]["integrated_init"], true, "{}", report["options"]);
    // Woodgrain neither tiles nor repeats along its axes: the report warns.
    let codes: Vec<&str> =
        report["warnings"].as_array().unwrap().iter().filter_map(|w| w["code"].as_str()).collect();
    assert!(codes.contains(&"integrated-init-irregular-exemplar"), "{codes:?}");
}
