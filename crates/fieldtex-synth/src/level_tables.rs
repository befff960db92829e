//! One domain level tabulated for the parallel synthesis ([`crate::synthesize`]):
//! neighbours, Jacobians (times the option scale), subpass classes, parents and, per
//! sample, which neighbours predict each corner of the four-corner neighbourhood.
//! Generic over the lattice dimension `D` and its stencil size `S = 3^D − 1`
//! ([`crate::lattice_domain`]).

use rayon::prelude::*;

use crate::SynthError;
use crate::lattice_domain::{Dim, Jacobian, LatticeDomain, Stencil};

/// No neighbour.
pub(crate) const NONE: u32 = u32::MAX;

/// One domain level, tabulated.
pub(crate) struct LevelTables<const D: usize, const S: usize> {
    /// Neighbours in the slot order of [`Stencil::OFFSETS`].
    pub(crate) nbr: Vec<[u32; S]>,
    pub(crate) jac: Vec<Jacobian<D>>,
    pub(crate) classes: Vec<Vec<u32>>,
    pub(crate) parent: Vec<(u32, [f32; D])>,
    /// Per sample and corner `Δ`, the three neighbour slots whose predictions the
    /// corner averages ([`Stencil::corner_slots`]).
    pub(crate) corner_slots: Vec<[[u8; 3]; 4]>,
}

pub(crate) fn tabulate<const D: usize, const S: usize>(
    domain: &dyn LatticeDomain<D>,
    level: usize,
    scale: f32,
    subpasses: usize,
    with_parent: bool,
) -> Result<LevelTables<D, S>, SynthError>
where
    Dim<D>: Stencil<D, S>,
{
    let n = domain.sample_count(level);
    let coarse_n = if with_parent { domain.sample_count(level + 1) } else { 0 };
    let n_classes = 1usize << D;
    type Row<const D: usize, const S: usize> = ([u32; S], Jacobian<D>, u8, (u32, [f32; D]));
    let rows: Vec<Result<Row<D, S>, SynthError>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut nb = [NONE; S];
            for (k, o) in <Dim<D> as Stencil<D, S>>::OFFSETS.iter().enumerate() {
                if let Some(q) = domain.neighbor(level, i, *o) {
                    if q >= n {
                        return Err(SynthError::InvalidDomain {
                            reason: format!(
                                "level {level} sample {i}: neighbour {q} ≥ sample count {n}"
                            ),
                        });
                    }
                    nb[k] = q as u32;
                }
            }
            let j = domain.jacobian(level, i);
            <Dim<D> as Stencil<D, S>>::check(level, i, &j)?;
            let j = j.map(|row| row.map(|v| v * scale));
            let class = if subpasses == 1 { 0 } else { domain.subpass_class(level, i) };
            if class >= n_classes {
                return Err(SynthError::InvalidDomain {
                    reason: format!(
                        "level {level} sample {i}: subpass class {class} ≥ {n_classes}"
                    ),
                });
            }
            let parent = if with_parent {
                let (pi, off) = domain.parent(level, i);
                if pi >= coarse_n || !off.iter().all(|v| v.is_finite()) {
                    return Err(SynthError::InvalidDomain {
                        reason: format!(
                            "level {level} sample {i}: parent {pi} / offset {off:?} invalid"
                        ),
                    });
                }
                (pi as u32, off)
            } else {
                (0, [0.0; D])
            };
            Ok((nb, j, class as u8, parent))
        })
        .collect();
    let classes = if subpasses == 1 { 1 } else { n_classes };
    let mut t = LevelTables {
        nbr: Vec::with_capacity(n),
        jac: Vec::with_capacity(n),
        classes: vec![Vec::new(); classes],
        parent: Vec::with_capacity(n),
        corner_slots: Vec::with_capacity(n),
    };
    for (i, r) in rows.into_iter().enumerate() {
        let (nb, j, class, parent) = r?;
        t.nbr.push(nb);
        t.corner_slots.push(<Dim<D> as Stencil<D, S>>::corner_slots(&j));
        t.jac.push(j);
        t.classes[class as usize].push(i as u32);
        t.parent.push(parent);
    }
    t.classes.retain(|c| !c.is_empty());
    Ok(t)
}
