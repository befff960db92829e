//! Bounding volume hierarchy over a triangle mesh: ray casting (closest hit, any hit)
//! and closest-point queries. One BVH serves occlusion, picking and baking.
//!
//! Built with obvhs 0.4: a PLOC binary BVH (Meister & Bittner 2018, "Parallel
//! Locally-Ordered Clustering for Bounding Volume Hierarchy Construction") refined by
//! parallel reinsertion, then collapsed into an own 8-wide BVH (module `bvh_wide`) whose
//! SIMD traversal casts the rays. The binary BVH is kept for closest-point queries, which
//! obvhs does not offer: an own best-first descent with `f64` point–triangle distances
//! (Ericson 2005, "Real-Time Collision Detection", §5.1.5).
//!
//! **Precision.** Traversal is `f32` with conservative box tests; the mesh is translated
//! so its bounding box is centred at the origin first, which keeps `f32` relative
//! precision for meshes far from the origin, and a ray direction far outside the `f32`
//! range is scaled by a power of two. Ray–triangle tests use the watertight algorithm of
//! Woop, Benthin & Wald 2013 ("Watertight Ray/Triangle Intersection", JCGT 2(1); module
//! `bvh_watertight`, on triangles stored by coordinate rows in BVH leaf order), so a ray
//! through a shared edge or vertex never slips between triangles; the winning
//! triangle's `t` and barycentric coordinates are then recomputed in `f64` (from `f64`
//! corners stored in leaf order, prefetched while traversal goes on). Ties (same `t`)
//! go to the lower triangle index, so results do not depend on the tree layout or the
//! thread count.
//!
//! **Batches.** [`Bvh::intersect_many`] and [`Bvh::occluded_many`] answer large batches
//! in a cache-coherent order (rays radix sorted by box entry point and direction, module
//! `bvh_ray_order`) over fixed chunks in parallel; every ray is still answered alone, so
//! results equal the single-ray queries for any thread count.
//!
//! **Measured** (`cargo build --release -p fieldtex-mesh --examples &&
//! target/release/examples/bench_geometry --rays-only --reps 5`: 388K-triangle torus, 1M
//! incoherent rays, 53 % hit; 2 cores, medians per run, load average at the start of the
//! run). Before the AVX2 box test and the huge-page ray staging: closest hit 1.85 M rays/s
//! (load 0.6), 1.63–1.84 (load 1.3–1.5), 2.17–2.37 (load 1.6–2.0); any hit 2.10–2.99;
//! 1 thread 0.88–1.31 M rays/s. After: closest hit 2.38–2.87 M rays/s (load 1.4–2.2,
//! quiet windows: BVH build ~300–370 ms), 1.94–2.18 (load 0.8–1.5 with a build of
//! 400–520 ms, i.e. another process still running); any hit 2.33–2.78; 1 thread
//! 1.30–1.54 M rays/s. The rate depends much on the other processes of this shared
//! 2-core machine; compare only runs taken side by side.
//!
//! **Conventions.** `t` is the ray parameter: hit point `origin + t · dir` (a distance
//! when `dir` is unit). Barycentric coordinates `[b0, b1, b2]` weight the triangle's
//! corners in order. Triangles with a non-finite corner are left out (counted in
//! [`Bvh::n_skipped`]); zero-area triangles are kept but never hit by rays (closest-point
//! queries can return them).

use crate::{MeshError, TriMesh};
use bvh_watertight::{RowTriangle, Shear};
use bvh_wide::{RayBoxes, WideBvh, huge_copy};
use fieldtex_core::vec3::{self, V3};
use glam::Vec3A;
use obvhs::BvhBuildParams;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::ploc::PlocBuilder;
use obvhs::ray::Ray as ORay;
use obvhs::triangle::Triangle;
use rayon::prelude::*;

/// A ray for batch queries: points `origin + t · dir` with `tmin ≤ t ≤ tmax`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    pub origin: V3,
    pub dir: V3,
    pub tmin: f64,
    pub tmax: f64,
}

impl Ray {
    /// A ray over `[0, ∞)`.
    pub fn new(origin: V3, dir: V3) -> Self {
        Self { origin, dir, tmin: 0.0, tmax: f64::INFINITY }
    }
    /// The same ray restricted to `[tmin, tmax]`.
    pub fn with_range(self, tmin: f64, tmax: f64) -> Self {
        Self { tmin, tmax, ..self }
    }
}

