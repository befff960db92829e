//! glTF 2.0 reader (`.gltf` JSON and `.glb` binary).
//!
//! Reads every triangle primitive (`TRIANGLES`, `TRIANGLE_STRIP`, `TRIANGLE_FAN`) of
//! every mesh reached from the default scene (or the first scene; with no scene, every
//! mesh once, untransformed), applies the node transforms (the normals with the inverse
//! transpose; triangles of mirrored nodes are re-wound), and merges everything into one
//! [`TriMesh`]: `POSITION`, `NORMAL`, `COLOR_0` and `TEXCOORD_0` (V flipped back:
//! `v = 1 − v_gltf`). The base-colour texture of the first material that has one is
//! decoded (embedded buffer view, `data:` URI or a file next to the glTF).
//!
//! glTF splits vertices at UV seams, so vertices with bit-identical positions are welded
//! after loading (texture coordinates stay per corner, so seams are kept); a `gltf-welded`
//! warning reports it. Not read: sparse accessors, morph targets, skins, Draco/meshopt
//! compression (refused with a clear error), textures other than base colour. Node
//! instancing is capped at [`MAX_MERGED_ELEMENTS`] vertices and triangles so a small
//! file cannot expand into an unbounded mesh.
//!
//! The JSON is parsed and its indices validated by the `gltf` crate; the GLB container
//! and every accessor are bounds-checked here, so a hostile file cannot make the reader
//! read out of bounds or allocate beyond what the file holds.

mod container;

use crate::IoError;
use fieldtex_core::{Image, Warning};
use fieldtex_mesh::{CornerUvs, TriMesh};
use gltf::accessor::DataType;
use gltf::mesh::Mode;
use std::path::Path;

pub(crate) use container::load_uri;

/// Parses glTF or GLB bytes. `base` is the directory external files are resolved from
/// (`None` for in-memory data: external buffers are then an error, external images a
/// warning). Returns the mesh, the base-colour image if found, and warnings.
pub fn read_gltf_bytes(
    bytes: &[u8],
    base: Option<&Path>,
    name: &str,
) -> Result<(TriMesh, Option<Image>, Vec<Warning>), IoError> {
    let (json, bin) =
        if bytes.starts_with(b"glTF") { container::split_glb(bytes, name)? } else { (bytes, None) };
    let root: gltf::json::Root = gltf::json::deserialize::from_slice(json).map_err(|e| {
        IoError::parse(name, format!("JSON line {} column {}", e.line(), e.column()), e.to_string())
    })?;
    // gltf-json 1.4's validation indexes the POSITION accessor before checking that it
    // exists (a panic on a dangling index): check that reference here first.
    let positions_key = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
    for (mi, mesh) in root.meshes.iter().enumerate() {
        for (pi, prim) in mesh.primitives.iter().enumerate() {
            if let Some(a) = prim.attributes.get(&positions_key)
                && a.value() >= root.accessors.len()
            {
                return Err(IoError::parse(
                    name,
                    format!("mesh {mi} primitive {pi}"),
                    format!(
                        "POSITION refers to accessor {} but only {} exist",
                        a.value(),
                        root.accessors.len()
                    ),
                ));
            }
        }
    }
    let doc = gltf::Document::from_json(root)
        .map_err(|e| IoError::parse(name, "glTF JSON", format!("invalid glTF document: {e}")))?;
    if let Some(ext) = doc.extensions_required().next() {
        return Err(IoError::Unsupported {
            file: name.to_string(),
            what: format!("the required glTF extension {ext}"),
        });
    }
    let mut buffers = Vec::new();
    for b in doc.buffers() {
        let data = match b.source() {
            gltf::buffer::Source::Bin => bin.map(<[u8]>::to_vec).ok_or_else(|| {
                IoError::parse(
                    name,
                    format!("buffer {}", b.index()),
                    "refers to a GLB BIN chunk that is missing",
                )
            })?,
            gltf::buffer::Source::Uri(uri) => load_uri(uri, base, name, Some(b.length() as u64))?,
        };
        if data.len() < b.length() {
            return Err(IoError::Truncated {
                file: name.to_string(),
                what: format!("buffer {} (byteLength {})", b.index(), b.length()),
                needed: b.length() as u64,
                available: data.len() as u64,
            });
        }
        buffers.push(data);
    }
    let mut m = Merger { name, buffers: &buffers, ..Default::default() };
    for (mesh, xf) in mesh_instances(&doc) {
        for prim in mesh.primitives() {
            m.add_primitive(&prim, &xf)?;
        }
    }
    let mut warnings = std::mem::take(&mut m.warnings);
    let image_index = m.image;
    let mesh = m.finish(&mut warnings)?;
    let base_color = image_index.and_then(|i| match load_image(&doc, i, &buffers, base, name) {
        Ok(im) => Some(im),
        Err(e) => {
            warnings.push(Warning::new(
                "texture-not-loaded",
                format!("base-colour texture not loaded: {e}"),
            ));
            None
        }
    });
    Ok((mesh, base_color, warnings))
}

