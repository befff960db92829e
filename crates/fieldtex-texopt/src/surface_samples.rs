//! A public surface-sample domain: the carriers of a [`SurfaceDomain`] (positions,
//! tangent frames) with a multi-resolution hierarchy of nested sample sets and
//! tangent-plane neighbourhood gathering — what texture optimisation (paper A §5) and
//! surface synthesis from samples (paper B's sample pyramid, Turk 2001) both need.
//!
//! **Hierarchy.** Level `l` (finest `0`) holds carriers at least `spacing · 2^l` apart,
//! chosen by the workspace's one dart thrower in its nested mode
//! (`fieldtex_mesh::nested_dart_throwing`) over the carriers in one seeded random order
//! (`stream_seed(seed, "surface-samples", carrier)`): every level contains the coarser
//! levels (`level(l + 1)` is a prefix of `level(l)`), is separated at its spacing, and
//! is maximal over the carriers (every carrier lies within the level's spacing of one of
//! its samples). Deterministic for any thread count.
//!
//! **Neighbourhoods.** [`SurfaceSamples::neighbourhood`] gathers the carriers within a
//! radius of a carrier whose normals lie within a cone of its normal (so the two sides
//! of a thin part, or two components that nearly touch, stay apart), each with its
//! coordinates in the centre's tangent plane (orthogonal projection onto
//! `(tangent, bitangent)`), in the deterministic order of the one spatial grid
//! (`fieldtex_mesh::SpatialGrid`).

use crate::SurfaceDomain;
use fieldtex_core::rng::stream_seed;
use fieldtex_core::vec3::{dot, sub};
use fieldtex_mesh::{SpatialGrid, nested_dart_throwing};
use rayon::prelude::*;

/// Carriers with a nested sample hierarchy and tangent-plane neighbourhoods (module
/// docs).
#[derive(Debug, Clone)]
pub struct SurfaceSamples {
    domain: SurfaceDomain,
    grid: SpatialGrid,
    /// Finest first; `levels[l]` lists carrier indices, `levels[l + 1]` as its prefix.
    levels: Vec<Vec<u32>>,
    spacings: Vec<f64>,
}

/// One neighbour of a gathered neighbourhood.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbour {
    /// Carrier index.
    pub carrier: u32,
    /// Coordinates along the centre's tangent and bitangent.
    pub uv: [f64; 2],
    /// Squared 3-D distance to the centre.
    pub distance2: f64,
}

impl SurfaceSamples {
    /// The hierarchy of `domain`'s carriers with finest spacing `spacing` (> 0, finite;
    /// otherwise the carrier spacing) and `levels` levels (at least 1), seeded by `seed`.
    pub fn new(domain: SurfaceDomain, spacing: f64, levels: usize, seed: u64) -> Self {
        let spacing =
            if spacing.is_finite() && spacing > 0.0 { spacing } else { domain.carrier_spacing() };
        let levels = levels.max(1);
        let pos = domain.positions();
        let mut keyed: Vec<(u64, u32)> = (0..pos.len() as u32)
            .into_par_iter()
            .map(|c| (stream_seed(seed, "surface-samples", c as u64), c))
            .collect();
        keyed.par_sort_unstable();
        let order: Vec<u32> = keyed.into_iter().map(|(_, c)| c).collect();
        // Coarsest first for the nested thrower, stored finest first.
        let spacings: Vec<f64> = (0..levels).map(|l| spacing * f64::powi(2.0, l as i32)).collect();
        let radii: Vec<f64> = spacings.iter().rev().copied().collect();
        let mut sets = nested_dart_throwing(pos, &order, &radii);
        sets.reverse();
        let grid = SpatialGrid::new(pos, spacing);
        Self { domain, grid, levels: sets, spacings }
    }

    /// The carriers' domain (positions, normals, frames).
    pub fn domain(&self) -> &SurfaceDomain {
        &self.domain
    }

    /// Number of levels.
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// Carrier indices of level `l` (finest `0`); the samples of level `l + 1` come
    /// first. Empty for a level beyond the last.
    pub fn level(&self, l: usize) -> &[u32] {
        self.levels.get(l).map_or(&[], |v| v.as_slice())
    }

    /// Minimum distance between the samples of level `l`.
    pub fn spacing(&self, l: usize) -> f64 {
        self.spacings.get(l).copied().unwrap_or(f64::INFINITY)
    }