/// A ray hit: triangle, ray parameter and barycentric coordinates of the hit point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    pub triangle: u32,
    pub t: f64,
    pub barycentric: [f64; 3],
}

/// The closest surface point to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestPoint {
    pub triangle: u32,
    pub barycentric: [f64; 3],
    pub point: V3,
    pub distance: f64,
}

/// Ray-casting and closest-point acceleration structure (module docs).
#[derive(Clone)]
pub struct Bvh {
    wide: WideBvh,
    /// `f32` triangles in BVH primitive order (translated by `-centre`).
    prim_tris: Vec<RowTriangle>,
    /// Mesh triangle of each BVH primitive.
    prim_ids: Vec<u32>,
    /// Binary BVH for closest-point queries (boxes translated by `-centre`) and the
    /// primitive (leaf-order index) of each of its leaf entries.
    nodes2: Vec<Bvh2Node>,
    prim_ids2: Vec<u32>,
    centre: V3,
    /// Inverse half extents of the mesh box (finite, positive), for ray ordering.
    inv_half: V3,
    /// Largest half extent of the mesh box (`f32`), for traversal slack.
    scene_half: f32,
    /// `f64` corners (untranslated) of every BVH primitive, in leaf order.
    corners: Vec<[V3; 3]>,
    /// Slack added to `f32` boxes in closest-point pruning.
    box_slack: f64,
    n_skipped: usize,
}

impl std::fmt::Debug for Bvh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Bvh")
            .field("triangles", &self.prim_ids.len())
            .field("wide", &self.wide)
            .field("skipped", &self.n_skipped)
            .finish()
    }
}

#[inline]
fn to_f32(p: V3, c: V3) -> Vec3A {
    Vec3A::new((p[0] - c[0]) as f32, (p[1] - c[1]) as f32, (p[2] - c[2]) as f32)
}

impl Bvh {
    /// Builds the BVH (parallel). Errors on an index out of range.
    pub fn build(mesh: &TriMesh) -> Result<Self, MeshError> {
        crate::checks::check_indices(mesh)?;
        let centre = mesh.bounding_box().map_or([0.0; 3], |b| b.center());
        let inv_half = mesh.bounding_box().map_or([1.0; 3], |b| {
            let d = b.diagonal();
            [0, 1, 2].map(|k| {
                let h = 1.0 / (0.5 * (b.max[k] - b.min[k])).max(1e-9 * d);
                if h.is_finite() { h } else { 1.0 }
            })
        });
        let extent = mesh.bounding_box().map_or(1.0, |b| b.diagonal().max(f64::MIN_POSITIVE));
        let corners: Vec<[V3; 3]> = mesh
            .triangles
            .par_iter()
            .with_min_len(4096)
            .map(|t| t.map(|i| mesh.positions[i as usize]))
            .collect();
        let keep: Vec<u32> = (0..corners.len() as u32)
            .filter(|&f| corners[f as usize].iter().all(|p| vec3::is_finite(*p)))
            .collect();
        let n_skipped = corners.len() - keep.len();
        let tris: Vec<Triangle> = keep
            .par_iter()
            .with_min_len(4096)
            .map(|&f| {
                let c = corners[f as usize];
                Triangle {
                    v0: to_f32(c[0], centre),
                    v1: to_f32(c[1], centre),
                    v2: to_f32(c[2], centre),
                }
            })
            .collect();
        let params = BvhBuildParams::medium_build();
        let (wide, nodes2, prim_ids2, prim_tris, prim_ids) = if tris.is_empty() {
            (WideBvh::default(), Vec::new(), Vec::new(), Vec::new(), Vec::new())
        } else {
            let mut bvh2 = PlocBuilder::with_capacity(tris.len()).build(
                params.ploc_search_distance,
                &tris,
                (0..tris.len() as u32).collect(),
                params.sort_precision,
                params.search_depth_threshold,
            );
            ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
            let (wide, order) = WideBvh::build(&bvh2);
            let prim_tris: Vec<RowTriangle> = huge_copy(
                &order.iter().map(|&i| RowTriangle::new(&tris[i as usize])).collect::<Vec<_>>(),
            );
            let prim_ids: Vec<u32> =
                huge_copy(&order.iter().map(|&i| keep[i as usize]).collect::<Vec<_>>());
            let mut slot = vec![0u32; tris.len()];
            for (k, &i) in order.iter().enumerate() {
                slot[i as usize] = k as u32;
            }
            let prim_ids2: Vec<u32> =
                bvh2.primitive_indices.iter().map(|&i| slot[i as usize]).collect();
            (wide, bvh2.nodes, prim_ids2, prim_tris, prim_ids)
        };
        let corners: Vec<[V3; 3]> =
            huge_copy(&prim_ids.iter().map(|&f| corners[f as usize]).collect::<Vec<_>>());
        let scene_half = mesh
            .bounding_box()
            .map_or(1.0, |b| (0..3).map(|k| 0.5 * (b.max[k] - b.min[k])).fold(0.0, f64::max))
            as f32;
        Ok(Self {
            wide,
            scene_half: if scene_half.is_finite() { scene_half } else { f32::MAX },
            prim_tris,
            prim_ids,
            nodes2,
            prim_ids2,
            centre,
            inv_half,
            corners,
            box_slack: 1e-6 * extent,
            n_skipped,
        })
    }

