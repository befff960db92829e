//! Transfer fidelity of a textured mesh against a reference texturing of the same
//! surface (`fieldtex eval --mesh A --reference B`, DESIGN.md §6): uniform samples on
//! `A`, the same surface points found on `B` by closest point (the two may differ in
//! triangulation or atlas), both colours read through their UVs, Pearson r per channel
//! and on luma (`fieldtex_eval::transfer_fidelity`).

use crate::{Error, Result};
use fieldtex_eval::TransferFidelity;
use fieldtex_io::LoadedMesh;
use std::path::Path;

fn textured(path: &Path) -> Result<(LoadedMesh, fieldtex_core::Image)> {
    let loaded = fieldtex_io::read_mesh(path)?;
    if loaded.mesh.uvs.is_none() {
        return Err(Error::bad_input(Some(path), "the mesh has no texture coordinates"));
    }
    let Some(tex) = loaded.base_color.clone() else {
        return Err(Error::bad_input(Some(path), "the mesh has no base-colour texture"));
    };
    if loaded.mesh.n_triangles() == 0 {
        return Err(Error::bad_input(Some(path), "the mesh has no faces"));
    }
    Ok((loaded, tex))
}

/// Fidelity of the textured mesh `mesh` against the textured `reference` (module docs),
/// on about `samples` surface points.
pub fn transfer_fidelity_files(
    mesh: &Path,
    reference: &Path,
    samples: usize,
    seed: u64,
) -> Result<TransferFidelity> {
    // transfer's own range: below it the correlation rests on a handful of points (0 was
    // silently 15), above it the closest-point queries ran for minutes (10⁸ did not
    // finish in a minute).
    if !(256..=8_000_000).contains(&samples) {
        return Err(Error::bad_input(
            None,
            format!("--samples must be in 256..=8000000, got {samples}"),
        ));
    }
    let (a, ta) = textured(mesh)?;
    let (b, tb) = textured(reference)?;
    let mut warnings = Vec::new();
    let s = fieldtex_transfer::sample_surface(&a.mesh, samples, seed, "evaluated", &mut warnings)
        .map_err(|e| Error::classify(&e, Some(mesh), ""))?;
    let bvh =
        fieldtex_mesh::Bvh::build(&b.mesh).map_err(|e| Error::classify(&e, Some(reference), ""))?;
    let closest = bvh.closest_points(&s.positions);
    let (mut tri_b, mut bary_b, mut keep) = (Vec::new(), Vec::new(), Vec::new());
    for (i, c) in closest.iter().enumerate() {
        if let Some(c) = c {
            tri_b.push(c.triangle);
            bary_b.push(c.barycentric);
            keep.push(i);
        }
    }
    let (ca, va) =
        fieldtex_transfer::surface_colors(&a.mesh, &ta, None, &s.triangles, &s.barycentric)
            .map_err(|e| Error::classify(&e, Some(mesh), ""))?;
    let (cb, vb) = fieldtex_transfer::surface_colors(&b.mesh, &tb, None, &tri_b, &bary_b)
        .map_err(|e| Error::classify(&e, Some(reference), ""))?;
    let mut x = Vec::new();
    let mut y = Vec::new();
    for (j, &i) in keep.iter().enumerate() {
        if va[i] && vb[j] {
            x.push([ca[i * 3], ca[i * 3 + 1], ca[i * 3 + 2]]);
            y.push([cb[j * 3], cb[j * 3 + 1], cb[j * 3 + 2]]);
        }
    }
    Ok(fieldtex_eval::transfer_fidelity(&x, &y))
}
