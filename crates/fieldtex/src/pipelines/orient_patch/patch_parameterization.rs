//! The patch of `orient --mesh`: the disk-topology check and the LSCM
//! parameterisation scaled into the texture, with per-triangle image corners and
//! image → surface Jacobians (see [`super`] for the conventions).

use crate::{Error, Result};
use fieldtex_core::vec3::{add, cross, norm, normalize, scale, sub};
use fieldtex_mesh::{CornerUvs, TriMesh};
use fieldtex_param::TexelMap;
use fieldtex_param::chart_topology::ChartMesh;
use fieldtex_param::face_graph::FaceGraph;
use std::path::Path;

/// Texels of margin around the UV bounding box.
const MARGIN_TEXELS: f64 = 2.0;

/// The parameterised patch: the mesh with texture UVs and, per triangle, its corners
/// in image coordinates (texels, x right, y down) and the image → surface Jacobian.
pub(super) struct Patch {
    pub(super) mesh: TriMesh,
    /// `#F` corners in image coordinates.
    pub(super) image_corners: Vec<[[f64; 2]; 3]>,
    /// `#F` Jacobian columns `(∂p/∂x, ∂p/∂y)`; `None` for degenerate triangles.
    pub(super) jacobian: Vec<Option<[[f64; 3]; 2]>>,
    /// `#F` unit normals.
    pub(super) normals: Vec<[f64; 3]>,
    /// UV bounding box in image coordinates: `[x0, y0, x1, y1]`.
    pub(super) image_box: [f64; 4],
    /// Mean surface length per texel over the chart.
    pub(super) length_per_texel: f64,
}

/// Bad input unless `mesh` is one disk: one component, one boundary loop, Euler
/// characteristic 1, no non-manifold edge.
pub(super) fn check_disk(mesh: &TriMesh, path: &Path, cut: bool) -> Result<()> {
    if mesh.triangles.is_empty() {
        return Err(Error::bad_input(Some(path), "no usable triangle is left after repair"));
    }
    let topo = fieldtex_mesh::Topology::build(mesh.n_vertices(), &mesh.triangles);
    let (_, components) = topo.face_components(&mesh.triangles);
    let loops = topo.boundary_loops(&mesh.triangles).len();
    let nonmanifold = (0..topo.n_edges()).filter(|&e| topo.is_nonmanifold_edge(e)).count();
    let mut used = vec![false; mesh.n_vertices()];
    for t in &mesh.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let nv = used.iter().filter(|&&u| u).count() as i64;
    let euler = nv - topo.n_edges() as i64 + mesh.n_triangles() as i64;
    if components != 1 || loops != 1 || euler != 1 || nonmanifold > 0 {
        return Err(Error::bad_input(
            Some(path),
            format!(
                "--mesh needs a disk-topology patch (1 component, 1 boundary loop, Euler \
                 characteristic 1, manifold); this mesh has {components} component(s), {loops} \
                 boundary loop(s), Euler characteristic {euler} and {nonmanifold} non-manifold \
                 edge(s). {}",
                if cut {
                    "The --patch region is not a disk: choose a smaller radius or another centre"
                } else {
                    "Cut a disk-like region out of it, e.g. with --patch X,Y,Z,R (closed meshes and \
                 meshes with holes cannot be flattened into one chart)"
                }
            ),
        ));
    }
    Ok(())
}

