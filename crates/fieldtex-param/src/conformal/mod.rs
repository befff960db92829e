//! Global conformal parameterisation (Gu & Yau 2003; Wang, Gu, Mueller & Yau 2005 §3)
//! of every connected component of a mesh into *conformal geometry images*: rectangles
//! whose opposite sides are identified by translations ([`Lattice`]).
//!
//! Per component — with boundary, the [`double_cover`] when its genus is ≥ 2 (first copy
//! kept), otherwise holes capped ([`hole_caps`], caps dropped afterwards):
//! - genus 0 → [`slit_cylinder`]: two point slits, one cylinder image (periodic in x);
//! - genus 1 → [`holomorphic_map`]: holomorphic 1-form, one torus image (periodic in x
//!   and, with a shift, in y), no zero points;
//! - genus ≥ 2 → [`holomorphic_map`] then [`critical_trajectories`] and
//!   [`translation_patches`]: the surface is cut along the critical horizontal
//!   trajectories through the zero points and each patch is mapped by integrating the
//!   form; the patches are packed into one image, and [`translation_patches::Ghost`]s
//!   across the cuts give the margins their partners
//!   ([`ConformalMethod::CriticalTrajectoryPatches`]); optionally a short homology basis
//!   ([`homology_loops`]) is cut as well.
//!
//! UVs are per corner: a triangle's corners are its local chart of `∫φ` moved into the
//! fundamental domain by one lattice translation; corners may stick out of the domain by
//! up to one triangle, which is why texture images get margins (Wang et al. §4.2).

pub mod atlas_charts;
pub mod conformal_polish;
pub mod cotan_system;
pub mod critical_trajectories;
pub mod cut_graph;
pub mod double_cover;
pub mod flip_untangle;
pub mod geometry_image;
pub mod harmonic_one_forms;
pub mod hole_caps;
pub mod holomorphic_basis;
pub mod holomorphic_map;
pub mod homology_loops;
pub mod mass_spring;
pub mod patch_merging;
pub mod patch_relaxation;
pub mod periodic_uv;
pub mod protrusion_slits;
mod rigid_triangles;
pub mod seam_length;
pub mod seam_placement;
pub mod similarity_ghosts;
pub mod slit_cylinder;
pub mod translation_patches;
pub mod tree_cotree;
pub mod uniform_form;
pub mod zero_points;

pub use geometry_image::GeometryImage;
pub use mass_spring::{MassSpringOptions, MassSpringStats, Targets};
pub use periodic_uv::Lattice;
pub use protrusion_slits::ProtrusionSummary;
use protrusion_slits::{ProtrusionChoice, protrusion_map};
pub use translation_patches::Ghost;

use crate::ParamError;
use fieldtex_core::{Progress, Warning};
use fieldtex_mesh::{Topology, TriMesh};
use serde::Serialize;

/// Holes whose boundary is at least this many `√area` long stay open for the double
/// cover; smaller ones are capped.
pub const LARGE_HOLE: f64 = 0.3;

/// Largest mean angle distortion `σ1/σ2` of a map that is kept (see [`rejection`]); the
/// shared meshes' maps stay below 1.12.
pub const MAX_ANGLE_DISTORTION: f64 = 2.0;

/// Vertex rings around slit and zero points flagged as near a singularity.
pub const NEAR_RINGS: usize = 3;

/// How a component was parameterised.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ConformalMethod {
    /// Genus 0: two point slits, harmonic `u` and its conjugate, one cylinder.
    SlitCylinder,
    /// Genus 1: holomorphic 1-form, one periodic rectangle.
    HolomorphicTorus,
    /// Genus ≥ 2: holomorphic 1-form, cut along its critical horizontal trajectories
    /// into patches, each mapped by integrating the form, packed into one image.
    CriticalTrajectoryPatches,
    /// Genus ≥ 2: holomorphic basis and zero points only; no UVs.
    HolomorphicBasisOnly,
    /// The construction failed (see the note); no UVs.
    Failed,
    /// Not a conformal map: the LSCM chart atlas of the faces whose component has none,
    /// with linked margins ([`atlas_charts`]).
    ChartAtlas,
}

