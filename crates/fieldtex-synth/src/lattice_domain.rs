//! Dimension-generic synthesis domains: the lattices the parallel engine
//! ([`crate::parallel_synthesis`]) runs over, in 2-D (images, charts, patches) and 3-D
//! (voxel volumes).
//!
//! A `D`-dimensional domain is a hierarchy of sample lattices, level 0 finest. Each
//! sample has up to `3^D − 1` lattice neighbours at offsets `δ ∈ {−1, 0, 1}^D \ {0}`,
//! one parent on the next coarser level (with the sample's offset from the parent's
//! centre, `{±½}^D` for a regular lattice), an interleaving class in `0..2^D` for the
//! correction subpasses (samples of one class are never neighbours) and a local
//! Jacobian `J` of 2 rows and `D` columns mapping a domain offset (in samples of its
//! level) to an exemplar offset (in exemplar pixels; the engine multiplies by the level
//! spacing `2^level`).
//!
//! **One exemplar for every dimension.** The exemplar is always the 2-D image of
//! [`crate::ExemplarAnalysis`]; a sample's value is a 2-D exemplar coordinate for any
//! `D`. On a 3-D lattice `J` has rank 2: it projects a voxel offset onto the exemplar
//! plane, and its null direction `n` is the direction along which the synthesised
//! volume repeats the same exemplar coordinates (the engine keeps columns along `n`
//! coherent, because the neighbours along `n` predict the centre's own coordinate).
//! Every slice across `n` shows the exemplar's texture with the frame `J` gives. This
//! is the parallel engine's own generalisation (Lefebvre & Hoppe 2005 §3, 2006 §6 with
//! a 3-D index space), not solid texture synthesis from three orthogonal views (Kopf et
//! al. 2007; Dong et al. 2008, paper E), which compares three 2-D neighbourhoods per
//! voxel against three exemplars: that is `crate::solid`'s lazy engine.
//!
//! 2-D domains keep the [`SynthesisDomain`] trait (2×2 Jacobian as `[f32; 4]`);
//! [`PlanarDomain`] presents one as a `LatticeDomain<2>`.

use crate::domain::check_jacobian;
use crate::{SynthError, SynthesisDomain};

/// A 2 × `D` Jacobian: two rows (exemplar x, exemplar y), `D` columns (domain axes).
pub type Jacobian<const D: usize> = [[f32; D]; 2];

/// A hierarchy of `D`-dimensional sample lattices the parallel engine runs over.
/// Implementations must be cheap to query: the engine tabulates one level at a time.
pub trait LatticeDomain<const D: usize>: Sync {
    /// Number of levels available (level 0 finest). The engine uses
    /// `min(analysis levels, level_count − 1)` synthesis levels plus one coarser
    /// initialisation level.
    fn level_count(&self) -> usize;
    /// Samples on `level`.
    fn sample_count(&self, level: usize) -> usize;
    /// The sample at lattice offset `offset` (each component in `−1..=1`) from
    /// `sample`, or `None` outside the domain.
    fn neighbor(&self, level: usize, sample: usize, offset: [i32; D]) -> Option<usize>;
    /// The parent of `sample` on `level + 1` and the sample's offset from the parent's
    /// centre in samples of `level`.
    fn parent(&self, level: usize, sample: usize) -> (usize, [f32; D]);
    /// Jacobian of `sample` (domain offset → exemplar offset).
    fn jacobian(&self, level: usize, sample: usize) -> Jacobian<D>;
    /// Interleaving class in `0..2^D` (samples of one class are never neighbours); for
    /// a lattice `Σ_i (x_i mod 2) 2^i`.
    fn subpass_class(&self, level: usize, sample: usize) -> usize;
}

/// A 2-D [`SynthesisDomain`] seen as a `LatticeDomain<2>` (the Jacobian's rows are
/// `[j00, j01]`, `[j10, j11]`; nothing else changes).
pub struct PlanarDomain<'a>(pub &'a dyn SynthesisDomain);

