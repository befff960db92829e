//! `orient --mesh`: orientation-field guided synthesis on curved disk patches (paper D,
//! curved patches). Synthetic bumpy spherical caps, a patch cut out of a real scan, and
//! the meshes that must be refused.

use fieldtex::crates::{fields, io, mesh};
use fieldtex::{Error, FieldSource, NoProgress, OrientOptions, Report, orient};
use mesh::TriMesh;
use std::path::{Path, PathBuf};

// The CLI tests' data and scratch-folder helpers.
#[path = "../../fieldtex-cli/tests/common/paths.rs"]
mod common;
use common::shared;

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("fieldtex-orient-patch", name)
}

fn exemplar(name: &str) -> PathBuf {
    shared().join("exemplars").join(name)
}

/// A bumpy spherical cap: the unit disk lifted onto a sphere of radius 1.5 plus a
/// gentle bump, y up (the cap bulges towards +y).
fn bumpy_cap(rings: usize) -> TriMesh {
    let mut m = fields::disk_mesh(1.0, rings);
    let r2: f64 = 1.5 * 1.5;
    for p in &mut m.positions {
        let (x, y) = (p[0], p[1]);
        let h = (r2 - x * x - y * y).sqrt() - (r2 - 1.0).sqrt()
            + 0.06 * (3.0 * x).sin() * (2.0 * y).cos();
        *p = [x, h, -y];
    }
    m
}

fn write_mesh(dir: &Path, name: &str, m: &TriMesh) -> PathBuf {
    let p = dir.join(name);
    io::write_obj(&p, m, None).unwrap();
    p
}

fn run(out: &Path, source: FieldSource, ex: &str, mesh: &Path, size: usize) -> Report {
    let mut o = OrientOptions::new(source, exemplar(ex));
    o.size = size;
    o.mesh = Some(mesh.to_path_buf());
    orient(out, &o, &NoProgress).unwrap_or_else(|e| panic!("orient --mesh failed: {e}"))
}

fn metric(r: &Report, path: &[&str]) -> f64 {
    let mut v = &r.metrics;
    for k in path {
        v = &v[*k];
    }
    v.as_f64().unwrap_or_else(|| panic!("metric {path:?} missing in {}", r.metrics))
}

