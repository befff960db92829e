//! `SolidSession`: cuts on demand equal the solid pipeline's `cut-N.png` byte for byte,
//! repeated cuts come from the kept blocks, and sketch edits go through the factored
//! frame field (kept / replaced / added / removed curves).

use fieldtex::crates::{fields, io};
use fieldtex::{NoProgress, SolidOptions, SolidSession, solid};
use std::path::{Path, PathBuf};

// The CLI tests' data and scratch-folder helpers.
#[path = "../../fieldtex-cli/tests/common/paths.rs"]
mod common;
use common::shared;

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("fieldtex-solid-session", name)
}

/// A surface curve around the torus (axis y) and a straight curve on the y = 0 plane.
const SKETCH: &str = r#"{"curves": [
  {"points": [[1.25, 0.2, 0], [0.9, 0.2, 0.9], [0, 0.2, 1.25], [-0.9, 0.2, 0.9]], "axis": "x"},
  {"points": [[-1.0, 0.0, -0.5], [1.0, 0.0, -0.5]], "plane": {"point": [0, 0, 0], "normal": [0, 1, 0]}, "axis": "y"}
]}"#;

/// The torus at 40 voxels (spacing 0.0625, y origin −0.21875), 3 levels, blocks of 6.
fn options(dir: &Path, cuts: Vec<[f64; 6]>) -> SolidOptions {
    let sketch = dir.join("sketch.json");
    std::fs::write(&sketch, SKETCH).unwrap();
    let mut o = SolidOptions {
        mesh: shared().join("meshes/torus.obj"),
        sketch: Some(sketch),
        exemplar: Some(shared().join("exemplars/woodgrain_Wood022.png")),
        resolution: 40,
        atlas_size: 128,
        cuts,
        ..Default::default()
    };
    o.analysis.levels = 3;
    o.analysis.pool = 256;
    o.synthesis.block = 6;
    o
}

fn bytes(im: &fieldtex::crates::core::Image) -> Vec<u8> {
    im.pixels.iter().flat_map(|p| p.map(|v| (v * 255.0).round() as u8)).collect()
}

