//! Initial slab coordinates integrated from the frame field over the coarsest level — an
//! option of [`super::lazy_solid_synthesis`]'s initialisation (our variant of paper E
//! §4.1, off by default).
//!
//! The paper warps the candidate slabs by the field in subparts: voxel `v` reads the
//! slab at `Rᵥᵀ (v − o)` with `o` its subpart's centre. Where the frame turns, two
//! neighbours whose frames differ by `Δθ` read points about `|v − o| Δθ` apart, so far
//! from the pivot the initial coordinates of a bent field are close to random (the
//! phase dislocations of the bent stripes, docs/solid.md). Here the coordinates are
//! instead the least-squares integral of the frame over the coarsest voxels of the
//! grid: `U` minimises `Σ |U(v + e_a) − U(v) − ½ (Rᵥᵀ + R_{v+e_a}ᵀ) e_a|²` over the
//! 6-neighbour edges (three independent Poisson problems with one graph Laplacian,
//! conjugate gradients from zero: the system is singular but consistent, and the
//! iterates stay orthogonal to the constants, so the mean of `U` is zero). Where the field's
//! axis is a gradient (the stripe normal of concentric rings is the radius) `U` follows
//! it exactly; elsewhere the misfit is spread smoothly instead of growing with the
//! distance from a pivot. Sequential and deterministic; a few thousand unknowns.

use fieldtex_linalg::conjugate_gradients;

use super::voxel_lattice::{FrameSource, VoxelLattice};

/// `U` over a box of coarsest-level voxels (see the module docs).
pub(crate) struct IntegratedInit {
    lo: [i32; 3],
    dims: [usize; 3],
    u: Vec<[f64; 3]>,
    /// The level `U` lives on.
    level: usize,
    /// `φ`, the fractional part of `2^g U` at the finest grid's first voxel, subtracted
    /// before rounding ([`Self::offset`], [`Self::residual`]): `U`'s constant is
    /// arbitrary, and a constant frame whose warp sits half-way between pixels would
    /// otherwise round its neighbours apart by the last bit.
    phase: [f64; 3],
}

