//! Constraints from curves for the curve-constrained harmonic field (paper A §4.2; see
//! [`crate::harmonic_diffusion`], "Constraints from curves"): a polyline is resampled
//! every `sample_spacing · h` and each sample goes to its nearest usable mesh vertex
//! within `max_distance · h`, found through the solver's `fieldtex_mesh::SpatialGrid`
//! of usable vertices.

use std::collections::HashMap;

use fieldtex_core::vec3::{self, V3};

use crate::harmonic_diffusion::{CurveConstraints, CurveFieldSolver};

impl CurveFieldSolver<'_> {
    /// Constraints of `polyline` (module docs) for its forward orientation. Never fails:
    /// non-finite points and samples off the mesh are counted in `dropped_samples`.
    pub fn sample_curve(&self, polyline: &[V3]) -> CurveConstraints {
        let h = self.mean_edge;
        let step = self.options.sample_spacing * h;
        let radius = self.options.max_distance * h;
        let mut out = CurveConstraints::default();
        let mut slot: HashMap<u32, usize> = HashMap::new();
        let mut sums: Vec<(V3, f64)> = Vec::new();
        let mut prev: Option<V3> = None;
        for &q in polyline {
            if !vec3::is_finite(q) {
                out.dropped_samples += 1;
                prev = None;
                continue;
            }
            if let Some(a) = prev {
                let d = vec3::sub(q, a);
                let len = vec3::norm(d);
                // Only the part near the mesh is sampled (bounds the work for far or
                // huge segments); an overflowing length counts as off the mesh.
                let span =
                    if len.is_finite() { self.grid.clip_segment(a, q, radius) } else { None };
                if len > 0.0 && span.is_none() {
                    out.dropped_samples += 1;
                }
                if let (true, Some((t0, t1))) = (len > 0.0, span) {
                    let dir = vec3::scale(d, 1.0 / len);
                    let k = (len * (t1 - t0) / step).ceil().max(1.0) as usize;
                    let w = len * (t1 - t0) / k as f64;
                    for s in 0..k {
                        let t = t0 + (t1 - t0) * (s as f64 + 0.5) / k as f64;
                        let x = vec3::lerp(a, q, t);
                        let Some((v, _)) =
                            self.grid.nearest_within(&self.mesh.positions, x, radius)
                        else {
                            out.dropped_samples += 1;
                            continue;
                        };
                        out.length += w;
                        let i = *slot.entry(v).or_insert_with(|| {
                            out.vertices.push(v);
                            sums.push(([0.0; 3], 0.0));
                            sums.len() - 1
                        });
                        sums[i].0 = vec3::add(sums[i].0, vec3::scale(dir, w));
                        sums[i].1 += w;
                    }
                }
            }
            prev = Some(q);
        }
        let mut keep = Vec::with_capacity(out.vertices.len());
        for (&v, &(s, w)) in out.vertices.iter().zip(&sums) {
            let n = self.normals[v as usize];
            let t = vec3::sub(s, vec3::scale(n, vec3::dot(s, n)));
            let tn = vec3::norm(t);
            if tn > 1e-3 * w {
                keep.push(v);
                out.tangents.push(vec3::scale(t, 1.0 / tn));
            }
        }
        out.vertices = keep;
        out
    }
}