/// Stripes follow the left-loop preset on a curved patch within 10° in parameter space
/// (chart texels and whole texture), the designed core and delta land on the patch,
/// and every output is written.
#[test]
fn stripes_follow_a_preset_on_a_bumpy_cap() {
    let dir = tmp("cap-left-loop");
    let mesh = write_mesh(&dir, "cap.obj", &bumpy_cap(20));
    let out = dir.join("out");
    let r = run(&out, FieldSource::Preset("left-loop".into()), "stripes_Fabric071.png", &mesh, 160);
    for f in ["texture.png", "field.npy", "preview.png", "model.glb", "report.json"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let glb = std::fs::read(out.join("model.glb")).unwrap();
    assert_eq!(&glb[..4], b"glTF");
    let (shape, field) = io::read_npy_f32(&out.join("field.npy")).unwrap();
    assert_eq!(shape, [160, 160, 2]);
    assert!(field.chunks(2).all(|v| ((v[0] * v[0] + v[1] * v[1]) - 1.0).abs() < 1e-3));
    let chart = metric(&r, &["chart_orientation_error", "mean_error_deg"]);
    let whole = metric(&r, &["texture", "orientation_error", "mean_error_deg"]);
    assert!(chart <= 10.0, "chart orientation error {chart}°");
    assert!(whole <= 10.0, "texture orientation error {whole}°");
    let designed = r.metrics["designed_singularities"].as_array().unwrap();
    assert_eq!(designed.len(), 2, "{designed:?}");
    let coverage = metric(&r, &["chart_coverage"]);
    assert!((0.6..0.8).contains(&coverage), "a disk covers about π/4 of its square: {coverage}");
    // A conformal map of a gentle cap: little angle distortion, nothing flipped.
    assert!(metric(&r, &["parameterization", "angle_mean"]) < 1.1);
    assert_eq!(metric(&r, &["parameterization", "flipped_triangles"]), 0.0);
    assert!(r.notes.iter().any(|n| n.contains("parameter")));
}

/// On a flat disk the mapped preset must reproduce the plane pipeline's field (the
/// singularity rotations are carried into the mesh frames correctly), for either
/// winding of the disk.
#[test]
fn flat_disk_reproduces_the_plane_field() {
    let dir = tmp("flat-disk");
    let ex = exemplar("stripes_Fabric071.png");
    let mut o = OrientOptions::new(FieldSource::Preset("left-loop".into()), ex.clone());
    o.size = 96;
    o.grid = 32;
    orient(&dir.join("plane"), &o, &NoProgress).unwrap();
    let (_, plane) = io::read_npy_f32(&dir.join("plane/field.npy")).unwrap();
    let mut disk = fields::disk_mesh(1.0, 20);
    for p in &mut disk.positions {
        *p = [p[0], 0.0, -p[1]];
    }
    let mut flipped = disk.clone();
    for t in &mut flipped.triangles {
        t.swap(1, 2);
    }
    for (name, m) in [("disk", disk), ("flipped", flipped)] {
        let mesh = write_mesh(&dir, &format!("{name}.obj"), &m);
        let out = dir.join(name);
        run(&out, FieldSource::Preset("left-loop".into()), "stripes_Fabric071.png", &mesh, 96);
        let (_, f) = io::read_npy_f32(&out.join("field.npy")).unwrap();
        let (mut sum, mut count) = (0.0, 0);
        for y in 0..96 {
            for x in 0..96 {
                if (x as f64 - 47.5).hypot(y as f64 - 47.5) > 32.0 {
                    continue;
                }
                let i = 2 * (y * 96 + x);
                let d = (plane[i + 1].atan2(plane[i]) - f[i + 1].atan2(f[i])) as f64;
                let d = d.rem_euclid(std::f64::consts::PI);
                sum += d.min(std::f64::consts::PI - d).to_degrees();
                count += 1;
            }
        }
        let mean = sum / count as f64;
        assert!(mean < 4.0, "{name}: mean difference from the plane field {mean}°");
    }
}

/// A mesh design places a wedge by its 3-D position; it is reported at the texel of
/// the cap's apex (the middle of the texture).
#[test]
fn mesh_design_places_singularities_by_position() {
    let dir = tmp("cap-mesh-design");
    let cap = bumpy_cap(16);
    let apex = cap.positions[0];
    let mesh = write_mesh(&dir, "cap.obj", &cap);
    let design = dir.join("d.toml");
    std::fs::write(
        &design,
        format!(
            "[domain]\nkind = \"mesh\"\n\n[[singularity]]\nkind = \"wedge\"\nposition = [{}, {}, {}]\n",
            apex[0] + 0.01,
            apex[1],
            apex[2] + 0.01
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let r = run(&out, FieldSource::Design(design), "bands-fingerprint-like_Onyx013.png", &mesh, 96);
    let designed = r.metrics["designed_singularities"].as_array().unwrap();
    assert_eq!(designed.len(), 1);
    let (x, y) = (designed[0]["x"].as_f64().unwrap(), designed[0]["y"].as_f64().unwrap());
    assert!((x - 48.0).abs() < 8.0 && (y - 48.0).abs() < 8.0, "wedge at ({x}, {y})");
    assert_eq!(designed[0]["index"].as_f64(), Some(0.5));
}

/// A disk cut out of a real scan with `patch` (the Demosthenes bust around the tip of
/// its face) goes through with a whorl: no flattening defect, outputs written, stripes
/// still follow the field. A cut far from the mesh, or `patch` without a mesh, is bad
/// input.
#[test]
fn real_scan_patch_with_a_whorl() {
    let bust = shared().join("meshes/demosthenes-bust-open.obj");
    let m = io::read_mesh(&bust).unwrap().mesh;
    let tip =
        *m.positions.iter().filter(|p| p[1] > 1.3).max_by(|a, b| a[2].total_cmp(&b[2])).unwrap();
    let dir = tmp("demosthenes");
    let out = dir.join("out");
    let mut o =
        OrientOptions::new(FieldSource::Preset("whorl".into()), exemplar("stripes_Fabric071.png"));
    o.size = 128;
    o.mesh = Some(bust.clone());
    o.patch = Some([tip[0], tip[1], tip[2], 0.5]);
    let r = orient(&out, &o, &NoProgress).unwrap_or_else(|e| panic!("{e}"));
    assert!(out.join("model.glb").is_file() && out.join("preview.png").is_file());
    let triangles = r.input["mesh_triangles"].as_u64().unwrap();
    assert!((800..4000).contains(&triangles), "{triangles} triangles in the cut");
    assert!(!r.warnings.iter().any(|w| w.code == "patch-flattening-defects"), "{:?}", r.warnings);
    let chart = metric(&r, &["chart_orientation_error", "mean_error_deg"]);
    assert!(chart <= 15.0, "chart orientation error {chart}°");
    assert!(!r.metrics["designed_singularities"].as_array().unwrap().is_empty());
    o.patch = Some([tip[0] + 100.0, tip[1], tip[2], 0.5]);
    let e = orient(&dir.join("far"), &o, &NoProgress).unwrap_err();
    assert!(e.exit_code() == 2 && e.to_string().contains("no triangle centre lies within"), "{e}");
    o.mesh = None;
    let e = orient(&dir.join("no-mesh"), &o, &NoProgress).unwrap_err();
    assert!(e.exit_code() == 2 && e.to_string().contains("--mesh"), "{e}");
}

/// Closed meshes and disks with a hole are refused as bad input naming the topology.
#[test]
fn non_disk_meshes_are_refused() {
    let dir = tmp("non-disk");
    let sphere = write_mesh(&dir, "sphere.obj", &mesh::primitives::icosphere(2));
    let g = mesh::primitives::grid(12, 12, 1.0, 1.0);
    let mut ring = g.clone();
    ring.triangles.retain(|t| {
        let c: [f64; 2] = std::array::from_fn(|k| {
            t.iter().map(|&v| g.positions[v as usize][k]).sum::<f64>() / 3.0
        });
        (c[0] - 0.5).abs() > 0.2 || (c[1] - 0.5).abs() > 0.2
    });
    let ring = write_mesh(&dir, "ring.obj", &ring);
    for (mesh, loops) in [(sphere, "0 boundary loop"), (ring, "2 boundary loop")] {
        let mut o = OrientOptions::new(
            FieldSource::Preset("arch".into()),
            exemplar("stripes_Fabric071.png"),
        );
        o.size = 64;
        o.mesh = Some(mesh.clone());
        match orient(&dir.join("out"), &o, &NoProgress) {
            Err(e @ Error::BadInput { .. }) => {
                let msg = e.to_string();
                assert!(msg.contains("disk") && msg.contains(loops), "{msg}");
                assert_eq!(e.exit_code(), 2);
            }
            other => panic!("{}: expected bad input, got {other:?}", mesh.display()),
        }
    }
}
