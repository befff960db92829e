//! Wavefront OBJ reader (own parser; robust to garbage, bounded memory).
//!
//! Supported statements: `v x y z [w]` and the common colour extension
//! `v x y z r g b [a]`, `vt u v [w]`, `vn x y z`, `f` with any number of corners in the
//! forms `v`, `v/vt`, `v//vn`, `v/vt/vn`, positive (1-based) and negative (relative)
//! indices, `mtllib`, `usemtl`. Groups and objects (`g`, `o`), smoothing groups (`s`),
//! lines/points (`l`, `p`) and free-form statements are accepted and ignored (one
//! warning lists ignored keywords). A trailing `\` continues a line.
//!
//! Polygons are triangulated as a fan from their first corner: exact for convex (and
//! star-shaped from that corner) polygons; a non-convex polygon may get overlapping
//! triangles (documented limitation). Faces with fewer than 3 corners are dropped with a
//! warning.
//!
//! Texture coordinates become per-corner [`CornerUvs`]. OBJ normals are per corner too;
//! [`TriMesh`] keeps per-vertex normals, so the normals of all corners at a vertex are
//! averaged (a warning counts vertices where they disagreed, i.e. hard edges); vertices
//! no face gives a normal get `[0, 0, 0]`.
//!
//! Non-finite coordinates (`nan`, `inf`) are loaded as they are and reported in a
//! warning; `TriMesh::validate` and the repair step deal with them. Bad numbers, index
//! 0 and out-of-range indices are errors naming the line and face.

use crate::IoError;
use fieldtex_core::Warning;
use fieldtex_mesh::{CornerUvs, TriMesh};

/// What an OBJ file refers to besides geometry (resolved by the path reader).
#[derive(Debug, Clone, Default)]
pub struct ObjMaterialRefs {
    /// Every `mtllib` argument, in file order.
    pub mtllibs: Vec<String>,
    /// Materials named by `usemtl` that faces use, in order of first use.
    pub used_materials: Vec<String>,
}

/// Parses OBJ bytes. `name` is used in messages (a path or `<memory>`).
pub fn read_obj_bytes(
    bytes: &[u8],
    name: &str,
) -> Result<(TriMesh, ObjMaterialRefs, Vec<Warning>), IoError> {
    if looks_binary(bytes) {
        return Err(IoError::parse(
            name,
            "start of file",
            "binary data where OBJ text was expected (is this really an OBJ file?)",
        ));
    }
    let mut p = ObjParser::new(name);
    let mut joined: Vec<u8> = Vec::new();
    let mut line_no = 0usize;
    let mut start_line = 0usize;
    for raw in bytes.split(|&b| b == b'\n') {
        line_no += 1;
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        if let Some(cont) = raw.strip_suffix(b"\\") {
            if joined.is_empty() {
                start_line = line_no;
            }
            joined.extend_from_slice(cont);
            joined.push(b' ');
            continue;
        }
        if joined.is_empty() {
            p.statement(raw, line_no)?;
        } else {
            joined.extend_from_slice(raw);
            let line = std::mem::take(&mut joined);
            p.statement(&line, start_line)?;
        }
    }
    if !joined.is_empty() {
        let line = std::mem::take(&mut joined);
        p.statement(&line, start_line)?;
    }
    p.finish()
}

/// True when the head of the data has NUL bytes or mostly non-text bytes.
fn looks_binary(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(4096)];
    if head.contains(&0) {
        return true;
    }
    let odd =
        head.iter().filter(|&&b| b < 0x20 && !matches!(b, b'\n' | b'\r' | b'\t' | 0x0c)).count();
    odd * 10 > head.len()
}

