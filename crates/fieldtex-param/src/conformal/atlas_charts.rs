//! The fallback chart atlas as a chart layout with linked margins (our addition).
//!
//! Faces whose component has no valid conformal map (a discrete map that folds on a
//! coarse CAD panel, a box of eight triangles with nothing to solve) are textured
//! through an LSCM chart atlas. Quilted on its own, such an atlas has a colour step at
//! every chart seam (2.7–3.1× the interior's on the painted stool and cabinet,
//! docs/conformal.md, session 17). Here its charts become a layout like the polished
//! patch layouts: one chart per atlas chart, repacked with room for margins, and every
//! seam's margin drawn by similarity ghosts
//! ([`super::patch_relaxation::repack_with_similarity_ghosts`]), so the geometry image
//! links the texels on both sides of each seam and the quilting continues the texture
//! across it (§4.2, as for the conformal patches).

use super::patch_relaxation::repack_with_similarity_ghosts;
use super::periodic_uv::{Lattice, signed_area};
use super::{ComponentMap, ConformalComponent, ConformalMethod};
use fieldtex_mesh::TriMesh;

/// A component made of the global faces `faces` of `mesh`, laid out by the chart atlas
/// `chart_of_face` / `corner_uv` (per entry of `faces`: its chart and its corners in
/// chart coordinates, any common unit), with id `component`. The corners are scaled so
/// the layout's area equals the faces' surface area (λ ≈ 1 on average), the charts are
/// repacked and the seams get similarity ghosts. Faces whose corners are not finite
/// keep a chart of their own.
pub fn atlas_component(
    mesh: &TriMesh,
    faces: &[u32],
    chart_of_face: &[u32],
    corner_uv: &[[[f64; 2]; 3]],
    component: usize,
) -> ConformalComponent {
    let n = faces.len().min(chart_of_face.len()).min(corner_uv.len());
    // Local mesh: the faces' vertices renumbered in order of first use.
    let mut local = vec![u32::MAX; mesh.n_vertices()];
    let mut local_to_global = Vec::new();
    let mut triangles = Vec::with_capacity(n);
    for &f in &faces[..n] {
        let t = mesh.triangles[f as usize].map(|v| {
            if local[v as usize] == u32::MAX {
                local[v as usize] = local_to_global.len() as u32;
                local_to_global.push(v);
            }
            local[v as usize]
        });
        triangles.push(t);
    }
    let positions = local_to_global.iter().map(|&v| mesh.positions[v as usize]).collect();
    let local_mesh = TriMesh::new(positions, triangles);
    // One common scale: UV area = surface area.
    let a3 = fieldtex_mesh::total_area(&local_mesh);
    let a2: f64 =
        corner_uv[..n].iter().map(|c| signed_area(c).abs()).filter(|a| a.is_finite()).sum();
    let scale = if a2 > 0.0 && a3 > 0.0 { (a3 / a2).sqrt() } else { 1.0 };
    let corners: Vec<[[f64; 2]; 3]> =
        corner_uv[..n].iter().map(|c| c.map(|p| [p[0] * scale, p[1] * scale])).collect();
    // Chart ids 0..k in order of first appearance (the packer's convention).
    let mut ids = std::collections::BTreeMap::new();
    let patch: Vec<u32> = chart_of_face[..n]
        .iter()
        .map(|&c| {
            let next = ids.len() as u32;
            *ids.entry(c).or_insert(next)
        })
        .collect();
    let mut map = ComponentMap {
        corner: corners.clone(),
        base: vec![[f64::NAN; 2]; local_mesh.n_vertices()],
        apex: vec![None; n],
        patch,
        ..ComponentMap::empty(ConformalMethod::ChartAtlas)
    };
    // Vertices are not split here, so each one is its own surface point.
    let original: Vec<u32> = (0..local_mesh.n_vertices() as u32).collect();
    repack_with_similarity_ghosts(&local_mesh, n, &mut map, &original, corners);
    let mut c = ConformalComponent {
        component,
        genus: 0,
        boundaries: 0,
        method: ConformalMethod::ChartAtlas,
        faces: faces[..n].to_vec(),
        corner_uv: Vec::new(),
        slit: Vec::new(),
        near_singularity: Vec::new(),
        lattice: Lattice { a: None, b: None },
        domain: [0.0; 4],
        zero_points: Vec::new(),
        conjugate_residual: f64::NAN,
        harmonic_forms: 0,
        note: Some(
            "chart atlas (LSCM charts) of the faces without a valid conformal map, its seams' \
             margins linked by similarity ghosts"
                .into(),
        ),
        double_cover_genus: None,
        protrusion_slits: None,
        local_mesh,
        local_to_global,
        map,
        polish: None,
    };
    c.refresh();
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_core::vec3;
    use fieldtex_mesh::primitives::cube;

    /// A cube cut into its six faces as six charts (each face's square in its own
    /// plane coordinates): the layout keeps every face, repacks the charts without
    /// overlap, scales the layout to the surface area and draws a ghost margin across
    /// every seam.
    #[test]
    fn a_cube_atlas_becomes_a_linked_layout() {
        let m = cube(2);
        let faces: Vec<u32> = (0..m.n_triangles() as u32).collect();
        let mut chart = Vec::new();
        let mut uv = Vec::new();
        for f in 0..m.n_triangles() {
            let p = m.triangle_positions(f);
            let nrm = vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0]));
            let axis = (0..3).max_by(|&a, &b| nrm[a].abs().total_cmp(&nrm[b].abs())).unwrap();
            let side = if nrm[axis] > 0.0 { 1 } else { 0 };
            chart.push((2 * axis + side) as u32);
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let flip = if nrm[axis] > 0.0 { 1.0 } else { -1.0 };
            uv.push(p.map(|q| [q[u] * flip * 10.0, q[v] * 10.0]));
        }
        let c = atlas_component(&m, &faces, &chart, &uv, 3);
        assert_eq!((c.component, c.method), (3, ConformalMethod::ChartAtlas));
        assert_eq!(c.faces.len(), m.n_triangles());
        assert!(c.has_uv());
        assert_eq!(c.map.n_patches(), 6);
        let area3 = fieldtex_mesh::total_area(&m);
        let area2: f64 = c.corner_uv.iter().map(signed_area).sum();
        assert!((area2 / area3 - 1.0).abs() < 1e-9, "{area2} vs {area3}");
        assert!(c.corner_uv.iter().all(|q| signed_area(q) > 0.0));
        // Every cube edge is a seam: ghosts on both sides of all of them.
        assert!(!c.map.ghosts.is_empty());
        let ghost_faces: std::collections::BTreeSet<u32> =
            c.map.ghosts.iter().map(|g| g.face).collect();
        assert!(c.domain[2] > c.domain[0] && c.domain[3] > c.domain[1]);
        assert!(ghost_faces.len() >= 6);
    }
}