    /// Triangles left out because a corner is not finite.
    pub fn n_skipped(&self) -> usize {
        self.n_skipped
    }

    /// Closest hit of the ray `origin + t · dir`, `0 ≤ t ≤ tmax`.
    pub fn closest_hit(&self, origin: V3, dir: V3, tmax: f64) -> Option<Hit> {
        self.intersect(&Ray { origin, dir, tmin: 0.0, tmax })
    }

    /// Whether anything is hit with `0 ≤ t ≤ tmax` (stops at the first hit found).
    pub fn any_hit(&self, origin: V3, dir: V3, tmax: f64) -> bool {
        self.occluded(&Ray { origin, dir, tmin: 0.0, tmax })
    }

    /// The `f32` obvhs ray, translated, with its direction scaled by a power of two `s`
    /// into `f32` range (ray parameter `t / s`), and `s`; `None` for a degenerate query.
    fn oray(&self, r: &Ray) -> Option<(ORay, f64)> {
        let ok = vec3::is_finite(r.origin)
            && vec3::is_finite(r.dir)
            && vec3::norm2(r.dir) > 0.0
            && !r.tmin.is_nan()
            && !r.tmax.is_nan()
            && r.tmin <= r.tmax
            && !self.prim_tris.is_empty();
        if !ok {
            return None;
        }
        let m = r.dir.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let s =
            if (1e-30..=1e30).contains(&m) { 1.0 } else { 2f64.powi(-(m.log2().round() as i32)) };
        let d = Vec3A::new((r.dir[0] * s) as f32, (r.dir[1] * s) as f32, (r.dir[2] * s) as f32);
        let o = to_f32(r.origin, self.centre);
        if !o.is_finite() {
            return None;
        }
        let ray = ORay::new(o, d, (r.tmin.max(0.0) / s) as f32, (r.tmax / s) as f32);
        Some((ray, s))
    }

