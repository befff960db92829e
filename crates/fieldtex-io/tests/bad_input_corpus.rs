//! Bad input never panics, hangs or exhausts memory: every reader either loads (with a
//! warning where something was off) or returns an error whose message names the file.
//! A panic anywhere fails the test; no `catch_unwind`.

use fieldtex_core::Image;
use fieldtex_core::rng::mix64;
use fieldtex_io::{
    GlbOptions, IoError, LoadedMesh, MeshFormat, encode_glb, encode_ply, encode_png, read_image,
    read_mesh, read_mesh_bytes,
};
use fieldtex_mesh::{CornerUvs, primitives};
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fieldtex-io-bad-input");
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn put(name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// Deterministic byte source (SplitMix64 over a counter).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 += 1;
        mix64(self.0)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Reads `p`; an error must name the file. Returns the result for further checks.
fn read_named(p: &Path) -> Result<LoadedMesh, IoError> {
    let r = read_mesh(p);
    if let Err(e) = &r {
        let msg = e.to_string();
        assert!(msg.contains(&p.display().to_string()), "error does not name the file: {msg}");
    }
    r
}

fn has_warning(m: &LoadedMesh, code: &str) -> bool {
    m.warnings.iter().any(|w| w.code == code)
}

const OBJ: &str = "# tiny\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
    vn 0 0 1\ng quad\nf 1/1/1 2/2/1 3/3/1 4/4/1\n";

fn ascii_stl() -> Vec<u8> {
    b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n\
      endfacet\nendsolid t\n"
        .to_vec()
}

fn binary_stl(tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend_from_slice(&[0u8; 12]);
        for p in t {
            for x in p {
                b.extend_from_slice(&x.to_le_bytes());
            }
        }
        b.extend_from_slice(&[0u8; 2]);
    }
    b
}

