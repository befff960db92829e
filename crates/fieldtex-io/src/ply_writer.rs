//! PLY writer (binary little-endian or ASCII) with optional extra per-vertex properties,
//! e.g. `field.ply` with `x y z nx ny nz fx fy fz`.
//!
//! Vertex properties, in order: `x y z` (`float`), `nx ny nz` (`float`, when the mesh has
//! normals), `red green blue alpha` (`uchar`, sRGB as stored, when it has colours), then
//! each extra property (`float`) in the order given. Faces: `list uchar int
//! vertex_indices`, then, when the mesh has per-corner UVs, `list uchar float texcoord`
//! with `u0 v0 u1 v1 u2 v2` per triangle (MeshLab's convention, read back by
//! [`crate::read_mesh`]). Values are stored as 32-bit floats (PLY's most widely read
//! type).

use crate::{IoError, atomic_write};
use fieldtex_mesh::TriMesh;
use std::fmt::Write as _;
use std::path::Path;

/// Writes `mesh` with `extra_vertex_props` (`(name, #V values)`) to `path` atomically.
/// Names must be non-empty, free of whitespace and distinct from each other and from
/// the standard properties written for this mesh.
pub fn write_ply(
    path: &Path,
    mesh: &TriMesh,
    extra_vertex_props: &[(&str, &[f32])],
    binary: bool,
) -> Result<(), IoError> {
    let bytes =
        encode_ply(mesh, extra_vertex_props, binary).map_err(|m| IoError::invalid(path, m))?;
    atomic_write(path, &bytes)
}

/// The bytes [`write_ply`] writes.
pub fn encode_ply(
    mesh: &TriMesh,
    extra: &[(&str, &[f32])],
    binary: bool,
) -> Result<Vec<u8>, String> {
    mesh.validate().map_err(|e| format!("the mesh is not valid ({e}); run repair first"))?;
    let nv = mesh.n_vertices();
    let mut names: Vec<&str> = vec!["x", "y", "z"];
    if mesh.vertex_normals.is_some() {
        names.extend(["nx", "ny", "nz"]);
    }
    let color_names = ["red", "green", "blue", "alpha"];
    if mesh.vertex_colors.is_some() {
        names.extend(color_names);
    }
    for &(name, values) in extra {
        if name.is_empty() || name.chars().any(char::is_whitespace) {
            return Err(format!("property name {name:?} is empty or contains whitespace"));
        }
        if names.contains(&name) {
            return Err(format!("property {name:?} appears twice"));
        }
        if values.len() != nv {
            return Err(format!("property {name:?} has {} values for {nv} vertices", values.len()));
        }
        names.push(name);
    }
    let mut h = String::from("ply\n");
    h.push_str(if binary { "format binary_little_endian 1.0\n" } else { "format ascii 1.0\n" });
    h.push_str("comment written by fieldtex\n");
    let _ = writeln!(h, "element vertex {nv}");
    for n in &names {
        let ty = if color_names.contains(n)
            && mesh.vertex_colors.is_some()
            && !extra.iter().any(|e| e.0 == *n)
        {
            "uchar"
        } else {
            "float"
        };
        let _ = writeln!(h, "property {ty} {n}");
    }
    let _ = writeln!(h, "element face {}", mesh.n_triangles());
    h.push_str("property list uchar int vertex_indices\n");
    if mesh.uvs.is_some() {
        h.push_str("property list uchar float texcoord\n");
    }
    h.push_str("end_header\n");
    let corner_uv = |f: usize| -> [f32; 6] {
        let mut c = [0.0f32; 6];
        if let Some(uv) = &mesh.uvs {
            for k in 0..3 {
                let t = uv.values[uv.indices[f][k] as usize];
                c[2 * k] = t[0] as f32;
                c[2 * k + 1] = t[1] as f32;
            }
        }
        c
    };
    let q = |c: f32| if c.is_nan() { 0 } else { (c.clamp(0.0, 1.0) * 255.0).round() as u8 };
    let mut out = h.into_bytes();
    if binary {
        out.reserve(nv * 4 * names.len() + 13 * mesh.n_triangles());
        for v in 0..nv {
            for x in mesh.positions[v] {
                out.extend_from_slice(&(x as f32).to_le_bytes());
            }
            if let Some(n) = &mesh.vertex_normals {
                for x in n[v] {
                    out.extend_from_slice(&(x as f32).to_le_bytes());
                }
            }
            if let Some(c) = &mesh.vertex_colors {
                out.extend(c[v].map(q));
            }
            for (_, values) in extra {
                out.extend_from_slice(&values[v].to_le_bytes());
            }
        }
        for (f, t) in mesh.triangles.iter().enumerate() {
            out.push(3);
            for i in t {
                out.extend_from_slice(&(*i as i32).to_le_bytes());
            }
            if mesh.uvs.is_some() {
                out.push(6);
                for x in corner_uv(f) {
                    out.extend_from_slice(&x.to_le_bytes());
                }
            }
        }
    } else {
        let mut s = String::new();
        for v in 0..nv {
            let p = mesh.positions[v];
            let _ = write!(s, "{} {} {}", p[0] as f32, p[1] as f32, p[2] as f32);
            if let Some(n) = &mesh.vertex_normals {
                let n = n[v];
                let _ = write!(s, " {} {} {}", n[0] as f32, n[1] as f32, n[2] as f32);
            }
            if let Some(c) = &mesh.vertex_colors {
                let c = c[v].map(q);
                let _ = write!(s, " {} {} {} {}", c[0], c[1], c[2], c[3]);
            }
            for (_, values) in extra {
                let _ = write!(s, " {}", values[v]);
            }
            s.push('\n');
        }
        for (f, t) in mesh.triangles.iter().enumerate() {
            let _ = write!(s, "3 {} {} {}", t[0], t[1], t[2]);
            if mesh.uvs.is_some() {
                let c = corner_uv(f);
                let _ = write!(s, " 6 {} {} {} {} {} {}", c[0], c[1], c[2], c[3], c[4], c[5]);
            }
            s.push('\n');
        }
        out.extend_from_slice(s.as_bytes());
    }
    Ok(out)
}
