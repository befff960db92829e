//! Checks and small fix-ups shared by the mesh readers: non-finite coordinates are
//! reported (not dropped), colours clamped, exactly coincident positions welded (STL,
//! glTF), and the vertex count checked against the `u32` index type.

use crate::IoError;
use fieldtex_core::Warning;
use std::collections::HashMap;

/// Adds a `non-finite-positions` warning when some coordinate is NaN or ±∞, naming the
/// first such vertex. The vertices are kept; `TriMesh::validate` flags them and the
/// repair step removes them.
pub(crate) fn warn_non_finite(name: &str, positions: &[[f64; 3]], warnings: &mut Vec<Warning>) {
    let bad = |p: &[f64; 3]| !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite());
    let count = positions.iter().filter(|p| bad(p)).count();
    if let Some(first) = positions.iter().position(bad) {
        warnings.push(Warning::new(
            "non-finite-positions",
            format!(
                "{name}: {count} vertices have NaN or infinite coordinates (first: vertex {first} \
                 = {:?}); run repair to drop them",
                positions[first]
            ),
        ));
    }
}

/// Clamps colour channels into `[0, 1]` (NaN → 0), warning when something changed.
pub(crate) fn clamp_colors(name: &str, colors: &mut [[f32; 4]], warnings: &mut Vec<Warning>) {
    let mut changed = 0usize;
    for c in colors.iter_mut() {
        for x in c.iter_mut() {
            let y = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
            if y != *x {
                changed += 1;
                *x = y;
            }
        }
    }
    if changed > 0 {
        warnings.push(Warning::new(
            "colors-clamped",
            format!("{name}: {changed} colour channel values were outside [0, 1] and were clamped"),
        ));
    }
}

/// Refuses vertex counts that do not fit the `u32` indices of `TriMesh`.
pub(crate) fn check_vertex_count(name: &str, n: u64) -> Result<(), IoError> {
    if n >= u32::MAX as u64 {
        return Err(IoError::Unsupported {
            file: name.to_string(),
            what: format!("{n} vertices (at most {} are supported)", u32::MAX - 1),
        });
    }
    Ok(())
}

/// Merges vertices whose positions are bit-identical (after mapping -0.0 to +0.0).
/// Returns the welded positions and, for each input vertex, its new index; the first
/// occurrence's index order is kept.
pub(crate) fn weld_identical(positions: &[[f64; 3]]) -> (Vec<[f64; 3]>, Vec<u32>) {
    let key = |p: &[f64; 3]| p.map(|x| if x == 0.0 { 0u64 } else { x.to_bits() });
    let mut map: HashMap<[u64; 3], u32> = HashMap::with_capacity(positions.len() / 2);
    let mut out = Vec::with_capacity(positions.len() / 2);
    let mut remap = Vec::with_capacity(positions.len());
    for p in positions {
        let next = out.len() as u32;
        let id = *map.entry(key(p)).or_insert(next);
        if id == next {
            out.push(*p);
        }
        remap.push(id);
    }
    (out, remap)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weld_merges_signed_zero() {
        let (p, r) = weld_identical(&[[0.0, 1.0, 2.0], [-0.0, 1.0, 2.0], [1.0, 1.0, 2.0]]);
        assert_eq!(p.len(), 2);
        assert_eq!(r, vec![0, 0, 1]);
    }
}