/// Most vertices (and, separately, triangles) a glTF may expand to after instancing.
pub const MAX_MERGED_ELEMENTS: usize = 1 << 27;

type Mat4 = [[f64; 4]; 4]; // column-major: m[col][row]

const IDENTITY: Mat4 = [[1., 0., 0., 0.], [0., 1., 0., 0.], [0., 0., 1., 0.], [0., 0., 0., 1.]];

fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut r = [[0.0; 4]; 4];
    for (c, rc) in r.iter_mut().enumerate() {
        for (row, x) in rc.iter_mut().enumerate() {
            *x = (0..4).map(|k| a[k][row] * b[c][k]).sum();
        }
    }
    r
}

/// Every (mesh, world transform) pair to read, each node visited at most once.
fn mesh_instances(doc: &gltf::Document) -> Vec<(gltf::Mesh<'_>, Mat4)> {
    let scene = doc.default_scene().or_else(|| doc.scenes().next());
    let Some(scene) = scene else {
        return doc.meshes().map(|m| (m, IDENTITY)).collect();
    };
    let mut out = Vec::new();
    let mut visited = vec![false; doc.nodes().count()];
    // Depth-first, children in document order (pushed reversed onto the stack).
    let mut stack: Vec<(gltf::Node<'_>, Mat4)> = scene.nodes().map(|n| (n, IDENTITY)).collect();
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            continue; // a cycle or a shared child: invalid glTF, read once
        }
        let local = node.transform().matrix().map(|c| c.map(|x| x as f64));
        let world = mul(&parent, &local);
        if let Some(mesh) = node.mesh() {
            out.push((mesh, world));
        }
        let first_child = stack.len();
        stack.extend(node.children().map(|c| (c, world)));
        stack[first_child..].reverse();
    }
    out
}

#[derive(Default)]
struct Merger<'a> {
    name: &'a str,
    buffers: &'a [Vec<u8>],
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    uvs: Vec<[f64; 2]>,
    normals: Vec<[f64; 3]>,
    colors: Vec<[f32; 4]>,
    /// Vertex counts of primitives lacking UV / normal / colour.
    missing: [usize; 3],
    present: [usize; 3],
    image: Option<usize>,
    skipped_modes: usize,
    warnings: Vec<Warning>,
}