struct ObjParser<'a> {
    name: &'a str,
    positions: Vec<[f64; 3]>,
    colors: Vec<[f32; 4]>,
    n_without_color: usize,
    texcoords: Vec<[f64; 2]>,
    normals: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    tri_uv: Vec<Option<[u32; 3]>>,
    tri_nrm: Vec<Option<[u32; 3]>>,
    any_uv: bool,
    any_nrm: bool,
    n_faces: usize,
    /// Positive indices that pointed past the vertices defined so far: (face, line, index).
    forward: Vec<(usize, usize, i64)>,
    short_faces: usize,
    mixed_uv_faces: usize,
    odd_vertex_arity: usize,
    refs: ObjMaterialRefs,
    current_material: Option<String>,
    ignored: Vec<String>,
    n_ignored: usize,
    corners: Vec<(u32, Option<u32>, Option<u32>)>,
}

impl<'a> ObjParser<'a> {
    fn new(name: &'a str) -> Self {
        Self {
            name,
            positions: Vec::new(),
            colors: Vec::new(),
            n_without_color: 0,
            texcoords: Vec::new(),
            normals: Vec::new(),
            triangles: Vec::new(),
            tri_uv: Vec::new(),
            tri_nrm: Vec::new(),
            any_uv: false,
            any_nrm: false,
            n_faces: 0,
            forward: Vec::new(),
            short_faces: 0,
            mixed_uv_faces: 0,
            odd_vertex_arity: 0,
            refs: ObjMaterialRefs::default(),
            current_material: None,
            ignored: Vec::new(),
            n_ignored: 0,
            corners: Vec::new(),
        }
    }

    fn err(&self, line: usize, msg: impl Into<String>) -> IoError {
        IoError::parse(self.name, format!("line {line}"), msg)
    }

    fn numbers<const N: usize>(
        &self,
        toks: &mut std::iter::Peekable<Tokens<'_>>,
        line: usize,
        what: &str,
    ) -> Result<([f64; N], usize), IoError> {
        let mut out = [0.0; N];
        let mut n = 0;
        for tok in toks.by_ref() {
            let v = parse_f64(tok).ok_or_else(|| {
                self.err(line, format!("cannot read {:?} as a number in {what}", lossy(tok)))
            })?;
            if n < N {
                out[n] = v;
            }
            n += 1;
        }
        Ok((out, n))
    }

    fn statement(&mut self, line: &[u8], line_no: usize) -> Result<(), IoError> {
        let line = match line.iter().position(|&b| b == b'#') {
            Some(i) => &line[..i],
            None => line,
        };
        let mut toks = tokens(line).peekable();
        let Some(kw) = toks.next() else { return Ok(()) };
        match kw {
            b"v" => {
                let (v, n) = self.numbers::<7>(&mut toks, line_no, "a vertex (v)")?;
                if n < 3 {
                    return Err(
                        self.err(line_no, format!("a vertex needs 3 coordinates, found {n}"))
                    );
                }
                self.positions.push([v[0], v[1], v[2]]);
                match n {
                    6 | 7 => {
                        let a = if n == 7 { v[6] } else { 1.0 };
                        self.colors.push([v[3] as f32, v[4] as f32, v[5] as f32, a as f32]);
                    }
                    3 | 4 => self.n_without_color += 1,
                    _ => {
                        self.odd_vertex_arity += 1;
                        self.n_without_color += 1;
                    }
                }
            }
            b"vt" => {
                let (v, n) = self.numbers::<3>(&mut toks, line_no, "a texture coordinate (vt)")?;
                if n < 1 {
                    return Err(self.err(line_no, "a texture coordinate (vt) needs at least u"));
                }
                self.texcoords.push([v[0], v[1]]);
            }
            b"vn" => {
                let (v, n) = self.numbers::<3>(&mut toks, line_no, "a normal (vn)")?;
                if n < 3 {
                    return Err(
                        self.err(line_no, format!("a normal (vn) needs 3 numbers, found {n}"))
                    );
                }
                self.normals.push(v);
            }
            b"f" | b"fo" => self.face(toks, line_no)?,
            b"mtllib" => {
                let rest = rest_of_line(line, kw);
                if !rest.is_empty() {
                    self.refs.mtllibs.push(rest);
                }
            }
            b"usemtl" => {
                let rest = rest_of_line(line, kw);
                self.current_material = (!rest.is_empty()).then_some(rest);
            }
            b"g" | b"o" | b"s" | b"l" | b"p" | b"vp" => {}
            other => {
                self.n_ignored += 1;
                let k = lossy(other);
                if self.ignored.len() < 5 && !self.ignored.contains(&k) {
                    self.ignored.push(k);
                }
            }
        }
        Ok(())
    }