#[test]
fn session_cuts_equal_the_pipeline_cuts_and_edits_go_through_the_field() {
    let dir = tmp("cuts");
    // A slice through voxel centres (y index 3) and an oblique plane.
    let cuts =
        vec![[0.0, -0.21875 + 0.0625 * 3.0, 0.0, 0.0, 1.0, 0.0], [0.1, 0.0, 0.2, 0.3, 0.2, 1.0]];
    let o = options(&dir, cuts.clone());
    solid(&dir.join("out"), &o, &NoProgress).unwrap();

    // The session reads the same sketch file; the cuts come in the other order.
    let mut session = SolidSession::new(&o, None, &NoProgress).unwrap();
    let oblique = session.cut(cuts[1], &NoProgress).unwrap();
    assert!(!oblique.grid_slice);
    assert!(oblique.voxels_computed > 0);
    let slice = session.cut(cuts[0], &NoProgress).unwrap();
    assert!(slice.grid_slice);
    for (i, c) in [(1, &slice), (2, &oblique)] {
        let want = io::read_image(&dir.join(format!("out/cut-{i}.png"))).unwrap();
        assert_eq!((c.image.width, c.image.height), (want.width, want.height), "cut {i} size");
        assert!(bytes(&c.image) == bytes(&want), "cut {i} differs from the pipeline's");
        let opaque = c.image.pixels.iter().filter(|p| p[3] > 0.0).count();
        assert!(opaque > 100, "cut {i}: {opaque} opaque pixels");
    }
    // Placement: the slice lies in its plane, one voxel per pixel; the oblique image
    // spans vectors in its plane.
    let [corner, u, v] = slice.placement;
    let sp = session.grid().spacing;
    assert!((corner[1] - cuts[0][1]).abs() < 1e-9);
    assert!((u[0] - slice.image.width as f64 * sp).abs() < 1e-9 && u[1] == 0.0);
    assert!((v[2] - slice.image.height as f64 * sp).abs() < 1e-9 && v[1] == 0.0);
    let [_, u, v] = oblique.placement;
    let n = [0.3, 0.2, 1.0];
    for w in [u, v] {
        assert!((w[0] * n[0] + w[1] * n[1] + w[2] * n[2]).abs() < 1e-9, "{w:?} not in the plane");
    }
    // Asked again, the cut comes from the kept blocks.
    let again = session.cut(cuts[0], &NoProgress).unwrap();
    assert_eq!(again.voxels_computed, 0);
    assert!(bytes(&again.image) == bytes(&slice.image));

    // The same sketch given in memory builds the same solid.
    let sketch: fields::Sketch = serde_json::from_str(SKETCH).unwrap();
    let mut o2 = o.clone();
    o2.sketch = None;
    let mut s2 = SolidSession::new(&o2, Some(&sketch), &NoProgress).unwrap();
    assert!(bytes(&s2.cut(cuts[0], &NoProgress).unwrap().image) == bytes(&slice.image));

    // Edits: the same sketch keeps both curves and the blocks.
    let e = session.set_sketch(&sketch).unwrap();
    assert_eq!((e.kept, e.replaced, e.added, e.removed), (2, 0, 0, 0));
    assert_eq!(session.cut(cuts[0], &NoProgress).unwrap().voxels_computed, 0);
    // The first curve bent the other way: replaced, the solid changes.
    let text = SKETCH
        .replace("[0.9, 0.2, 0.9]", "[0.9, 0.2, -0.9]")
        .replace("[0, 0.2, 1.25]", "[0, 0.2, -1.25]")
        .replace("[-0.9, 0.2, 0.9]", "[-0.9, 0.2, -0.9]");
    let bent: fields::Sketch = serde_json::from_str(&text).unwrap();
    let e = session.set_sketch(&bent).unwrap();
    assert_eq!((e.kept, e.replaced, e.added, e.removed), (1, 1, 0, 0));
    let changed = session.cut(cuts[0], &NoProgress).unwrap();
    assert!(changed.voxels_computed > 0);
    assert!(bytes(&changed.image) != bytes(&slice.image), "the edit did not change the cut");
    // Dropping a curve removes it; restoring the sketch adds it back.
    let one: fields::Sketch =
        serde_json::from_str(&format!("{{\"curves\": [{}]}}", first_curve(&text))).unwrap();
    let e = session.set_sketch(&one).unwrap();
    assert_eq!((e.kept, e.removed), (1, 1));
    let e = session.set_sketch(&sketch).unwrap();
    assert_eq!((e.replaced, e.added), (1, 1));
    // No curves: back to the constant field (the pipeline without --sketch).
    let e = session.set_sketch(&fields::Sketch { curves: Vec::new() }).unwrap();
    assert_eq!(e.removed, 2);
    assert!(session.field().is_none());
    let plain = session.cut(cuts[0], &NoProgress).unwrap();
    assert!(bytes(&plain.image) != bytes(&slice.image));

    // Bad planes are refused with a message.
    assert!(session.cut([0.0, 0.0, 0.0, 0.0, 0.0, 0.0], &NoProgress).is_err());
    assert!(session.cut([0.0, 10.0, 0.0, 0.0, -1.0, 0.0], &NoProgress).is_err());
    assert!(session.cut([f64::NAN, 0.0, 0.0, 0.0, 1.0, 0.0], &NoProgress).is_err());
}

/// The first curve object of a sketch text (`{...}` up to its matching brace).
fn first_curve(text: &str) -> &str {
    let start = text.find("{\"points\"").unwrap();
    let end = start + text[start..].find("\"axis\": \"x\"}").unwrap() + "\"axis\": \"x\"}".len();
    &text[start..end]
}