/// LSCM of the whole patch, scaled into the `n × n` texture (module docs).
pub(super) fn parameterize(
    mut mesh: TriMesh,
    n: usize,
    warnings: &mut Vec<fieldtex_core::Warning>,
) -> Result<Patch> {
    let nf = mesh.n_triangles();
    let graph = FaceGraph::build(&mesh);
    let chart = ChartMesh::build((0..nf as u32).collect(), &graph, &mesh.triangles);
    let uv = match fieldtex_param::lscm::lscm(&chart, &mesh, &graph) {
        Ok(uv) if uv.iter().all(|p| p[0].is_finite() && p[1].is_finite()) => uv,
        other => {
            let why = other.err().map(|e| e.to_string()).unwrap_or_else(|| "non-finite UVs".into());
            warnings.push(fieldtex_core::Warning::new(
                "lscm-failed",
                format!("LSCM failed ({why}); the patch is projected onto its mean plane instead"),
            ));
            fieldtex_param::lscm::planar_projection(&chart, &mesh, &graph)
        }
    };
    let defects = fieldtex_param::lscm::flattening_defects(&chart, &uv, &graph);
    if !defects.is_clean() {
        warnings.push(fieldtex_core::Warning::new(
            "patch-flattening-defects",
            format!(
                "the flattened patch has {} flipped or collapsed triangle(s){}; the texture may \
                 overlap itself there",
                defects.flipped,
                if defects.boundary_crossing { " and its boundary crosses itself" } else { "" }
            ),
        ));
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &uv {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let side = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    if !(side > 0.0 && side.is_finite()) {
        return Err(Error::bad_input(None, "the patch flattens to a point or a line"));
    }
    let nf64 = n as f64;
    // Texture uv = (uv − centre) / span + ½, span leaving MARGIN_TEXELS on each side.
    let span = side * nf64 / (nf64 - 2.0 * MARGIN_TEXELS);
    let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    let values: Vec<[f64; 2]> = uv
        .iter()
        .map(|p| [(p[0] - centre[0]) / span + 0.5, (p[1] - centre[1]) / span + 0.5])
        .collect();
    let to_image = |t: [f64; 2]| [t[0] * nf64, (1.0 - t[1]) * nf64];
    let (bl, tr) = (
        to_image([(lo[0] - centre[0]) / span + 0.5, (lo[1] - centre[1]) / span + 0.5]),
        to_image([(hi[0] - centre[0]) / span + 0.5, (hi[1] - centre[1]) / span + 0.5]),
    );
    let image_box = [bl[0], tr[1], tr[0], bl[1]];
    let mut image_corners = Vec::with_capacity(nf);
    let mut jacobian = Vec::with_capacity(nf);
    let mut normals = Vec::with_capacity(nf);
    let (mut area3, mut area_img) = (0.0, 0.0);
    for f in 0..nf {
        let q: [[f64; 2]; 3] =
            std::array::from_fn(|k| to_image(values[chart.corners[f][k] as usize]));
        let p = mesh.triangle_positions(f);
        let (e1, e2) = (sub(p[1], p[0]), sub(p[2], p[0]));
        let c = cross(e1, e2);
        let a3 = 0.5 * norm(c);
        normals.push(normalize(c).unwrap_or([0.0, 0.0, 1.0]));
        let (a, b) =
            ([q[1][0] - q[0][0], q[1][1] - q[0][1]], [q[2][0] - q[0][0], q[2][1] - q[0][1]]);
        let det = a[0] * b[1] - a[1] * b[0];
        image_corners.push(q);
        if !(det.abs() > 1e-12 && a3 > 0.0) {
            jacobian.push(None);
            continue;
        }
        area3 += a3;
        area_img += 0.5 * det.abs();
        // [∂p/∂x ∂p/∂y] = [e1 e2] · inv([a b]).
        let (i00, i01, i10, i11) = (b[1] / det, -b[0] / det, -a[1] / det, a[0] / det);
        let px = add(scale(e1, i00), scale(e2, i10));
        let py = add(scale(e1, i01), scale(e2, i11));
        jacobian.push(Some([px, py]));
    }
    if !(area3 > 0.0 && area_img > 0.0) {
        return Err(Error::bad_input(None, "the patch has no triangle of positive area"));
    }
    mesh.uvs = Some(CornerUvs { values, indices: chart.corners.clone() });
    Ok(Patch {
        mesh,
        image_corners,
        jacobian,
        normals,
        image_box,
        length_per_texel: (area3 / area_img).sqrt(),
    })
}

impl Patch {
    /// Triangle and barycentric coordinates of image point `q` (texels), starting from
    /// the triangle the texel map shows there; `None` outside the chart.
    pub(super) fn locate_image(&self, map: &TexelMap, q: [f64; 2]) -> Option<(usize, [f64; 3])> {
        let (x, y) = (q[0].floor(), q[1].floor());
        if !(x >= 0.0 && y >= 0.0 && (x as usize) < map.width && (y as usize) < map.height) {
            return None;
        }
        let i = y as usize * map.width + x as usize;
        let e = map.entries[i].filter(|_| map.is_covered(i))?;
        let f = e.triangle as usize;
        let t = self.image_corners[f];
        let (a, b, p) = (
            [t[1][0] - t[0][0], t[1][1] - t[0][1]],
            [t[2][0] - t[0][0], t[2][1] - t[0][1]],
            [q[0] - t[0][0], q[1] - t[0][1]],
        );
        let det = a[0] * b[1] - a[1] * b[0];
        if det.abs() < 1e-12 {
            return Some((f, e.bary.map(f64::from)));
        }
        // Barycentric coordinates of q, clamped into the triangle (q may lie just
        // outside the triangle nearest its texel's centre).
        let v = ((p[0] * b[1] - p[1] * b[0]) / det).max(0.0);
        let w = ((a[0] * p[1] - a[1] * p[0]) / det).max(0.0);
        let (v, w) = if v + w > 1.0 { (v / (v + w), w / (v + w)) } else { (v, w) };
        Some((f, [1.0 - v - w, v, w]))
    }

    pub(super) fn surface_point(&self, f: usize, b: [f64; 3]) -> [f64; 3] {
        let p = self.mesh.triangle_positions(f);
        add(add(scale(p[0], b[0]), scale(p[1], b[1])), scale(p[2], b[2]))
    }

    pub(super) fn image_point(&self, f: usize, b: [f64; 3]) -> [f64; 2] {
        let t = self.image_corners[f];
        std::array::from_fn(|k| b[0] * t[0][k] + b[1] * t[1][k] + b[2] * t[2][k])
    }
}

/// Passes of ear trimming on a cut patch's rim.
const EAR_PASSES: usize = 3;

/// The connected set of triangles, grown from the triangle whose centroid is nearest
/// `cut`'s centre `(x, y, z)`, whose centroids lie within its radius, with ears on its
/// rim trimmed ([`EAR_PASSES`] passes), compacted (unused vertices dropped). Bad input for a non-positive radius or when no centroid
/// lies within it.
pub(super) fn cut_ball(mesh: &TriMesh, cut: [f64; 4], path: &Path) -> Result<TriMesh> {
    let (c, r) = ([cut[0], cut[1], cut[2]], cut[3]);
    if !(cut.iter().all(|v| v.is_finite()) && r > 0.0) {
        return Err(Error::bad_input(
            None,
            format!(
                "--patch {},{},{},{}: give a finite centre X,Y,Z and a positive radius R",
                cut[0], cut[1], cut[2], cut[3]
            ),
        ));
    }
    let dist: Vec<f64> = (0..mesh.n_triangles())
        .map(|f| {
            let p = mesh.triangle_positions(f);
            norm(sub(scale(add(add(p[0], p[1]), p[2]), 1.0 / 3.0), c))
        })
        .collect();
    let Some(seed) = (0..dist.len())
        .filter(|&f| dist[f] < r)
        .min_by(|&a, &b| dist[a].total_cmp(&dist[b]).then(a.cmp(&b)))
    else {
        // Regression: this message used to print the bounding box as Rust debug text.
        let span = match mesh.bounding_box() {
            Some(b) => format!(
                "the mesh spans x {:.4} to {:.4}, y {:.4} to {:.4}, z {:.4} to {:.4}",
                b.min[0], b.max[0], b.min[1], b.max[1], b.min[2], b.max[2]
            ),
            None => "the mesh has no finite vertex".to_string(),
        };
        return Err(Error::bad_input(
            Some(path),
            format!(
                "--patch: no triangle centre lies within {r} of ({}, {}, {}); {span}. Pick a \
                 centre on the surface (e.g. a vertex from `fieldtex inspect`) or a larger R",
                c[0], c[1], c[2]
            ),
        ));
    };
    let topo = fieldtex_mesh::Topology::build(mesh.n_vertices(), &mesh.triangles);
    let mut keep = vec![false; mesh.n_triangles()];
    keep[seed] = true;
    let mut stack = vec![seed];
    while let Some(f) = stack.pop() {
        for &e in &topo.face_edges[f] {
            for &g in topo.edge_faces(e as usize) {
                let g = g as usize;
                if dist[g] < r && !keep[g] {
                    keep[g] = true;
                    stack.push(g);
                }
            }
        }
    }
    // Trim the saw-tooth rim: drop "ears" (kept triangles with two or three rim edges)
    // for a few passes, so the cut boundary is smoother to flatten and to design on.
    for _ in 0..EAR_PASSES {
        let ears: Vec<usize> = (0..keep.len())
            .filter(|&f| keep[f])
            .filter(|&f| {
                let rim = topo.face_edges[f]
                    .iter()
                    .filter(|&&e| {
                        topo.edge_faces(e as usize)
                            .iter()
                            .all(|&g| g as usize == f || !keep[g as usize])
                    })
                    .count();
                rim >= 2
            })
            .collect();
        if ears.is_empty() || ears.len() * 4 >= keep.iter().filter(|&&k| k).count() {
            break;
        }
        for f in ears {
            keep[f] = false;
        }
    }
    let mut index = vec![u32::MAX; mesh.n_vertices()];
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for (f, t) in mesh.triangles.iter().enumerate() {
        if keep[f] {
            triangles.push(t.map(|v| {
                if index[v as usize] == u32::MAX {
                    index[v as usize] = positions.len() as u32;
                    positions.push(mesh.positions[v as usize]);
                }
                index[v as usize]
            }));
        }
    }
    Ok(TriMesh::new(positions, triangles))
}
