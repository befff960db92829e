//! 8-wide BVH for ray casting: a binary BVH collapsed into nodes of up to eight children
//! whose boxes are stored by coordinate (two 4-lane SIMD registers per bound), tested
//! against a ray four at a time, or all eight at once with AVX2 where the CPU has it
//! (detected at run time; the same operations in the same order on every lane, so the
//! same results, checked by tests) (the layout of Wald, Benthin & Boulos 2008, "Getting Rid of
//! Packets: Efficient SIMD Single-Ray Traversal using Multi-branching BVHs", and of
//! Dammertz, Hanika & Keller 2008, "Shallow Bounding Volume Hierarchies for Fast SIMD Ray
//! Tracing of Incoherent Rays").
//!
//! Collapse: starting from a binary node's two children, the child with the largest box
//! is repeatedly replaced by its own two children until eight slots are used; a subtree
//! with at most [`LEAF_MAX`] triangles becomes a leaf. Nodes are stored depth first
//! (a node's first inner child directly follows it) and leaf triangles in traversal
//! order, so the triangle rows of a leaf are contiguous.
//!
//! Traversal visits the hit children nearest first and prunes by the current closest
//! hit. Box tests are conservative: the far slab distance is enlarged by `1 + 2γ₃`
//! (Ize 2013, "Robust BVH Ray Traversal", JCGT 2(2)), a zero direction component is
//! replaced by a tiny one of the same sign while the stored boxes are one ulp wider than
//! their contents (a ray lying in a box face stays inside), and the pruning distance
//! carries a slack of a few hundred ulps of the scene size, so a triangle tying the best
//! hit is still visited. Results therefore do not depend on the tree layout.
//!
//! Memory: the children of every entered node (nodes or leaf triangles) are prefetched
//! as soon as the node is tested, and the large arrays are asked to live on huge pages
//! ([`huge_copy`]). Batches of closest-hit rays are traversed four at a time,
//! interleaved step by step ([`WideBvh::closest_many`]), so one ray's cache misses
//! overlap the others' work (2 or 8 rays measured slower than 4).
//!
//! Measured (instructions counted by `valgrind --tool=callgrind` over
//! `Bvh::intersect_many`, 388K-triangle torus of `bench_geometry`, 100K rays): 2,536
//! instructions per ray before the AVX2 path, 2,228 after it (the box test inlined into
//! the AVX2-compiled traversal, a fixed-size stack push instead of a `memcpy` call); of
//! these ~1,400 are traversal (~6.9 nodes, 1.2 leaves, 1.7 triangles per ray), the rest
//! per-ray setup, `f64` refinement and the ray ordering. With identical rays (all in
//! cache) traversal took nearly as long as with the benchmark's rays: it is bound by
//! instructions and branches more than by memory, which is why compressed (quantised)
//! boxes were not tried. Not implemented: quantised boxes, AVX-512 16-lane tests, packet
//! traversal.

use super::bvh_watertight::{RowTriangle, Shear};
use glam::{Vec3A, Vec4};
use obvhs::bvh2::Bvh2;

/// Children per node (a multiple of 4: boxes are tested 4 at a time).
const W: usize = 8;
/// Largest number of triangles in a leaf.
pub(super) const LEAF_MAX: usize = 3;
/// Entries of the fixed traversal stack; deeper trees use a heap stack.
const FIXED_STACK: usize = 96;

/// A node: boxes of [`W`] children by bound (`b[0..6]` = min x, max x, min y, max y,
/// min z, max z) and the children. `count[i] == 0`: `child[i]` is a node index;
/// otherwise child `i` is a leaf of `count[i]` triangles starting at `child[i]`. Empty
/// slots have inverted (+∞, −∞) boxes, which no ray hits.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Node {
    b: [[f32; W]; 6],
    child: [u32; W],
    count: [u32; W],
}

/// A [`W`]-wide BVH over triangles stored by rows in leaf order.
#[derive(Clone, Debug, Default)]
pub(super) struct WideBvh {
    nodes: Vec<Node>,
    /// Upper bound of the traversal stack size (`W − 1` per level + 1).
    stack_len: usize,
}

