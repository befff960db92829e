//! Every mesh of the shared test data loads, with the counts its README states.

use fieldtex_io::{MeshFormat, read_mesh};
use std::path::{Path, PathBuf};

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

/// Every mesh file under `dir` (recursively).
fn mesh_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("test data missing at {}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            mesh_files(&p, out);
        } else if MeshFormat::from_extension(&p).is_some() {
            out.push(p);
        }
    }
}

#[test]
fn every_shared_mesh_loads() {
    let mut files = Vec::new();
    for sub in ["meshes", "textured"] {
        mesh_files(&data().join(sub), &mut files);
    }
    assert!(files.len() >= 19, "expected the 19 meshes of shared/data, found {}", files.len());
    for f in &files {
        let m = read_mesh(f).unwrap_or_else(|e| panic!("{e}"));
        assert!(m.mesh.n_triangles() > 0, "{}", f.display());
        let nv = m.mesh.n_vertices();
        assert!(m.mesh.triangles.iter().flatten().all(|&i| (i as usize) < nv), "{}", f.display());
        assert!(m.mesh.positions.iter().flatten().all(|x| x.is_finite()), "{}", f.display());
    }
}

#[test]
fn counts_match_the_readme() {
    let expect: &[(&str, usize, usize)] = &[
        ("meshes/stanford-bunny.obj", 35947, 69451),
        ("meshes/fandisk.obj", 6475, 12946),
        ("meshes/fertility.obj", 4494, 9000),
        ("meshes/rocker-arm.obj", 10044, 20088),
        ("meshes/armadillo.obj", 14587, 29170),
        ("meshes/horse.ply", 48485, 96966),
        ("meshes/koala-lowres.obj", 3560, 7116),
        ("meshes/torus.obj", 2304, 4608),
        ("meshes/demosthenes-bust-open.obj", 8394, 16719),
        ("meshes/defects/beetle-1972-nonmanifold.obj", 1148, 2053),
        ("meshes/defects/nonmanifold_edge.obj", 8, 6),
        ("meshes/defects/nonmanifold_vertex.obj", 7, 4),
        ("meshes/defects/nonoriented_edge.obj", 6, 4),
        ("meshes/defects/narrow_triangles.obj", 34, 46),
        ("meshes/defects/cube_soup.obj", 24, 12),
        ("meshes/defects/moebius-160-10.ply", 1600, 2880),
        ("textured/avocado/avocado.obj", 406, 682),
        ("textured/spot/spot_triangulated.obj", 2930, 5856),
        ("textured/blub/blub.obj", 7106, 14208),
    ];
    for &(f, nv, nf) in expect {
        let m = read_mesh(&data().join(f)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((m.mesh.n_vertices(), m.mesh.n_triangles()), (nv, nf), "{f}");
    }
    let horse = read_mesh(&data().join("meshes/horse.ply")).unwrap();
    assert_eq!(horse.format, MeshFormat::Ply);
    // horse.ply stores unnormalised normals; they are kept as read.
    let n = horse.mesh.vertex_normals.as_ref().expect("horse.ply has normals");
    assert!(n.iter().all(|v| v.iter().all(|x| x.is_finite()) && v.iter().any(|&x| x != 0.0)));
}

#[test]
fn textured_meshes_bring_uvs_and_textures() {
    for (f, tex_size, n_uv) in [
        ("textured/avocado/avocado.obj", Some(2048), 406),
        ("textured/blub/blub.obj", Some(2048), 7317),
        ("textured/spot/spot_triangulated.obj", None, 3225),
    ] {
        let m = read_mesh(&data().join(f)).unwrap();
        let uv = m.mesh.uvs.as_ref().unwrap_or_else(|| panic!("{f} has UVs"));
        assert_eq!(uv.values.len(), n_uv, "{f}");
        assert_eq!(uv.indices.len(), m.mesh.n_triangles());
        assert!(uv.values.iter().flatten().all(|x| (-0.1..=1.1).contains(x)), "{f}");
        assert_eq!(m.base_color.as_ref().map(|i| i.width), tex_size, "{f}: {:?}", m.warnings);
        assert!(m.warnings.iter().all(|w| w.code != "texture-not-loaded"), "{f}: {:?}", m.warnings);
    }
    let avocado = read_mesh(&data().join("textured/avocado/avocado.obj")).unwrap();
    assert!(avocado.mesh.vertex_normals.is_some());
}
