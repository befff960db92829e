//! Binary glTF 2.0 (`.glb`) writer that passes the Khronos glTF validator with 0 errors.
//!
//! One node, one mesh, one triangle primitive with `POSITION` (`f32`, with the `min`/
//! `max` the specification requires), optional `NORMAL` (unit `f32`), `TEXCOORD_0`
//! (`f32`, **V flipped**: `v_gltf = 1 − v`, because glTF's UV origin is the top-left of
//! the image while [`TriMesh`] uses the bottom-left), optional `COLOR_0` (`u8`
//! normalised RGBA, converted from the mesh's sRGB colours to the linear values glTF
//! expects), `u32` indices, and an optional base-colour texture embedded as PNG.
//!
//! glTF attributes are per vertex while [`TriMesh`] UVs are per corner, so vertices are
//! split wherever one vertex has several UVs (seams); output vertices are created in
//! triangle-corner order (deterministic). Unreferenced input vertices are not written.
//!
//! Layout details the validator checks: every buffer view starts on a 4-byte boundary,
//! the JSON chunk is padded with spaces and the BIN chunk with zeros to 4 bytes, vertex
//! views carry `target` 34962 and the index view 34963, image views none.

use crate::{IoError, atomic_write, encode_png};
use fieldtex_core::Image;
use fieldtex_core::image::srgb_to_linear;
use fieldtex_mesh::TriMesh;
use serde_json::{Value, json};
use std::collections::HashMap;
use std::path::Path;

/// What to include in a GLB besides positions, indices and UVs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GlbOptions {
    /// Write `COLOR_0` from `TriMesh::vertex_colors` (ignored when the mesh has none).
    /// Default `false`.
    pub with_vertex_colors: bool,
    /// Write `NORMAL`: the mesh's own normals (normalised) when present, otherwise
    /// area-weighted vertex normals. Default `true`.
    pub with_normals: bool,
}

impl Default for GlbOptions {
    fn default() -> Self {
        Self { with_vertex_colors: false, with_normals: true }
    }
}

impl GlbOptions {
    pub fn with_vertex_colors(mut self, on: bool) -> Self {
        self.with_vertex_colors = on;
        self
    }
    pub fn with_normals(mut self, on: bool) -> Self {
        self.with_normals = on;
        self
    }
}

/// Writes `mesh` (and `texture` as its base colour, which requires UVs) to `path`
/// atomically. The mesh must pass `TriMesh::validate`.
pub fn write_glb(
    path: &Path,
    mesh: &TriMesh,
    texture: Option<&Image>,
    options: &GlbOptions,
) -> Result<(), IoError> {
    let bytes = encode_glb(mesh, texture, options).map_err(|m| IoError::invalid(path, m))?;
    atomic_write(path, &bytes)
}

/// The GLB bytes [`write_glb`] writes; errors describe what is wrong with the input.
pub fn encode_glb(
    mesh: &TriMesh,
    texture: Option<&Image>,
    options: &GlbOptions,
) -> Result<Vec<u8>, String> {
    mesh.validate().map_err(|e| format!("the mesh is not valid ({e}); run repair first"))?;
    if texture.is_some() && mesh.uvs.is_none() {
        return Err("a texture was given but the mesh has no texture coordinates".into());
    }
    let (src, indices) = split_at_seams(mesh);
    let n = src.len();
    let mut bin = Bin::default();
    let mut attributes = serde_json::Map::new();
    let mut accessors: Vec<Value> = Vec::new();

    let pos: Vec<[f32; 3]> =
        src.iter().map(|&(v, _)| mesh.positions[v as usize].map(|x| x as f32)).collect();
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in &pos {
        for k in 0..3 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    }
    if pos.iter().flatten().any(|x| !x.is_finite()) {
        return Err("a position does not fit in a 32-bit float".into());
    }
    let view = bin.push(bytes_of(pos.iter().flatten()), Some(34962));
    accessors.push(json!({"bufferView": view, "componentType": 5126, "count": n, "type": "VEC3",
        "min": min, "max": max}));
    attributes.insert("POSITION".into(), json!(accessors.len() - 1));

    if options.with_normals {
        let nrm = vertex_normals(mesh);
        let data: Vec<f32> = src.iter().flat_map(|&(v, _)| nrm[v as usize]).collect();
        let view = bin.push(bytes_of(data.iter()), Some(34962));
        accessors
            .push(json!({"bufferView": view, "componentType": 5126, "count": n, "type": "VEC3"}));
        attributes.insert("NORMAL".into(), json!(accessors.len() - 1));
    }
    if let Some(uv) = &mesh.uvs {
        let clean = |x: f64| if x.is_finite() { x as f32 } else { 0.0 };
        let data: Vec<f32> = src
            .iter()
            .flat_map(|&(_, t)| {
                let q = uv.values[t as usize];
                [clean(q[0]), clean(1.0 - q[1])]
            })
            .collect();
        let view = bin.push(bytes_of(data.iter()), Some(34962));
        accessors
            .push(json!({"bufferView": view, "componentType": 5126, "count": n, "type": "VEC2"}));
        attributes.insert("TEXCOORD_0".into(), json!(accessors.len() - 1));
    }
    if let (true, Some(colors)) = (options.with_vertex_colors, &mesh.vertex_colors) {
        let q = |c: f32| (c.clamp(0.0, 1.0) * 255.0).round() as u8;
        let data: Vec<u8> = src
            .iter()
            .flat_map(|&(v, _)| {
                let c = colors[v as usize].map(|x| if x.is_nan() { 0.0 } else { x });
                [q(srgb_to_linear(c[0])), q(srgb_to_linear(c[1])), q(srgb_to_linear(c[2])), q(c[3])]
            })
            .collect();
        let view = bin.push(data, Some(34962));
        accessors.push(json!({"bufferView": view, "componentType": 5121, "normalized": true,
            "count": n, "type": "VEC4"}));
        attributes.insert("COLOR_0".into(), json!(accessors.len() - 1));
    }
    let view = bin.push(bytes_of(indices.iter()), Some(34963));
    accessors.push(json!({"bufferView": view, "componentType": 5125, "count": indices.len(), "type": "SCALAR"}));
    let index_accessor = accessors.len() - 1;

    let mut pbr = json!({"metallicFactor": 0.0, "roughnessFactor": 1.0});
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": concat!("fieldtex ", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": index_accessor,
            "material": 0, "mode": 4}]}],
    });
    if let Some(tex) = texture {
        let png = encode_png(tex).map_err(|e| e.to_string())?;
        let view = bin.push(png, None);
        pbr["baseColorTexture"] = json!({"index": 0});
        doc["images"] = json!([{"bufferView": view, "mimeType": "image/png"}]);
        doc["samplers"] = json!([{"magFilter": 9729, "minFilter": 9987}]);
        doc["textures"] = json!([{"sampler": 0, "source": 0}]);
    }
    doc["materials"] = json!([{"pbrMetallicRoughness": pbr, "doubleSided": false}]);
    doc["accessors"] = Value::Array(accessors);
    doc["bufferViews"] = Value::Array(bin.views);
    doc["buffers"] = json!([{"byteLength": bin.data.len()}]);
    let mut json_bytes = serde_json::to_vec(&doc).map_err(|e| e.to_string())?;
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    let total = 12 + 8 + json_bytes.len() as u64 + 8 + bin.data.len() as u64;
    if total > u32::MAX as u64 {
        return Err(format!("the GLB would be {total} bytes; the format allows at most 4 GiB"));
    }
    let mut out = Vec::with_capacity(total as usize);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(bin.data.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin.data);
    Ok(out)
}

