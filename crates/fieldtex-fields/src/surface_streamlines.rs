//! Streamlines of a per-vertex tangent line field on a triangle mesh, for drawing the
//! field over the surface (the studio's align and solid views; the planar counterpart
//! is the page's own tracer).
//!
//! Seeds are Poisson-disk samples of the surface ([`fieldtex_mesh::poisson_disk_sampling`],
//! seeded, so the lines are reproducible). From each seed the line is integrated in both
//! directions with explicit Euler steps of length `step`: at a surface point (triangle,
//! barycentric `b`) the direction is `Σ bᵢ sᵢ fᵢ` over the triangle's corner vectors
//! `fᵢ`, where the signs `sᵢ = ±1` turn each corner vector towards the previous step
//! (the field is a 2-RoSy line field, as in paper A, so a vector and its negative are
//! the same direction), projected into the triangle's plane; the moved point is put back
//! on the surface by the closest-point query of the BVH. A line stops after
//! `max_steps` steps per direction, where the field vanishes, when a step moves less
//! than a tenth of `step` (a boundary or a singularity), or when it turns by more than
//! 60° in one step (across a singularity).
//!
//! Shapes: `field` is `#V` vectors (`[f64; 3]`, any length, 0 = undefined); each line is
//! a polyline of surface points (`[f64; 3]`) with at least two points.

use crate::FieldsError;
use fieldtex_mesh::{Bvh, PoissonDiskOptions, TriMesh, poisson_disk_sampling};

type V3 = [f64; 3];

/// Options of [`surface_streamlines`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StreamlineOptions {
    /// Number of seeds (Poisson-disk target count). Default 300.
    pub seeds: usize,
    /// Step length in mesh units; `None` = 0.4 % of the bounding-box diagonal.
    pub step: Option<f64>,
    /// Steps in each direction from a seed. Default 12.
    pub max_steps: usize,
    pub seed: u64,
}

impl Default for StreamlineOptions {
    fn default() -> Self {
        Self { seeds: 300, step: None, max_steps: 12, seed: 1 }
    }
}

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

/// The field direction at a surface point, turned towards `reference` (module docs);
/// `None` where it vanishes.
fn direction_at(
    mesh: &TriMesh,
    field: &[V3],
    triangle: u32,
    bary: [f64; 3],
    reference: V3,
) -> Option<V3> {
    let t = mesh.triangles.get(triangle as usize)?;
    let mut v = [0.0; 3];
    for (k, &vi) in t.iter().enumerate() {
        let f = *field.get(vi as usize)?;
        let s = if dot(f, reference) < 0.0 { -1.0 } else { 1.0 };
        for (va, fa) in v.iter_mut().zip(f) {
            *va += bary[k] * s * fa;
        }
    }
    let p = t.map(|i| mesh.positions[i as usize]);
    let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
    let nn = norm(n);
    if nn > 0.0 {
        let n = n.map(|x| x / nn);
        let d = dot(v, n);
        v = [v[0] - d * n[0], v[1] - d * n[1], v[2] - d * n[2]];
    }
    let l = norm(v);
    (l.is_finite() && l > 1e-12).then(|| v.map(|x| x / l))
}

/// Traces one direction from a seed; returns the points after the seed.
fn trace(
    mesh: &TriMesh,
    bvh: &Bvh,
    field: &[V3],
    start: (V3, u32, [f64; 3]),
    first: V3,
    step: f64,
    max_steps: usize,
) -> Vec<V3> {
    let (mut p, mut tri, mut bary) = start;
    let mut reference = first;
    let mut out = Vec::new();
    for _ in 0..max_steps {
        let Some(d) = direction_at(mesh, field, tri, bary, reference) else { break };
        if dot(d, reference) < 0.5 {
            break;
        }
        let q = [p[0] + step * d[0], p[1] + step * d[1], p[2] + step * d[2]];
        let Some(c) = bvh.closest_point(q) else { break };
        if norm(sub(c.point, p)) < 0.1 * step {
            break;
        }
        reference = d;
        p = c.point;
        tri = c.triangle;
        bary = c.barycentric;
        out.push(p);
    }
    out
}

