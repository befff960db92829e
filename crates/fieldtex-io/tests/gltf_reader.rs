//! glTF files written by hand (not by our writer): data URIs, external buffers and
//! images, node hierarchies with mirroring, strips, normalised colours.

use fieldtex_core::Image;
use fieldtex_io::{IoError, encode_png, read_mesh, read_mesh_bytes};
use serde_json::json;
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fieldtex-io-gltf-reader").join(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn b64(data: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// Buffer: triangle positions (36 B), u16 indices (6 B + 2 pad), UVs (24 B), strip of 4
/// positions (48 B), u8 RGB colours for the strip (12 B).
fn buffer() -> Vec<u8> {
    let mut b = Vec::new();
    for x in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
        b.extend_from_slice(&x.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    for x in [0f32, 1., 1., 1., 0., 0.] {
        b.extend_from_slice(&x.to_le_bytes());
    }
    for x in [0f32, 0., 5., 1., 0., 5., 0., 1., 5., 1., 1., 5.] {
        b.extend_from_slice(&x.to_le_bytes());
    }
    b.extend_from_slice(&[255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255]);
    b
}

fn document(buffer_uri: &str, image_uri: Option<&str>) -> serde_json::Value {
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"children": [1, 2, 3], "translation": [10.0, 0.0, 0.0]},
            {"mesh": 0, "scale": [2.0, 2.0, 2.0]},
            {"mesh": 0, "scale": [-1.0, 1.0, 1.0]},
            {"mesh": 1}
        ],
        "meshes": [
            {"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 2}, "indices": 1, "material": 0}]},
            {"primitives": [{"attributes": {"POSITION": 3, "COLOR_0": 4}, "mode": 5}]}
        ],
        "materials": [{"pbrMetallicRoughness": {}}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
            {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0.0, 0.0, 5.0], "max": [1.0, 1.0, 5.0]},
            {"bufferView": 4, "componentType": 5121, "normalized": true, "count": 4, "type": "VEC3"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6},
            {"buffer": 0, "byteOffset": 44, "byteLength": 24},
            {"buffer": 0, "byteOffset": 68, "byteLength": 48},
            {"buffer": 0, "byteOffset": 116, "byteLength": 12}
        ],
        "buffers": [{"byteLength": 128, "uri": buffer_uri}]
    });
    if let Some(uri) = image_uri {
        doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
        doc["textures"] = json!([{"source": 0}]);
        doc["images"] = json!([{"uri": uri}]);
    }
    doc
}

fn normal_z(m: &fieldtex_mesh::TriMesh, f: usize) -> f64 {
    let [a, b, c] = m.triangle_positions(f);
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

#[test]
fn embedded_data_uri_hierarchy_mirroring_strip_and_colors() {
    let uri = format!("data:application/octet-stream;base64,{}", b64(&buffer()));
    let bytes = serde_json::to_vec(&document(&uri, None)).unwrap();
    let m = read_mesh_bytes(&bytes, None).unwrap();
    let mesh = &m.mesh;
    // 3 + 3 + 4 vertices, the two triangles' corners at the origin welded; nodes in
    // document order; 1 + 1 + 2 triangles.
    assert_eq!((mesh.n_vertices(), mesh.n_triangles()), (9, 4));
    assert_eq!(mesh.positions[1], [12.0, 0.0, 0.0]); // scaled by 2, translated by 10
    assert_eq!(mesh.positions[3], [9.0, 0.0, 0.0]); // mirrored, translated
    assert_eq!(mesh.positions[8], [11.0, 1.0, 5.0]);
    for f in 0..4 {
        assert!(normal_z(mesh, f) > 0.0, "triangle {f} lost its counter-clockwise winding");
    }
    // UVs of the first mesh (V flipped back), (0, 0) fill for the strip with a warning.
    let uv = mesh.uvs.as_ref().unwrap();
    assert_eq!(uv.values[uv.indices[0][1] as usize], [1.0, 0.0]);
    assert!(m.warnings.iter().any(|w| w.code == "gltf-attribute-missing"), "{:?}", m.warnings);
    // Colours: white fill for the triangles, red/green/blue/white for the strip.
    let c = mesh.vertex_colors.as_ref().unwrap();
    let close = |a: [f32; 4], b: [f32; 4]| a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-6);
    assert!(close(c[5], [1.0, 0.0, 0.0, 1.0]) && close(c[0], [1.0; 4]), "{:?} {:?}", c[5], c[0]);
}

