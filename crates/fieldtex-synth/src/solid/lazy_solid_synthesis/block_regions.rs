//! Voxel regions of the lazy solid synthesizer's blocks: the index of a voxel in a
//! block, a cube of voxels built voxel by voxel, and a cursor that reads voxels from a
//! level's cached primary or dual blocks (the version-0 regions of [`super`]).

use super::{BlockMap, Triple};

#[inline]
pub(super) fn local_index(v: [i32; 3], o: [i32; 3], m: i32) -> usize {
    (((v[2] - o[2]) * m + (v[1] - o[1])) * m + (v[0] - o[0])) as usize
}

/// The values of the cube of side `s` from voxel `origin` (x fastest).
pub(super) fn region_of<T>(
    origin: [i32; 3],
    s: i32,
    mut value: impl FnMut([i32; 3]) -> T,
) -> Vec<T> {
    let mut out = Vec::with_capacity((s * s * s) as usize);
    for_box(origin, origin.map(|x| x + s - 1), |v| out.push(value(v)));
    out
}

/// Reads voxels from the cached blocks of one grid (primary or dual) of one level,
/// keeping the last block found (neighbouring reads mostly fall in the same block).
pub(super) struct BlockCursor<'c> {
    map: &'c BlockMap,
    m: i32,
    block_of: fn([i32; 3], i32) -> [i32; 3],
    origin_of: fn([i32; 3], i32) -> [i32; 3],
    last: Option<([i32; 3], [i32; 3], &'c [Triple])>,
}

impl<'c> BlockCursor<'c> {
    pub(super) fn new(
        map: &'c BlockMap,
        m: i32,
        block_of: fn([i32; 3], i32) -> [i32; 3],
        origin_of: fn([i32; 3], i32) -> [i32; 3],
    ) -> Self {
        Self { map, m, block_of, origin_of, last: None }
    }

    /// The triple of voxel `v`, whose block the dependency pass computed first.
    pub(super) fn at(&mut self, v: [i32; 3]) -> Triple {
        let b = (self.block_of)(v, self.m);
        let (_, o, blk) = match self.last {
            Some(last) if last.0 == b => last,
            _ => {
                let blk = self.map.get(&b).expect("block computed by the dependency pass");
                let found = (b, (self.origin_of)(b, self.m), blk.as_slice());
                self.last = Some(found);
                found
            }
        };
        blk[local_index(v, o, self.m)]
    }
}

pub(super) fn for_box(lo: [i32; 3], hi: [i32; 3], mut f: impl FnMut([i32; 3])) {
    for z in lo[2]..=hi[2] {
        for y in lo[1]..=hi[1] {
            for x in lo[0]..=hi[0] {
                f([x, y, z]);
            }
        }
    }
}
