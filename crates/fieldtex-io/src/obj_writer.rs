//! OBJ writers: textured meshes (`.obj` + `.mtl` + `.png`) and polylines (`l` elements).
//!
//! Numbers are written with Rust's shortest round-trip formatting, so reading a written
//! file gives back the exact `f64` positions and UVs. Vertex colours use the common
//! `v x y z r g b` extension (sRGB, as stored). Normals (when the mesh has them) are
//! written once per vertex and referenced by the vertex's index.

use crate::{IoError, atomic_write, encode_png};
use fieldtex_core::Image;
use fieldtex_mesh::TriMesh;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Writes `path_obj`; with a texture also `NAME.mtl` (material `fieldtex_material`,
/// `map_Kd NAME.png`) and `NAME.png` beside it, where `NAME` is the OBJ's file stem. Each
/// file is written atomically; the image first, the OBJ last.
pub fn write_obj(path_obj: &Path, mesh: &TriMesh, texture: Option<&Image>) -> Result<(), IoError> {
    mesh.validate().map_err(|e| {
        IoError::invalid(path_obj, format!("the mesh is not valid ({e}); run repair first"))
    })?;
    let stem = path_obj
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .ok_or_else(|| IoError::invalid(path_obj, "the output path has no file name"))?;
    let beside = |ext: &str| -> PathBuf { path_obj.with_file_name(format!("{stem}.{ext}")) };
    let mut out = String::with_capacity(64 * (mesh.n_vertices() + mesh.n_triangles()));
    out.push_str("# written by fieldtex\n");
    if let Some(tex) = texture {
        if mesh.uvs.is_none() {
            return Err(IoError::invalid(
                path_obj,
                "a texture was given but the mesh has no texture coordinates",
            ));
        }
        let png = encode_png(tex).map_err(|e| IoError::invalid(path_obj, e.to_string()))?;
        atomic_write(&beside("png"), &png)?;
        let mtl = format!(
            "# written by fieldtex\nnewmtl fieldtex_material\nKa 0 0 0\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd {stem}.png\n"
        );
        atomic_write(&beside("mtl"), mtl.as_bytes())?;
        let _ = writeln!(out, "mtllib {stem}.mtl");
    }
    for (v, p) in mesh.positions.iter().enumerate() {
        match &mesh.vertex_colors {
            Some(c) => {
                let c = c[v];
                let _ = writeln!(out, "v {} {} {} {} {} {}", p[0], p[1], p[2], c[0], c[1], c[2]);
            }
            None => {
                let _ = writeln!(out, "v {} {} {}", p[0], p[1], p[2]);
            }
        }
    }
    if let Some(uv) = &mesh.uvs {
        for t in &uv.values {
            let _ = writeln!(out, "vt {} {}", t[0], t[1]);
        }
    }
    if let Some(n) = &mesh.vertex_normals {
        for q in n {
            let _ = writeln!(out, "vn {} {} {}", q[0], q[1], q[2]);
        }
    }
    if texture.is_some() {
        out.push_str("usemtl fieldtex_material\n");
    }
    let has_n = mesh.vertex_normals.is_some();
    for (f, t) in mesh.triangles.iter().enumerate() {
        out.push('f');
        for (k, &v) in t.iter().enumerate() {
            let v = v + 1;
            match (&mesh.uvs, has_n) {
                (Some(uv), true) => write!(out, " {v}/{}/{v}", uv.indices[f][k] + 1),
                (Some(uv), false) => write!(out, " {v}/{}", uv.indices[f][k] + 1),
                (None, true) => write!(out, " {v}//{v}"),
                (None, false) => write!(out, " {v}"),
            }
            .expect("writing to a String cannot fail");
        }
        out.push('\n');
    }
    atomic_write(path_obj, out.as_bytes())
}

/// Writes polylines as an OBJ of `v` and `l` elements (one `l` per polyline). Polylines
/// with fewer than 2 points are skipped (an `l` element needs two); non-finite points
/// are an error.
pub fn write_obj_polylines(path: &Path, polylines: &[Vec<[f64; 3]>]) -> Result<(), IoError> {
    let mut out = String::from("# written by fieldtex: polylines\n");
    let mut next = 1usize;
    let mut lines = String::new();
    for (i, pl) in polylines.iter().enumerate() {
        if pl.len() < 2 {
            continue;
        }
        lines.push('l');
        for p in pl {
            if !p.iter().all(|x| x.is_finite()) {
                return Err(IoError::invalid(
                    path,
                    format!("polyline {i} has a non-finite point {p:?}"),
                ));
            }
            let _ = writeln!(out, "v {} {} {}", p[0], p[1], p[2]);
            let _ = write!(lines, " {next}");
            next += 1;
        }
        lines.push('\n');
    }
    out.push_str(&lines);
    atomic_write(path, out.as_bytes())
}