/// Per-ray constants of the box test.
#[derive(Clone, Copy)]
pub(super) struct RayBoxes {
    org: [Vec4; 3],
    inv: [Vec4; 3],
    /// Bound index (into `Node::b`) of the near and far plane per axis.
    near: [usize; 3],
    far: [usize; 3],
    tmin: f32,
    /// Pruning slack added to the best hit distance.
    slack: f32,
}

impl RayBoxes {
    /// `org`, `dir`: the `f32` ray (finite); `scene_half`: largest half extent of the
    /// (translated, centred) scene box.
    pub(super) fn new(org: Vec3A, dir: Vec3A, tmin: f32, scene_half: f32) -> Self {
        let safe = |x: f32| if x.abs() < 1e-30 { 1e30f32.copysign(x) } else { 1.0 / x };
        let inv = Vec3A::new(safe(dir.x), safe(dir.y), safe(dir.z));
        let nf = |k: usize| if inv[k] >= 0.0 { (2 * k, 2 * k + 1) } else { (2 * k + 1, 2 * k) };
        let (n0, f0) = nf(0);
        let (n1, f1) = nf(1);
        let (n2, f2) = nf(2);
        let scale = (org.abs().max_element() + scene_half) / dir.abs().max_element();
        Self {
            org: [Vec4::splat(org.x), Vec4::splat(org.y), Vec4::splat(org.z)],
            inv: [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)],
            near: [n0, n1, n2],
            far: [f0, f1, f2],
            tmin,
            slack: scale * (1.0 / 65536.0),
        }
    }

    /// Entry distances of the children's boxes and the mask of those entered within
    /// `[tmin, tlimit]`.
    #[inline(always)]
    fn test(&self, n: &Node, tlimit: f32) -> ([f32; W], u32) {
        // 1 + 2γ₃ with γ₃ = 3ε / (1 − 3ε), ε = 2⁻²⁴, rounded up.
        const GROW: f32 = 1.0 + 2.0 * 3.0 * (f32::EPSILON * 0.5) * 1.000_001;
        let mut tns = [0.0; W];
        let mut mask = 0;
        for h in 0..W / 4 {
            let slab = |k: usize, i: usize| {
                (Vec4::from_slice(&n.b[i][4 * h..4 * h + 4]) - self.org[k]) * self.inv[k]
            };
            let tn = slab(0, self.near[0])
                .max(slab(1, self.near[1]))
                .max(slab(2, self.near[2]).max(Vec4::splat(self.tmin)));
            let tf = slab(0, self.far[0]).min(slab(1, self.far[1])).min(slab(2, self.far[2]))
                * Vec4::splat(GROW);
            let tf = tf.min(Vec4::splat(tlimit));
            tn.write_to_slice(&mut tns[4 * h..4 * h + 4]);
            mask |= tn.cmple(tf).bitmask() << (4 * h);
        }
        (tns, mask)
    }

    /// [`RayBoxes::test`] with 8-lane AVX registers: the same operations in the same
    /// order on every lane, so the same results.
    ///
    /// # Safety
    /// The CPU must support AVX2. Meant to be inlined into functions compiled for AVX2
    /// (the intrinsics are inlined there; elsewhere, as in tests, each is a call).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn test_avx2(&self, n: &Node, tlimit: f32) -> ([f32; W], u32) {
        use std::arch::x86_64::*;
        const GROW: f32 = 1.0 + 2.0 * 3.0 * (f32::EPSILON * 0.5) * 1.000_001;
        const { assert!(W == 8) };
        let mut tns = [0.0; W];
        // SAFETY: the caller guarantees AVX2; `near` and `far` hold bound indices below 6
        // (`RayBoxes::new`), so every row read is one of `n.b`'s 8-float rows, and `tns`
        // holds 8 floats.
        let mask = unsafe {
            let slab = |k: usize, i: usize| {
                _mm256_mul_ps(
                    _mm256_sub_ps(
                        _mm256_loadu_ps(n.b.get_unchecked(i).as_ptr()),
                        _mm256_set1_ps(self.org[k].x),
                    ),
                    _mm256_set1_ps(self.inv[k].x),
                )
            };
            let tn = _mm256_max_ps(
                _mm256_max_ps(slab(0, self.near[0]), slab(1, self.near[1])),
                _mm256_max_ps(slab(2, self.near[2]), _mm256_set1_ps(self.tmin)),
            );
            let tf = _mm256_mul_ps(
                _mm256_min_ps(
                    _mm256_min_ps(slab(0, self.far[0]), slab(1, self.far[1])),
                    slab(2, self.far[2]),
                ),
                _mm256_set1_ps(GROW),
            );
            let tf = _mm256_min_ps(tf, _mm256_set1_ps(tlimit));
            _mm256_storeu_ps(tns.as_mut_ptr(), tn);
            _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(tn, tf)) as u32
        };
        (tns, mask)
    }

    /// [`RayBoxes::test`] on AVX2 lanes when `AVX` (the caller checked the CPU).
    #[inline(always)]
    fn test_on<const AVX: bool>(&self, n: &Node, tlimit: f32) -> ([f32; W], u32) {
        #[cfg(target_arch = "x86_64")]
        if AVX {
            // SAFETY: `AVX` is only set after the CPU was found to support AVX2.
            return unsafe { self.test_avx2(n, tlimit) };
        }
        self.test(n, tlimit)
    }
}