    /// Converts an OBJ index (1-based or negative) against `count` defined elements.
    fn resolve(&self, tok: &[u8], count: usize, line: usize, what: &str) -> Result<i64, IoError> {
        let i = parse_i64(tok).ok_or_else(|| {
            self.err(
                line,
                format!("cannot read {:?} as a {what} index in face {}", lossy(tok), self.n_faces),
            )
        })?;
        if i == 0 {
            return Err(self.err(
                line,
                format!("{what} index 0 in face {} (OBJ indices start at 1)", self.n_faces),
            ));
        }
        Ok(if i < 0 { count as i64 + i } else { i - 1 })
    }

    fn face(&mut self, toks: std::iter::Peekable<Tokens<'_>>, line: usize) -> Result<(), IoError> {
        let face = self.n_faces;
        self.n_faces += 1;
        self.corners.clear();
        for tok in toks {
            let mut parts = tok.splitn(3, |&b| b == b'/');
            let vtok = parts.next().unwrap_or(b"");
            let v = self.resolve(vtok, self.positions.len(), line, "vertex")?;
            if v < 0 {
                return Err(IoError::IndexOutOfRange {
                    file: self.name.to_string(),
                    face,
                    index: parse_i64(vtok).unwrap_or(0),
                    n_vertices: self.positions.len(),
                });
            }
            if v >= u32::MAX as i64 {
                return Err(IoError::IndexOutOfRange {
                    file: self.name.to_string(),
                    face,
                    index: v + 1,
                    n_vertices: self.positions.len(),
                });
            }
            if v as usize >= self.positions.len() {
                self.forward.push((face, line, v));
            }
            let mut idx = [None, None];
            for (k, (t, count, what)) in [
                (parts.next(), self.texcoords.len(), "texture coordinate"),
                (parts.next(), self.normals.len(), "normal"),
            ]
            .into_iter()
            .enumerate()
            {
                let Some(t) = t.filter(|t| !t.is_empty()) else { continue };
                let i = self.resolve(t, count, line, what)?;
                if i < 0 || i as usize >= count {
                    return Err(self.err(
                        line,
                        format!(
                            "face {face} uses {what} index {} but only {count} are defined before it",
                            lossy(t)
                        ),
                    ));
                }
                idx[k] = Some(i as u32);
            }
            self.corners.push((v as u32, idx[0], idx[1]));
        }
        if self.corners.len() < 3 {
            self.short_faces += 1;
            return Ok(());
        }
        let has_uv = self.corners.iter().all(|c| c.1.is_some());
        if !has_uv && self.corners.iter().any(|c| c.1.is_some()) {
            self.mixed_uv_faces += 1;
        }
        let has_nrm = self.corners.iter().all(|c| c.2.is_some());
        let c0 = self.corners[0];
        for w in self.corners[1..].windows(2) {
            let (c1, c2) = (w[0], w[1]);
            self.triangles.push([c0.0, c1.0, c2.0]);
            if has_uv {
                self.any_uv = true;
                self.tri_uv.push(Some([c0.1.unwrap_or(0), c1.1.unwrap_or(0), c2.1.unwrap_or(0)]));
            } else {
                self.tri_uv.push(None);
            }
            if has_nrm {
                self.any_nrm = true;
                self.tri_nrm.push(Some([c0.2.unwrap_or(0), c1.2.unwrap_or(0), c2.2.unwrap_or(0)]));
            } else {
                self.tri_nrm.push(None);
            }
        }
        if let Some(m) = &self.current_material
            && !self.refs.used_materials.contains(m)
        {
            self.refs.used_materials.push(m.clone());
        }
        Ok(())
    }