/// Output vertices as `(input vertex, uv index)` pairs and the `3·#F` output indices.
/// Referenced input vertices come first, in input order, each with the UV of its first
/// corner (in triangle order); copies for further UVs at a vertex follow in corner
/// order. So a mesh without seams keeps its vertex order, and reading the file back
/// (which welds the copies) gives the input's order for referenced vertices.
fn split_at_seams(mesh: &TriMesh) -> (Vec<(u32, u32)>, Vec<u32>) {
    let uv_of = |f: usize, k: usize| mesh.uvs.as_ref().map_or(0, |u| u.indices[f][k]);
    let mut first_uv = vec![u32::MAX; mesh.n_vertices()];
    for (f, t) in mesh.triangles.iter().enumerate() {
        for (k, &v) in t.iter().enumerate() {
            if first_uv[v as usize] == u32::MAX {
                first_uv[v as usize] = uv_of(f, k);
            }
        }
    }
    let mut src = Vec::with_capacity(mesh.n_vertices());
    let mut out_id = vec![u32::MAX; mesh.n_vertices()];
    for (v, &uv) in first_uv.iter().enumerate() {
        if uv != u32::MAX {
            out_id[v] = src.len() as u32;
            src.push((v as u32, uv));
        }
    }
    let mut extra: HashMap<(u32, u32), u32> = HashMap::new();
    let mut indices = Vec::with_capacity(3 * mesh.n_triangles());
    for (f, t) in mesh.triangles.iter().enumerate() {
        for (k, &v) in t.iter().enumerate() {
            let uv = uv_of(f, k);
            let id = if uv == first_uv[v as usize] {
                out_id[v as usize]
            } else {
                *extra.entry((v, uv)).or_insert_with(|| {
                    src.push((v, uv));
                    src.len() as u32 - 1
                })
            };
            indices.push(id);
        }
    }
    (src, indices)
}

/// The binary chunk under construction: views padded to 4 bytes.
#[derive(Default)]
struct Bin {
    data: Vec<u8>,
    views: Vec<Value>,
}

impl Bin {
    fn push(&mut self, bytes: Vec<u8>, target: Option<u32>) -> usize {
        let offset = self.data.len();
        self.data.extend_from_slice(&bytes);
        while !self.data.len().is_multiple_of(4) {
            self.data.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.views.push(v);
        self.views.len() - 1
    }
}

trait LeBytes {
    fn le(&self) -> [u8; 4];
}
impl LeBytes for f32 {
    fn le(&self) -> [u8; 4] {
        self.to_le_bytes()
    }
}
impl LeBytes for u32 {
    fn le(&self) -> [u8; 4] {
        self.to_le_bytes()
    }
}

fn bytes_of<'a, T: LeBytes + 'a>(it: impl Iterator<Item = &'a T>) -> Vec<u8> {
    it.flat_map(|x| x.le()).collect()
}

/// Unit `f32` normals per input vertex: the mesh's own (normalised) where usable, else
/// area-weighted face normals, else `[0, 0, 1]` (the validator requires unit length).
fn vertex_normals(mesh: &TriMesh) -> Vec<[f32; 3]> {
    let unit = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        (l > 1e-300 && l.is_finite()).then(|| v.map(|x| (x / l) as f32))
    };
    let mut acc = vec![[0.0f64; 3]; mesh.n_vertices()];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let cr = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
        for &i in t {
            for k in 0..3 {
                acc[i as usize][k] += cr[k];
            }
        }
    }
    (0..mesh.n_vertices())
        .map(|v| {
            mesh.vertex_normals
                .as_ref()
                .and_then(|n| unit(n[v]))
                .or_else(|| unit(acc[v]))
                .map(|n| {
                    // Renormalise in f32 so the stored length is 1 to f32 precision.
                    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                    n.map(|x| x / l)
                })
                .unwrap_or([0.0, 0.0, 1.0])
        })
        .collect()
}