/// Streamlines of `field` over `mesh` (module docs).
pub fn surface_streamlines(
    mesh: &TriMesh,
    bvh: &Bvh,
    field: &[V3],
    options: &StreamlineOptions,
) -> Result<Vec<Vec<V3>>, FieldsError> {
    if field.len() != mesh.n_vertices() {
        return Err(FieldsError::InvalidOption {
            name: "streamline field length",
            value: field.len() as f64,
            expected: "one vector per mesh vertex",
        });
    }
    if mesh.triangles.is_empty() || options.seeds == 0 {
        return Ok(Vec::new());
    }
    let (lo, hi) = mesh.positions.iter().fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
        (std::array::from_fn(|a| lo[a].min(p[a])), std::array::from_fn(|a| hi[a].max(p[a])))
    });
    let diagonal = norm(sub(hi, lo));
    let step = options.step.unwrap_or(0.004 * diagonal);
    if !(step.is_finite() && step > 0.0) {
        return Err(FieldsError::InvalidOption {
            name: "streamline step",
            value: step,
            expected: "a positive finite length",
        });
    }
    let popts = PoissonDiskOptions {
        target_count: Some(options.seeds),
        seed: options.seed,
        ..Default::default()
    };
    let (samples, _) = poisson_disk_sampling(mesh, &popts)?;
    let mut lines = Vec::new();
    for s in &samples.samples {
        let t = mesh.triangles[s.triangle as usize];
        // The seed's reference: the largest corner vector.
        let f0 = t
            .iter()
            .map(|&i| field[i as usize])
            .fold([0.0; 3], |a, f| if norm(f) > norm(a) { f } else { a });
        let Some(d) = direction_at(mesh, field, s.triangle, s.barycentric, f0) else {
            continue;
        };
        let start = (s.position, s.triangle, s.barycentric);
        let fwd = trace(mesh, bvh, field, start, d, step, options.max_steps);
        let back = trace(mesh, bvh, field, start, d.map(|x| -x), step, options.max_steps);
        let mut line: Vec<V3> = back.into_iter().rev().collect();
        line.push(s.position);
        line.extend(fwd);
        if line.len() >= 2 {
            lines.push(line);
        }
    }
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_on_a_plane_follow_a_constant_field() {
        // A 10 × 10 grid of the unit square, field along x.
        let n = 10;
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                positions.push([i as f64 / n as f64, j as f64 / n as f64, 0.0]);
            }
        }
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let a = (j * (n + 1) + i) as u32;
                let b = a + 1;
                let c = a + (n + 1) as u32;
                triangles.push([a, b, c + 1]);
                triangles.push([a, c + 1, c]);
            }
        }
        let mesh = TriMesh::new(positions, triangles);
        let bvh = Bvh::build(&mesh).unwrap();
        // Alternate signs: a line field, the tracer must still go straight.
        let field: Vec<V3> = (0..mesh.n_vertices())
            .map(|i| if i % 2 == 0 { [1.0, 0.0, 0.0] } else { [-1.0, 0.0, 0.0] })
            .collect();
        let opts = StreamlineOptions { seeds: 20, step: Some(0.02), ..Default::default() };
        let lines = surface_streamlines(&mesh, &bvh, &field, &opts).unwrap();
        assert!(lines.len() >= 10, "{} lines", lines.len());
        for l in &lines {
            let y0 = l[0][1];
            assert!(l.iter().all(|p| (p[1] - y0).abs() < 1e-9), "a line left its row");
            assert!((l.last().unwrap()[0] - l[0][0]).abs() > 0.019, "a line did not move");
        }
        let bad = surface_streamlines(&mesh, &bvh, &field[1..], &opts);
        assert!(bad.is_err());
    }
}
