//! Design domains: a `W × H` plane triangulated as a regular grid (pixel coordinates),
//! or a triangle-mesh patch; point location and per-face tangent frames.
//!
//! Plane conventions: the domain is `[0, W] × [0, H]` in *pixel units*, `x` to the right
//! and `y` **down** (image convention), `z = 0`. The grid is
//! [`fieldtex_mesh::primitives::grid`]: vertex `(i, j)` at `(i·W/nx, j·H/ny)`, index
//! `j·(nx+1) + i`, cell `(i, j)` holding triangles `2·(j·nx + i)` and `+1`. Triangles
//! have normal `+z`, so "counter-clockwise" and every angle in this crate turn from
//! `+x` towards `+y`, which is *clockwise on screen*. Indices of singularities do not
//! depend on this choice; the sign of a vortex's rotation and the angle α do.

use fieldtex_core::vec3::{cross, dot, normalize, scale, sub};
use fieldtex_mesh::bvh::closest_point_on_triangle;
use fieldtex_mesh::{TriMesh, primitives};

use crate::dec::Dec;

/// A tangent frame `(e1, e2)` of a triangle, `e1 × e2 = n`.
pub type Frame = ([f64; 3], [f64; 3]);

/// A regular triangulated grid over a `width × height` rectangle (pixel units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneGrid {
    pub width: f64,
    pub height: f64,
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
}

impl PlaneGrid {
    /// A grid with `grid` cells along the longer side and square-ish cells.
    pub fn with_cells(width: f64, height: f64, grid: usize) -> Self {
        let grid = grid.max(2);
        let (nx, ny) = if width >= height {
            (grid, ((grid as f64 * height / width).round() as usize).max(2))
        } else {
            (((grid as f64 * width / height).round() as usize).max(2), grid)
        };
        Self { width, height, nx, ny }
    }

    /// The triangulated grid (`(nx+1)(ny+1)` vertices, `2·nx·ny` triangles).
    pub fn mesh(&self) -> TriMesh {
        primitives::grid(self.nx, self.ny, self.width, self.height)
    }

    /// Cell size `(hx, hy)`.
    pub fn cell_size(&self) -> (f64, f64) {
        (self.width / self.nx as f64, self.height / self.ny as f64)
    }

    /// `true` when `(x, y)` lies in the closed rectangle.
    pub fn contains(&self, x: f64, y: f64) -> bool {
        x >= 0.0 && y >= 0.0 && x <= self.width && y <= self.height
    }

    /// Triangle and barycentric coordinates of `(x, y)`, clamped into the rectangle.
    /// `O(1)`. Non-finite input gives triangle 0's barycentre.
    #[inline]
    pub fn locate(&self, x: f64, y: f64) -> (usize, [f64; 3]) {
        let (hx, hy) = self.cell_size();
        if !(x.is_finite() && y.is_finite()) {
            return (0, [1.0 / 3.0; 3]);
        }
        let x = x.clamp(0.0, self.width);
        let y = y.clamp(0.0, self.height);
        let i = ((x / hx) as usize).min(self.nx - 1);
        let j = ((y / hy) as usize).min(self.ny - 1);
        // Local coordinates in the cell, in [0, 1].
        let u = (x / hx - i as f64).clamp(0.0, 1.0);
        let v = (y / hy - j as f64).clamp(0.0, 1.0);
        let base = 2 * (j * self.nx + i);
        // Corners a=(0,0) b=(1,0) c=(1,1) d=(0,1), see primitives::grid.
        if (i + j).is_multiple_of(2) {
            // Diagonal a–c: [a,b,c] below it (u ≥ v), [a,c,d] above.
            if u >= v { (base, [1.0 - u, u - v, v]) } else { (base + 1, [1.0 - v, u, v - u]) }
        } else if u + v <= 1.0 {
            // Diagonal b–d: [a,b,d] then [b,c,d].
            (base, [1.0 - u - v, u, v])
        } else {
            (base + 1, [1.0 - v, u + v - 1.0, 1.0 - u])
        }
    }
}