    fn finish(self) -> Result<(TriMesh, ObjMaterialRefs, Vec<Warning>), IoError> {
        let nv = self.positions.len();
        if let Some(&(face, _line, v)) = self.forward.iter().find(|f| f.2 as usize >= nv) {
            return Err(IoError::IndexOutOfRange {
                file: self.name.to_string(),
                face,
                index: v + 1,
                n_vertices: nv,
            });
        }
        let mut warnings = Vec::new();
        if self.triangles.is_empty() {
            return Err(IoError::EmptyMesh {
                file: self.name.to_string(),
                detail: format!("{} vertices, {} face statements, {} usable", nv, self.n_faces, 0),
            });
        }
        if self.short_faces > 0 {
            warnings.push(Warning::new(
                "obj-short-faces-dropped",
                format!(
                    "{}: dropped {} face(s) with fewer than 3 corners",
                    self.name, self.short_faces
                ),
            ));
        }
        if self.n_ignored > 0 {
            warnings.push(Warning::new(
                "obj-statements-ignored",
                format!(
                    "{}: ignored {} statement(s) with unsupported keywords ({})",
                    self.name,
                    self.n_ignored,
                    self.ignored.join(", ")
                ),
            ));
        }
        if self.odd_vertex_arity > 0 {
            warnings.push(Warning::new(
                "obj-vertex-arity",
                format!(
                    "{}: {} vertex line(s) had an unusual number of values (not 3, 4, 6 or 7); \
                     only x y z were used",
                    self.name, self.odd_vertex_arity
                ),
            ));
        }
        crate::mesh_checks::warn_non_finite(self.name, &self.positions, &mut warnings);

        let vertex_colors = if !self.colors.is_empty() && self.n_without_color == 0 {
            let mut c = self.colors;
            crate::mesh_checks::clamp_colors(self.name, &mut c, &mut warnings);
            Some(c)
        } else {
            if !self.colors.is_empty() {
                warnings.push(Warning::new(
                    "obj-colors-dropped",
                    format!(
                        "{}: only {} of {} vertices had colours; colours were dropped",
                        self.name,
                        self.colors.len(),
                        nv
                    ),
                ));
            }
            None
        };

        let uvs = if self.any_uv {
            let mut values = self.texcoords;
            let n_missing = self.tri_uv.iter().filter(|t| t.is_none()).count();
            let fill = values.len() as u32;
            if n_missing > 0 {
                values.push([0.0, 0.0]);
                warnings.push(Warning::new(
                    "obj-missing-uvs",
                    format!(
                        "{}: {} triangle(s) had no texture coordinates ({} mixed faces); \
                         they were given UV (0, 0)",
                        self.name, n_missing, self.mixed_uv_faces
                    ),
                ));
            }
            let indices = self.tri_uv.iter().map(|t| t.unwrap_or([fill; 3])).collect();
            Some(CornerUvs { values, indices })
        } else {
            None
        };

        let vertex_normals = if self.any_nrm {
            Some(average_corner_normals(
                self.name,
                nv,
                &self.triangles,
                &self.tri_nrm,
                &self.normals,
                &mut warnings,
            ))
        } else {
            None
        };

        let mesh = TriMesh {
            positions: self.positions,
            triangles: self.triangles,
            uvs,
            vertex_colors,
            vertex_normals,
        };
        Ok((mesh, self.refs, warnings))
    }
}

/// Per-vertex normals from per-corner normal indices (see module docs).
fn average_corner_normals(
    name: &str,
    nv: usize,
    triangles: &[[u32; 3]],
    tri_nrm: &[Option<[u32; 3]>],
    normals: &[[f64; 3]],
    warnings: &mut Vec<Warning>,
) -> Vec<[f64; 3]> {
    let mut sum = vec![[0.0f64; 3]; nv];
    let mut first = vec![u32::MAX; nv];
    let mut disagree = vec![false; nv];
    for (t, n) in triangles.iter().zip(tri_nrm) {
        let Some(n) = n else { continue };
        for k in 0..3 {
            let v = t[k] as usize;
            let nn = normals[n[k] as usize];
            if first[v] == u32::MAX {
                first[v] = n[k];
            } else if first[v] != n[k] && normals[first[v] as usize] != nn {
                disagree[v] = true;
            }
            for d in 0..3 {
                sum[v][d] += nn[d];
            }
        }
    }
    for s in &mut sum {
        let l = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        if l > 0.0 && l.is_finite() {
            *s = [s[0] / l, s[1] / l, s[2] / l];
        } else {
            *s = [0.0; 3];
        }
    }
    let n_dis = disagree.iter().filter(|&&d| d).count();
    if n_dis > 0 {
        warnings.push(Warning::new(
            "obj-normals-averaged",
            format!(
                "{name}: {n_dis} vertices had different normals at different corners \
                 (hard edges); their normals were averaged"
            ),
        ));
    }
    sum
}

