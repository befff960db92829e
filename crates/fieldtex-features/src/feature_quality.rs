//! How well detected lines match a mesh's sharp edges: the crest-line target of
//! issue 4 ("≥ 90 % of the length of sharp edges lies within 2 mean edge lengths of a
//! detected line, and ≥ 80 % of the detected length lies within 2 mean edge lengths of
//! a sharp edge").
//!
//! Both fractions are length-weighted: each sharp edge (dihedral angle above the
//! threshold, see [`crate::sharp_edges`]) and each line segment is cut into pieces no
//! longer than `radius / 8`, and a piece counts as covered when its midpoint lies
//! within `radius` of the other set (midpoint rule; the error is below one piece per
//! transition between covered and uncovered). Nearest-segment queries use a uniform
//! grid, so the cost is linear in the total length over the radius.

use crate::FeaturesError;
use crate::mesh_scale::mean_edge_length_of;
use crate::segment_grid::{SegmentGrid, split_segment};
use crate::sharp_edges::sharp_edges;
use fieldtex_core::vec3::{self, V3};
use fieldtex_mesh::{Topology, TriMesh};
use rayon::prelude::*;
use serde::Serialize;

/// Result of [`sharp_edge_coverage`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SharpEdgeCoverage {
    /// Fraction of sharp-edge length within `radius` of a line (1 when there is no
    /// sharp edge).
    pub sharp_covered: f64,
    /// Fraction of line length within `radius` of a sharp edge (1 when there is no
    /// line, 0 when there are lines but no sharp edge).
    pub lines_on_sharp: f64,
    /// Total sharp-edge length.
    pub sharp_length: f64,
    /// Total line length.
    pub line_length: f64,
    /// Number of sharp edges.
    pub sharp_edges: usize,
    /// The radius used, in mesh units.
    pub radius: f64,
}