impl LatticeDomain<2> for PlanarDomain<'_> {
    fn level_count(&self) -> usize {
        self.0.level_count()
    }
    fn sample_count(&self, level: usize) -> usize {
        self.0.sample_count(level)
    }
    fn neighbor(&self, level: usize, sample: usize, offset: [i32; 2]) -> Option<usize> {
        self.0.neighbor(level, sample, offset)
    }
    fn parent(&self, level: usize, sample: usize) -> (usize, [f32; 2]) {
        self.0.parent(level, sample)
    }
    fn jacobian(&self, level: usize, sample: usize) -> Jacobian<2> {
        let j = self.0.jacobian(level, sample);
        [[j[0], j[1]], [j[2], j[3]]]
    }
    fn subpass_class(&self, level: usize, sample: usize) -> usize {
        self.0.subpass_class(level, sample)
    }
}

/// Corner offsets `Δ` of the four-corner neighbourhood (exemplar space, any `D`); bit 0
/// of the index is the x sign (0 = −1), bit 1 the y sign.
pub(crate) const CORNERS: [[i32; 2]; 4] = [[-1, -1], [1, -1], [-1, 1], [1, 1]];

/// What the engine needs to know about the neighbour stencil of a `D`-dimensional
/// lattice with `S = 3^D − 1` neighbours. Implemented by [`Dim`]`<2>` and `Dim<3>`.
pub(crate) trait Stencil<const D: usize, const S: usize> {
    /// Neighbour offsets, in the order of the engine's neighbour slots.
    const OFFSETS: [[i32; D]; S];
    /// Slots of the `2D` axis neighbours (the flip-combing sweep).
    const AXES: &'static [usize];
    /// Per corner of [`CORNERS`], the three neighbour slots whose predictions the
    /// corner's appearance averages, given the sample's (scaled) Jacobian.
    fn corner_slots(j: &Jacobian<D>) -> [[u8; 3]; 4];
    /// Rejects non-finite and (nearly) rank-deficient Jacobians.
    fn check(level: usize, sample: usize, j: &Jacobian<D>) -> Result<(), SynthError>;
}

/// Marker type of the lattice dimension (see [`Stencil`]).
pub(crate) struct Dim<const D: usize>;

/// 2-D neighbour offsets in angular order (angle `k · 45°` from +x, y down).
pub(crate) const OFFS8: [[i32; 2]; 8] =
    [[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1]];

/// Unit vectors of [`OFFS8`] (angle `k · 45°`).
const DIRS8: [[f32; 2]; 8] = {
    const R: f32 = std::f32::consts::FRAC_1_SQRT_2;
    [[1.0, 0.0], [R, R], [0.0, 1.0], [-R, R], [-1.0, 0.0], [-R, -R], [0.0, -1.0], [R, -R]]
};

impl Stencil<2, 8> for Dim<2> {
    const OFFSETS: [[i32; 2]; 8] = OFFS8;
    const AXES: &'static [usize] = &[0, 2, 4, 6];

    /// Per corner, the direction of [`OFFS8`] with the largest dot product with the
    /// warped corner offset `J⁻¹ Δ` (the angularly nearest; the lowest index on exact
    /// ties) and its two angular neighbours.
    fn corner_slots(j: &Jacobian<2>) -> [[u8; 3]; 4] {
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let jinv = [[j[1][1] / det, -j[0][1] / det], [-j[1][0] / det, j[0][0] / det]];
        CORNERS.map(|cd| {
            let phi = mat_vec(&jinv, [cd[0] as f32, cd[1] as f32]);
            let mut best = (f32::NEG_INFINITY, 0u8);
            for (k, d) in DIRS8.iter().enumerate() {
                let dot = d[0] * phi[0] + d[1] * phi[1];
                if dot > best.0 {
                    best = (dot, k as u8);
                }
            }
            let dir = best.1;
            [(dir + 7) % 8, dir, (dir + 1) % 8]
        })
    }