    /// Closest hit of a ray with a `[tmin, tmax]` range.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let (oray, s) = self.oray(ray)?;
        let mut shear = Shear::new(&oray);
        let rb = RayBoxes::new(oray.origin, oray.direction, oray.tmin, self.scene_half);
        let (best_prim, best_t) =
            self.wide.closest(&rb, &mut shear, &self.prim_tris, &self.prim_ids, &self.corners)?;
        Some(self.hit(ray, &oray, s, best_prim, best_t))
    }

    /// The hit of `ray` on primitive `best_prim`, refined in `f64` (`oray`, `s`: the
    /// traversal ray of [`Bvh::oray`]; `best_t`: its `f32` ray parameter).
    fn hit(&self, ray: &Ray, oray: &ORay, s: f64, best_prim: u32, best_t: f32) -> Hit {
        let tri = self.prim_ids[best_prim as usize];
        let (t, bary) = refine_hit(self.corners[best_prim as usize], ray.origin, ray.dir)
            .unwrap_or_else(|| {
                let b = self.prim_tris[best_prim as usize].triangle().compute_barycentric(oray);
                (best_t as f64 * s, [1.0 - (b.x + b.y) as f64, b.x as f64, b.y as f64])
            });
        Hit { triangle: tri, t, barycentric: bary }
    }

    /// [`Bvh::intersect`] for a chunk of rays, traversed interleaved
    /// (`WideBvh::closest_many`; same results).
    fn intersect_chunk(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        let mut jobs = Vec::with_capacity(rays.len());
        let mut meta = Vec::with_capacity(rays.len());
        for (i, r) in rays.iter().enumerate() {
            out[i] = None;
            if let Some((oray, s)) = self.oray(r) {
                let rb = RayBoxes::new(oray.origin, oray.direction, oray.tmin, self.scene_half);
                jobs.push((rb, Shear::new(&oray), None));
                meta.push((i, oray, s));
            }
        }
        self.wide.closest_many(&mut jobs, &self.prim_tris, &self.prim_ids, &self.corners);
        for ((_, _, best), (i, oray, s)) in jobs.iter().zip(&meta) {
            if let Some((p, t)) = *best {
                out[*i] = Some(self.hit(&rays[*i], oray, *s, p, t));
            }
        }
    }

    /// Whether a ray with a `[tmin, tmax]` range hits anything.
    pub fn occluded(&self, ray: &Ray) -> bool {
        let Some((oray, _)) = self.oray(ray) else { return false };
        let shear = Shear::new(&oray);
        let rb = RayBoxes::new(oray.origin, oray.direction, oray.tmin, self.scene_half);
        self.wide.any(&rb, &shear, &self.prim_tris)
    }

    /// [`Bvh::intersect`] for many rays, in parallel (deterministic).
    pub fn intersect_many(&self, rays: &[Ray]) -> Vec<Option<Hit>> {
        bvh_ray_order::map_coherent(rays, self.centre, self.inv_half, |r, out| {
            self.intersect_chunk(r, out)
        })
    }

    /// [`Bvh::occluded`] for many rays, in parallel (deterministic).
    pub fn occluded_many(&self, rays: &[Ray]) -> Vec<bool> {
        bvh_ray_order::map_coherent(rays, self.centre, self.inv_half, |r, out| {
            for (o, r) in out.iter_mut().zip(r) {
                *o = self.occluded(r);
            }
        })
    }

    /// The closest surface point to `p` (ties to the lower triangle index); `None` for an
    /// empty BVH or a non-finite `p`.
    pub fn closest_point(&self, p: V3) -> Option<ClosestPoint> {
        if self.nodes2.is_empty() || !vec3::is_finite(p) {
            return None;
        }
        let q = vec3::sub(p, self.centre);
        let mut best: Option<ClosestPoint> = None;
        let mut best_d2 = f64::INFINITY;
        let mut stack: Vec<(u32, f64)> = Vec::with_capacity(64);
        stack.push((0, self.box_dist2(0, q)));
        while let Some((ni, d2)) = stack.pop() {
            if d2 > best_d2 {
                continue;
            }
            let node = &self.nodes2[ni as usize];
            if node.is_leaf() {
                let start = node.first_index as usize;
                for &slot in &self.prim_ids2[start..start + node.prim_count as usize] {
                    let (tri, c) = (self.prim_ids[slot as usize], self.corners[slot as usize]);
                    let (cp, bary) = closest_point_on_triangle(p, c);
                    let dd = vec3::norm2(vec3::sub(cp, p));
                    let better =
                        dd < best_d2 || (dd == best_d2 && best.is_some_and(|b| tri < b.triangle));
                    if better {
                        best_d2 = dd;
                        best = Some(ClosestPoint {
                            triangle: tri,
                            barycentric: bary,
                            point: cp,
                            distance: dd.sqrt(),
                        });
                    }
                }
                continue;
            }
            let (a, b) = (node.first_index, node.first_index + 1);
            let (da, db) = (self.box_dist2(a, q), self.box_dist2(b, q));
            // Push the farther child first so the nearer one is explored first.
            let (near, far) = if da <= db { ((a, da), (b, db)) } else { ((b, db), (a, da)) };
            if far.1 <= best_d2 {
                stack.push(far);
            }
            if near.1 <= best_d2 {
                stack.push(near);
            }
        }
        best
    }

    /// [`Bvh::closest_point`] for many points, in parallel (deterministic).
    pub fn closest_points(&self, points: &[V3]) -> Vec<Option<ClosestPoint>> {
        points.par_iter().with_min_len(64).map(|&p| self.closest_point(p)).collect()
    }

    /// Squared distance from the translated point `q` to node `ni`'s box, made
    /// conservative for the `f32` rounding of the box.
    #[inline]
    fn box_dist2(&self, ni: u32, q: V3) -> f64 {
        let bb = self.nodes2[ni as usize].aabb();
        let (mn, mx) = (bb.min, bb.max);
        let mut d2 = 0.0;
        for k in 0..3 {
            let lo = mn[k] as f64 - self.box_slack;
            let hi = mx[k] as f64 + self.box_slack;
            let d = if q[k] < lo {
                lo - q[k]
            } else if q[k] > hi {
                q[k] - hi
            } else {
                0.0
            };
            d2 += d * d;
        }
        d2
    }
}