impl IntegratedInit {
    /// `U` on level `c` of `lattice` over the level-`c` voxels covering the finest grid
    /// `[0, extent)` plus `pad` voxels on every side (blocks read a halo beyond it).
    pub(crate) fn new(
        lattice: &VoxelLattice,
        frames: &dyn FrameSource,
        c: usize,
        extent: [usize; 3],
        pad: i32,
    ) -> Self {
        let lo = [-pad; 3];
        let dims: [usize; 3] =
            std::array::from_fn(|a| (extent[a].div_ceil(1usize << c)) + 2 * pad as usize);
        let n = dims[0] * dims[1] * dims[2];
        let idx = |i: [usize; 3]| (i[2] * dims[1] + i[1]) * dims[0] + i[0];
        let voxel = |i: [usize; 3]| -> [i32; 3] { std::array::from_fn(|a| lo[a] + i[a] as i32) };
        let mut rt: Vec<[f64; 9]> = Vec::with_capacity(n);
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    rt.push(frames.frame(lattice.centre(c, voxel([i, j, k]))));
                }
            }
        }
        // Rᵀ e_a: row a of R (rows of the row-major matrix).
        let axis = |r: &[f64; 9], a: usize| [r[3 * a], r[3 * a + 1], r[3 * a + 2]];
        let mut b = vec![[0.0f64; 3]; n];
        let mut degree = vec![0.0f64; n];
        let mut edges: Vec<(usize, usize)> = Vec::with_capacity(3 * n);
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let p = idx([i, j, k]);
                    for a in 0..3 {
                        let mut q3 = [i, j, k];
                        q3[a] += 1;
                        if q3[a] >= dims[a] {
                            continue;
                        }
                        let q = idx(q3);
                        let (gp, gq) = (axis(&rt[p], a), axis(&rt[q], a));
                        for d in 0..3 {
                            let g = 0.5 * (gp[d] + gq[d]);
                            b[q][d] += g;
                            b[p][d] -= g;
                        }
                        degree[p] += 1.0;
                        degree[q] += 1.0;
                        edges.push((p, q));
                    }
                }
            }
        }
        let apply = |x: &[f64], y: &mut [f64]| {
            for (i, yi) in y.iter_mut().enumerate() {
                *yi = degree[i] * x[i];
            }
            for &(p, q) in &edges {
                y[p] -= x[q];
                y[q] -= x[p];
            }
        };
        let mut u = vec![[0.0f64; 3]; n];
        for d in 0..3 {
            let rhs: Vec<f64> = b.iter().map(|v| v[d]).collect();
            let x = conjugate_gradients(&apply, &rhs, 4000, 1e-10);
            for (ui, xi) in u.iter_mut().zip(x) {
                ui[d] = xi;
            }
        }
        let mut init = Self { lo, dims, u, level: c, phase: [0.0; 3] };
        let h = (1i64 << c) as f64;
        if let Some(u0) = init.interpolated(0, [0; 3]) {
            init.phase = u0.map(|x| h * x - (h * x).floor());
        }
        init
    }

    /// `U` trilinearly interpolated at the centre of voxel `v` of level `c` (in voxels of
    /// `U`'s level, as [`Self::get`]), or `None` where the
    /// interpolation would leave the box. A function of the position alone, so every
    /// level reads one smooth warp.
    pub(crate) fn interpolated(&self, c: usize, v: [i32; 3]) -> Option<[f64; 3]> {
        let (sc, sm) = ((1i64 << c) as f64, (1i64 << self.level) as f64);
        let mut i0 = [0usize; 3];
        let mut t = [0.0f64; 3];
        for a in 0..3 {
            // Finest-voxel position of the centre, then index units of U's level.
            let x =
                (sc * v[a] as f64 + 0.5 * (sc - 1.0) - 0.5 * (sm - 1.0)) / sm - self.lo[a] as f64;
            let f = x.floor();
            if f < 0.0 || f as usize + 1 >= self.dims[a] {
                return None;
            }
            i0[a] = f as usize;
            t[a] = x - f;
        }
        let mut acc = [0.0f64; 3];
        for corner in 0..8 {
            let mut w = 1.0;
            let mut idx = [0usize; 3];
            for a in 0..3 {
                let bit = (corner >> a) & 1;
                idx[a] = i0[a] + bit;
                w *= if bit == 1 { t[a] } else { 1.0 - t[a] };
            }
            let u = self.u[(idx[2] * self.dims[1] + idx[1]) * self.dims[0] + idx[0]];
            for d in 0..3 {
                acc[d] += w * u[d];
            }
        }
        Some(acc)
    }

    /// The exemplar-pixel offset `R = round(2^g U − φ)` of voxel `v` of level `c` on the
    /// warp (`g` the level `U` lives on; `U` interpolated at the voxel's centre; `φ` the
    /// grid's [`Self::phase`]), so a child's step from its parent telescopes between
    /// neighbours on every level.
    pub(crate) fn offset(&self, c: usize, v: [i32; 3]) -> Option<[i32; 3]> {
        let h = (1i64 << self.level) as f64;
        let u = self.interpolated(c, v)?;
        Some(std::array::from_fn(|a| (h * u[a] - self.phase[a]).round() as i32))
    }

    /// The sub-pixel part of the warp at finest voxel `v`, what [`Self::offset`] rounds
    /// away on level 0: `2^g U − φ − R`, each in `[−½, ½]`; `None` off the grid. A
    /// function of the position alone.
    pub(crate) fn residual(&self, v: [i32; 3]) -> Option<[f64; 3]> {
        let h = (1i64 << self.level) as f64;
        let u = self.interpolated(0, v)?;
        Some(std::array::from_fn(|a| {
            let x = h * u[a] - self.phase[a];
            x - x.round()
        }))
    }

    /// `U(v)`, or `None` outside the box.
    #[cfg(test)]
    pub(crate) fn get(&self, v: [i32; 3]) -> Option<[f64; 3]> {
        let mut i = [0usize; 3];
        for a in 0..3 {
            let o = v[a] - self.lo[a];
            if o < 0 || o as usize >= self.dims[a] {
                return None;
            }
            i[a] = o as usize;
        }
        Some(self.u[(i[2] * self.dims[1] + i[1]) * self.dims[0] + i[0]])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solid::voxel_lattice::ConstantFrame;

    #[test]
    fn a_constant_frame_integrates_to_its_own_coordinates() {
        // Frame turned 90° about z: local x = world y, local y = −world x.
        let r = [0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];
        let lattice = VoxelLattice { origin: [0.0; 3], spacing: 1.0 };
        let init = IntegratedInit::new(&lattice, &ConstantFrame(r), 2, [20, 16, 12], 3);
        let (a, b) = (init.get([1, 1, 1]).unwrap(), init.get([2, 1, 1]).unwrap());
        // One voxel along world x is Rᵀ e_x = (0, −1, 0) in local coordinates.
        let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        assert!((d[0]).abs() < 1e-6 && (d[1] + 1.0).abs() < 1e-6 && d[2].abs() < 1e-6, "{d:?}");
        assert!(init.get([-4, 0, 0]).is_none());
    }
}
