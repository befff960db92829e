//! Texture blocks of the `conformal` pipeline: the fallback chart atlas (as a component
//! of its own), the stacking of blocks into one texture, and the `--keep` artefacts.

use super::Block;
use crate::{Error, Progress, Result};
use fieldtex_core::Image;
use fieldtex_mesh::{CornerUvs, TriMesh};
use fieldtex_param::conformal::ConformalComponent;
use std::path::Path;

/// The faces without a conformal map as one more component: their LSCM chart atlas
/// laid out with linked margins (`fieldtex_param::conformal::atlas_charts`), so the
/// quilting continues the texture across its seams. `component` is its id.
pub(super) fn fallback_atlas(
    mesh: &TriMesh,
    faces: &[u32],
    size: usize,
    component: usize,
    progress: &dyn Progress,
) -> Result<ConformalComponent> {
    let sub = TriMesh::new(
        mesh.positions.clone(),
        faces.iter().map(|&f| mesh.triangles[f as usize]).collect(),
    );
    let opts =
        fieldtex_param::AtlasOptions { resolution: size as u32, gutter: 4, ..Default::default() };
    let atlas = fieldtex_param::build_atlas(&sub, &opts, progress)
        .map_err(|e| Error::Internal(format!("fallback atlas: {e}")))?;
    let uvs = atlas
        .mesh
        .uvs
        .as_ref()
        .ok_or_else(|| Error::Internal("fallback atlas has no UVs".into()))?;
    let corners: Vec<[[f64; 2]; 3]> =
        uvs.indices.iter().map(|idx| idx.map(|i| uvs.values[i as usize])).collect();
    Ok(fieldtex_param::conformal::atlas_charts::atlas_component(
        mesh,
        faces,
        &atlas.chart_of_triangle,
        &corners,
        component,
    ))
}

/// Stacks the blocks into one texture (rows follow increasing canvas y, top to bottom)
/// and gives the mesh per-corner UVs (one UV per distinct corner position per vertex).
pub(super) fn assemble(mesh: &TriMesh, blocks: &[Block]) -> (Image, TriMesh) {
    let width = blocks.iter().map(|b| b.image.width).max().unwrap_or(1);
    let height: usize = blocks.iter().map(|b| b.image.height).sum::<usize>().max(1);
    let mut tex = Image::new(width, height, [0.5, 0.5, 0.5, 1.0]);
    let mut corner: Vec<[[f64; 2]; 3]> = vec![[[0.0; 2]; 3]; mesh.n_triangles()];
    let mut y_off = 0usize;
    for b in blocks {
        for y in 0..b.image.height {
            for x in 0..b.image.width {
                tex.set(x, y + y_off, b.image.get(x, y));
            }
        }
        for &(f, c) in &b.faces {
            corner[f as usize] =
                c.map(|p| [p[0] / width as f64, 1.0 - (p[1] + y_off as f64) / height as f64]);
        }
        y_off += b.image.height;
    }
    // Deduplicate corner UVs per vertex.
    let mut values: Vec<[f64; 2]> = Vec::new();
    let mut per_vertex: Vec<Vec<u32>> = vec![Vec::new(); mesh.n_vertices()];
    let mut indices = Vec::with_capacity(mesh.n_triangles());
    for (f, t) in mesh.triangles.iter().enumerate() {
        let mut idx = [0u32; 3];
        for k in 0..3 {
            let uv = corner[f][k];
            let list = &mut per_vertex[t[k] as usize];
            let found = list.iter().copied().find(|&i| {
                let v = values[i as usize];
                (v[0] - uv[0]).abs() < 1e-9 && (v[1] - uv[1]).abs() < 1e-9
            });
            idx[k] = match found {
                Some(i) => i,
                None => {
                    values.push(uv);
                    list.push((values.len() - 1) as u32);
                    (values.len() - 1) as u32
                }
            };
        }
        indices.push(idx);
    }
    let mut out = TriMesh::new(mesh.positions.clone(), mesh.triangles.clone());
    out.uvs = Some(CornerUvs { values, indices });
    // The input's normals (or the refinement's interpolated ones) shade the output.
    out.vertex_normals = mesh.vertex_normals.clone();
    (tex, out)
}

pub(super) fn write_keep(
    out_dir: &Path,
    mesh: &TriMesh,
    comps: &[ConformalComponent],
    blocks: &[Block],
) -> Result<()> {
    // patches.ply: per-vertex patch id (1000 × component + patch of the vertex's
    // lowest face; fallback = −1).
    let mut patch = vec![-1.0f32; mesh.n_vertices()];
    for c in comps {
        if c.has_uv() {
            for (f, t) in c.local_mesh.triangles[..c.faces.len()].iter().enumerate().rev() {
                let p = c.map.patch.get(f).copied().unwrap_or(0) as f32;
                for &l in t {
                    patch[c.local_to_global[l as usize] as usize] = 1000.0 * c.component as f32 + p;
                }
            }
        }
    }
    let plain = TriMesh::new(mesh.positions.clone(), mesh.triangles.clone());
    fieldtex_io::write_ply(&out_dir.join("patches.ply"), &plain, &[("patch", &patch)], true)?;
    // trajectories.obj: the cut curves = mesh edges where the corner UVs jump.
    let mut lines: Vec<Vec<[f64; 3]>> =
        comps.iter().flat_map(|c| c.map.cut_curves.iter().cloned()).collect();
    for c in comps.iter().filter(|c| c.has_uv()) {
        let topo = fieldtex_mesh::Topology::build(
            c.local_mesh.n_vertices(),
            &c.local_mesh.triangles[..c.faces.len()],
        );
        for e in 0..topo.n_edges() {
            let fs = topo.edge_faces(e);
            if fs.len() != 2 {
                continue;
            }
            let [a, b] = topo.edges[e];
            let uv = |f: usize, v: u32| {
                let k = (0..3).find(|&k| c.local_mesh.triangles[f][k] == v).unwrap_or(0);
                c.corner_uv[f][k]
            };
            let (f0, f1) = (fs[0] as usize, fs[1] as usize);
            let d = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).abs() + (p[1] - q[1]).abs();
            if d(uv(f0, a), uv(f1, a)) > 1e-9 || d(uv(f0, b), uv(f1, b)) > 1e-9 {
                lines.push(vec![
                    c.local_mesh.positions[a as usize],
                    c.local_mesh.positions[b as usize],
                ]);
            }
        }
    }
    fieldtex_io::write_obj_polylines(&out_dir.join("trajectories.obj"), &lines)?;
    for b in blocks {
        fieldtex_io::write_png(&out_dir.join(format!("geometry_image_{}.png", b.label)), &b.image)?;
        let (tmin, tmax) = b
            .tau
            .iter()
            .filter(|t| t.is_finite())
            .fold((f32::INFINITY, 0.0f32), |(a, z), &t| (a.min(t), z.max(t)));
        let mut im = Image::new(b.image.width, b.image.height, [0.0, 0.0, 0.0, 1.0]);
        for (i, &t) in b.tau.iter().enumerate() {
            if t.is_finite() && tmax > tmin {
                let v = ((t.ln() - tmin.ln()) / (tmax.ln() - tmin.ln())).clamp(0.0, 1.0);
                im.pixels[i] = [v, v, v, 1.0];
            }
        }
        fieldtex_io::write_png(&out_dir.join(format!("tau_{}.png", b.label)), &im)?;
    }
    Ok(())
}