impl Merger<'_> {
    fn add_primitive(&mut self, prim: &gltf::Primitive<'_>, xf: &Mat4) -> Result<(), IoError> {
        let mode = prim.mode();
        if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
            self.skipped_modes += 1;
            return Ok(());
        }
        let what = |s: &str| format!("mesh primitive {} attribute {s}", prim.index());
        let Some(pos_acc) = prim.get(&gltf::Semantic::Positions) else {
            return Err(IoError::parse(
                self.name,
                what("POSITION"),
                "a triangle primitive without positions",
            ));
        };
        // Instancing (many nodes, one mesh) can multiply a small file into a huge mesh.
        let first = self.positions.len();
        let budget = |what: &str, total: usize| {
            if total > MAX_MERGED_ELEMENTS {
                return Err(IoError::Unsupported {
                    file: self.name.to_string(),
                    what: format!(
                        "more than {MAX_MERGED_ELEMENTS} {what} after applying node instancing"
                    ),
                });
            }
            Ok(())
        };
        let pos = read_accessor::<3>(&pos_acc, self.buffers, self.name, &what("POSITION"))?;
        let n = pos.len();
        budget("vertices", first.saturating_add(n))?;
        self.positions.extend(pos.iter().map(|p| {
            let t = |r: usize| xf[0][r] * p[0] + xf[1][r] * p[1] + xf[2][r] * p[2] + xf[3][r];
            [t(0), t(1), t(2)]
        }));
        let idx: Vec<u32> = match prim.indices() {
            Some(a) => read_accessor::<1>(&a, self.buffers, self.name, &what("indices"))?
                .into_iter()
                .map(|v| v[0] as u32)
                .collect(),
            None => (0..n as u32).collect(),
        };
        budget("triangles", self.triangles.len().saturating_add(idx.len()))?;
        let tri_count = self.triangles.len();
        let mut push = |t: [u32; 3]| -> Result<(), IoError> {
            if let Some(&bad) = t.iter().find(|&&i| i as usize >= n) {
                return Err(IoError::IndexOutOfRange {
                    file: self.name.to_string(),
                    face: self.triangles.len(),
                    index: bad as i64,
                    n_vertices: n,
                });
            }
            self.triangles.push(t.map(|i| i + first as u32));
            Ok(())
        };
        match mode {
            Mode::Triangles => idx.chunks_exact(3).try_for_each(|c| push([c[0], c[1], c[2]]))?,
            Mode::TriangleStrip => (2..idx.len()).try_for_each(|i| {
                let (a, b, c) = (idx[i - 2], idx[i - 1], idx[i]);
                push(if i % 2 == 0 { [a, b, c] } else { [b, a, c] })
            })?,
            _ => (2..idx.len()).try_for_each(|i| push([idx[0], idx[i - 1], idx[i]]))?,
        }
        // A mirroring transform flips the winding; restore counter-clockwise.
        let det = xf[0][0] * (xf[1][1] * xf[2][2] - xf[2][1] * xf[1][2])
            - xf[1][0] * (xf[0][1] * xf[2][2] - xf[2][1] * xf[0][2])
            + xf[2][0] * (xf[0][1] * xf[1][2] - xf[1][1] * xf[0][2]);
        if det < 0.0 {
            for t in &mut self.triangles[tri_count..] {
                t.swap(1, 2);
            }
        }
        self.add_uvs(prim, n, &what)?;
        self.add_normals(prim, n, xf, &what)?;
        self.add_colors(prim, n, &what)?;
        if let Some(info) = prim.material().pbr_metallic_roughness().base_color_texture() {
            let img = info.texture().source().index();
            match self.image {
                None => {
                    self.image = Some(img);
                    if info.tex_coord() != 0 {
                        self.warnings.push(Warning::new(
                            "gltf-texcoord-set",
                            format!(
                                "{}: the base-colour texture uses TEXCOORD_{}; TEXCOORD_0 was read",
                                self.name,
                                info.tex_coord()
                            ),
                        ));
                    }
                }
                Some(i) if i != img => {
                    self.warnings.push(Warning::new(
                        "gltf-several-textures",
                        format!("{}: primitives use different base-colour images; only image {i} was loaded", self.name),
                    ));
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn add_uvs(
        &mut self,
        prim: &gltf::Primitive<'_>,
        n: usize,
        what: &dyn Fn(&str) -> String,
    ) -> Result<(), IoError> {
        match prim.get(&gltf::Semantic::TexCoords(0)) {
            Some(a) => {
                let uv = read_accessor::<2>(&a, self.buffers, self.name, &what("TEXCOORD_0"))?;
                check_len(self.name, &what("TEXCOORD_0"), uv.len(), n)?;
                self.uvs.extend(uv.iter().map(|t| [t[0], 1.0 - t[1]]));
                self.present[0] += n;
            }
            None => {
                self.uvs.extend(std::iter::repeat_n([0.0, 0.0], n));
                self.missing[0] += n;
            }
        }
        Ok(())
    }

    fn add_normals(
        &mut self,
        prim: &gltf::Primitive<'_>,
        n: usize,
        xf: &Mat4,
        what: &dyn Fn(&str) -> String,
    ) -> Result<(), IoError> {
        match prim.get(&gltf::Semantic::Normals) {
            Some(a) => {
                let nr = read_accessor::<3>(&a, self.buffers, self.name, &what("NORMAL"))?;
                check_len(self.name, &what("NORMAL"), nr.len(), n)?;
                // Cofactor matrix = det · inverse transpose; the scale is removed below.
                let m = |c: usize, r: usize| xf[c][r];
                let cof = [
                    [
                        m(1, 1) * m(2, 2) - m(2, 1) * m(1, 2),
                        m(2, 1) * m(0, 2) - m(0, 1) * m(2, 2),
                        m(0, 1) * m(1, 2) - m(1, 1) * m(0, 2),
                    ],
                    [
                        m(2, 0) * m(1, 2) - m(1, 0) * m(2, 2),
                        m(0, 0) * m(2, 2) - m(2, 0) * m(0, 2),
                        m(1, 0) * m(0, 2) - m(0, 0) * m(1, 2),
                    ],
                    [
                        m(1, 0) * m(2, 1) - m(2, 0) * m(1, 1),
                        m(2, 0) * m(0, 1) - m(0, 0) * m(2, 1),
                        m(0, 0) * m(1, 1) - m(1, 0) * m(0, 1),
                    ],
                ];
                self.normals.extend(nr.iter().map(|v| {
                    let t =
                        [0, 1, 2].map(|r| cof[r][0] * v[0] + cof[r][1] * v[1] + cof[r][2] * v[2]);
                    let l = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
                    if l > 0.0 && l.is_finite() { t.map(|x| x / l) } else { [0.0; 3] }
                }));
                self.present[1] += n;
            }
            None => {
                self.normals.extend(std::iter::repeat_n([0.0; 3], n));
                self.missing[1] += n;
            }
        }
        Ok(())
    }

    fn add_colors(
        &mut self,
        prim: &gltf::Primitive<'_>,
        n: usize,
        what: &dyn Fn(&str) -> String,
    ) -> Result<(), IoError> {
        match prim.get(&gltf::Semantic::Colors(0)) {
            Some(a) => {
                let dims = a.dimensions().multiplicity();
                let c: Vec<[f32; 4]> = if dims == 3 {
                    read_accessor::<3>(&a, self.buffers, self.name, &what("COLOR_0"))?
                        .iter()
                        .map(|c| {
                            [linear_to_srgb(c[0]), linear_to_srgb(c[1]), linear_to_srgb(c[2]), 1.0]
                        })
                        .collect()
                } else {
                    read_accessor::<4>(&a, self.buffers, self.name, &what("COLOR_0"))?
                        .iter()
                        .map(|c| {
                            [
                                linear_to_srgb(c[0]),
                                linear_to_srgb(c[1]),
                                linear_to_srgb(c[2]),
                                c[3] as f32,
                            ]
                        })
                        .collect()
                };
                check_len(self.name, &what("COLOR_0"), c.len(), n)?;
                self.colors.extend(c);
                self.present[2] += n;
            }
            None => {
                self.colors.extend(std::iter::repeat_n([1.0; 4], n));
                self.missing[2] += n;
            }
        }
        Ok(())
    }

    fn finish(self, warnings: &mut Vec<Warning>) -> Result<TriMesh, IoError> {
        let name = self.name;
        if self.skipped_modes > 0 {
            warnings.push(Warning::new(
                "gltf-non-triangle-primitives",
                format!("{name}: skipped {} point/line primitive(s)", self.skipped_modes),
            ));
        }
        if self.triangles.is_empty() {
            return Err(IoError::EmptyMesh {
                file: name.to_string(),
                detail: format!("{} vertices in triangle primitives", self.positions.len()),
            });
        }
        for (k, attr) in
            ["TEXCOORD_0 (given UV (0, 0))", "NORMAL (normals dropped)", "COLOR_0 (given white)"]
                .iter()
                .enumerate()
        {
            if self.present[k] > 0 && self.missing[k] > 0 {
                warnings.push(Warning::new(
                    "gltf-attribute-missing",
                    format!(
                        "{name}: {} of {} vertices have no {attr}",
                        self.missing[k],
                        self.missing[k] + self.present[k]
                    ),
                ));
            }
        }
        crate::mesh_checks::warn_non_finite(name, &self.positions, warnings);
        let (positions, remap) = crate::mesh_checks::weld_identical(&self.positions);
        let nv = positions.len();
        if nv < self.positions.len() {
            warnings.push(Warning::new(
                "gltf-welded",
                format!("{name}: welded {} vertices into {nv} (bit-identical positions, e.g. at UV seams)", self.positions.len()),
            ));
        }
        let gather = |n: usize| {
            let mut first = vec![usize::MAX; n];
            for (old, &new) in remap.iter().enumerate() {
                if first[new as usize] == usize::MAX {
                    first[new as usize] = old;
                }
            }
            first
        };
        let first = gather(nv);
        let uvs = (self.present[0] > 0)
            .then(|| CornerUvs { values: self.uvs, indices: self.triangles.clone() });
        let vertex_normals = (self.present[1] > 0 && self.missing[1] == 0)
            .then(|| first.iter().map(|&o| self.normals[o]).collect());
        let vertex_colors =
            (self.present[2] > 0).then(|| first.iter().map(|&o| self.colors[o]).collect());
        let triangles = self.triangles.iter().map(|t| t.map(|i| remap[i as usize])).collect();
        Ok(TriMesh { positions, triangles, uvs, vertex_colors, vertex_normals })
    }
}

fn linear_to_srgb(c: f64) -> f32 {
    fieldtex_core::image::linear_to_srgb((c as f32).clamp(0.0, 1.0))
}

fn check_len(name: &str, what: &str, got: usize, want: usize) -> Result<(), IoError> {
    if got != want {
        return Err(IoError::parse(
            name,
            what,
            format!("has {got} elements but POSITION has {want}"),
        ));
    }
    Ok(())
}

/// Reads an accessor of `N` components per element as `f64`, honouring `normalized`,
/// with every offset checked against the buffer.
fn read_accessor<const N: usize>(
    acc: &gltf::Accessor<'_>,
    buffers: &[Vec<u8>],
    name: &str,
    what: &str,
) -> Result<Vec<[f64; N]>, IoError> {
    let bad = |m: String| IoError::parse(name, what, m);
    if acc.dimensions().multiplicity() != N {
        return Err(bad(format!(
            "expected {N} components per element, found {}",
            acc.dimensions().multiplicity()
        )));
    }
    if acc.sparse().is_some() {
        return Err(IoError::Unsupported {
            file: name.to_string(),
            what: format!("sparse accessor ({what})"),
        });
    }
    let view = acc.view().ok_or_else(|| bad("accessor without a bufferView".into()))?;
    let comp = acc.data_type();
    let csize = comp.size();
    let elem = csize * N;
    let stride = view.stride().unwrap_or(elem).max(elem);
    let data = &buffers[view.buffer().index()];
    let view_end = view.offset().checked_add(view.length()).filter(|&e| e <= data.len());
    let view_end = view_end.ok_or_else(|| IoError::Truncated {
        file: name.to_string(),
        what: format!("bufferView {} of {what}", view.index()),
        needed: (view.offset() as u64).saturating_add(view.length() as u64),
        available: data.len() as u64,
    })?;
    let view_data = &data[view.offset()..view_end];
    let count = acc.count();
    if count > 0 {
        let need = (count as u64 - 1)
            .checked_mul(stride as u64)
            .and_then(|x| x.checked_add(acc.offset() as u64))
            .and_then(|x| x.checked_add(elem as u64));
        if need.is_none_or(|need| need > view_data.len() as u64) {
            return Err(IoError::Truncated {
                file: name.to_string(),
                what: format!("{count} elements of {what}"),
                needed: need.unwrap_or(u64::MAX),
                available: view_data.len() as u64,
            });
        }
    }
    let norm = acc.normalized();
    let mut out = Vec::with_capacity(count);
    for i in 0..count {
        let base = acc.offset() + i * stride;
        let mut v = [0.0; N];
        for (k, x) in v.iter_mut().enumerate() {
            let o = base + k * csize;
            let b = &view_data[o..o + csize];
            *x = match comp {
                DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                DataType::U16 => {
                    let r = u16::from_le_bytes([b[0], b[1]]) as f64;
                    if norm { r / 65535.0 } else { r }
                }
                DataType::I16 => {
                    let r = i16::from_le_bytes([b[0], b[1]]) as f64;
                    if norm { (r / 32767.0).max(-1.0) } else { r }
                }
                DataType::U8 => {
                    let r = b[0] as f64;
                    if norm { r / 255.0 } else { r }
                }
                DataType::I8 => {
                    let r = b[0] as i8 as f64;
                    if norm { (r / 127.0).max(-1.0) } else { r }
                }
            };
        }
        out.push(v);
    }
    Ok(out)
}

/// Decodes image `index`. Reads the JSON directly: `gltf::Image::source` panics on an
/// image with neither `uri` nor `mimeType`.
fn load_image(
    doc: &gltf::Document,
    index: usize,
    buffers: &[Vec<u8>],
    base: Option<&Path>,
    name: &str,
) -> Result<Image, IoError> {
    let label = format!("{name} (image {index})");
    let json = doc
        .as_json()
        .images
        .get(index)
        .ok_or_else(|| IoError::parse(name, format!("image {index}"), "does not exist"))?;
    if let Some(v) = &json.buffer_view {
        let view = doc.views().nth(v.value()).ok_or_else(|| {
            IoError::parse(name, format!("image {index}"), "refers to a missing bufferView")
        })?;
        let data = &buffers[view.buffer().index()];
        let bytes = data
            .get(view.offset()..view.offset().saturating_add(view.length()))
            .ok_or_else(|| IoError::Truncated {
                file: name.to_string(),
                what: format!("image bufferView {}", view.index()),
                needed: (view.offset() as u64).saturating_add(view.length() as u64),
                available: data.len() as u64,
            })?;
        crate::read_image_bytes(bytes, &label)
    } else if let Some(uri) = &json.uri {
        let bytes = load_uri(uri, base, name, None)?;
        crate::read_image_bytes(&bytes, &label)
    } else {
        Err(IoError::parse(name, format!("image {index}"), "has neither a uri nor a bufferView"))
    }
}