#[test]
fn external_buffer_and_image_beside_the_file() {
    let d = dir("external");
    std::fs::write(d.join("mesh data.bin"), buffer()).unwrap();
    let tex = Image::new(3, 2, [0.0, 1.0, 0.0, 1.0]);
    std::fs::write(d.join("tex.png"), encode_png(&tex).unwrap()).unwrap();
    let bytes = serde_json::to_vec(&document("mesh%20data.bin", Some("tex.png"))).unwrap();
    std::fs::write(d.join("scene.gltf"), &bytes).unwrap();
    let m = read_mesh(&d.join("scene.gltf")).unwrap();
    assert_eq!(m.mesh.n_triangles(), 4);
    assert_eq!(m.base_color.as_ref().map(|i| (i.width, i.height)), Some((3, 2)));

    // From memory, the external buffer cannot be resolved: a clear error.
    let e = read_mesh_bytes(&bytes, None).unwrap_err();
    assert!(matches!(e, IoError::Unsupported { .. }) && e.to_string().contains("<memory>"), "{e}");
    // A missing image is a warning, a missing buffer an error naming it.
    let bytes = serde_json::to_vec(&document("mesh%20data.bin", Some("missing.png"))).unwrap();
    std::fs::write(d.join("no-image.gltf"), &bytes).unwrap();
    let m = read_mesh(&d.join("no-image.gltf")).unwrap();
    assert!(m.base_color.is_none() && m.warnings.iter().any(|w| w.code == "texture-not-loaded"));
    let bytes = serde_json::to_vec(&document("gone.bin", None)).unwrap();
    std::fs::write(d.join("no-buffer.gltf"), &bytes).unwrap();
    let e = read_mesh(&d.join("no-buffer.gltf")).unwrap_err().to_string();
    assert!(e.contains("gone.bin"), "{e}");
}

#[test]
fn hostile_documents_are_clear_errors() {
    let uri = format!("data:application/octet-stream;base64,{}", b64(&buffer()));
    let mut doc = document(&uri, None);
    // An accessor running past its buffer view.
    doc["accessors"][0]["count"] = json!(1_000_000_000u64);
    let e = read_mesh_bytes(&serde_json::to_vec(&doc).unwrap(), None).unwrap_err();
    assert!(matches!(e, IoError::Truncated { .. }), "{e}");
    // An index past the primitive's vertices.
    let mut doc = document(&uri, None);
    doc["bufferViews"][1]["byteOffset"] = json!(116);
    let e = read_mesh_bytes(&serde_json::to_vec(&doc).unwrap(), None).unwrap_err();
    assert!(matches!(e, IoError::IndexOutOfRange { .. }), "{e}");
    // A node cycle is read once, not forever.
    let mut doc = document(&uri, None);
    doc["nodes"][1]["children"] = json!([0]);
    let _ = read_mesh_bytes(&serde_json::to_vec(&doc).unwrap(), None);
    // A dangling reference is caught by validation.
    let mut doc = document(&uri, None);
    doc["meshes"][0]["primitives"][0]["indices"] = json!(42);
    let e = read_mesh_bytes(&serde_json::to_vec(&doc).unwrap(), None).unwrap_err();
    assert!(e.to_string().contains("invalid glTF"), "{e}");
    // Required extensions are refused by name.
    let mut doc = document(&uri, None);
    doc["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    doc["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    let e = read_mesh_bytes(&serde_json::to_vec(&doc).unwrap(), None).unwrap_err();
    assert!(e.to_string().contains("KHR_draco_mesh_compression"), "{e}");

    // Regression (fuzzing): gltf-json's validation indexed a dangling POSITION accessor
    // and panicked; it is now an error naming the primitive.
    let mut doc = document(&uri, None);
    doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(99);
    let e = read_mesh_bytes(&serde_json::to_vec(&doc).unwrap(), None).unwrap_err();
    assert!(e.to_string().contains("mesh 0 primitive 0"), "{e}");
    // Regression (fuzzing): an image with neither uri nor mimeType made gltf's
    // `Image::source` panic; it is now a warning and the mesh still loads.
    let mut doc = document(&uri, Some("x.png"));
    doc["images"] = json!([{}]);
    let m = read_mesh_bytes(&serde_json::to_vec(&doc).unwrap(), None).unwrap();
    assert!(m.warnings.iter().any(|w| w.code == "texture-not-loaded"), "{:?}", m.warnings);
}
