//! A box of samples in `D` dimensions as a synthesis domain ([`LatticeDomain`]): the
//! finest level is `size[0] × … × size[D−1]`, each coarser level halves every side
//! (rounding up) down to one sample. Everything is computed arithmetically from the
//! sample index (x fastest); the only state is the size and the Jacobian field, a
//! function of the finest-level position, so a volume is never stored whole.
//!
//! `RegularLattice<2>` is the plane (what [`crate::ImageDomain`] is with a stored
//! Jacobian per pixel); `RegularLattice<3>` a voxel volume, which the parallel engine
//! synthesises with [`crate::synthesize_volume`].

use std::sync::Arc;

use crate::SynthError;
use crate::lattice_domain::{Jacobian, LatticeDomain};

/// Levels a [`RegularLattice`] reports (levels beyond one sample stay one sample).
const LATTICE_LEVELS: usize = 24;

/// The Jacobian field of a lattice: finest-level sample position (`[x, y, …]`, in
/// samples) → 2 × `D` Jacobian.
pub type JacobianField<const D: usize> = Arc<dyn Fn([f32; D]) -> Jacobian<D> + Send + Sync>;

/// A `D`-dimensional box of samples with a Jacobian field (see the module doc).
#[derive(Clone)]
pub struct RegularLattice<const D: usize> {
    size: [usize; D],
    field: JacobianField<D>,
}

impl<const D: usize> std::fmt::Debug for RegularLattice<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RegularLattice").field("size", &self.size).finish_non_exhaustive()
    }
}

impl<const D: usize> RegularLattice<D> {
    /// A lattice of `size` finest samples whose Jacobian at finest position `x` is
    /// `field(x)`. Every side must be at least 1 and the sample count fit `u32`.
    pub fn new(size: [usize; D], field: JacobianField<D>) -> Result<Self, SynthError> {
        let count = size.iter().try_fold(1usize, |a, &s| a.checked_mul(s));
        if size.contains(&0) || count.is_none_or(|c| c > u32::MAX as usize / 2) {
            return Err(SynthError::InvalidDomain {
                reason: format!(
                    "lattice of {size:?} samples: every side must be at least 1 and the \
                     sample count below 2^31"
                ),
            });
        }
        Ok(Self { size, field })
    }

    /// A lattice with one Jacobian everywhere.
    pub fn constant(size: [usize; D], jacobian: Jacobian<D>) -> Result<Self, SynthError> {
        Self::new(size, Arc::new(move |_| jacobian))
    }

    /// Finest size.
    pub fn size(&self) -> [usize; D] {
        self.size
    }

    /// Size of `level`.
    pub fn level_size(&self, level: usize) -> [usize; D] {
        let sh = level.min(63) as u32;
        self.size.map(|n| n.div_ceil(1usize.checked_shl(sh).unwrap_or(usize::MAX)).max(1))
    }

    /// Lattice position of `sample` on a level of size `dims`.
    fn position(dims: &[usize; D], mut sample: usize) -> [usize; D] {
        let mut p = [0usize; D];
        for (c, &n) in p.iter_mut().zip(dims) {
            *c = sample % n;
            sample /= n;
        }
        p
    }

    /// Index of position `p` on a level of size `dims`.
    fn index(dims: &[usize; D], p: &[usize; D]) -> usize {
        (0..D).rev().fold(0, |acc, i| acc * dims[i] + p[i])
    }
}

impl<const D: usize> LatticeDomain<D> for RegularLattice<D> {
    fn level_count(&self) -> usize {
        LATTICE_LEVELS
    }

    fn sample_count(&self, level: usize) -> usize {
        self.level_size(level).iter().product()
    }

    fn neighbor(&self, level: usize, sample: usize, offset: [i32; D]) -> Option<usize> {
        let dims = self.level_size(level);
        let mut p = Self::position(&dims, sample);
        for i in 0..D {
            let v = p[i] as i64 + offset[i] as i64;
            if v < 0 || v >= dims[i] as i64 {
                return None;
            }
            p[i] = v as usize;
        }
        Some(Self::index(&dims, &p))
    }

    fn parent(&self, level: usize, sample: usize) -> (usize, [f32; D]) {
        let p = Self::position(&self.level_size(level), sample);
        let parent = p.map(|v| v / 2);
        let off = p.map(|v| if v.is_multiple_of(2) { -0.5 } else { 0.5 });
        (Self::index(&self.level_size(level + 1), &parent), off)
    }

    fn jacobian(&self, level: usize, sample: usize) -> Jacobian<D> {
        // Point-sample the field at the centre of the coarse sample's finest footprint.
        let p = Self::position(&self.level_size(level), sample);
        let half = if level == 0 { 0 } else { 1usize << (level.min(62) - 1) };
        let mut x = [0f32; D];
        for i in 0..D {
            x[i] = (p[i] << level.min(62)).saturating_add(half).min(self.size[i] - 1) as f32;
        }
        (self.field)(x)
    }

    fn subpass_class(&self, level: usize, sample: usize) -> usize {
        let p = Self::position(&self.level_size(level), sample);
        (0..D).map(|i| (p[i] % 2) << i).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_volume_hierarchy_is_consistent() {
        let j: Jacobian<3> = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let v = RegularLattice::constant([5, 3, 4], j).unwrap();
        assert_eq!(v.sample_count(0), 60);
        assert_eq!(v.level_size(1), [3, 2, 2]);
        assert_eq!(v.level_size(4), [1, 1, 1]);
        // Sample (4, 2, 3) = 4 + 5 (2 + 3·3) = 59: parent (2, 1, 1) on 3×2×2.
        assert_eq!(v.parent(0, 59), (2 + 3 * (1 + 2), [-0.5, -0.5, 0.5]));
        assert_eq!(v.neighbor(0, 59, [1, 0, 0]), None);
        assert_eq!(v.neighbor(0, 59, [-1, 0, -1]), Some(3 + 5 * (2 + 3 * 2)));
        assert_eq!(v.subpass_class(0, 59), 4);
        // Neighbours are never in the sample's own class.
        for s in 0..60 {
            for o in [[1, 0, 0], [0, 1, 1], [1, 1, 1], [-1, 0, 1]] {
                if let Some(q) = v.neighbor(0, s, o) {
                    assert_ne!(v.subpass_class(0, s), v.subpass_class(0, q));
                }
            }
        }
        assert!(RegularLattice::constant([0, 3, 4], j).is_err());
    }

    #[test]
    fn the_plane_matches_the_image_domain() {
        use crate::{ImageDomain, SynthesisDomain};
        let img = ImageDomain::constant(7, 5, 0.4, 1.0).unwrap();
        let j = img.jacobian[0];
        let lat = RegularLattice::constant([7, 5], [[j[0], j[1]], [j[2], j[3]]]).unwrap();
        for level in 0..4 {
            assert_eq!(lat.sample_count(level), img.sample_count(level));
            for s in 0..img.sample_count(level) {
                assert_eq!(lat.parent(level, s), img.parent(level, s));
                assert_eq!(lat.subpass_class(level, s), img.subpass_class(level, s));
                for o in [[1, 0], [-1, 1], [0, -1]] {
                    assert_eq!(lat.neighbor(level, s, o), img.neighbor(level, s, o));
                }
            }
        }
    }
}