/// `f64` Möller–Trumbore without rejection: `(t, barycentric)` of the ray against the
/// plane of the triangle, barycentrics clamped into the triangle; `None` when the ray is
/// parallel to a (near) degenerate triangle.
fn refine_hit(c: [V3; 3], o: V3, d: V3) -> Option<(f64, [f64; 3])> {
    let e1 = vec3::sub(c[1], c[0]);
    let e2 = vec3::sub(c[2], c[0]);
    let pv = vec3::cross(d, e2);
    let det = vec3::dot(e1, pv);
    if det.is_nan() || det.abs() <= 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = vec3::sub(o, c[0]);
    let u = vec3::dot(tv, pv) * inv;
    let qv = vec3::cross(tv, e1);
    let v = vec3::dot(d, qv) * inv;
    let t = vec3::dot(e2, qv) * inv;
    let mut b = [1.0 - u - v, u, v].map(|x| x.clamp(0.0, 1.0));
    let s = b[0] + b[1] + b[2];
    if !(s > 0.0 && t.is_finite()) {
        return None;
    }
    b = b.map(|x| x / s);
    Some((t, b))
}

/// Closest point on triangle `c` to `p` and its barycentric coordinates (Ericson 2005,
/// §5.1.5, by Voronoi regions); degenerate triangles fall back to their edges.
pub fn closest_point_on_triangle(p: V3, c: [V3; 3]) -> (V3, [f64; 3]) {
    let [a, b, cc] = c;
    let ab = vec3::sub(b, a);
    let ac = vec3::sub(cc, a);
    let ap = vec3::sub(p, a);
    let d1 = vec3::dot(ab, ap);
    let d2 = vec3::dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = vec3::sub(p, b);
    let d3 = vec3::dot(ab, bp);
    let d4 = vec3::dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 && d1 - d3 > 0.0 {
        let v = d1 / (d1 - d3);
        return (vec3::add(a, vec3::scale(ab, v)), [1.0 - v, v, 0.0]);
    }
    let cp = vec3::sub(p, cc);
    let d5 = vec3::dot(ab, cp);
    let d6 = vec3::dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (cc, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 && d2 - d6 > 0.0 {
        let w = d2 / (d2 - d6);
        return (vec3::add(a, vec3::scale(ac, w)), [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 && (d4 - d3) + (d5 - d6) > 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (vec3::add(b, vec3::scale(vec3::sub(cc, b), w)), [0.0, 1.0 - w, w]);
    }
    let denom = va + vb + vc;
    if denom > 0.0 && denom.is_finite() {
        let v = vb / denom;
        let w = vc / denom;
        let q = vec3::add(a, vec3::add(vec3::scale(ab, v), vec3::scale(ac, w)));
        return (q, [1.0 - v - w, v, w]);
    }
    // Degenerate triangle: the best of its three edges.
    let seg = |x: V3, y: V3| {
        let d = vec3::sub(y, x);
        let l2 = vec3::norm2(d);
        let s = if l2 > 0.0 { (vec3::dot(vec3::sub(p, x), d) / l2).clamp(0.0, 1.0) } else { 0.0 };
        (vec3::add(x, vec3::scale(d, s)), s)
    };
    let cands = [(seg(a, b), 0usize), (seg(b, cc), 1), (seg(cc, a), 2)];
    let mut best = (a, [1.0, 0.0, 0.0]);
    let mut best_d = f64::INFINITY;
    for ((q, s), k) in cands {
        let d = vec3::norm2(vec3::sub(q, p));
        if d < best_d {
            best_d = d;
            let mut bary = [0.0; 3];
            bary[k] = 1.0 - s;
            bary[(k + 1) % 3] = s;
            best = (q, bary);
        }
    }
    best
}

#[path = "bvh_watertight.rs"]
mod bvh_watertight;

#[path = "bvh_wide.rs"]
mod bvh_wide;

#[path = "bvh_ray_order.rs"]
mod bvh_ray_order;

#[cfg(test)]
#[path = "bvh_tests.rs"]
mod tests;