    /// The carriers within `radius` of carrier `center` whose normal makes a cosine of
    /// at least `normal_cosine` with the centre's (module docs), the centre included,
    /// in the grid's deterministic order. Empty for an index out of range.
    pub fn neighbourhood(&self, center: u32, radius: f64, normal_cosine: f64) -> Vec<Neighbour> {
        let d = &self.domain;
        let c = center as usize;
        if c >= d.len() {
            return Vec::new();
        }
        let (p, n) = (d.positions()[c], d.normals()[c]);
        let (t, b) = (d.tangents()[c], d.bitangents()[c]);
        let mut out = Vec::new();
        self.grid.for_each_within(d.positions(), p, radius, |q, distance2| {
            if dot(d.normals()[q as usize], n) < normal_cosine {
                return;
            }
            let v = sub(d.positions()[q as usize], p);
            out.push(Neighbour { carrier: q, uv: [dot(v, t), dot(v, b)], distance2 });
        });
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_core::vec3::{self, V3};
    use fieldtex_mesh::TriMesh;
    use fieldtex_mesh::primitives::{grid, icosphere};

    fn samples(mesh: &TriMesh, spacing: f64, levels: usize) -> SurfaceSamples {
        let field: Vec<V3> = vec![[1.0, 0.3, 0.2]; mesh.n_vertices()];
        let (d, _, _) = SurfaceDomain::at_vertices(mesh, &field).unwrap();
        SurfaceSamples::new(d, spacing, levels, 7)
    }

    /// Two unit spheres 0.05 apart along x (two components).
    fn two_spheres(level: usize) -> TriMesh {
        let mut two = icosphere(level);
        let other = icosphere(level);
        let off = two.positions.len() as u32;
        two.positions.extend(other.positions.iter().map(|p| [p[0] + 2.05, p[1], p[2]]));
        two.triangles.extend(other.triangles.iter().map(|t| t.map(|v| v + off)));
        two
    }

    fn check_hierarchy(s: &SurfaceSamples) {
        let pos = s.domain().positions();
        for l in 0..s.level_count() {
            let set = s.level(l);
            assert!(!set.is_empty());
            if l + 1 < s.level_count() {
                let coarse = s.level(l + 1);
                assert!(coarse.len() < set.len(), "level {l}: {} vs {}", coarse.len(), set.len());
                assert_eq!(&set[..coarse.len()], coarse);
            }
            let r = s.spacing(l);
            for (i, &a) in set.iter().enumerate() {
                for &b in &set[i + 1..] {
                    assert!(vec3::norm(vec3::sub(pos[a as usize], pos[b as usize])) >= r);
                }
            }
            // Maximal: every carrier is within the spacing of a sample of the level.
            for p in pos {
                assert!(set.iter().any(|&a| vec3::norm(vec3::sub(pos[a as usize], *p)) < r));
            }
        }
    }

    #[test]
    fn hierarchy_on_a_closed_an_open_and_a_two_component_mesh() {
        let sphere = icosphere(3);
        check_hierarchy(&samples(&sphere, 0.08, 3));
        let open = grid(24, 16, 2.0, 1.3);
        check_hierarchy(&samples(&open, 0.05, 3));
        let two = two_spheres(2);
        let s = samples(&two, 0.15, 2);
        check_hierarchy(&s);
        // Both components are sampled at every level.
        for l in 0..2 {
            let right =
                s.level(l).iter().filter(|&&c| s.domain().positions()[c as usize][0] > 1.025);
            assert!(right.count() > 0 && s.level(l).len() > 2);
        }
        // Deterministic.
        let again = samples(&two, 0.15, 2);
        assert_eq!(again.level(0), s.level(0));
    }

    #[test]
    fn neighbourhoods_are_tangent_plane_discs_on_one_sheet() {
        // Open grid (z = 0): uv are the plane offsets in the centre's frame.
        let open = grid(20, 20, 1.0, 1.0);
        let s = samples(&open, 0.05, 1);
        let pos = s.domain().positions();
        let c = (0..pos.len()).find(|&i| pos[i] == [0.5, 0.5, 0.0]).unwrap() as u32;
        let nb = s.neighbourhood(c, 0.12, 0.5);
        assert!(nb.iter().any(|n| n.carrier == c && n.uv == [0.0, 0.0]));
        // Disc of radius 0.12 on a 0.05 lattice: 5 rows of up to 5 points.
        assert_eq!(nb.len(), 21, "{}", nb.len());
        for n in &nb {
            let q = pos[n.carrier as usize];
            let r2 = n.uv[0] * n.uv[0] + n.uv[1] * n.uv[1];
            assert!((r2 - n.distance2).abs() < 1e-12 && n.distance2 <= 0.12 * 0.12 + 1e-15);
            assert!((vec3::norm2(vec3::sub(q, pos[c as usize])) - n.distance2).abs() < 1e-15);
        }
        // A corner of the open mesh: a quarter disc, all on one side of each axis.
        let corner = (0..pos.len()).find(|&i| pos[i] == [0.0, 0.0, 0.0]).unwrap() as u32;
        let q = s.neighbourhood(corner, 0.12, 0.5);
        assert!(q.len() < nb.len() / 2 + 3, "{}", q.len());
        // Two spheres 0.05 apart: a neighbourhood across the gap keeps to its own sheet.
        let two = two_spheres(3);
        let off = (two.n_vertices() / 2) as u32;
        let s = samples(&two, 0.1, 1);
        let pos = s.domain().positions();
        let tip = (0..pos.len()).max_by(|&a, &b| {
            let on_left = |i: usize| if (i as u32) < off { pos[i][0] } else { f64::MIN };
            on_left(a).total_cmp(&on_left(b))
        });
        let tip = tip.unwrap() as u32;
        let nb = s.neighbourhood(tip, 0.3, 0.5);
        assert!(!nb.is_empty());
        assert!(nb.iter().all(|n| n.carrier < off), "the other sphere leaked in");
        let all = s.neighbourhood(tip, 0.3, -2.0);
        assert!(all.iter().any(|n| n.carrier >= off), "without the cone it is within reach");
        assert!(s.neighbourhood(u32::MAX, 1.0, 0.0).is_empty());
    }
}