/// What one construction returns, on the capped component mesh.
#[derive(Debug, Clone)]
pub struct ComponentMap {
    pub method: ConformalMethod,
    /// Per capped face: corner UVs (empty when no map).
    pub corner: Vec<[[f64; 2]; 3]>,
    /// Per capped vertex: integrated position (NaN for slit points).
    pub base: Vec<[f64; 2]>,
    /// Per capped face: `(apex corner, at the y-min end)` for slit fan triangles.
    pub apex: Vec<Option<(u8, bool)>>,
    pub lattice: Lattice,
    /// `(vertex, index)` of the zero points (capped-mesh vertex ids).
    pub zero_points: Vec<(u32, i32)>,
    /// Relative misfit of the discrete conjugate (see the constructions).
    pub conjugate_residual: f64,
    /// The same misfit with Gu & Yau's wedge system instead of the DEC projection
    /// (genus ≥ 1; `NaN` otherwise), for comparison.
    pub conjugate_residual_wedge_system: f64,
    /// The slit points (capped-mesh vertex ids).
    pub slit_vertices: Vec<u32>,
    /// Number of harmonic 1-forms computed.
    pub harmonic_forms: usize,
    /// Per capped face: patch id (empty: one patch).
    pub patch: Vec<u32>,
    /// Faces drawn shifted beside a patch across a cut (empty for lattice images).
    pub ghosts: Vec<Ghost>,
    /// Traced cut curves (3-D polylines), e.g. the critical trajectories.
    pub cut_curves: Vec<Vec<[f64; 3]>>,
    /// Patches made by the overlap guard that hold under 1 % of the faces.
    pub small_patches: usize,
    /// Faces the discrete form folds left on their own one-face charts.
    pub folded_faces: usize,
    /// Patch merges into maximal charts ([`patch_merging`]).
    pub patch_merges: usize,
    /// Area-stretch CV of the best basis form and of the optimised form (genus ≥ 2).
    pub stretch_cv: Option<[f64; 2]>,
    /// Per capped edge: on a snapped critical trajectory (genus ≥ 2; empty otherwise).
    pub trajectory_cut: Vec<bool>,
    /// Per capped edge: on a shortest homology loop (genus ≥ 2 with the loop cut; empty
    /// otherwise).
    pub loop_cut: Vec<bool>,
}

impl ComponentMap {
    /// An empty map of the given method (no UVs).
    pub fn empty(method: ConformalMethod) -> Self {
        Self {
            method,
            corner: Vec::new(),
            base: Vec::new(),
            apex: Vec::new(),
            lattice: Lattice { a: None, b: None },
            zero_points: Vec::new(),
            conjugate_residual: f64::NAN,
            conjugate_residual_wedge_system: f64::NAN,
            slit_vertices: Vec::new(),
            harmonic_forms: 0,
            patch: Vec::new(),
            ghosts: Vec::new(),
            cut_curves: Vec::new(),
            small_patches: 0,
            stretch_cv: None,
            folded_faces: 0,
            patch_merges: 0,
            trajectory_cut: Vec::new(),
            loop_cut: Vec::new(),
        }
    }

    /// Number of patches (images regions) of the map.
    pub fn n_patches(&self) -> usize {
        if self.corner.is_empty() {
            0
        } else {
            self.patch
                .iter()
                .filter(|&&p| p != u32::MAX)
                .map(|&p| p as usize + 1)
                .max()
                .unwrap_or(1)
        }
    }
}

/// One component's conformal geometry image.
#[derive(Debug, Clone)]
pub struct ConformalComponent {
    pub component: usize,
    pub genus: usize,
    /// Boundary loops of the input component.
    pub boundaries: usize,
    pub method: ConformalMethod,
    /// Global triangle ids of the component.
    pub faces: Vec<u32>,
    /// Per entry of `faces`: corner UVs in the fundamental domain (empty without a map).
    pub corner_uv: Vec<[[f64; 2]; 3]>,
    /// Per entry of `faces`: a slit fan triangle.
    pub slit: Vec<bool>,
    /// Per entry of `faces`: within [`NEAR_RINGS`] vertex rings of a slit point or a zero
    /// point (the "away from zero points and slits" statistics skip these).
    pub near_singularity: Vec<bool>,
    pub lattice: Lattice,
    /// Fundamental domain `[x0, y0, x1, y1]`.
    pub domain: [f64; 4],
    /// `(global vertex, index)`; zero points on caps are reported with vertex `u32::MAX`.
    pub zero_points: Vec<(u32, i32)>,
    pub conjugate_residual: f64,
    pub harmonic_forms: usize,
    pub note: Option<String>,
    /// Genus of the double cover when the component (with boundary, or slit open at its
    /// protrusions) was doubled.
    pub double_cover_genus: Option<usize>,
    /// Genus 0: the protrusion tips chosen instead of the two extremal slit points
    /// ([`protrusion_slits`]), when they were.
    pub protrusion_slits: Option<ProtrusionSummary>,
    /// Capped (or doubled) component mesh (local indices) and local → global vertex ids.
    pub local_mesh: TriMesh,
    pub local_to_global: Vec<u32>,
    pub map: ComponentMap,
    /// What [`ConformalComponent::polish_conformal`] did, when it ran.
    pub polish: Option<conformal_polish::PolishStats>,
}

