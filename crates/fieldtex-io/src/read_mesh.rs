//! The mesh reading entry points: format recognition, dispatch, and resolution of the
//! textures a file refers to (OBJ `mtllib`/`map_Kd`, PLY `TextureFile`, glTF images).

use crate::error::MEMORY_NAME;
use crate::mesh_format::sniff_mesh_format;
use crate::{IoError, MeshFormat};
use fieldtex_core::{Image, Warning};
use fieldtex_mesh::TriMesh;
use std::path::Path;

/// A mesh as read from a file, with the base-colour texture it refers to (if any and if
/// it could be loaded) and every warning produced while reading.
#[derive(Debug, Clone)]
pub struct LoadedMesh {
    pub mesh: TriMesh,
    /// The diffuse/base-colour texture (OBJ `map_Kd`, glTF `baseColorTexture`, PLY
    /// `comment TextureFile`), when the file names one that loaded.
    pub base_color: Option<Image>,
    pub warnings: Vec<Warning>,
    /// The format actually read (from content first, extension second).
    pub format: MeshFormat,
}

/// Reads an OBJ, PLY, STL, glTF or GLB file. The format comes from the content first and
/// the extension second; a mismatch is a warning. Textures named by the file are looked
/// up relative to it; a missing one is a warning, not an error.
pub fn read_mesh(path: &Path) -> Result<LoadedMesh, IoError> {
    let bytes = crate::read_input_file(path, crate::InputKind::Mesh, "read the mesh")?;
    let base = path.parent().map(|p| if p.as_os_str().is_empty() { Path::new(".") } else { p });
    read_impl(&bytes, MeshFormat::from_extension(path), base, &path.display().to_string())
}

/// Reads a mesh from memory (`<memory>` in messages). `format_hint` plays the role of the
/// extension. External files (OBJ materials, glTF buffers and images) cannot be
/// resolved: materials and images are skipped with a warning, external glTF buffers are
/// an error.
pub fn read_mesh_bytes(
    bytes: &[u8],
    format_hint: Option<MeshFormat>,
) -> Result<LoadedMesh, IoError> {
    read_impl(bytes, format_hint, None, MEMORY_NAME)
}

fn read_impl(
    bytes: &[u8],
    hint: Option<MeshFormat>,
    base: Option<&Path>,
    name: &str,
) -> Result<LoadedMesh, IoError> {
    if bytes.is_empty() {
        return Err(IoError::EmptyFile { file: name.to_string() });
    }
    let sniffed = sniff_mesh_format(bytes);
    let mut warnings = Vec::new();
    let format = match (sniffed, hint) {
        (Some(s), Some(h)) if s != h => {
            warnings.push(Warning::new(
                "format-mismatch",
                format!("{name}: the name says {h} but the content is {s}; read as {s}"),
            ));
            s
        }
        (Some(s), _) => s,
        (None, Some(h)) => h,
        (None, None) => {
            return Err(IoError::UnknownFormat {
                file: name.to_string(),
                detail: "neither the content nor the file extension identifies a mesh format"
                    .into(),
            });
        }
    };
    let (mesh, base_color, mut w) = match format {
        MeshFormat::Obj => {
            let (mesh, refs, mut w) = crate::obj_reader::read_obj_bytes(bytes, name)?;
            let tex = obj_texture(&refs, base, name, &mut w);
            (mesh, tex, w)
        }
        MeshFormat::Ply => {
            let (mesh, refs, mut w) = crate::ply_reader::read_ply_bytes(bytes, name)?;
            let tex = refs.texture_file.and_then(|t| load_texture(&t, base, name, &mut w));
            (mesh, tex, w)
        }
        MeshFormat::Stl => {
            let (mesh, w) = crate::stl_reader::read_stl_bytes(bytes, name)?;
            (mesh, None, w)
        }
        MeshFormat::Gltf => crate::gltf_reader::read_gltf_bytes(bytes, base, name)?,
    };
    warnings.append(&mut w);
    Ok(LoadedMesh { mesh, base_color, warnings, format })
}