type Tokens<'b> =
    std::iter::Filter<std::slice::Split<'b, u8, fn(&u8) -> bool>, fn(&&'b [u8]) -> bool>;

fn tokens(line: &[u8]) -> Tokens<'_> {
    fn is_space(b: &u8) -> bool {
        b.is_ascii_whitespace()
    }
    fn non_empty(t: &&[u8]) -> bool {
        !t.is_empty()
    }
    line.split(is_space as fn(&u8) -> bool).filter(non_empty as fn(&&[u8]) -> bool)
}

/// The text after keyword `kw` on `line`, trimmed (file names may contain spaces).
fn rest_of_line(line: &[u8], kw: &[u8]) -> String {
    let t = line.trim_ascii_start();
    let rest = t.get(kw.len()..).unwrap_or(b"").trim_ascii();
    lossy(rest)
}

pub(crate) fn lossy(b: &[u8]) -> String {
    let s = String::from_utf8_lossy(&b[..b.len().min(64)]).into_owned();
    if b.len() > 64 { format!("{s}…") } else { s }
}

pub(crate) fn parse_f64(tok: &[u8]) -> Option<f64> {
    std::str::from_utf8(tok).ok()?.parse::<f64>().ok()
}

pub(crate) fn parse_i64(tok: &[u8]) -> Option<i64> {
    std::str::from_utf8(tok).ok()?.parse::<i64>().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(s: &str) -> Result<(TriMesh, ObjMaterialRefs, Vec<Warning>), IoError> {
        read_obj_bytes(s.as_bytes(), "t.obj")
    }

    #[test]
    fn quad_negative_indices_and_uvs() {
        let (m, _, w) = read(
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
             g grp\nf -4/-4 -3/-3 -2/-2 -1/-1\n",
        )
        .unwrap();
        assert!(w.is_empty(), "{w:?}");
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let uv = m.uvs.unwrap();
        assert_eq!(uv.indices, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(uv.values[2], [1.0, 1.0]);
    }

    #[test]
    fn normals_colors_continuation() {
        let (m, _, _) =
            read("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nvn 0 0 2\nf 1//1 \\\n 2//1 3//1\n")
                .unwrap();
        assert_eq!(m.vertex_normals.unwrap()[1], [0.0, 0.0, 1.0]);
        assert_eq!(m.vertex_colors.unwrap()[2], [0.0, 0.0, 1.0, 1.0]);
    }

    #[test]
    fn errors_name_line_and_face() {
        let e = read("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n").unwrap_err().to_string();
        assert!(e.contains("line 4") && e.contains("index 0"), "{e}");
        let e = read("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap_err().to_string();
        assert!(e.contains("face 0") && e.contains("index 9"), "{e}");
        let e = read("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -7\n").unwrap_err().to_string();
        assert!(e.contains("-7"), "{e}");
        let e = read("v 0 zero 0\n").unwrap_err().to_string();
        assert!(e.contains("line 1") && e.contains("zero"), "{e}");
        assert!(matches!(read("v 0 0 0\n"), Err(IoError::EmptyMesh { .. })));
    }

    #[test]
    fn nan_loads_with_warning() {
        let (m, _, w) = read("v nan 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n").unwrap();
        assert!(m.positions[0][0].is_nan());
        assert!(w.iter().any(|w| w.code == "non-finite-positions"), "{w:?}");
    }
}
