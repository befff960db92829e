//! Test-only loaders for the shared data (`fieldtex-io` cannot be a dependency of this
//! crate: it sits above it). Minimal on purpose: OBJ `v`/`vt`/`f` (polygons fanned,
//! `a/b/c` forms, negative indices), PLY ascii and binary little-endian with scalar
//! vertex properties and one face list.

use crate::{CornerUvs, TriMesh};
use std::path::{Path, PathBuf};

/// `../shared/data` beside the repository.
pub(crate) fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

/// Loads `meshes/<rel>` from the shared data.
pub(crate) fn load(rel: &str) -> TriMesh {
    let path = data_dir().join("meshes").join(rel);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    if rel.ends_with(".ply") {
        parse_ply(&bytes)
    } else {
        parse_obj(&String::from_utf8_lossy(&bytes))
    }
}

pub(crate) fn parse_obj(text: &str) -> TriMesh {
    let mut positions = Vec::new();
    let mut uv_values = Vec::new();
    let mut triangles = Vec::new();
    let mut uv_idx = Vec::new();
    let mut all_uv = true;
    let resolve = |s: &str, n: usize| -> u32 {
        let i: i64 = s.parse().expect("index");
        (if i < 0 { n as i64 + i } else { i - 1 }) as u32
    };
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f64> = it.take(3).map(|x| x.parse().expect("coordinate")).collect();
                positions.push([c[0], c[1], c[2]]);
            }
            Some("vt") => {
                let c: Vec<f64> = it.take(2).map(|x| x.parse().expect("uv")).collect();
                uv_values.push([c[0], c[1]]);
            }
            Some("f") => {
                let corners: Vec<(u32, Option<u32>)> = it
                    .map(|c| {
                        let mut p = c.split('/');
                        let v = resolve(p.next().unwrap(), positions.len());
                        let t =
                            p.next().filter(|s| !s.is_empty()).map(|s| resolve(s, uv_values.len()));
                        (v, t)
                    })
                    .collect();
                for k in 1..corners.len() - 1 {
                    let c = [corners[0], corners[k], corners[k + 1]];
                    triangles.push(c.map(|x| x.0));
                    match (c[0].1, c[1].1, c[2].1) {
                        (Some(a), Some(b), Some(d)) => uv_idx.push([a, b, d]),
                        _ => all_uv = false,
                    }
                }
            }
            _ => {}
        }
    }
    let mut m = TriMesh::new(positions, triangles);
    if all_uv && !uv_idx.is_empty() {
        m.uvs = Some(CornerUvs { values: uv_values, indices: uv_idx });
    }
    m
}

pub(crate) fn parse_ply(bytes: &[u8]) -> TriMesh {
    let end = bytes.windows(11).position(|w| w == b"end_header\n").expect("header") + 11;
    let header = std::str::from_utf8(&bytes[..end]).expect("ascii header");
    let binary = header.contains("binary_little_endian");
    // (element name, count, properties as (name, type, list count type))
    type Property = (String, String, Option<String>);
    let mut elements: Vec<(String, usize, Vec<Property>)> = Vec::new();
    for line in header.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.first().copied() {
            Some("element") => elements.push((w[1].into(), w[2].parse().unwrap(), Vec::new())),
            Some("property") if w[1] == "list" => {
                elements.last_mut().unwrap().2.push((w[4].into(), w[3].into(), Some(w[2].into())))
            }
            Some("property") => {
                elements.last_mut().unwrap().2.push((w[2].into(), w[1].into(), None))
            }
            _ => {}
        }
    }
    let size = |t: &str| match t {
        "char" | "uchar" | "int8" | "uint8" => 1,
        "short" | "ushort" | "int16" | "uint16" => 2,
        "int" | "uint" | "float" | "int32" | "uint32" | "float32" => 4,
        _ => 8,
    };
    let read = |b: &[u8], t: &str| -> f64 {
        match t {
            "char" | "int8" => b[0] as i8 as f64,
            "uchar" | "uint8" => b[0] as f64,
            "short" | "int16" => i16::from_le_bytes([b[0], b[1]]) as f64,
            "ushort" | "uint16" => u16::from_le_bytes([b[0], b[1]]) as f64,
            "int" | "int32" => i32::from_le_bytes(b[..4].try_into().unwrap()) as f64,
            "uint" | "uint32" => u32::from_le_bytes(b[..4].try_into().unwrap()) as f64,
            "float" | "float32" => f32::from_le_bytes(b[..4].try_into().unwrap()) as f64,
            _ => f64::from_le_bytes(b[..8].try_into().unwrap()),
        }
    };
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut pos = end;
    let body = String::from_utf8_lossy(&bytes[end..]).into_owned();
    let mut tokens = body.split_whitespace();
    for (name, count, props) in &elements {
        for _ in 0..*count {
            let mut xyz = [0.0; 3];
            let mut list: Vec<u32> = Vec::new();
            for (pname, ty, list_ty) in props {
                let mut scalar = |ty: &str| -> f64 {
                    if binary {
                        let v = read(&bytes[pos..], ty);
                        pos += size(ty);
                        v
                    } else {
                        tokens.next().unwrap().parse().unwrap()
                    }
                };
                if let Some(ct) = list_ty {
                    let n = scalar(ct) as usize;
                    let vals: Vec<u32> = (0..n).map(|_| scalar(ty) as u32).collect();
                    if pname == "vertex_indices" || pname == "vertex_index" {
                        list = vals;
                    }
                } else {
                    let v = scalar(ty);
                    match pname.as_str() {
                        "x" => xyz[0] = v,
                        "y" => xyz[1] = v,
                        "z" => xyz[2] = v,
                        _ => {}
                    }
                }
            }
            if name == "vertex" {
                positions.push(xyz);
            } else if name == "face" {
                for k in 1..list.len().saturating_sub(1) {
                    triangles.push([list[0], list[k], list[k + 1]]);
                }
            }
        }
    }
    TriMesh::new(positions, triangles)
}