/// Finds and loads the diffuse texture of an OBJ: the first material used by a face that
/// has a `map_Kd` (or, with no `usemtl`, the first material that has one).
fn obj_texture(
    refs: &crate::obj_reader::ObjMaterialRefs,
    base: Option<&Path>,
    name: &str,
    warnings: &mut Vec<Warning>,
) -> Option<Image> {
    if refs.mtllibs.is_empty() {
        return None;
    }
    let Some(base) = base else {
        warnings.push(Warning::new(
            "materials-not-resolved",
            format!("{name}: material libraries are not read for in-memory data"),
        ));
        return None;
    };
    let mut materials: Vec<(String, Option<String>, std::path::PathBuf)> = Vec::new();
    for lib in &refs.mtllibs {
        // A name with spaces is one file if it exists, otherwise several files.
        let candidates: Vec<String> = if base.join(lib.replace('\\', "/")).is_file() {
            vec![lib.clone()]
        } else {
            lib.split_whitespace().map(str::to_string).collect()
        };
        for c in candidates {
            let read = crate::resolve_confined(base, &c, name, "material library (mtllib)")
                .and_then(|p| {
                    let b = crate::read_input_file(
                        &p,
                        crate::InputKind::Text,
                        "read the material library",
                    )?;
                    Ok((p, b))
                });
            match read {
                Ok((p, b)) => {
                    // Textures are named relative to the MTL file's folder.
                    let dir = p.parent().unwrap_or(base).to_path_buf();
                    materials.extend(
                        crate::mtl_reader::parse_mtl(&b)
                            .into_iter()
                            .map(|(n, t)| (n, t, dir.clone())),
                    );
                }
                Err(e) => warnings.push(Warning::new(
                    "mtl-missing",
                    format!("material library {c:?} not read ({e}); no texture loaded"),
                )),
            }
        }
    }
    let chosen = if refs.used_materials.is_empty() {
        materials.iter().find(|m| m.1.is_some())
    } else {
        let used_with_tex: Vec<_> = refs
            .used_materials
            .iter()
            .filter_map(|u| materials.iter().find(|m| &m.0 == u && m.1.is_some()))
            .collect();
        if used_with_tex.len() > 1 {
            warnings.push(Warning::new(
                "obj-several-textures",
                format!(
                    "{name}: {} materials with textures are used; only {:?} was loaded",
                    used_with_tex.len(),
                    used_with_tex[0].0
                ),
            ));
        }
        used_with_tex.first().copied()
    }?;
    // Confine the texture to the OBJ's folder: name it relative to that folder.
    let root = std::fs::canonicalize(base).ok()?;
    let rel_dir = chosen.2.strip_prefix(&root).unwrap_or(Path::new(""));
    let file = chosen.1.as_deref()?;
    let reference = if rel_dir.as_os_str().is_empty() {
        file.to_string()
    } else {
        format!("{}/{file}", rel_dir.display())
    };
    load_texture(&reference, Some(base), name, warnings)
}

/// Loads `file` relative to `base`; failure is a `texture-not-loaded` warning.
fn load_texture(
    file: &str,
    base: Option<&Path>,
    name: &str,
    warnings: &mut Vec<Warning>,
) -> Option<Image> {
    let Some(base) = base else {
        warnings.push(Warning::new(
            "texture-not-loaded",
            format!("{name}: texture {file:?} is not read for in-memory data"),
        ));
        return None;
    };
    let image =
        crate::resolve_confined(base, file, name, "texture").and_then(|p| crate::read_image(&p));
    match image {
        Ok(im) => Some(im),
        Err(e) => {
            warnings.push(Warning::new(
                "texture-not-loaded",
                format!("{name}: texture {file:?} not loaded: {e}"),
            ));
            None
        }
    }
}
