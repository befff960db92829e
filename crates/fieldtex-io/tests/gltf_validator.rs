//! Every kind of GLB we write passes the Khronos glTF validator with 0 errors and 0
//! warnings. Needs node and `npm ci --prefix tools/gltf-validator` (scripts/test does it);
//! without them the test FAILS with that instruction (no silent skip).

use fieldtex_core::Image;
use fieldtex_io::{GlbOptions, read_mesh, write_glb};
use fieldtex_mesh::{CornerUvs, TriMesh, primitives};
use std::path::{Path, PathBuf};
use std::process::Command;

fn validator_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tools/gltf-validator")
}

fn out_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fieldtex-io-gltf-validator").join(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs the validator; returns (errors, warnings, the report text).
fn validate(file: &Path) -> (u64, u64, String) {
    let dir = validator_dir();
    assert!(
        dir.join("node_modules/gltf-validator").is_dir(),
        "the Khronos glTF validator is not installed: run `npm ci --prefix tools/gltf-validator` \
         from the repository root (scripts/test does this), then re-run the tests"
    );
    let out =
        Command::new("node").arg(dir.join("validate.js")).arg(file).output().unwrap_or_else(|e| {
            panic!("cannot run `node` ({e}); install Node.js to run the glTF validator tests")
        });
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let report: serde_json::Value = serde_json::from_str(&text).unwrap_or_else(|e| {
        panic!(
            "validator output is not JSON ({e}): {text}\n{}",
            String::from_utf8_lossy(&out.stderr)
        )
    });
    let n = |k: &str| report["issues"][k].as_u64().unwrap_or(u64::MAX);
    (n("numErrors"), n("numWarnings"), text)
}

fn assert_clean(file: &Path) {
    let (errors, warnings, report) = validate(file);
    assert_eq!(errors, 0, "{}: validator errors:\n{report}", file.display());
    assert_eq!(warnings, 0, "{}: validator warnings:\n{report}", file.display());
}

/// A torus with parametric per-corner UVs: the grid has `(nu+1)·(nv+1)` UV values, so
/// the two wrap-around seams give vertices two or four UVs each.
fn textured_torus() -> TriMesh {
    let (nu, nv) = (32, 16);
    let mut m = primitives::torus(1.0, 0.35, nu, nv);
    let id = |i: usize, j: usize| (i * (nv + 1) + j) as u32;
    let mut values = Vec::new();
    for i in 0..=nu {
        for j in 0..=nv {
            values.push([i as f64 / nu as f64, j as f64 / nv as f64]);
        }
    }
    // Same corner pattern as `primitives::torus`.
    let mut indices = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            indices.push([a, b, c]);
            indices.push([a, c, d]);
        }
    }
    m.uvs = Some(CornerUvs { values, indices });
    m
}

fn checker(n: usize) -> Image {
    let mut im = Image::new(n, n, [1.0; 4]);
    for y in 0..n {
        for x in 0..n {
            if (x / 8 + y / 8) % 2 == 0 {
                im.set(x, y, [0.8, 0.1, 0.1, 1.0]);
            }
        }
    }
    im
}

#[test]
fn textured_torus_is_valid_and_round_trips() {
    let m = textured_torus();
    let p = out_dir("torus").join("torus.glb");
    write_glb(&p, &m, Some(&checker(64)), &GlbOptions::default()).unwrap();
    assert_clean(&p);
    let back = read_mesh(&p).unwrap();
    // Welding undoes the seam split: the torus's topology comes back.
    assert_eq!(back.mesh.n_vertices(), m.n_vertices());
    assert_eq!(back.mesh.n_triangles(), m.n_triangles());
    assert_eq!(back.base_color.as_ref().map(|i| (i.width, i.height)), Some((64, 64)));
    let uv = back.mesh.uvs.as_ref().unwrap();
    let orig = m.uvs.as_ref().unwrap();
    for f in [0, 17, 500, m.n_triangles() - 1] {
        for k in 0..3 {
            let a = orig.values[orig.indices[f][k] as usize];
            let b = uv.values[uv.indices[f][k] as usize];
            assert!((a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6, "{a:?} vs {b:?}");
        }
    }
}

#[test]
fn vertex_colors_are_valid() {
    let mut m = primitives::icosphere(2);
    m.vertex_colors = Some(
        m.positions
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let c = p.map(|x| (0.5 + 0.5 * x) as f32);
                [c[0], c[1], c[2], if i % 3 == 0 { 0.5 } else { 1.0 }]
            })
            .collect(),
    );
    let p = out_dir("colors").join("colors.glb");
    write_glb(&p, &m, None, &GlbOptions::default().with_vertex_colors(true)).unwrap();
    assert_clean(&p);
    let back = read_mesh(&p).unwrap();
    let c = back.mesh.vertex_colors.unwrap();
    let orig = m.vertex_colors.as_ref().unwrap();
    for (a, b) in orig.iter().zip(&c) {
        // u8 quantisation in linear space: coarse near black, fine elsewhere.
        for k in 0..4 {
            assert!((a[k] - b[k]).abs() < 0.03, "{a:?} vs {b:?}");
        }
    }
}

#[test]
fn uv_seams_everywhere_and_odd_normals_are_valid() {
    // Every triangle has its own UVs (a fully split atlas) and the mesh carries
    // unnormalised and zero normals, as read from files.
    let mut m = primitives::grid(6, 5, 2.0, 1.0);
    let mut values = Vec::new();
    let mut indices = Vec::new();
    for (f, t) in m.triangles.iter().enumerate() {
        let base = values.len() as u32;
        for &v in t {
            let p = m.positions[v as usize];
            values.push([0.05 + 0.4 * p[0] + 0.01 * (f % 3) as f64, 0.1 + 0.8 * p[1]]);
        }
        indices.push([base, base + 1, base + 2]);
    }
    m.uvs = Some(CornerUvs { values, indices });
    m.vertex_normals = Some(
        (0..m.n_vertices()).map(|i| if i == 3 { [0.0; 3] } else { [0.0, 0.0, 3.0] }).collect(),
    );
    let p = out_dir("seams").join("seams.glb");
    write_glb(&p, &m, Some(&checker(16)), &GlbOptions::default()).unwrap();
    assert_clean(&p);
    let no_normals = out_dir("seams").join("seams-no-normals.glb");
    write_glb(&no_normals, &m, None, &GlbOptions::default().with_normals(false)).unwrap();
    assert_clean(&no_normals);
}

#[test]
fn shared_textured_mesh_is_valid() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data");
    let spot = read_mesh(&data.join("textured/spot/spot_triangulated.obj")).unwrap();
    let p = out_dir("spot").join("spot.glb");
    write_glb(&p, &spot.mesh, Some(&checker(32)), &GlbOptions::default()).unwrap();
    assert_clean(&p);
}