impl ConformalComponent {
    pub fn has_uv(&self) -> bool {
        !self.corner_uv.is_empty()
    }

    /// Distortion of the map over its faces that `skip` does not mark; `None` without
    /// a map.
    fn distortion_without(&self, skip: &[bool]) -> Option<mass_spring::MapDistortion> {
        self.has_uv().then(|| {
            mass_spring::map_distortion(&self.local_mesh, self.faces.len(), &self.corner_uv, &|f| {
                skip[f]
            })
        })
    }

    /// Distortion of the map over its non-slit faces; `None` without a map.
    pub fn distortion_non_slit(&self) -> Option<mass_spring::MapDistortion> {
        self.distortion_without(&self.slit)
    }

    /// Area-weighted mean σ1/σ2 of the map away from zero points and slits (the faces
    /// of [`Self::near_singularity`] skipped); `None` without a map.
    pub fn angle_mean_away(&self) -> Option<f64> {
        self.distortion_without(&self.near_singularity).map(|d| d.angle_mean)
    }

    /// Recomputes `corner_uv`, `slit` and `domain` from `map` (after relaxation).
    fn refresh(&mut self) {
        let nf = self.faces.len();
        if self.map.corner.is_empty() {
            return;
        }
        self.corner_uv = self.map.corner[..nf].to_vec();
        self.slit = (0..nf).map(|f| self.map.apex[f].is_some()).collect();
        let tris = &self.local_mesh.triangles;
        let mut near_v = vec![false; self.local_mesh.n_vertices()];
        for &v in self.map.slit_vertices.iter().chain(self.map.zero_points.iter().map(|z| &z.0)) {
            near_v[v as usize] = true;
        }
        for _ in 0..NEAR_RINGS {
            let cur = near_v.clone();
            for t in tris.iter() {
                if t.iter().any(|&v| cur[v as usize]) {
                    for &v in t {
                        near_v[v as usize] = true;
                    }
                }
            }
        }
        self.near_singularity =
            (0..nf).map(|f| tris[f].iter().any(|&v| near_v[v as usize])).collect();
        let (mut x0, mut y0, mut x1, mut y1) =
            (f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
        for c in &self.corner_uv {
            for p in c {
                x0 = x0.min(p[0]);
                x1 = x1.max(p[0]);
                y0 = y0.min(p[1]);
                y1 = y1.max(p[1]);
            }
        }
        if let Some(a) = self.lattice.a {
            x0 = 0.0;
            x1 = a;
        }
        if let Some(b) = self.lattice.b {
            y0 = 0.0;
            y1 = b[1];
        }
        self.domain = [x0, y0, x1, y1];
    }

    /// Conformal polish ([`conformal_polish`]) of this component's map where its mean
    /// angle distortion away from singularities exceeds `options.above`: slit cylinders
    /// and patch layouts; `None` (and no change) for the torus image or without UVs.
    pub fn polish_conformal(
        &mut self,
        options: &conformal_polish::PolishOptions,
    ) -> Option<conformal_polish::PolishStats> {
        if !self.has_uv()
            || !matches!(
                self.method,
                ConformalMethod::SlitCylinder | ConformalMethod::CriticalTrajectoryPatches
            )
        {
            return None;
        }
        let slit = self.slit.clone();
        let near = self.near_singularity.clone();
        let stats = conformal_polish::polish_layout(
            &self.local_mesh,
            self.faces.len(),
            &mut self.map,
            &self.local_to_global,
            &|f| slit[f],
            &|f| near[f],
            options,
        )?;
        if stats.applied {
            self.lattice = self.map.lattice;
            self.refresh();
        }
        self.polish = Some(stats);
        Some(stats)
    }

    /// Quasi-isometric relaxation (Wang et al. 2005 §5) of this component's map.
    pub fn relax_quasi_isometric(
        &mut self,
        options: &MassSpringOptions,
    ) -> Option<MassSpringStats> {
        if !self.has_uv() {
            return None;
        }
        let n_orig = self.faces.len();
        // A polished map is a set of charts like a patch layout, even from the cylinder.
        let charts = self.method == ConformalMethod::CriticalTrajectoryPatches
            || self.polish.is_some_and(|p| p.applied);
        let stats = if charts {
            patch_relaxation::relax_patches(
                &self.local_mesh,
                n_orig,
                &mut self.map,
                &self.local_to_global,
                options,
            )
        } else {
            mass_spring::relax(&self.local_mesh, n_orig, &mut self.map, options)
        };
        self.refresh();
        Some(stats)
    }
}

/// The slit cylinder's ends on a genus-0 component: the cap centres of its largest hole
/// and, when at least half as long, its second largest, counting only holes whose
/// boundary is at least [`LARGE_HOLE`] `√area` long; small holes stay capped and the
/// slits go to extremal points.
fn cylinder_ends(caps: &[(u32, f64)], area: f64) -> [Option<usize>; 2] {
    let mut caps = caps.to_vec();
    caps.sort_by(|x, y| y.1.total_cmp(&x.1).then(x.0.cmp(&y.0)));
    caps.retain(|c| c.1 >= LARGE_HOLE * area.sqrt());
    let a = caps.first().map(|c| c.0 as usize);
    let b = match (caps.first(), caps.get(1)) {
        (Some(c0), Some(c1)) if c1.1 >= 0.5 * c0.1 => Some(c1.0 as usize),
        _ => None,
    };
    [a, b]
}

/// Why a component's map is not worth texturing, if it is not: it still folds triangles
/// after untangling, or its area-weighted mean angle distortion `σ1/σ2` (slit fans left
/// out) exceeds [`MAX_ANGLE_DISTORTION`] — coarse CAD-like pieces whose long thin
/// triangles give negative cotan weights. Such a component falls back to the chart
/// atlas like a failed one.
fn rejection(mesh: &TriMesh, n_keep: usize, map: &ComponentMap) -> Option<String> {
    if map.corner.is_empty() {
        return None;
    }
    let slit = |f: usize| map.apex.get(f).is_some_and(|a| a.is_some());
    let d = mass_spring::map_distortion(mesh, n_keep.min(map.corner.len()), &map.corner, &slit);
    if d.flipped > 0 {
        Some(format!(
            "the discrete conformal map folds {} triangles; the component is textured through the chart atlas instead",
            d.flipped
        ))
    } else if d.angle_mean > MAX_ANGLE_DISTORTION {
        Some(format!(
            "the discrete conformal map's mean angle distortion is {:.2} (above {MAX_ANGLE_DISTORTION}); the component is textured through the chart atlas instead",
            d.angle_mean
        ))
    } else {
        None
    }
}

/// Parameterises every component of `mesh` (which must be manifold and consistently
/// oriented; run `fieldtex_mesh::repair` first). Components whose construction fails get
/// [`ConformalMethod::Failed`] and a warning, never an error.
pub fn global_conformal(
    mesh: &TriMesh,
    progress: &dyn Progress,
) -> Result<(Vec<ConformalComponent>, Vec<Warning>), ParamError> {
    global_conformal_with(mesh, &MapOptions::default(), progress)
}

/// How [`global_conformal_with`] maps the components.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapOptions {
    /// Genus 0: slits at protrusion tips ([`protrusion_slits`]); off: every genus-0
    /// component gets the two-point slit cylinder. Default on.
    pub protrusion_slits: bool,
    /// How patch layouts are cut ([`holomorphic_map::LayoutOptions`]).
    pub layout: holomorphic_map::LayoutOptions,
}