/// Coverage of the sharp edges of `mesh` (dihedral angle above `dihedral_deg`) by
/// `lines` and the converse, within `radius_in_mean_edges` mean edge lengths
/// (module docs). Typical call: `sharp_edge_coverage(mesh, &crest.polylines(), 30.0, 2.0)`.
pub fn sharp_edge_coverage(
    mesh: &TriMesh,
    lines: &[&[V3]],
    dihedral_deg: f64,
    radius_in_mean_edges: f64,
) -> Result<SharpEdgeCoverage, FeaturesError> {
    crate::error::check_option(
        "dihedral_deg",
        dihedral_deg,
        (0.0..=180.0).contains(&dihedral_deg),
        "in [0, 180]",
    )?;
    crate::error::check_option(
        "radius_in_mean_edges",
        radius_in_mean_edges,
        radius_in_mean_edges > 0.0,
        "> 0",
    )?;
    if mesh.triangles.is_empty() {
        return Err(FeaturesError::EmptyMesh);
    }
    mesh.validate()?;
    let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
    let h = mean_edge_length_of(mesh, &topo)?;
    let radius = radius_in_mean_edges * h;
    let normals = fieldtex_mesh::face_normals(mesh);
    let sharp = sharp_edges(mesh, &topo, &normals, dihedral_deg.to_radians());
    let sharp_lines: Vec<[V3; 2]> = sharp
        .iter()
        .map(|s| topo.edges[s.edge as usize].map(|v| mesh.positions[v as usize]))
        .collect();
    let sharp_grid = SegmentGrid::new(sharp_lines.iter().map(|s| s.as_slice()), radius);
    let line_grid = SegmentGrid::new(lines.iter().copied(), radius);
    let piece = radius / 8.0;
    let covered = |a: V3, b: V3, grid: &SegmentGrid| -> (f64, f64) {
        let mut total = 0.0;
        let mut near = 0.0;
        for (p, q) in split_segment(a, b, piece) {
            let len = vec3::norm(vec3::sub(q, p));
            total += len;
            if grid.nearest_within(vec3::lerp(p, q, 0.5), radius).is_some() {
                near += len;
            }
        }
        (total, near)
    };
    let sum =
        |parts: Vec<(f64, f64)>| parts.iter().fold((0.0, 0.0), |acc, x| (acc.0 + x.0, acc.1 + x.1));
    let (sharp_length, sharp_near) = sum(sharp_lines
        .par_iter()
        .with_min_len(256)
        .map(|s| covered(s[0], s[1], &line_grid))
        .collect());
    let segments: Vec<(V3, V3)> =
        lines.iter().flat_map(|l| l.windows(2).map(|w| (w[0], w[1]))).collect();
    let (line_length, line_near) = sum(segments
        .par_iter()
        .with_min_len(256)
        .map(|&(a, b)| covered(a, b, &sharp_grid))
        .collect());
    let frac = |near: f64, total: f64, empty: f64| if total > 0.0 { near / total } else { empty };
    Ok(SharpEdgeCoverage {
        sharp_covered: frac(sharp_near, sharp_length, 1.0),
        lines_on_sharp: frac(line_near, line_length, 1.0),
        sharp_length,
        line_length,
        sharp_edges: sharp.len(),
        radius,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_shapes::cube;

    #[test]
    fn exact_lines_cover_everything() {
        let m = cube();
        let edges: Vec<[V3; 2]> = (0..12)
            .map(|i| {
                // The twelve cube edges: axis k, the other two coordinates from i.
                let (k, a, b) = (i / 4, (i & 1) as f64, ((i >> 1) & 1) as f64);
                let mut p = [a, b, 0.0];
                p.rotate_right(k);
                let mut q = p;
                p[(k + 2) % 3] = 0.0;
                q[(k + 2) % 3] = 1.0;
                [p, q]
            })
            .collect();
        let lines: Vec<&[V3]> = edges.iter().map(|e| e.as_slice()).collect();
        let c = sharp_edge_coverage(&m, &lines, 30.0, 0.05).unwrap();
        assert_eq!(c.sharp_edges, 12);
        assert!((c.sharp_length - 12.0).abs() < 1e-12);
        assert!((c.line_length - 12.0).abs() < 1e-12);
        assert!((c.sharp_covered - 1.0).abs() < 1e-12, "{c:?}");
        assert!((c.lines_on_sharp - 1.0).abs() < 1e-12, "{c:?}");
    }

    #[test]
    fn partial_and_missing_lines() {
        let m = cube();
        let h = crate::mean_edge_length(&m).unwrap();
        // A line 0.02 beside the edge x ∈ [0, 1], y = z = 0, on the bottom face.
        let beside: Vec<V3> = vec![[0.0, 0.02, 0.0], [1.0, 0.02, 0.0]];
        let r = 0.05 / h;
        let c = sharp_edge_coverage(&m, &[&beside], 30.0, r).unwrap();
        assert!((c.lines_on_sharp - 1.0).abs() < 1e-12, "{c:?}");
        // One edge of 12, plus the ends of the two edges meeting it within the radius.
        assert!(
            c.sharp_covered > 1.0 / 12.0 - 1e-9 && c.sharp_covered < 1.0 / 12.0 + 0.03,
            "{c:?}"
        );
        // A line in the middle of a face is on no sharp edge.
        let middle: Vec<V3> = vec![[0.3, 0.5, 1.0], [0.7, 0.5, 1.0]];
        let c = sharp_edge_coverage(&m, &[&middle], 30.0, r).unwrap();
        assert_eq!(c.lines_on_sharp, 0.0);
        assert_eq!(c.sharp_covered, 0.0);
        // No line: nothing covered, precision vacuous.
        let c = sharp_edge_coverage(&m, &[], 30.0, r).unwrap();
        assert_eq!((c.sharp_covered, c.lines_on_sharp), (0.0, 1.0));
        assert!(sharp_edge_coverage(&m, &[], 30.0, 0.0).is_err());
    }
}
