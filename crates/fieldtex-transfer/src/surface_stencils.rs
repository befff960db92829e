//! Tangent-plane neighbourhoods of surface samples: the `n × n` grid stencils that the
//! non-parametric engine compares (paper B §5.1, after Turk 2001 and Wei & Levoy 2001,
//! who resample a small grid in each point's tangent plane).
//!
//! Frame: at a sample with unit normal `n` the first tangent `t₁` is the up axis
//! projected on the tangent plane (normalised), `t₂ = n × t₁`. Where the normal is within
//! about 8° of the up axis the projection is unstable, so the next object axis (up + 1
//! mod 3) is projected instead. Orienting by the up axis (gravity) is this
//! implementation's choice: the paper's textures are isotropic or follow gravity, and
//! the same rule on source and target makes "up" on one mean "up" on the other (Turk
//! orients by a user-designed vector field instead).
//!
//! Stencil cell `(a, b)`, `a, b ∈ −h..=h` (`h = n / 2`), stored at index
//! `(b + h) · n + (a + h)`, is the sample of the same set nearest to
//! `p + step · (a t₁ + b t₂)` among those within `2 · step` whose normal agrees
//! (`n·n' > 0.3`); the centre sample itself when none does (holes, borders, thin
//! sheets). `step` is the set's Poisson spacing, so the grid resamples the surface at
//! its own resolution. Cells of a *coarser* set (the image-analogies parent
//! neighbourhood) use the same frame with the coarse set's spacing.
//!
//! Every row is computed independently (same result for any thread count).

use crate::surface_samples::SampleSet;
use fieldtex_core::vec3::{self, V3};
use fieldtex_texopt::UniformGrid;
use rayon::prelude::*;

/// Cells of every sample's stencil, row-major `#samples × size²`.
#[derive(Debug, Clone, PartialEq)]
pub struct Stencils {
    /// Side of the stencil (odd).
    pub size: usize,
    pub cells: Vec<u32>,
}

impl Stencils {
    pub fn cells_of(&self, i: usize) -> &[u32] {
        let k = self.size * self.size;
        &self.cells[i * k..(i + 1) * k]
    }
    /// Index of the cell opposite to cell `c` (offset negated).
    pub fn mirror(&self, c: usize) -> usize {
        self.size * self.size - 1 - c
    }
    /// Index of the centre cell.
    pub fn centre(&self) -> usize {
        self.size * self.size / 2
    }
}

/// The tangent frame `(t₁, t₂)` at normal `n` (module docs).
pub fn tangent_frame(n: V3, up: usize) -> (V3, V3) {
    let project = |axis: usize| {
        let mut e = [0.0; 3];
        e[axis] = 1.0;
        vec3::sub(e, vec3::scale(n, vec3::dot(e, n)))
    };
    let mut t = project(up);
    if vec3::norm2(t) < 0.02 {
        t = project((up + 1) % 3);
    }
    let t1 = vec3::normalize(t).unwrap_or([1.0, 0.0, 0.0]);
    let t2 = vec3::cross(n, t1);
    (t1, t2)
}

/// Stencils of `size × size` cells (odd `size ≥ 1`) of the samples `centres` (positions
/// and normals) resampled in `set` with step `set.spacing` (module docs). `centres` may
/// be `set` itself or a finer set (parent neighbourhoods).
pub fn stencils(
    centres_pos: &[V3],
    centres_nrm: &[V3],
    set: &SampleSet,
    grid: &UniformGrid,
    size: usize,
    up: usize,
) -> Stencils {
    assert!(size % 2 == 1, "stencil size must be odd");
    let h = (size / 2) as isize;
    let step = set.spacing;
    let k = size * size;
    let mut cells = vec![0u32; centres_pos.len() * k];
    cells.par_chunks_mut(k).enumerate().for_each(|(i, row)| {
        let (p, n) = (centres_pos[i], centres_nrm[i]);
        let (t1, t2) = tangent_frame(n, up);
        let own = nearest(set, grid, p, n, 2.0 * step).unwrap_or(0);
        for b in -h..=h {
            for a in -h..=h {
                let c = ((b + h) as usize) * size + (a + h) as usize;
                let q = vec3::add(
                    p,
                    vec3::add(vec3::scale(t1, a as f64 * step), vec3::scale(t2, b as f64 * step)),
                );
                row[c] = if a == 0 && b == 0 {
                    own
                } else {
                    nearest(set, grid, q, n, 2.0 * step).unwrap_or(own)
                };
            }
        }
    });
    Stencils { size, cells }
}

/// Nearest sample of `set` to `q` within `radius` whose normal agrees with `n`.
fn nearest(set: &SampleSet, grid: &UniformGrid, q: V3, n: V3, radius: f64) -> Option<u32> {
    let mut best = (u32::MAX, f64::INFINITY);
    grid.for_each_within(&set.positions, q, radius, |j, d2| {
        if vec3::dot(set.normals[j as usize], n) > 0.3 && d2 < best.1 {
            best = (j, d2);
        }
    });
    (best.0 != u32::MAX).then_some(best.0)
}

/// The spatial grid [`stencils`] searches, for `set`.
pub fn stencil_grid(set: &SampleSet) -> UniformGrid {
    UniformGrid::new(&set.positions, 2.0 * set.spacing)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_stencils_are_regular_grids_and_mirror_cells_are_opposite() {
        // A square lattice of spacing 1 in the x-z plane, normal +y, up = z.
        let mut set = SampleSet {
            triangles: vec![],
            barycentric: vec![],
            positions: vec![],
            normals: vec![],
            face_normals: vec![],
            spacing: 1.0,
        };
        for j in 0..20 {
            for i in 0..20 {
                set.positions.push([i as f64, 0.0, j as f64]);
                set.normals.push([0.0, 1.0, 0.0]);
            }
        }
        let grid = stencil_grid(&set);
        let s = stencils(&set.positions, &set.normals, &set, &grid, 5, 2);
        let i = 10 * 20 + 10; // (10, 10)
        let cells = s.cells_of(i);
        assert_eq!(cells[s.centre()] as usize, i);
        // t₁ = +z (up projected), t₂ = n × t₁ = +x.
        let (t1, t2) = tangent_frame([0.0, 1.0, 0.0], 2);
        assert_eq!(t1, [0.0, 0.0, 1.0]);
        assert!((t2[0] - 1.0).abs() < 1e-12);
        for c in 0..25 {
            let (a, b) = ((c % 5) as f64 - 2.0, (c / 5) as f64 - 2.0);
            let p = set.positions[cells[c] as usize];
            assert_eq!(p, [10.0 + b, 0.0, 10.0 + a], "cell {c}");
            let m = set.positions[cells[s.mirror(c)] as usize];
            assert_eq!(m, [10.0 - b, 0.0, 10.0 - a]);
        }
        // A corner sample: cells off the lattice fall back to the centre sample.
        let corner = s.cells_of(0);
        assert_eq!(corner[0], 0);
    }
}
