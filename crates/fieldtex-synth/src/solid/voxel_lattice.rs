//! The 3-D voxel lattice of solid synthesis: an infinite integer lattice per level,
//! computed arithmetically (never stored whole), with the block partition of the
//! dual-grid correction (paper E §5.3).
//!
//! Level `c` (0 = finest) has voxels `v ∈ ℤ³`; voxel `v` of level `c` covers the finest
//! voxels `2^c v + [0, 2^c)³` and its parent is `⌊v / 2⌋` at level `c + 1`. The finest
//! voxel `(i, j, k)` has its centre at `origin + (i, j, k) · spacing` (world units),
//! so level `c`'s voxel centre is `origin + (2^c v + (2^c − 1)/2) · spacing`.
//!
//! Blocks of side `M`: the *primary* block `b` holds voxels `M b + [0, M)³`, the *dual*
//! block `b` holds `M b + M/2 + [0, M)³` (the primary grid shifted by half a block,
//! paper E Fig. 7).

/// World frame of a point: a rotation matrix, row-major, whose columns are the local
/// x, y, z axes (`[f64; 9]`, see `fieldtex_fields::quaternion`).
pub trait FrameSource: Sync {
    /// The local frame at world point `p`.
    fn frame(&self, p: [f64; 3]) -> [f64; 9];
}

/// The identity frame everywhere (a "trivial field": unguided solid synthesis).
pub struct ConstantFrame(pub [f64; 9]);

impl FrameSource for ConstantFrame {
    fn frame(&self, _p: [f64; 3]) -> [f64; 9] {
        self.0
    }
}

/// Placement of the finest lattice in world space.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct VoxelLattice {
    /// Centre of finest voxel (0, 0, 0).
    pub origin: [f64; 3],
    /// Finest voxel size (cubic voxels).
    pub spacing: f64,
}

impl VoxelLattice {
    /// World centre of voxel `v` of level `c`.
    #[inline]
    pub fn centre(&self, c: usize, v: [i32; 3]) -> [f64; 3] {
        let s = (1i64 << c) as f64;
        let half = (s - 1.0) * 0.5;
        std::array::from_fn(|a| self.origin[a] + (s * v[a] as f64 + half) * self.spacing)
    }
}

/// `⌊a / b⌋` for `b > 0`.
#[inline]
pub fn floor_div(a: i32, b: i32) -> i32 {
    a.div_euclid(b)
}

/// Primary block holding voxel `v` (block side `m`).
#[inline]
pub fn primary_block(v: [i32; 3], m: i32) -> [i32; 3] {
    std::array::from_fn(|a| floor_div(v[a], m))
}

/// Dual block holding voxel `v` (block side `m`).
#[inline]
pub fn dual_block(v: [i32; 3], m: i32) -> [i32; 3] {
    std::array::from_fn(|a| floor_div(v[a] - m / 2, m))
}

/// First voxel of primary block `b`.
#[inline]
pub fn primary_origin(b: [i32; 3], m: i32) -> [i32; 3] {
    std::array::from_fn(|a| b[a] * m)
}

/// First voxel of dual block `b`.
#[inline]
pub fn dual_origin(b: [i32; 3], m: i32) -> [i32; 3] {
    std::array::from_fn(|a| b[a] * m + m / 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_contain_their_voxels() {
        for v in [[0, 0, 0], [-1, 5, 13], [-13, -6, 7], [24, 23, 11]] {
            let m = 12;
            let p = primary_origin(primary_block(v, m), m);
            let d = dual_origin(dual_block(v, m), m);
            for a in 0..3 {
                assert!(p[a] <= v[a] && v[a] < p[a] + m);
                assert!(d[a] <= v[a] && v[a] < d[a] + m);
            }
        }
        let l = VoxelLattice { origin: [1.0, 2.0, 3.0], spacing: 0.5 };
        // Level 1 voxel 0 covers finest voxels 0 and 1: centre halfway between them.
        assert_eq!(l.centre(1, [0, 0, 0]), [1.25, 2.25, 3.25]);
    }
}
