//! Writers and readers agree: what is written reads back (exactly where the format
//! allows, to `f32` precision where it stores `f32`).

use fieldtex_core::Image;
use fieldtex_io::{
    GlbOptions, MeshFormat, encode_glb, read_image, read_mesh, read_mesh_bytes, read_npy_f32,
    write_glb, write_npy_f32, write_obj, write_obj_polylines, write_ply, write_png,
    write_png_gray16,
};
use fieldtex_mesh::{CornerUvs, TriMesh, primitives};
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fieldtex-io-round-trip").join(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn uv_grid() -> TriMesh {
    let mut m = primitives::grid(4, 3, 1.0, 0.75);
    let values: Vec<[f64; 2]> = m.positions.iter().map(|p| [p[0], p[1] / 0.75]).collect();
    m.uvs = Some(CornerUvs { values, indices: m.triangles.clone() });
    m.vertex_colors = Some(m.positions.iter().map(|p| [p[0] as f32, 0.25, 0.5, 1.0]).collect());
    m.vertex_normals = Some(vec![[0.0, 0.0, 1.0]; m.n_vertices()]);
    m
}

fn gradient(w: usize, h: usize) -> Image {
    Image::from_fn(w, h, |x, y| [x as f32 / (w - 1) as f32, y as f32 / (h - 1) as f32, 0.5, 1.0])
}

#[test]
fn obj_with_texture_round_trips_exactly() {
    let m = uv_grid();
    let p = dir("obj").join("model.obj");
    write_obj(&p, &m, Some(&gradient(8, 4))).unwrap();
    assert!(p.with_extension("mtl").is_file() && p.with_extension("png").is_file());
    let back = read_mesh(&p).unwrap();
    assert_eq!(back.format, MeshFormat::Obj);
    assert_eq!(back.mesh.positions, m.positions);
    assert_eq!(back.mesh.triangles, m.triangles);
    assert_eq!(back.mesh.uvs, m.uvs);
    assert_eq!(back.mesh.vertex_colors, m.vertex_colors);
    assert_eq!(back.mesh.vertex_normals, m.vertex_normals);
    let tex = back.base_color.expect("texture loaded through the MTL");
    assert_eq!((tex.width, tex.height), (8, 4));
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
}

#[test]
fn ply_binary_and_ascii_with_extra_properties() {
    let m = uv_grid();
    let fx: Vec<f32> = (0..m.n_vertices()).map(|i| i as f32 * 0.5).collect();
    for binary in [true, false] {
        let p = dir("ply").join(format!("field-{binary}.ply"));
        write_ply(&p, &m, &[("fx", &fx), ("fy", &fx), ("fz", &fx)], binary).unwrap();
        let text = std::fs::read(&p).unwrap();
        let header = String::from_utf8_lossy(&text[..600.min(text.len())]).into_owned();
        assert!(header.contains("property float fz"), "{header}");
        let back = read_mesh(&p).unwrap();
        assert_eq!(back.mesh.triangles, m.triangles);
        for (a, b) in back.mesh.positions.iter().zip(&m.positions) {
            for k in 0..3 {
                assert_eq!(a[k], b[k] as f32 as f64);
            }
        }
        assert_eq!(back.mesh.vertex_normals, m.vertex_normals);
        let c = back.mesh.vertex_colors.unwrap();
        assert!((c[4][0] - m.vertex_colors.as_ref().unwrap()[4][0]).abs() <= 0.5 / 255.0);
        // Per-corner UVs travel as face `texcoord` lists.
        assert!(header.contains("property list uchar float texcoord"), "{header}");
        let (a, b) = (back.mesh.uvs.expect("uvs read back"), m.uvs.as_ref().unwrap());
        for f in 0..m.n_triangles() {
            for k in 0..3 {
                let (ua, ub) =
                    (a.values[a.indices[f][k] as usize], b.values[b.indices[f][k] as usize]);
                let close = (ua[0] - ub[0]).abs() < 1e-7 && (ua[1] - ub[1]).abs() < 1e-7;
                assert!(close, "face {f} corner {k}: {ua:?} vs {ub:?}");
            }
        }
    }
    let p = dir("ply").join("dup.ply");
    assert!(write_ply(&p, &m, &[("nx", &fx)], true).is_err());
    assert!(write_ply(&p, &m, &[("fx", &fx[1..])], true).is_err());
}

#[test]
fn glb_round_trip_and_determinism() {
    let m = uv_grid();
    let tex = gradient(16, 16);
    let opts = GlbOptions::default().with_vertex_colors(true);
    let a = encode_glb(&m, Some(&tex), &opts).unwrap();
    let b = encode_glb(&m, Some(&tex), &opts).unwrap();
    assert_eq!(a, b, "GLB output must be byte-identical for identical input");
    let back = read_mesh_bytes(&a, None).unwrap();
    assert_eq!(back.format, MeshFormat::Gltf);
    assert_eq!(back.mesh.triangles, m.triangles);
    let uv = back.mesh.uvs.unwrap();
    for (f, t) in m.triangles.iter().enumerate() {
        for (k, &v) in t.iter().enumerate() {
            let orig = m.uvs.as_ref().unwrap().values[v as usize];
            let got = uv.values[uv.indices[f][k] as usize];
            assert!((orig[0] - got[0]).abs() < 1e-6 && (orig[1] - got[1]).abs() < 1e-6);
        }
    }
    let t = back.base_color.unwrap();
    assert!((t.get(15, 0)[0] - 1.0).abs() < 1e-6 && t.get(0, 15)[1] > 0.99);
    // A texture without UVs is refused, as is an invalid mesh.
    let p = dir("glb").join("bad.glb");
    assert!(write_glb(&p, &primitives::icosphere(0), Some(&tex), &opts).is_err());
    assert!(write_glb(&p, &TriMesh::new(vec![[0.0; 3]], vec![[0, 0, 5]]), None, &opts).is_err());
    assert!(!p.exists());
}

#[test]
fn images_npy_and_polylines() {
    let d = dir("misc");
    let im = gradient(5, 3);
    write_png(&d.join("g.png"), &im).unwrap();
    let back = read_image(&d.join("g.png")).unwrap();
    assert_eq!((back.width, back.height), (5, 3));
    assert!((back.get(4, 2)[1] - 1.0).abs() < 1e-6);

    let vals: Vec<f32> = (0..12).map(|i| i as f32 / 11.0).collect();
    write_png_gray16(&d.join("g16.png"), 4, 3, &vals).unwrap();
    let g = read_image(&d.join("g16.png")).unwrap();
    for (i, v) in vals.iter().enumerate() {
        assert!((g.pixels[i][0] - v).abs() < 1e-4 && g.pixels[i][3] == 1.0);
    }

    let field: Vec<f32> = (0..3 * 4 * 2).map(|i| (i as f32).sin()).collect();
    write_npy_f32(&d.join("f.npy"), &[3, 4, 2], &field).unwrap();
    assert_eq!(read_npy_f32(&d.join("f.npy")).unwrap(), (vec![3, 4, 2], field));

    let lines = vec![
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.5]],
        vec![[2.0; 3]],
        vec![[0.0; 3], [0.0, 0.0, 1.0]],
    ];
    write_obj_polylines(&d.join("curves.obj"), &lines).unwrap();
    let text = std::fs::read_to_string(d.join("curves.obj")).unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("v ")).count(), 5);
    let ls: Vec<&str> = text.lines().filter(|l| l.starts_with("l ")).collect();
    assert_eq!(ls, vec!["l 1 2 3", "l 4 5"]);
}