    fn check(level: usize, sample: usize, j: &Jacobian<2>) -> Result<(), SynthError> {
        check_jacobian(level, sample, &[j[0][0], j[0][1], j[1][0], j[1][1]])
    }
}

/// 3-D neighbour offsets: `{−1, 0, 1}³ \ {0}`, x fastest.
const OFFS26: [[i32; 3]; 26] = {
    let mut out = [[0i32; 3]; 26];
    let mut n = 0;
    let mut i = 0i32;
    while i < 27 {
        let o = [i % 3 - 1, (i / 3) % 3 - 1, i / 9 - 1];
        if !(o[0] == 0 && o[1] == 0 && o[2] == 0) {
            out[n] = o;
            n += 1;
        }
        i += 1;
    }
    out
};

impl Stencil<3, 26> for Dim<3> {
    const OFFSETS: [[i32; 3]; 26] = OFFS26;
    // (−1,0,0), (1,0,0), (0,−1,0), (0,1,0), (0,0,−1), (0,0,1).
    const AXES: &'static [usize] = &[12, 13, 10, 15, 4, 21];

    /// Per corner `Δ`, the three neighbours whose exemplar-space offsets `J δ` point
    /// most nearly along `Δ` (largest cosine; the lowest slot on exact ties; offsets
    /// along the null direction of `J`, `|J δ| ≈ 0`, never). The 2-D rule's analogue
    /// measured in exemplar space, where a rank-2 `J` has a well-defined direction.
    fn corner_slots(j: &Jacobian<3>) -> [[u8; 3]; 4] {
        let e: Vec<[f32; 2]> =
            OFFS26.iter().map(|d| mat_vec(j, [d[0] as f32, d[1] as f32, d[2] as f32])).collect();
        let norm2 = frobenius(j, j);
        CORNERS.map(|cd| {
            let mut best = [(f32::NEG_INFINITY, 0u8); 3];
            for (k, v) in e.iter().enumerate() {
                let len = (v[0] * v[0] + v[1] * v[1]).sqrt();
                if len <= 1e-4 * norm2.sqrt() {
                    continue;
                }
                let cos = (v[0] * cd[0] as f32 + v[1] * cd[1] as f32) / len;
                // Insert into the sorted top three (strictly better only: ties keep
                // the lower slot).
                let mut slot = (cos, k as u8);
                for b in best.iter_mut() {
                    if slot.0 > b.0 {
                        std::mem::swap(b, &mut slot);
                    }
                }
            }
            best.map(|b| b.1)
        })
    }