/// Whether the AVX2 box test may be used (checked once, cached by the standard library).
#[inline(always)]
pub(super) fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// A copy of `v` in memory that the kernel is asked to back by huge pages (Linux
/// transparent huge pages, `madvise(MADV_HUGEPAGE)`; a plain copy elsewhere). Traversal
/// touches these arrays at random, and with 4 KiB pages nearly every access to the lower
/// tree levels is also a TLB miss.
pub(super) fn huge_copy<T: Copy>(v: &[T]) -> Vec<T> {
    let mut out = huge_with_capacity(v.len());
    out.extend_from_slice(v);
    out
}

/// An empty vector with room for `n` elements, whose memory the kernel is asked to back
/// by huge pages (see [`huge_copy`]); fill it without reallocating.
pub(super) fn huge_with_capacity<T>(n: usize) -> Vec<T> {
    let out: Vec<T> = Vec::with_capacity(n);
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 1 << 21;
        let bytes = n * size_of::<T>();
        if bytes >= 2 * HUGE {
            let start = out.as_ptr() as usize;
            let a = start.next_multiple_of(HUGE);
            let b = (start + bytes) / HUGE * HUGE;
            if b > a {
                // SAFETY: `[a, b)` lies inside the allocation of `out` (not yet touched);
                // MADV_HUGEPAGE changes only how the kernel backs it, never its contents,
                // and a failure is harmless (the result is ignored).
                unsafe { libc::madvise(a as *mut libc::c_void, b - a, libc::MADV_HUGEPAGE) };
            }
        }
    }
    out
}

/// Hints the cache to load the 64-byte lines holding bytes `p .. p + bytes` (any
/// address: nothing is read and nothing faults; no effect elsewhere than on x86-64).
#[inline(always)]
pub(super) fn prefetch_bytes(p: *const u8, bytes: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // SAFETY: a prefetch never faults and reads nothing into the program, whatever
        // the address; SSE is part of the x86-64 baseline.
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>(p.cast());
            _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(bytes.max(1) - 1).cast());
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (p, bytes);
}