/// Valid small files of every format: (name, bytes).
fn valid_files() -> Vec<(&'static str, Vec<u8>)> {
    let ico = primitives::icosphere(1);
    let mut uvm = primitives::grid(3, 2, 1.0, 1.0);
    uvm.uvs = Some(CornerUvs {
        values: uvm.positions.iter().map(|p| [p[0], p[1]]).collect(),
        indices: uvm.triangles.clone(),
    });
    let tex = Image::new(4, 4, [0.3, 0.6, 0.9, 1.0]);
    vec![
        ("ok.obj", OBJ.as_bytes().to_vec()),
        ("ok-bin.ply", encode_ply(&ico, &[], true).unwrap()),
        ("ok-ascii.ply", encode_ply(&ico, &[], false).unwrap()),
        ("ok-ascii.stl", ascii_stl()),
        ("ok-bin.stl", binary_stl(&[[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; 2])),
        ("ok.glb", encode_glb(&uvm, Some(&tex), &GlbOptions::default()).unwrap()),
        ("ok-colors.glb", {
            let mut c = uvm.clone();
            c.vertex_colors = Some(vec![[0.2, 0.4, 0.6, 1.0]; c.n_vertices()]);
            encode_glb(&c, None, &GlbOptions::default().with_vertex_colors(true)).unwrap()
        }),
    ]
}

#[test]
fn valid_files_load() {
    for (name, bytes) in valid_files() {
        let m = read_named(&put(name, &bytes)).unwrap_or_else(|e| panic!("{e}"));
        assert!(m.mesh.validate().is_ok(), "{name}");
    }
}

#[test]
fn truncated_files_are_errors_naming_the_file() {
    for (name, bytes) in valid_files() {
        for frac in [0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99] {
            let cut = ((bytes.len() as f64 * frac) as usize).max(1).min(bytes.len() - 1);
            let p = put(&format!("trunc-{cut}-{name}"), &bytes[..cut]);
            // A text file cut between complete statements may still be a valid mesh.
            if let Ok(m) = read_named(&p) {
                assert!(m.mesh.n_triangles() > 0);
            }
        }
    }
    // Cut binary formats are always errors.
    let ply = encode_ply(&primitives::icosphere(1), &[], true).unwrap();
    let e = read_named(&put("cut.ply", &ply[..ply.len() - 5])).unwrap_err();
    assert!(e.to_string().contains("`face`"), "{e}");
    let stl = binary_stl(&[[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; 3]);
    assert!(matches!(
        read_named(&put("cut.stl", &stl[..stl.len() - 1])),
        Err(IoError::Truncated { .. })
    ));
}

#[test]
fn empty_and_garbage_files() {
    for ext in ["obj", "ply", "stl", "glb", "gltf", "xyz", ""] {
        let p = put(&format!("empty.{ext}"), b"");
        assert!(matches!(read_named(&p), Err(IoError::EmptyFile { .. })), "{ext}");
    }
    let mut rng = Rng(7);
    for (i, ext) in ["obj", "ply", "stl", "glb", "gltf", "bin"].iter().enumerate() {
        let garbage: Vec<u8> = (0..4096 + 37 * i).map(|_| rng.next() as u8).collect();
        let e = read_named(&put(&format!("garbage.{ext}"), &garbage));
        assert!(e.is_err(), "garbage .{ext} loaded");
    }
    let e = read_named(&put("garbage.bin", b"\x01\x02 hello")).unwrap_err();
    assert!(matches!(e, IoError::UnknownFormat { .. }), "{e}");
    assert!(matches!(read_mesh(&dir().join("does-not-exist.obj")), Err(IoError::Os { .. })));
    assert!(matches!(read_mesh(&dir()), Err(IoError::NotRegularFile { .. })));
}

#[test]
fn non_finite_coordinates_load_with_a_warning() {
    let obj = put("nan.obj", b"v nan 0 0\nv 1 0 0\nv 0 inf 0\nv 0 0 1\nf 1 2 3\nf 2 4 3\n");
    let m = read_named(&obj).unwrap();
    assert!(has_warning(&m, "non-finite-positions") && m.mesh.validate().is_err());
    let mut ply = encode_ply(&primitives::icosphere(0), &[], true).unwrap();
    let at = ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11 + 3 * 12;
    ply[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    let m = read_named(&put("nan.ply", &ply)).unwrap();
    assert!(has_warning(&m, "non-finite-positions"));
    let stl = binary_stl(&[[[0.0; 3], [f32::INFINITY, 0.0, 0.0], [0.0, 1.0, 0.0]]]);
    assert!(has_warning(&read_named(&put("inf.stl", &stl)).unwrap(), "non-finite-positions"));
}

#[test]
fn bad_indices_name_the_face() {
    let base = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    for (face, needle) in [
        ("f 1 2 -100", "-100"),
        ("f 1 2 99999999999", "99999999999"),
        ("f 1 2 99999999999999999999999", "line 4"),
        ("f 1 2 0", "index 0"),
        ("f 1/7 2/1 3/1", "texture coordinate"),
    ] {
        let p = put("idx.obj", format!("{base}{face}\n").as_bytes());
        let e = read_named(&p).unwrap_err().to_string();
        assert!(e.contains(needle), "{face}: {e}");
    }
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
        property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n\
        0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 4294967295\n";
    let e = read_named(&put("idx.ply", ply.as_bytes())).unwrap_err().to_string();
    assert!(e.contains("face 1") && e.contains("4294967295"), "{e}");
    let e = read_named(&put("neg.ply", ply.replace("4294967295", "-3").as_bytes())).unwrap_err();
    assert!(matches!(e, IoError::IndexOutOfRange { index: -3, face: 1, .. }), "{e}");
}

#[test]
fn absurd_ply_headers_fail_fast_without_allocating() {
    let head = |nv: &str, nf: &str| {
        format!(
            "ply\nformat binary_little_endian 1.0\nelement vertex {nv}\nproperty float x\n\
             property float y\nproperty float z\nelement face {nf}\n\
             property list uchar int vertex_indices\nend_header\n"
        )
        .into_bytes()
    };
    let mut b = head("3", "1000000000000");
    b.extend_from_slice(&[0u8; 36]);
    b.extend_from_slice(&[3, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0]);
    let e = read_named(&put("claims-1e12.ply", &b)).unwrap_err();
    assert!(
        matches!(e, IoError::Truncated { .. }) && e.to_string().contains("1000000000000"),
        "{e}"
    );
    let e = read_named(&put("claims-1e12-v.ply", &head("1000000000000", "1"))).unwrap_err();
    assert!(matches!(e, IoError::Truncated { .. }), "{e}");
    let e = read_named(&put("claims-2e19.ply", &head("99999999999999999999", "1"))).unwrap_err();
    assert!(e.to_string().contains("element count"), "{e}");
    // A list claiming 255 corners with 3 present.
    let mut b = head("3", "1");
    b.extend_from_slice(&[0u8; 36]);
    b.extend_from_slice(&[255, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0]);
    assert!(read_named(&put("long-list.ply", &b)).is_err());
    // An element with no properties and a huge count is skipped, not looped over.
    let s = "ply\nformat ascii 1.0\nelement junk 1000000000000000\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n\
        end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_eq!(read_named(&put("empty-element.ply", s.as_bytes())).unwrap().mesh.n_triangles(), 1);
}

#[test]
fn wrong_extensions_load_by_content() {
    let ply = encode_ply(&primitives::icosphere(1), &[], true).unwrap();
    let m = read_named(&put("really-ply.obj", &ply)).unwrap();
    assert_eq!(m.format, MeshFormat::Ply);
    assert!(has_warning(&m, "format-mismatch"));
    let m = read_named(&put("really-obj.stl", OBJ.as_bytes())).unwrap();
    assert_eq!(m.format, MeshFormat::Obj);
    let m = read_named(&put("really-stl.glb", &ascii_stl())).unwrap();
    assert_eq!(m.format, MeshFormat::Stl);
    let m = read_named(&put("obj-without-extension", OBJ.as_bytes())).unwrap();
    assert_eq!(m.format, MeshFormat::Obj);
}

#[test]
fn empty_meshes_are_errors() {
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("verts-only.obj", b"v 0 0 0\nv 1 0 0\n".to_vec()),
        ("comments-only.obj", b"# nothing\n".to_vec()),
        ("degenerate-faces.obj", b"v 0 0 0\nv 1 0 0\nf 1 2\n".to_vec()),
        ("no-faces.stl", binary_stl(&[])),
        ("no-faces.ply", encode_ply(&primitives::icosphere(0), &[], false).unwrap()),
        ("no-mesh.gltf", br#"{"asset":{"version":"2.0"}}"#.to_vec()),
    ];
    for (name, mut bytes) in cases {
        if name == "no-faces.ply" {
            let s = String::from_utf8(bytes).unwrap();
            let head_end = s.find("end_header\n").unwrap() + 11;
            let body: Vec<&str> = s[head_end..].lines().take(12).collect();
            bytes = format!(
                "{}{}\n",
                s[..head_end].replace("element face 20", "element face 0"),
                body.join("\n")
            )
            .into_bytes();
        }
        let e = read_named(&put(name, &bytes)).unwrap_err();
        assert!(matches!(e, IoError::EmptyMesh { .. }), "{name}: {e}");
    }
}

#[test]
fn broken_and_odd_images() {
    let png = encode_png(&Image::new(8, 8, [0.1, 0.2, 0.3, 1.0])).unwrap();
    for (name, bytes) in [
        ("empty.png", Vec::new()),
        ("trunc.png", png[..png.len() / 2].to_vec()),
        ("header-only.png", png[..33].to_vec()),
        ("garbage.png", b"\x89PNG\r\n\x1a\nthis is not a png".to_vec()),
        ("text.png", b"hello".to_vec()),
    ] {
        let p = put(name, &bytes);
        let e = read_image(&p).unwrap_err().to_string();
        assert!(e.contains(&p.display().to_string()), "{e}");
    }
    // 1 × 1 and 16-bit RGBA images load.
    let one =
        read_image(&put("one.png", &encode_png(&Image::new(1, 1, [1.0, 0.0, 0.0, 0.5])).unwrap()))
            .unwrap();
    assert_eq!((one.width, one.height), (1, 1));
    let mut buf = Vec::new();
    let px: Vec<u16> = vec![65535, 0, 32768, 65535, 0, 65535, 0, 0];
    let raw: Vec<u8> = px.iter().flat_map(|v| v.to_ne_bytes()).collect();
    use image::ImageEncoder;
    image::codecs::png::PngEncoder::new(&mut buf)
        .write_image(&raw, 2, 1, image::ExtendedColorType::Rgba16)
        .unwrap();
    let im = read_image(&put("rgba16.png", &buf)).unwrap();
    assert!((im.pixels[0][2] - 32768.0 / 65535.0).abs() < 1e-6 && im.pixels[1][3] == 0.0);
    // Absurd dimensions in the header are refused before decoding.
    let mut huge = png.clone();
    huge[16..20].copy_from_slice(&100_000u32.to_be_bytes());
    huge[20..24].copy_from_slice(&100_000u32.to_be_bytes());
    let crc = crc32(&huge[12..29]);
    huge[29..33].copy_from_slice(&crc.to_be_bytes());
    let e = read_image(&put("huge.png", &huge)).unwrap_err();
    assert!(matches!(e, IoError::ImageTooLarge { .. }), "{e}");
}

fn crc32(data: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in data {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
        }
    }
    !c
}

#[test]
fn defect_fixtures_load() {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/meshes/defects");
    let mut n = 0;
    for e in std::fs::read_dir(&d).unwrap() {
        let p = e.unwrap().path();
        if MeshFormat::from_extension(&p).is_some() {
            let m = read_named(&p).unwrap_or_else(|e| panic!("{e}"));
            assert!(m.mesh.validate().is_ok(), "{}", p.display());
            n += 1;
        }
    }
    assert_eq!(n, 7);
}

/// Random byte mutations of valid files (fixed seed): flips, inserts, deletes, cuts,
/// duplicated ranges. Any result is fine except a panic; errors name `<memory>`.
#[test]
fn random_mutations_never_panic() {
    let mut rng = Rng(20261122);
    let mut outcomes = [0usize; 2];
    for (name, bytes) in valid_files() {
        let hint = MeshFormat::from_extension(Path::new(name));
        for _ in 0..2000 {
            let mut b = bytes.clone();
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(b.len());
                match rng.below(5) {
                    0 => b[i] ^= 1 << rng.below(8),
                    1 => b[i] = rng.next() as u8,
                    2 => b.insert(i, rng.next() as u8),
                    3 => {
                        b.remove(i);
                    }
                    _ => {
                        let j = (i + rng.below(16)).min(b.len());
                        let chunk = b[i..j].to_vec();
                        b.splice(i..i, chunk);
                    }
                }
                if b.is_empty() {
                    b.push(b'v');
                }
            }
            if rng.below(10) == 0 {
                b.truncate(rng.below(b.len()) + 1);
            }
            match read_mesh_bytes(&b, hint) {
                Ok(m) => {
                    outcomes[0] += 1;
                    let nv = m.mesh.n_vertices();
                    assert!(
                        m.mesh.triangles.iter().flatten().all(|&i| (i as usize) < nv),
                        "{name}"
                    );
                }
                Err(e) => {
                    outcomes[1] += 1;
                    assert!(e.to_string().contains("<memory>"), "{e}");
                }
            }
        }
    }
    assert!(outcomes[0] > 0 && outcomes[1] > 0, "{outcomes:?}");
}
