//! Field designs on a parameterised patch: the mesh design itself (with a stronger
//! regularisation when the default one leaves the matrix numerically indefinite), and
//! plane designs (and presets) laid on the patch: positions through the UV bounding
//! box, singularity rotations into the mesh design's frames, strokes densified, lifted
//! to the surface and split where they leave the chart.

use super::patch_parameterization::Patch;
use fieldtex_core::vec3::{add, dot, norm, scale, sub};
use fieldtex_fields::{
    DesignFile, Domain, FieldDesign, FieldsError, Singularity, SingularityKind, Stroke,
};
use fieldtex_mesh::TriMesh;
use fieldtex_param::TexelMap;

/// Largest relative Tikhonov regularisation tried when factoring the design matrix.
const MAX_REGULARIZATION: f64 = 1e-2;

/// The mesh design of `file`'s weights on `mesh`, with its singularities and strokes
/// when `with_elements` (a `[domain] kind = "mesh"` file). If the factorisation fails
/// (jagged or sliver-rich patches can leave the smoothness matrix numerically
/// indefinite), it is retried with the regularisation raised ×10 up to
/// [`MAX_REGULARIZATION`], with a warning.
pub(super) fn build_mesh_design(
    file: &DesignFile,
    mesh: &TriMesh,
    with_elements: bool,
    warnings: &mut Vec<fieldtex_core::Warning>,
) -> Result<FieldDesign, FieldsError> {
    file.validate()?;
    let base = file.options();
    let mut eps = base.regularization;
    let mut design = loop {
        let options = base.clone().with_regularization(eps);
        match FieldDesign::new(Domain::Mesh(mesh.clone()), file.symmetry()?, options) {
            Ok(d) => break d,
            Err(FieldsError::Solve(e)) if eps < MAX_REGULARIZATION => {
                let next = (eps * 10.0).min(MAX_REGULARIZATION);
                warnings.push(fieldtex_core::Warning::new(
                    "field-regularized",
                    format!(
                        "the patch's field design matrix could not be factored with \
                         regularisation {eps:.0e} ({e}); retried with {next:.0e}, which smooths \
                         the field slightly more"
                    ),
                ));
                eps = next;
            }
            Err(e) => return Err(e),
        }
    };
    if with_elements {
        for s in file.singularity_list()? {
            design.add_singularity(s)?;
        }
        for s in file.stroke_list() {
            design.add_stroke(s)?;
        }
    }
    Ok(design)
}

/// Lays the plane design `file` on the UV bounding box and adds its singularities and
/// strokes to the mesh design `fd` (module docs, step 3).
pub(super) fn map_plane_design(
    file: &DesignFile,
    patch: &Patch,
    map: &TexelMap,
    fd: &mut FieldDesign,
    warnings: &mut Vec<fieldtex_core::Warning>,
) -> std::result::Result<(), FieldsError> {
    let (w, h) = (file.domain.width.unwrap_or(1.0), file.domain.height.unwrap_or(1.0));
    let [x0, y0, x1, y1] = patch.image_box;
    let (kx, ky) = ((x1 - x0) / w, (y1 - y0) / h);
    let to_image = |x: f64, y: f64| [x0 + x * kx, y0 + y * ky];
    for (i, s) in file.singularity_list()?.into_iter().enumerate() {
        let Some((f, b)) = patch.locate_image(map, to_image(s.position[0], s.position[1])) else {
            warnings.push(fieldtex_core::Warning::new(
                "singularity-outside-patch",
                format!(
                    "singularity {i} ({}) at ({:.1}, {:.1}) of the {w}×{h} design falls outside \
                     the flattened patch; it is left out",
                    s.kind.name(),
                    s.position[0],
                    s.position[1]
                ),
            ));
            continue;
        };
        let p = patch.surface_point(f, b);
        let g = fd.locate(p).map_or(f, |(g, _)| g);
        let angle = match patch.jacobian[g] {
            Some([px, py]) => {
                let (e1, e2) = fd.frames()[g];
                // Plane axes on the surface, in the frame of the singularity's triangle.
                let (ax, ay) = (scale(px, kx), scale(py, ky));
                let m = [[dot(e1, ax), dot(e1, ay)], [dot(e2, ax), dot(e2, ay)]];
                let phi = m[1][0].atan2(m[0][0]);
                let reflect = m[0][0] * m[1][1] - m[0][1] * m[1][0] < 0.0;
                angle_in_frame(s.kind, s.angle, phi, reflect)
            }
            None => s.angle,
        };
        fd.add_singularity(Singularity { position: p, angle, ..s })?;
    }
    // Strokes: samples every 1/256 of the box's longer side, lifted to the surface.
    let step = w.max(h) / 256.0;
    for (i, st) in file.stroke_list().into_iter().enumerate() {
        let mut pieces: Vec<Vec<[f64; 3]>> = vec![Vec::new()];
        let mut push = |q: [f64; 3]| match patch.locate_image(map, to_image(q[0], q[1])) {
            Some((f, b)) => pieces.last_mut().expect("non-empty").push(patch.surface_point(f, b)),
            None => {
                if !pieces.last().expect("non-empty").is_empty() {
                    pieces.push(Vec::new());
                }
            }
        };
        for seg in st.points.windows(2) {
            let d = sub(seg[1], seg[0]);
            let k = ((norm(d) / step).ceil() as usize).clamp(1, 100_000);
            for j in 0..k {
                push(add(seg[0], scale(d, j as f64 / k as f64)));
            }
        }
        if let Some(last) = st.points.last() {
            push(*last);
        }
        let mut added = 0;
        for piece in pieces.into_iter().filter(|p| p.len() >= 2) {
            match fd.add_stroke(Stroke { points: piece, weight: st.weight }) {
                Ok(_) => added += 1,
                Err(FieldsError::StrokeMissesDomain { .. }) => {}
                Err(e) => return Err(e),
            }
        }
        if added == 0 {
            warnings.push(fieldtex_core::Warning::new(
                "stroke-outside-patch",
                format!(
                    "stroke {i} of the design lies outside the flattened patch; it is left out"
                ),
            ));
        }
    }
    Ok(())
}

/// Rotation α of a singularity re-expressed in a frame where the design plane's x axis
/// has angle `phi` (and the plane is mirrored when `reflect`): angles `a` of the plane
/// become `±a + phi` in the frame. Derived from the model fields of
/// [`SingularityKind`] (wedge `θ = ψ/2 + α`, trisector `θ = −(ψ/2 + α)`, vector kinds
/// `u = ψ + arg c`, saddle `u = −ψ − α`).
pub(super) fn angle_in_frame(kind: SingularityKind, alpha: f64, phi: f64, reflect: bool) -> f64 {
    use std::f64::consts::PI;
    match (kind, reflect) {
        (SingularityKind::Wedge, false) => alpha + 0.5 * phi,
        (SingularityKind::Wedge, true) => 0.5 * phi - alpha,
        (SingularityKind::Trisector, false) => alpha - 1.5 * phi,
        (SingularityKind::Trisector, true) => -alpha - 1.5 * phi,
        (SingularityKind::Saddle, false) => alpha - 2.0 * phi,
        (SingularityKind::Saddle, true) => -alpha - 2.0 * phi,
        (SingularityKind::Vortex, true) => PI - alpha,
        (_, true) => -alpha,
        (_, false) => alpha,
    }
}