/// Closest point of a mesh to `p`: `(triangle, barycentric coordinates, distance)`,
/// by brute force over the triangles (`O(F)`; fine for interactive edits and strokes).
/// `None` for a mesh without triangles.
pub fn locate_in_mesh(dec: &Dec, p: [f64; 3]) -> Option<(usize, [f64; 3], f64)> {
    let mut best: Option<(usize, [f64; 3], f64)> = None;
    for (f, t) in dec.triangles.iter().enumerate() {
        let a = dec.positions[t[0] as usize];
        let b = dec.positions[t[1] as usize];
        let c = dec.positions[t[2] as usize];
        let (q, bary) = closest_point_on_triangle(p, [a, b, c]);
        let d = sub(p, q);
        let dist = dot(d, d).sqrt();
        if best.as_ref().is_none_or(|bb| dist < bb.2) {
            best = Some((f, bary, dist));
        }
    }
    best
}

/// Per-face orthonormal tangent frames `(e1, e2)` with `e1 × e2 = n`: the projection of
/// `reference` onto each face plane (falling back to the first edge where the projection
/// vanishes). For the plane domain, `reference = +x` gives `e1 = +x`, `e2 = +y`.
pub fn projected_frames(dec: &Dec, reference: &[[f64; 3]]) -> Vec<Frame> {
    (0..dec.n_faces())
        .map(|f| {
            let n = dec.face_normals[f];
            let r = reference[f];
            let t = sub(r, scale(n, dot(n, r)));
            let e1 = normalize(t)
                .filter(|_| dot(t, t) > 1e-24 * dot(r, r).max(1e-300))
                .or_else(|| {
                    let tri = dec.triangles[f];
                    normalize(sub(dec.positions[tri[1] as usize], dec.positions[tri[0] as usize]))
                })
                .unwrap_or([1.0, 0.0, 0.0]);
            (e1, cross(n, e1))
        })
        .collect()
}

/// A disk of radius `radius` centred at the origin (z = 0), triangulated by `rings`
/// concentric rings with `6·k` vertices on ring `k` (a centre vertex, `3·rings²+3·rings+1`
/// vertices in all). Counter-clockwise (+z), one boundary loop; for tests and demos.
pub fn disk_mesh(radius: f64, rings: usize) -> TriMesh {
    let rings = rings.max(1);
    let mut positions = vec![[0.0, 0.0, 0.0]];
    let ring_start = |k: usize| if k == 0 { 0 } else { 1 + 3 * k * (k - 1) };
    for k in 1..=rings {
        let r = radius * k as f64 / rings as f64;
        let n = 6 * k;
        for s in 0..n {
            let a = 2.0 * std::f64::consts::PI * s as f64 / n as f64;
            positions.push([r * a.cos(), r * a.sin(), 0.0]);
        }
    }
    let mut triangles = Vec::new();
    for k in 1..=rings {
        // Merge the vertex sequences of ring k-1 (n0 vertices) and ring k (n1 vertices)
        // by angle, emitting one triangle per step.
        let (s0, n0) = (ring_start(k - 1), if k == 1 { 1 } else { 6 * (k - 1) });
        let (s1, n1) = (ring_start(k), 6 * k);
        let (mut i0, mut i1) = (0usize, 0usize);
        while i0 < n0 || i1 < n1 {
            let a0 = (i0 as f64 + 0.5) / n0 as f64;
            let a1 = (i1 as f64 + 0.5) / n1 as f64;
            let inner = (s0 + i0 % n0) as u32;
            let outer = (s1 + i1 % n1) as u32;
            if n0 == 1 || (i1 < n1 && (i0 >= n0 || a1 <= a0)) {
                triangles.push([inner, outer, (s1 + (i1 + 1) % n1) as u32]);
                i1 += 1;
            } else {
                triangles.push([inner, outer, (s0 + (i0 + 1) % n0) as u32]);
                i0 += 1;
            }
            if n0 == 1 && i1 >= n1 {
                break;
            }
        }
    }
    TriMesh::new(positions, triangles)
}