/// Hints the cache to load the `lines` 64-byte lines from `r` on (no effect elsewhere
/// than on x86-64).
#[inline(always)]
fn prefetch<T>(r: &T, lines: usize) {
    #[cfg(target_arch = "x86_64")]
    for k in 0..lines {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let p = (r as *const T).cast::<i8>().wrapping_add(64 * k);
        // SAFETY: a prefetch never faults and reads nothing into the program, whatever
        // the address; SSE is part of the x86-64 baseline.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(p) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (r, lines);
}

impl Node {
    /// Prefetches child `i` (a node or a leaf's triangles).
    #[inline(always)]
    fn prefetch_child(&self, i: usize, nodes: &[Node], tris: &[RowTriangle]) {
        let c = self.child[i] as usize;
        if self.count[i] == 0 {
            if let Some(n) = nodes.get(c) {
                prefetch(n, size_of::<Node>() / 64);
            }
        } else if let Some(t) = tris.get(c) {
            prefetch(t, (self.count[i] as usize * size_of::<RowTriangle>()).div_ceil(64));
        }
    }
}

/// A ray of [`WideBvh::closest_many`]: box constants, triangle test, result.
pub(super) type ClosestJob = (RayBoxes, Shear, Option<(u32, f32)>);

/// Closest-hit traversal state of one ray (besides its stack).
#[derive(Clone, Copy)]
struct Closest {
    best: Option<(u32, f32)>,
    /// Entries entered beyond this distance are skipped.
    tlimit: f32,
    sp: usize,
    cur: Entry,
}

impl Closest {
    fn new(tmax: f32) -> Self {
        Self { best: None, tlimit: tmax, sp: 0, cur: Entry { child: 0, count: 0, tn: 0.0 } }
    }
}

#[derive(Clone, Copy, Default)]
struct Entry {
    child: u32,
    count: u32,
    tn: f32,
}

impl WideBvh {
    /// Collapses `bvh2` (primitive indices into `tris`); returns the BVH and the
    /// primitive (index into `tris`) of every leaf slot, in leaf order.
    pub(super) fn build(bvh2: &Bvh2) -> (Self, Vec<u32>) {
        let n2 = &bvh2.nodes;
        let mut nodes: Vec<Node> = Vec::with_capacity(n2.len() / 3 + 1);
        let mut order: Vec<u32> = Vec::with_capacity(bvh2.primitive_indices.len());
        if n2.is_empty() {
            return (Self::default(), order);
        }
        // Work: (binary node, parent node, slot, depth); the root has no parent.
        let mut work: Vec<(u32, u32, usize, usize)> = vec![(0, u32::MAX, 0, 1)];
        let mut max_depth = 1;
        let mut small = Vec::with_capacity(LEAF_MAX);
        while let Some((bi, parent, slot, depth)) = work.pop() {
            let me = nodes.len() as u32;
            if parent != u32::MAX {
                nodes[parent as usize].child[slot] = me;
            }
            max_depth = max_depth.max(depth);
            let mut cands: Vec<u32> = if n2[bi as usize].is_leaf() {
                vec![bi]
            } else {
                let f = n2[bi as usize].first_index;
                vec![f, f + 1]
            };
            while cands.len() < W {
                let pick = cands
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| !n2[**c as usize].is_leaf())
                    .max_by(|a, b| {
                        let area = |c: &u32| n2[*c as usize].aabb().half_area();
                        area(a.1).total_cmp(&area(b.1)).then(b.0.cmp(&a.0))
                    })
                    .map(|(k, _)| k);
                let Some(k) = pick else { break };
                let f = n2[cands[k] as usize].first_index;
                cands[k] = f;
                cands.insert(k + 1, f + 1);
            }
            let mut node = Node {
                b: [
                    [f32::INFINITY; W],
                    [f32::NEG_INFINITY; W],
                    [f32::INFINITY; W],
                    [f32::NEG_INFINITY; W],
                    [f32::INFINITY; W],
                    [f32::NEG_INFINITY; W],
                ],
                child: [u32::MAX; W],
                count: [0; W],
            };
            let mut inner = Vec::new();
            for (i, &c) in cands.iter().enumerate() {
                let bn = &n2[c as usize];
                let bb = bn.aabb();
                // One ulp wider, so a ray with a zero direction component lying in a
                // box face is still inside that slab.
                for k in 0..3 {
                    node.b[2 * k][i] = bb.min[k].next_down();
                    node.b[2 * k + 1][i] = bb.max[k].next_up();
                }
                small.clear();
                if gather_small(bvh2, c, &mut small) {
                    node.child[i] = order.len() as u32;
                    node.count[i] = small.len() as u32;
                    order.extend_from_slice(&small);
                } else {
                    inner.push((c, i));
                }
            }
            nodes.push(node);
            // Reverse, so the first inner child is built next (directly after `me`).
            for &(c, i) in inner.iter().rev() {
                work.push((c, me, i, depth + 1));
            }
        }
        (Self { nodes: huge_copy(&nodes), stack_len: (W - 1) * max_depth + 1 }, order)
    }

    /// Closest hit: `(slot, t)` of the hit with the least `t` (ties: least `ids[slot]`),
    /// or `None`. `shear.tmax` bounds the hits; it is lowered while traversing. The
    /// winner's entries of `refine` and `ids` (indexed by slot) are prefetched.
    #[inline]
    pub(super) fn closest<R>(
        &self,
        rb: &RayBoxes,
        shear: &mut Shear,
        tris: &[RowTriangle],
        ids: &[u32],
        refine: &[R],
    ) -> Option<(u32, f32)> {
        #[cfg(target_arch = "x86_64")]
        if has_avx2() {
            // SAFETY: the CPU supports AVX2 (checked).
            return unsafe { self.closest_avx2(rb, shear, tris, ids, refine) };
        }
        self.closest_impl::<false, R>(rb, shear, tris, ids, refine)
    }

    /// [`WideBvh::closest`] compiled for AVX2.
    ///
    /// # Safety
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn closest_avx2<R>(
        &self,
        rb: &RayBoxes,
        shear: &mut Shear,
        tris: &[RowTriangle],
        ids: &[u32],
        refine: &[R],
    ) -> Option<(u32, f32)> {
        self.closest_impl::<true, R>(rb, shear, tris, ids, refine)
    }

    #[inline(always)]
    pub(super) fn closest_impl<const AVX: bool, R>(
        &self,
        rb: &RayBoxes,
        shear: &mut Shear,
        tris: &[RowTriangle],
        ids: &[u32],
        refine: &[R],
    ) -> Option<(u32, f32)> {
        if self.stack_len <= FIXED_STACK {
            let mut stack = [Entry::default(); FIXED_STACK];
            self.closest_with::<AVX, R>(rb, shear, tris, ids, refine, &mut stack)
        } else {
            let mut stack = vec![Entry::default(); self.stack_len];
            self.closest_with::<AVX, R>(rb, shear, tris, ids, refine, &mut stack)
        }
    }

    /// Whether any triangle is hit within `[shear.tmin, shear.tmax]`.
    #[inline]
    pub(super) fn any(&self, rb: &RayBoxes, shear: &Shear, tris: &[RowTriangle]) -> bool {
        #[cfg(target_arch = "x86_64")]
        if has_avx2() {
            // SAFETY: the CPU supports AVX2 (checked).
            return unsafe { self.any_avx2(rb, shear, tris) };
        }
        self.any_impl::<false>(rb, shear, tris)
    }

    /// [`WideBvh::any`] compiled for AVX2.
    ///
    /// # Safety
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn any_avx2(&self, rb: &RayBoxes, shear: &Shear, tris: &[RowTriangle]) -> bool {
        self.any_impl::<true>(rb, shear, tris)
    }

    #[inline(always)]
    pub(super) fn any_impl<const AVX: bool>(
        &self,
        rb: &RayBoxes,
        shear: &Shear,
        tris: &[RowTriangle],
    ) -> bool {
        if self.stack_len <= FIXED_STACK {
            let mut stack = [Entry::default(); FIXED_STACK];
            self.any_with::<AVX>(rb, shear, tris, &mut stack)
        } else {
            let mut stack = vec![Entry::default(); self.stack_len];
            self.any_with::<AVX>(rb, shear, tris, &mut stack)
        }
    }

    #[inline(always)]
    fn closest_with<const AVX: bool, R>(
        &self,
        rb: &RayBoxes,
        shear: &mut Shear,
        tris: &[RowTriangle],
        ids: &[u32],
        refine: &[R],
        stack: &mut [Entry],
    ) -> Option<(u32, f32)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut st = Closest::new(shear.tmax);
        while self.closest_step::<AVX, R>(&mut st, rb, shear, tris, ids, refine, stack) {}
        st.best
    }

    /// [`WideBvh::closest`] for several rays (`rays[i] = (boxes, shear, result)`),
    /// traversed interleaved: a few rays advance in turn, one node or leaf at a time, so
    /// that the memory latency of one ray's next node overlaps the others' work. Every
    /// ray takes exactly the steps it takes alone, so results are the same.
    pub(super) fn closest_many<R>(
        &self,
        rays: &mut [ClosestJob],
        tris: &[RowTriangle],
        ids: &[u32],
        refine: &[R],
    ) {
        #[cfg(target_arch = "x86_64")]
        if has_avx2() {
            // SAFETY: the CPU supports AVX2 (checked).
            return unsafe { self.closest_many_avx2(rays, tris, ids, refine) };
        }
        self.closest_many_impl::<false, R>(rays, tris, ids, refine)
    }

    /// [`WideBvh::closest_many`] compiled for AVX2.
    ///
    /// # Safety
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn closest_many_avx2<R>(
        &self,
        rays: &mut [ClosestJob],
        tris: &[RowTriangle],
        ids: &[u32],
        refine: &[R],
    ) {
        self.closest_many_impl::<true, R>(rays, tris, ids, refine)
    }

    #[inline(always)]
    fn closest_many_impl<const AVX: bool, R>(
        &self,
        rays: &mut [ClosestJob],
        tris: &[RowTriangle],
        ids: &[u32],
        refine: &[R],
    ) {
        const LANES: usize = 4;
        if self.stack_len > FIXED_STACK || self.nodes.is_empty() {
            for (rb, shear, out) in rays.iter_mut() {
                *out = self.closest_impl::<AVX, R>(rb, shear, tris, ids, refine);
            }
            return;
        }
        let mut stacks = [[Entry::default(); FIXED_STACK]; LANES];
        let mut lanes: [Option<(usize, Closest)>; LANES] = [None; LANES];
        let mut next = 0;
        loop {
            let mut busy = false;
            for (lane, stack) in lanes.iter_mut().zip(stacks.iter_mut()) {
                if lane.is_none() && next < rays.len() {
                    *lane = Some((next, Closest::new(rays[next].1.tmax)));
                    next += 1;
                }
                let Some((i, st)) = lane else { continue };
                busy = true;
                let (rb, shear, out) = &mut rays[*i];
                if !self.closest_step::<AVX, R>(st, rb, shear, tris, ids, refine, stack) {
                    *out = st.best;
                    *lane = None;
                }
            }
            if !busy {
                return;
            }
        }
    }

    /// One step of closest-hit traversal: visits `st.cur` (a node or a leaf) and picks
    /// the next entry; `false` once the traversal is over (result in `st.best`).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn closest_step<const AVX: bool, R>(
        &self,
        st: &mut Closest,
        rb: &RayBoxes,
        shear: &mut Shear,
        tris: &[RowTriangle],
        ids: &[u32],
        refine: &[R],
        stack: &mut [Entry],
    ) -> bool {
        let cur = st.cur;
        if cur.count == 0 {
            let node = &self.nodes[cur.child as usize];
            let (tn, mask) = rb.test_on::<AVX>(node, st.tlimit);
            if mask != 0 {
                let first = mask.trailing_zeros() as usize;
                let rest = mask & (mask - 1);
                let at = |i: usize| Entry { child: node.child[i], count: node.count[i], tn: tn[i] };
                if rest == 0 {
                    node.prefetch_child(first, &self.nodes, tris);
                    st.cur = at(first);
                    return true;
                }
                // Two or more: push all but the nearest, farthest first.
                let mut hits = [Entry::default(); W];
                let mut nh = 0;
                let mut m = mask;
                while m != 0 {
                    let i = m.trailing_zeros() as usize;
                    m &= m - 1;
                    node.prefetch_child(i, &self.nodes, tris);
                    // Insertion by entry distance (descending).
                    let e = at(i);
                    let mut j = nh;
                    while j > 0 && hits[j - 1].tn < e.tn {
                        hits[j] = hits[j - 1];
                        j -= 1;
                    }
                    hits[j] = e;
                    nh += 1;
                }
                if st.sp + W <= stack.len() {
                    // A fixed-size copy (no library call); entries past `nh − 1` are
                    // overwritten by later pushes before they are read.
                    stack[st.sp..st.sp + W].copy_from_slice(&hits);
                } else {
                    stack[st.sp..st.sp + nh - 1].copy_from_slice(&hits[..nh - 1]);
                }
                st.sp += nh - 1;
                st.cur = hits[nh - 1];
                return true;
            }
        } else {
            for p in cur.child..cur.child + cur.count {
                let t = shear.intersect(&tris[p as usize]);
                if t.is_finite() {
                    // A finite `t` is at most `shear.tmax`, the best `t` so far.
                    let better = match st.best {
                        None => true,
                        Some((bp, bt)) => t < bt || ids[p as usize] < ids[bp as usize],
                    };
                    if better {
                        if let Some(r) = refine.get(p as usize) {
                            prefetch(r, 2);
                        }
                        if let Some(id) = ids.get(p as usize) {
                            prefetch(id, 1);
                        }
                        st.best = Some((p, t));
                        shear.tmax = t;
                        st.tlimit = t + rb.slack;
                    }
                }
            }
        }
        // Pop the next entry still in range.
        while st.sp > 0 {
            st.sp -= 1;
            let e = stack[st.sp];
            if e.tn <= st.tlimit {
                st.cur = e;
                return true;
            }
        }
        false
    }

    #[inline(always)]
    fn any_with<const AVX: bool>(
        &self,
        rb: &RayBoxes,
        shear: &Shear,
        tris: &[RowTriangle],
        stack: &mut [Entry],
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let tlimit = shear.tmax;
        let mut sp = 0usize;
        let mut cur = Entry { child: 0, count: 0, tn: 0.0 };
        loop {
            if cur.count == 0 {
                let node = &self.nodes[cur.child as usize];
                let (_, mask) = rb.test_on::<AVX>(node, tlimit);
                let mut m = mask;
                if m != 0 {
                    let first = m.trailing_zeros() as usize;
                    node.prefetch_child(first, &self.nodes, tris);
                    m &= m - 1;
                    while m != 0 {
                        let i = m.trailing_zeros() as usize;
                        m &= m - 1;
                        node.prefetch_child(i, &self.nodes, tris);
                        stack[sp] = Entry { child: node.child[i], count: node.count[i], tn: 0.0 };
                        sp += 1;
                    }
                    cur = Entry { child: node.child[first], count: node.count[first], tn: 0.0 };
                    continue;
                }
            } else {
                for p in cur.child..cur.child + cur.count {
                    if shear.intersect(&tris[p as usize]).is_finite() {
                        return true;
                    }
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            cur = stack[sp];
        }
    }
}

/// The primitives of the binary subtree at `c` into `out` when it has at most
/// [`LEAF_MAX`] of them or is a single leaf (`true`); otherwise `false`.
fn gather_small(bvh2: &Bvh2, c: u32, out: &mut Vec<u32>) -> bool {
    let n = &bvh2.nodes[c as usize];
    if n.is_leaf() {
        let s = n.first_index as usize;
        out.extend_from_slice(&bvh2.primitive_indices[s..s + n.prim_count as usize]);
        return true;
    }
    let mut todo = vec![c];
    while let Some(x) = todo.pop() {
        let n = &bvh2.nodes[x as usize];
        if n.is_leaf() {
            let s = n.first_index as usize;
            out.extend_from_slice(&bvh2.primitive_indices[s..s + n.prim_count as usize]);
            if out.len() > LEAF_MAX {
                return false;
            }
        } else {
            todo.push(n.first_index + 1);
            todo.push(n.first_index);
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX2 box test gives bit-identical entry distances and masks to the 4-lane one
    /// (boxes with empty slots, rays with zero and tiny direction components).
    #[test]
    fn avx2_box_test_equals_sse() {
        if !has_avx2() {
            return;
        }
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        };
        for case in 0..20_000 {
            let mut node = Node { b: [[0.0; W]; 6], child: [0; W], count: [0; W] };
            for i in 0..W {
                for k in 0..3 {
                    let (a, b) = (rnd(), rnd());
                    node.b[2 * k][i] = a.min(b);
                    node.b[2 * k + 1][i] = a.max(b);
                }
                if (case + i) % 7 == 0 {
                    for k in 0..3 {
                        node.b[2 * k][i] = f32::INFINITY;
                        node.b[2 * k + 1][i] = f32::NEG_INFINITY;
                    }
                }
            }
            let org = Vec3A::new(2.0 * rnd(), 2.0 * rnd(), 2.0 * rnd());
            let mut dir = Vec3A::new(rnd(), rnd(), rnd());
            if case % 5 == 0 {
                dir[case % 3] = 0.0;
            }
            if case % 11 == 0 {
                dir[(case + 1) % 3] = 1e-35;
            }
            let rb = RayBoxes::new(org, dir, 0.0, 1.0);
            for tlimit in [f32::INFINITY, 1.0, 0.25] {
                let (ta, ma) = rb.test(&node, tlimit);
                // SAFETY: AVX2 support was checked above.
                let (tb, mb) = unsafe { rb.test_avx2(&node, tlimit) };
                assert_eq!(ma, mb, "case {case}");
                for i in 0..W {
                    assert_eq!(ta[i].to_bits(), tb[i].to_bits(), "case {case} lane {i}");
                }
            }
        }
    }
}
