//! Test-only meshes: procedural defect categories and minimal loaders for the fixtures
//! in `../shared/data/meshes`. `fieldtex-io` cannot be a dependency of this crate (it
//! sits above it), so the loaders are minimal on purpose: OBJ `v`/`vt`/`f` (polygons
//! fanned, `a/b/c` forms, negative indices), PLY ascii and binary little-endian with
//! scalar vertex properties and one face list.

use crate::primitives::{grid, icosphere, torus};
use crate::{CornerUvs, TriMesh};
use std::path::PathBuf;

/// `shared/data/meshes/<name>` beside the repository.
pub fn fixture_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/meshes").join(name)
}

/// An OBJ fixture, or `None` when the file is missing so tests can skip.
pub fn load_obj(name: &str) -> Option<TriMesh> {
    let text = std::fs::read_to_string(fixture_path(name)).ok()?;
    Some(parse_obj(&text))
}

/// Loads `meshes/<name>` (OBJ or PLY), panicking with the path when it cannot be read.
pub fn load(name: &str) -> TriMesh {
    let path = fixture_path(name);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    if name.ends_with(".ply") {
        parse_ply(&bytes)
    } else {
        parse_obj(&String::from_utf8_lossy(&bytes))
    }
}

/// A grid patch with defects attached on its boundary: a zero-area flap (collinear
/// corners), a needle (apex angle ≈ 2.5e-4), an extreme needle (≈ 2.5e-9, gets
/// floored), a triangle with three coincident corners, and one unreferenced vertex.
pub fn defective_patch() -> TriMesh {
    let mut m = grid(4, 4, 1.0, 1.0);
    let id = |i: u32, j: u32| j * 5 + i;
    let add = |m: &mut TriMesh, p: [f64; 3]| {
        m.positions.push(p);
        (m.positions.len() - 1) as u32
    };
    // Zero-area flap on the bottom edge (0,0)-(1,0): midpoint.
    let mid = add(&mut m, [0.125, 0.0, 0.0]);
    m.triangles.push([id(1, 0), id(0, 0), mid]);
    // Needle on the right edge.
    let far = add(&mut m, [1000.0, 0.375, 0.0]);
    m.triangles.push([id(4, 1), far, id(4, 2)]);
    // Extreme needle on the top edge, pointing up 1e8.
    let very_far = add(&mut m, [0.375, 1e8, 0.0]);
    m.triangles.push([id(2, 4), id(1, 4), very_far]);
    // Three coincident corners (distinct indices).
    let a = add(&mut m, [2.0, 2.0, 2.0]);
    let b = add(&mut m, [2.0, 2.0, 2.0]);
    let c = add(&mut m, [2.0, 2.0, 2.0]);
    m.triangles.push([a, b, c]);
    // Unreferenced vertex.
    add(&mut m, [-3.0, 0.0, 1.0]);
    m
}

/// Two triangles meeting only at vertex 0 (a bowtie: one non-manifold vertex, two
/// fans): positions `0..5`, triangles `[0, 1, 2]` and `[0, 3, 4]`.
pub fn bowtie() -> TriMesh {
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [-1.0, -1.0, 0.0],
    ];
    TriMesh::new(p, vec![[0, 1, 2], [0, 3, 4]])
}

/// Two components: an icosphere and a torus beside it.
pub fn two_components() -> TriMesh {
    let mut m = icosphere(2);
    let t = torus(1.0, 0.3, 24, 10);
    let off = m.n_vertices() as u32;
    m.positions.extend(t.positions.iter().map(|p| [p[0] + 4.0, p[1], p[2]]));
    m.triangles.extend(t.triangles.iter().map(|t| t.map(|i| i + off)));
    m
}

/// [`categories`] followed by the shared fixtures `names` that are present (a missing
/// file is skipped, as in [`load_obj`]).
pub fn categories_and(names: &[&'static str]) -> Vec<(&'static str, TriMesh)> {
    let mut all = categories();
    all.extend(names.iter().filter_map(|&name| load_obj(name).map(|m| (name, m))));
    all
}

/// The procedural categories every operator is run over, with a name.
pub fn categories() -> Vec<(&'static str, TriMesh)> {
    vec![
        ("closed-genus0", icosphere(3)),
        ("closed-genus1", torus(2.0, 0.6, 36, 14)),
        ("boundary-grid", grid(10, 8, 2.0, 1.5)),
        ("defective", defective_patch()),
        ("two-components", two_components()),
    ]
}

/// An OBJ's positions, triangles and (when every face has them) corner UVs.
pub fn parse_obj(text: &str) -> TriMesh {
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

/// A PLY's positions and triangles.
pub fn parse_ply(bytes: &[u8]) -> TriMesh {
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