impl Default for MapOptions {
    fn default() -> Self {
        Self { protrusion_slits: true, layout: holomorphic_map::LayoutOptions::default() }
    }
}

/// [`global_conformal`] with the map options given.
pub fn global_conformal_with(
    mesh: &TriMesh,
    options: &MapOptions,
    progress: &dyn Progress,
) -> Result<(Vec<ConformalComponent>, Vec<Warning>), ParamError> {
    mesh.validate()?;
    let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
    let (comp, n) = topo.face_components(&mesh.triangles);
    let mut faces_of: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (f, &c) in comp.iter().enumerate() {
        faces_of[c as usize].push(f as u32);
    }
    let mut warnings = Vec::new();
    let mut out = Vec::with_capacity(n);
    progress.stage("conformal map", n as u64);
    for (ci, faces) in faces_of.into_iter().enumerate() {
        let mut local_of = std::collections::HashMap::new();
        let mut local_to_global = Vec::new();
        let mut tris = Vec::with_capacity(faces.len());
        for &f in &faces {
            let t = mesh.triangles[f as usize];
            let mut lt = [0u32; 3];
            for k in 0..3 {
                lt[k] = *local_of.entry(t[k]).or_insert_with(|| {
                    local_to_global.push(t[k]);
                    (local_to_global.len() - 1) as u32
                });
            }
            tris.push(lt);
        }
        let positions = local_to_global.iter().map(|&v| mesh.positions[v as usize]).collect();
        let sub = TriMesh::new(positions, tris);
        let capped = hole_caps::cap_holes(&sub);
        let ctopo = Topology::build(capped.mesh.n_vertices(), &capped.mesh.triangles);
        let manifold = (0..ctopo.n_edges()).all(|e| ctopo.edge_faces(e).len() == 2);
        let chi = capped.mesh.n_vertices() as i64 - ctopo.n_edges() as i64
            + capped.mesh.n_triangles() as i64;
        let genus = ((2 - chi).max(0) / 2) as usize;
        // Open surfaces use the double cover (paper §3) when the holes that count make
        // its genus ≥ 2. A hole counts when its boundary is at least `LARGE_HOLE` √area
        // long; smaller holes stay capped (doubled, a tiny hole becomes a thin handle
        // whose conformal factor is extreme). A disk or an annulus (double genus 0 or
        // 1) stays capped: the slit cylinder gives the map an annulus's double gives.
        let sub_area = fieldtex_mesh::areas::total_area(&sub);
        let large: Vec<u32> = capped
            .caps
            .iter()
            .filter(|c| c.1 >= LARGE_HOLE * sub_area.sqrt())
            .map(|c| c.0)
            .collect();
        let cover_genus = (2 * genus + large.len()).saturating_sub(1);
        let mut double = None;
        let mut cylinder: Option<Result<ComponentMap, ParamError>> = None;
        if manifold && !large.is_empty() && cover_genus >= 2 && faces.len() >= 8 {
            // The input with its small holes capped, large holes open, doubled.
            let partly = TriMesh::new(
                capped.mesh.positions.clone(),
                capped
                    .mesh
                    .triangles
                    .iter()
                    .copied()
                    .filter(|t| !t.iter().any(|v| large.contains(v)))
                    .collect(),
            );
            let dc = double_cover::double_cover(&partly);
            match holomorphic_map::holomorphic_map_with(&dc.mesh, cover_genus, faces.len(), &options.layout) {
                Ok(m) => double = Some((dc, m)),
                Err(e) => warnings.push(Warning::new(
                    "conformal-double-cover-failed",
                    format!("component {ci}: the double cover (genus {cover_genus}) failed ({e}); holes are capped instead"),
                )),
            }
        }
        let mut twin: Vec<u32> = Vec::new();
        let mut slits: Option<ProtrusionSummary> = None;
        let mut slit_cover_genus = None;
        // Genus 0 (small holes capped, at most two large ones left as the cylinder's
        // ends): the slit cylinder, unless protrusion slits spread the area scale less
        // (protrusion_slits.rs). Genus ≥ 1 keeps the paper's holomorphic map: slits there
        // would add zero points to a torus (measured on the rocker arm: docs/conformal.md).
        if options.protrusion_slits
            && double.is_none()
            && manifold
            && genus == 0
            && faces.len() >= 8
        {
            let [a, b] = cylinder_ends(&capped.caps, sub_area);
            match protrusion_map(&capped.mesh, faces.len(), genus, [a, b], &options.layout) {
                Ok(ProtrusionChoice::Slits { cut, cover, map }) => {
                    local_to_global.resize(capped.mesh.n_vertices(), u32::MAX);
                    for v in capped.mesh.n_vertices()..cut.original.len() {
                        local_to_global.push(local_to_global[cut.original[v] as usize]);
                    }
                    slits = Some(ProtrusionSummary {
                        tips: cut.tips.iter().map(|&t| local_to_global[t as usize]).collect(),
                        slit_paths: cut
                            .paths
                            .iter()
                            .map(|p| p.iter().map(|&v| local_to_global[v as usize]).collect())
                            .collect(),
                        log_area_std: map.1,
                        cylinder_log_area_std: map.2,
                    });
                    slit_cover_genus =
                        Some(2 * genus + cut.tips.len() + a.iter().chain(&b).count() - 1);
                    double = Some((*cover, map.0));
                }
                Ok(ProtrusionChoice::Cylinder(m, moved)) => {
                    if let Some(std) = moved {
                        slits = Some(ProtrusionSummary {
                            tips: m
                                .slit_vertices
                                .iter()
                                .map(|&t| {
                                    local_to_global.get(t as usize).copied().unwrap_or(u32::MAX)
                                })
                                .collect(),
                            slit_paths: Vec::new(),
                            log_area_std: std[0],
                            cylinder_log_area_std: std[1],
                        });
                    }
                    cylinder = Some(Ok(*m));
                }
                Err(e) => cylinder = Some(Err(e)),
            }
        }
        let (capped_mesh, result, is_double) = if let Some((dc, m)) = double {
            twin = dc.twin;
            (dc.mesh, Ok(m), true)
        } else if let Some(r) = cylinder {
            (capped.mesh, r, false)
        } else {
            let r = if !manifold {
                Err(cotan_system::conformal_error(
                    "the capped component is not a closed manifold (non-manifold edges)",
                ))
            } else if faces.len() < 8 {
                Err(cotan_system::conformal_error("fewer than 8 triangles"))
            } else if genus == 0 {
                slit_cylinder::slit_cylinder(&capped.mesh, cylinder_ends(&capped.caps, sub_area))
            } else {
                holomorphic_map::holomorphic_map_with(
                    &capped.mesh,
                    genus,
                    faces.len(),
                    &options.layout,
                )
            };
            (capped.mesh, r, false)
        };
        let (map, note) = match result {
            Ok(mut m) => {
                let mut note = (m.method == ConformalMethod::HolomorphicBasisOnly).then(|| {
                    format!("genus {genus}: holomorphic basis and zero points computed; critical-trajectory patches not implemented")
                });
                if matches!(
                    m.method,
                    ConformalMethod::SlitCylinder | ConformalMethod::HolomorphicTorus
                ) {
                    let (moved, left) =
                        flip_untangle::untangle_flips(&capped_mesh.triangles, faces.len(), &mut m);
                    if moved > 0 || left > 0 {
                        let text = format!(
                            "{moved} vertices of triangles the discrete map folded were moved to their one-ring mean (local untangling); {left} triangles still folded"
                        );
                        warnings.push(Warning::new(
                            "conformal-folds-untangled",
                            format!("component {ci}: {text}"),
                        ));
                        note = Some(note.map_or(text.clone(), |n| format!("{n}; {text}")));
                    }
                }
                match rejection(&capped_mesh, faces.len(), &m) {
                    Some(why) => {
                        warnings.push(Warning::new(
                            "conformal-map-rejected",
                            format!(
                                "component {ci} ({} triangles, genus {genus}): {why}",
                                faces.len()
                            ),
                        ));
                        (ComponentMap::empty(ConformalMethod::Failed), Some(why))
                    }
                    None => (m, note),
                }
            }
            Err(e) => {
                warnings.push(Warning::new(
                    "conformal-component-failed",
                    format!("component {ci} ({} triangles, genus {genus}): {e}", faces.len()),
                ));
                (ComponentMap::empty(ConformalMethod::Failed), Some(e.to_string()))
            }
        };
        let zero_points = map
            .zero_points
            .iter()
            .map(|&(v, i)| {
                // On a double cover, a zero on the second copy is reported at its twin.
                let v = twin.get(v as usize).map_or(v, |&t| t.min(v));
                (local_to_global.get(v as usize).copied().unwrap_or(u32::MAX), i)
            })
            .collect();
        let mut c = ConformalComponent {
            component: ci,
            genus,
            boundaries: capped.n_holes,
            method: map.method,
            faces,
            corner_uv: Vec::new(),
            slit: Vec::new(),
            near_singularity: Vec::new(),
            lattice: map.lattice,
            domain: [0.0; 4],
            zero_points,
            conjugate_residual: map.conjugate_residual,
            harmonic_forms: map.harmonic_forms,
            note,
            double_cover_genus: is_double.then_some(slit_cover_genus.unwrap_or(cover_genus)),
            protrusion_slits: slits,
            local_mesh: capped_mesh,
            local_to_global,
            map,
            polish: None,
        };
        c.refresh();
        out.push(c);
        progress.advance(1);
    }
    progress.finish_stage();
    Ok((out, warnings))
}

#[cfg(test)]
mod polish_tests;
#[cfg(test)]
mod protrusion_tests;
#[cfg(test)]
mod tests;