    fn check(level: usize, sample: usize, j: &Jacobian<3>) -> Result<(), SynthError> {
        let bad = |reason: &str| {
            Err(SynthError::InvalidDomain {
                reason: format!(
                    "level {level} sample {sample}: Jacobian {j:?} is {reason} (a 3-D lattice \
                     needs a finite 2×3 Jacobian of rank 2)"
                ),
            })
        };
        if j.iter().flatten().any(|v| !v.is_finite()) {
            return bad("not finite");
        }
        // Gram determinant of the two rows: det(J Jᵀ), the square of the 2-D |det J|.
        let dot = |a: &[f32; 3], b: &[f32; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let gram = dot(&j[0], &j[0]) * dot(&j[1], &j[1]) - dot(&j[0], &j[1]).powi(2);
        let norm2 = frobenius(j, j);
        if gram.is_nan() || norm2 < 1e-12 || gram <= (1e-6 * norm2).powi(2) {
            return bad("singular");
        }
        Ok(())
    }
}

/// `J v` (the sums in index order, as the 2-D engine always wrote them).
#[inline]
pub(crate) fn mat_vec<const D: usize>(j: &Jacobian<D>, v: [f32; D]) -> [f32; 2] {
    j.map(|row| {
        let mut acc = row[0] * v[0];
        for i in 1..D {
            acc += row[i] * v[i];
        }
        acc
    })
}

/// Frobenius product `⟨a, b⟩` (row-major sum, left to right).
#[inline]
pub(crate) fn frobenius<const D: usize>(a: &Jacobian<D>, b: &Jacobian<D>) -> f32 {
    let mut acc = a[0][0] * b[0][0];
    for i in 1..D {
        acc += a[0][i] * b[0][i];
    }
    for i in 0..D {
        acc += a[1][i] * b[1][i];
    }
    acc
}

/// `−J`.
#[inline]
pub(crate) fn negated<const D: usize>(j: &Jacobian<D>) -> Jacobian<D> {
    j.map(|row| row.map(|v| -v))
}

/// `½ (a + b)`, entrywise.
#[inline]
pub(crate) fn mean<const D: usize>(a: &Jacobian<D>, b: &Jacobian<D>) -> Jacobian<D> {
    std::array::from_fn(|r| std::array::from_fn(|c| 0.5 * (a[r][c] + b[r][c])))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stencils_list_every_offset_once_and_name_the_axes() {
        let o3 = <Dim<3> as Stencil<3, 26>>::OFFSETS;
        for (k, o) in o3.iter().enumerate() {
            assert!(o.iter().all(|c| (-1..=1).contains(c)) && *o != [0, 0, 0]);
            assert!(!o3[..k].contains(o));
        }
        let axes3: Vec<[i32; 3]> =
            <Dim<3> as Stencil<3, 26>>::AXES.iter().map(|&k| o3[k]).collect();
        assert_eq!(axes3, [[-1, 0, 0], [1, 0, 0], [0, -1, 0], [0, 1, 0], [0, 0, -1], [0, 0, 1]]);
        let axes2: Vec<[i32; 2]> =
            <Dim<2> as Stencil<2, 8>>::AXES.iter().map(|&k| OFFS8[k]).collect();
        assert_eq!(axes2, [[1, 0], [0, 1], [-1, 0], [0, -1]]);
    }

    #[test]
    fn corner_slots_follow_the_exemplar_frame() {
        // Identity in x and y, z along the null direction: the corner (+1, +1) is
        // predicted by the neighbours whose xy part is (1, 1) (all three z layers).
        let j: Jacobian<3> = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let slots = <Dim<3> as Stencil<3, 26>>::corner_slots(&j);
        for s in slots[3] {
            let o = OFFS26[s as usize];
            assert_eq!([o[0], o[1]], [1, 1], "{:?}", slots[3]);
        }
        // The 2-D rule for the identity: the diagonal and its two angular neighbours.
        let s2 = <Dim<2> as Stencil<2, 8>>::corner_slots(&[[1.0, 0.0], [0.0, 1.0]]);
        assert_eq!(s2[3], [0, 1, 2]);
        // Rank-deficient 3-D Jacobians are rejected.
        let flat: Jacobian<3> = [[1.0, 1.0, 0.0], [2.0, 2.0, 0.0]];
        assert!(<Dim<3> as Stencil<3, 26>>::check(0, 0, &flat).is_err());
        assert!(<Dim<3> as Stencil<3, 26>>::check(0, 0, &j).is_ok());
    }

    #[test]
    fn generic_products_match_the_flat_2d_formulas() {
        let a: Jacobian<2> = [[0.3, -1.7], [2.1, 0.45]];
        let b: Jacobian<2> = [[-0.9, 0.2], [1.3, -0.05]];
        let flat = a[0][0] * b[0][0] + a[0][1] * b[0][1] + a[1][0] * b[1][0] + a[1][1] * b[1][1];
        assert_eq!(frobenius(&a, &b).to_bits(), flat.to_bits());
        let v = [0.7f32, -1.1];
        let mv = [a[0][0] * v[0] + a[0][1] * v[1], a[1][0] * v[0] + a[1][1] * v[1]];
        assert_eq!(mat_vec(&a, v).map(f32::to_bits), mv.map(f32::to_bits));
    }
}
