//! Fingerprint presets: the five classes of Henry's classification as orientation-field
//! designs (paper D, Fig. 7).
//!
//! Layouts (reference frame 512 × 512 px, y down; scaled to the requested size):
//! - `arch`: no singularities; ridges cross from left to right and bulge upwards in the
//!   middle (three strokes).
//! - `tented-arch`: one wedge (core) straight above one trisector (delta), close
//!   together, so the ridges above form a tent.
//! - `left-loop`: a wedge with a trisector to its lower right: ridges enter from the
//!   left, recurve around the core and leave to the left.
//! - `right-loop`: the mirror image (trisector to the lower left).
//! - `whorl`: two wedges side by side (together a +1 centre of circular ridges) between
//!   two trisectors at the lower left and lower right.
//!
//! Every preset also has a horizontal stroke along the bottom and an arching stroke
//! along the top (the flexion crease and fingertip sides of a print). The rotation α of
//! each singularity is not free: it is set so that near each singularity the design
//! agrees with the zero-pole model of fingerprint orientation (Sherlock & Monro 1993,
//! "A model for interpreting fingerprint topology"), `2θ(z) = 2θ₀ + Σ_cores arg(z −
//! c) − Σ_deltas arg(z − d)` with horizontal background `θ₀ = 0` — see
//! [`consistent_angles`]. Angles are rounded to 0.1°.
//!
//! The same designs ship as TOML files in `crates/fieldtex-fields/presets/` (generated
//! by `cargo run --release -p fieldtex-fields --example write_presets`; a test checks
//! that they agree with these built-in versions).

use crate::FieldsError;
use crate::design_elements::{Singularity, SingularityKind, Symmetry, zero_pole_angles};
use crate::design_file::{DesignFile, SingularitySpec, StrokeSpec};

/// Names of the presets, in the classification's usual order.
pub const PRESET_NAMES: [&str; 5] = ["arch", "tented-arch", "left-loop", "right-loop", "whorl"];

/// Reference size of the preset layouts.
pub const REFERENCE_SIZE: f64 = 512.0;

/// Sets the angle (degrees) of every wedge/trisector from
/// [`zero_pole_angles`] with background orientation `background` (degrees), rounded to
/// 0.1°, in `(−90, 90]` (a wedge's or trisector's α is defined modulo 180°).
pub fn consistent_angles(singularities: &mut [SingularitySpec], background: f64) {
    let list: Vec<Singularity> = singularities
        .iter()
        .map(|s| Singularity::at_pixel(s.kind, s.x.unwrap_or(0.0), s.y.unwrap_or(0.0)))
        .collect();
    let angles = zero_pole_angles(&list, background.to_radians());
    for (s, a) in singularities.iter_mut().zip(angles) {
        if s.kind.symmetry() != Symmetry::Orientation {
            continue;
        }
        let mut deg = a.to_degrees().rem_euclid(180.0);
        if deg > 90.0 {
            deg -= 180.0;
        }
        s.angle = (deg * 10.0).round() / 10.0;
    }
}

fn sing(kind: SingularityKind, x: f64, y: f64, sx: f64, sy: f64) -> SingularitySpec {
    SingularitySpec {
        kind,
        x: Some(x * sx),
        y: Some(y * sy),
        position: None,
        angle: 0.0,
        strength: 1.0,
    }
}

fn stroke(points: &[[f64; 2]], sx: f64, sy: f64, weight: f64) -> StrokeSpec {
    StrokeSpec { points: points.iter().map(|p| vec![p[0] * sx, p[1] * sy]).collect(), weight }
}

/// The preset `name` as a plane design of `width × height` pixels with a `grid`-cell
/// grid. Unknown names are an error listing the available ones.
pub fn preset(name: &str, width: f64, height: f64, grid: usize) -> Result<DesignFile, FieldsError> {
    use SingularityKind::{Trisector, Wedge};
    let (sx, sy) = (width / REFERENCE_SIZE, height / REFERENCE_SIZE);
    let mut d = DesignFile::plane(width, height, grid, Symmetry::Orientation);
    let bottom = stroke(&[[16.0, 476.0], [256.0, 468.0], [496.0, 476.0]], sx, sy, 1.0);
    let top = stroke(
        &[[40.0, 120.0], [150.0, 60.0], [256.0, 42.0], [362.0, 60.0], [472.0, 120.0]],
        sx,
        sy,
        1.0,
    );
    match name {
        "arch" => {
            d.strokes = vec![
                top,
                stroke(
                    &[
                        [16.0, 296.0],
                        [96.0, 279.4],
                        [176.0, 245.2],
                        [256.0, 224.0],
                        [336.0, 245.2],
                        [416.0, 279.4],
                        [496.0, 296.0],
                    ],
                    sx,
                    sy,
                    1.0,
                ),
                bottom,
            ];
        }
        "tented-arch" => {
            d.singularities =
                vec![sing(Wedge, 257.3, 214.6, sx, sy), sing(Trisector, 255.7, 318.2, sx, sy)];
            d.strokes = vec![top, bottom];
        }
        "left-loop" => {
            d.singularities =
                vec![sing(Wedge, 226.5, 230.3, sx, sy), sing(Trisector, 350.7, 342.6, sx, sy)];
            d.strokes = vec![top, bottom];
        }
        "right-loop" => {
            d.singularities =
                vec![sing(Wedge, 285.5, 230.3, sx, sy), sing(Trisector, 161.3, 342.6, sx, sy)];
            d.strokes = vec![top, bottom];
        }
        "whorl" => {
            d.singularities = vec![
                sing(Wedge, 229.7, 238.2, sx, sy),
                sing(Wedge, 283.3, 262.1, sx, sy),
                sing(Trisector, 118.6, 366.3, sx, sy),
                sing(Trisector, 393.4, 370.9, sx, sy),
            ];
            d.strokes = vec![top, bottom];
        }
        _ => {
            return Err(FieldsError::UnknownPreset {
                name: name.to_string(),
                available: PRESET_NAMES.join(", "),
            });
        }
    }
    consistent_angles(&mut d.singularities, 0.0);
    Ok(d)
}
