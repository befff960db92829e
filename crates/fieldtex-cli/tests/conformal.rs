//! End-to-end tests of `fieldtex conformal` (issue 13, paper C): a torus and an open
//! tube through the whole pipeline, determinism across thread counts, bad input.

use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::Duration;

mod common;
use common::shared;

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("fieldtex-conformal", name)
}

/// `conformal --mesh MESH --exemplar EXEMPLAR --out OUT EXTRA…`.
fn conformal(mesh: &Path, exemplar: &Path, out: &Path, extra: &[&str]) -> Output {
    common::run_on_mesh("conformal", mesh, exemplar, out, extra, Duration::from_secs(900))
}

/// A torus (`skip_ring`: leave one ring of quads out, giving an open tube) as OBJ text.
fn torus_obj(nu: usize, nv: usize, skip_ring: bool) -> String {
    let mut s = String::new();
    for i in 0..nu {
        for j in 0..nv {
            let (a, b) = (
                i as f64 / nu as f64 * std::f64::consts::TAU,
                j as f64 / nv as f64 * std::f64::consts::TAU,
            );
            let r = 1.0 + 0.4 * b.cos();
            s += &format!("v {} {} {}\n", r * a.cos(), r * a.sin(), 0.4 * b.sin());
        }
    }
    for i in 0..nu {
        if skip_ring && i == 0 {
            continue;
        }
        for j in 0..nv {
            let v = |i: usize, j: usize| (i % nu) * nv + (j % nv) + 1;
            s += &format!(
                "f {} {} {}\nf {} {} {}\n",
                v(i, j),
                v(i + 1, j),
                v(i + 1, j + 1),
                v(i, j),
                v(i + 1, j + 1),
                v(i, j + 1)
            );
        }
    }
    s
}

/// A fresh scratch folder `name` holding `torus.obj`, a closed `nu × nv` torus.
fn torus_in(name: &str, nu: usize, nv: usize) -> (PathBuf, PathBuf) {
    let d = tmp(name);
    let mesh = d.join("torus.obj");
    std::fs::write(&mesh, torus_obj(nu, nv, false)).unwrap();
    (d, mesh)
}

fn pebbles() -> PathBuf {
    shared().join("exemplars/pebbles_Rocks002.png")
}

fn report(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap()
}

/// `conformal` on `mesh` with pebbles at `--size 256` (plus `extra`) into scratch folder
/// `name`, which must succeed: the folder and its report.
fn run_256(mesh: &Path, name: &str, extra: &[&str]) -> (PathBuf, serde_json::Value) {
    let d = tmp(name);
    let args: Vec<&str> = ["--size", "256", "--quiet"].iter().chain(extra).copied().collect();
    let out = conformal(mesh, &pebbles(), &d, &args);
    assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
    let r = report(&d);
    (d, r)
}

#[test]
fn torus_and_tube_end_to_end_deterministic() {
    let (d, mesh) = torus_in("torus", 48, 24);
    let ex = pebbles();
    let o1 = d.join("t1");
    let o2 = d.join("t2");
    for (o, threads) in [(&o1, "1"), (&o2, "2")] {
        let out =
            conformal(&mesh, &ex, o, &["--size", "256", "--keep", "--threads", threads, "--quiet"]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    for f in ["model.glb", "preview.png", "patches.ply", "trajectories.obj"] {
        assert_eq!(
            std::fs::read(o1.join(f)).unwrap(),
            std::fs::read(o2.join(f)).unwrap(),
            "{f} differs between 1 and 2 threads"
        );
    }
    // Valid glTF (Khronos validator, installed by scripts/test).
    assert_eq!(common::validator_errors(&o1.join("model.glb")), 0);
    let r = report(&o1);
    let c = &r["metrics"]["components"][0];
    assert_eq!(c["genus"], 1);
    assert_eq!(c["method"], "holomorphic-torus");
    assert_eq!(c["zero_points"], 0);
    assert_eq!(c["distortion"]["flipped"], 0);
    // This coarse torus (2 304 triangles) is refined once, so the thread-count equality
    // above covers the refined path too.
    assert_eq!(r["metrics"]["refinement"]["levels"], 1, "{}", r["metrics"]["refinement"]);
    // Seams are continuous: the colour jump across them is of the order of the jump
    // between neighbouring texels inside the image.
    let ratio = r["metrics"]["seams"]["ratio"].as_f64().unwrap();
    assert!(ratio < 2.0, "seam colour jump ratio {ratio}");

    // The open tube (two boundaries): capped, one cylinder image, no flips.
    let tube = d.join("tube.obj");
    std::fs::write(&tube, torus_obj(48, 16, true)).unwrap();
    let o3 = d.join("tube-out");
    let out = conformal(&tube, &ex, &o3, &["--size", "256", "--quiet"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r = report(&o3);
    let c = &r["metrics"]["components"][0];
    assert_eq!((c["genus"].as_u64(), c["boundaries"].as_u64()), (Some(0), Some(2)));
    assert_eq!(c["method"], "slit-cylinder");
    assert_eq!(c["distortion"]["flipped"], 0);
}

#[test]
fn bad_inputs_exit_2() {
    let (d, mesh) = torus_in("bad", 12, 8);
    let ex = pebbles();
    let o = d.join("o");
    let out = conformal(Path::new("/nonexistent.obj"), &ex, &o, &["--quiet"]);
    assert_eq!(out.status.code(), Some(2));
    let out = conformal(&mesh, &ex, &o, &["--size", "10", "--quiet"]);
    assert_eq!(out.status.code(), Some(2));
}

/// Zero points on the shared meshes: rocker-arm (genus 1) has none, fertility (genus 4)
/// has 2g − 2 = 6 (Wang et al. 2005 §3), and neither map flips a triangle.
#[test]
fn zero_points_of_shared_meshes() {
    let ex = pebbles();
    for (name, genus, zeros) in [("rocker-arm", 1u64, 0u64), ("fertility", 4, 6)] {
        let d = tmp(name);
        let mesh = shared().join(format!("meshes/{name}.obj"));
        let out = conformal(&mesh, &ex, &d, &["--size", "256", "--quiet"]);
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let r = report(&d);
        let c = &r["metrics"]["components"][0];
        assert_eq!(c["genus"].as_u64(), Some(genus), "{name}");
        let z: i64 = c["zero_point_indices"]
            .as_array()
            .unwrap()
            .iter()
            .map(|z| z["index"].as_i64().unwrap())
            .sum();
        assert_eq!(c["zero_points"].as_u64(), Some(zeros), "{name}: {:?}", c["zero_point_indices"]);
        assert_eq!(z, -(zeros as i64), "{name}: zero-point indices sum to 2 − 2g");
        assert_eq!(r["metrics"]["distortion_all_faces"]["flipped_triangles"], 0, "{name}");
        assert_eq!(c["distortion"]["flipped"], 0, "{name}");
        if genus >= 2 {
            // Genus ≥ 2: critical-trajectory patches, not the fallback atlas.
            assert_eq!(c["method"], "critical-trajectory-patches", "{name}");
            assert!(c["critical_trajectories"].as_u64().unwrap() >= 6, "{name}");
            assert!(c["margin_links"].as_u64().unwrap() > 0, "{name}");
        }
    }
}

/// Genus 0 with protrusions (the horse's legs, head and tail): slits at the tips and the
/// double cover instead of a cylinder that shrinks the legs to points; the ablation flag
/// gives the two-point cylinder back.
#[test]
fn horse_gets_protrusion_slits() {
    let ex = pebbles();
    let mesh = shared().join("meshes/horse.ply");
    let d = tmp("horse");
    let out = conformal(&mesh, &ex, &d, &["--size", "256", "--quiet"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r = report(&d);
    let c = &r["metrics"]["components"][0];
    assert_eq!(c["genus"], 0);
    assert_eq!(c["method"], "critical-trajectory-patches");
    let p = &c["protrusion_slits"];
    let tips = p["tips"].as_array().unwrap().len();
    assert!(tips >= 3, "{p}");
    assert_eq!(c["double_cover_genus"].as_u64(), Some(tips as u64 - 1));
    assert_eq!(p["slit_paths"].as_array().unwrap().len(), tips);
    let (now, cylinder) =
        (p["log_area_std"].as_f64().unwrap(), p["cylinder_log_area_std"].as_f64());
    assert!(now < 2.0 && cylinder.is_none_or(|c| now < 0.5 * c), "{p}");
    assert_eq!(c["distortion"]["flipped"], 0);
    assert!(c["margin_links"].as_u64().unwrap() > 0);
    let d2 = tmp("horse-two-point");
    let out = conformal(&mesh, &ex, &d2, &["--size", "256", "--quiet", "--no-protrusion-slits"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let c2 = &report(&d2)["metrics"]["components"][0];
    assert_eq!(c2["method"], "slit-cylinder");
    assert!(c2["protrusion_slits"].is_null());
}

/// `--quasi-isometric` on a patch layout (fertility, genus 4): relaxed chart by chart,
/// no flips, area distortion lower, angle distortion within the bound.
#[test]
fn quasi_isometric_relaxes_a_patch_layout() {
    let mesh = shared().join("meshes/fertility.obj");
    let d = tmp("fertility-quasi");
    let out = conformal(&mesh, &pebbles(), &d, &["--size", "256", "--quiet", "--quasi-isometric"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r = report(&d);
    let s = &r["metrics"]["mass_spring"][0]["stats"];
    let (before, after) = (&s["before"], &s["after"]);
    assert_eq!(after["flipped"], 0, "{s}");
    assert!(
        after["log_area_std"].as_f64().unwrap() < 0.8 * before["log_area_std"].as_f64().unwrap(),
        "{s}"
    );
    assert!(after["angle_mean"].as_f64().unwrap() <= 1.3 + 1e-9, "{s}");
    let c = &r["metrics"]["components"][0];
    assert_eq!(c["method"], "critical-trajectory-patches");
    assert_eq!(c["distortion"]["flipped"], 0);
    assert!(c["margin_links"].as_u64().unwrap() > 0);
}

/// The conformal polish on a coarse CAD mesh (fandisk, a slit cylinder whose integrated
/// map is 1.06 away from its slits), on the input's triangles: applied by default, the angle distortion away from
/// singularities within 1.05, no folds, the cylinder one chart with margin links;
/// `--no-polish` keeps the integrated periodic map.
#[test]
fn fandisk_is_polished_within_the_angle_target() {
    let mesh = shared().join("meshes/fandisk.obj");
    let d = tmp("fandisk-polish");
    // On the input's triangles (the default refines fandisk first; see the next test).
    let out = conformal(&mesh, &pebbles(), &d, &["--size", "256", "--quiet", "--refine", "0"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r = report(&d);
    let c = &r["metrics"]["components"][0];
    let p = &c["polish"];
    assert_eq!(p["applied"], true, "{p}");
    let (before, after) = (p["away_before"].as_f64().unwrap(), p["away_after"].as_f64().unwrap());
    assert!(before > 1.05 && after <= 1.05, "{p}");
    let away = c["distortion"]["angle_mean_away_from_singularities"].as_f64().unwrap();
    assert!((away - after).abs() < 1e-9, "{c}");
    assert_eq!(c["distortion"]["flipped"], 0);
    assert!(c["lattice"]["a"].is_null());
    assert!(c["margin_links"].as_u64().unwrap() > 0, "{c}");
    // Its margins are feathered by default, not with --no-seam-feather.
    assert!(r["metrics"]["quilting"][0]["feathered_pairs"].as_u64().unwrap() > 0);
    let d3 = tmp("fandisk-no-feather");
    let out = conformal(
        &mesh,
        &pebbles(),
        &d3,
        &["--size", "256", "--quiet", "--no-seam-feather", "--refine", "0"],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(report(&d3)["metrics"]["quilting"][0]["feathered_pairs"], 0);
    let d2 = tmp("fandisk-no-polish");
    let out = conformal(
        &mesh,
        &pebbles(),
        &d2,
        &["--size", "256", "--quiet", "--no-polish", "--refine", "0"],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let c2 = &report(&d2)["metrics"]["components"][0];
    assert!(c2["polish"].is_null());
    assert!(c2["lattice"]["a"].is_number());
    let away2 = c2["distortion"]["angle_mean_away_from_singularities"].as_f64().unwrap();
    assert!((away2 - before).abs() < 1e-9);
}

/// Refinement of a coarse mesh (koala-lowres, 7K triangles, whose polished map is 1.047
/// away from singularities on its own triangles): `auto` splits it once, the map on the
/// refined mesh is within 1.04 and `model.glb` holds the refined triangles with normals;
/// `--refine 0` keeps the input's triangles; levels beyond 3 or a refinement past the
/// hard limit exit 2.
#[test]
fn a_coarse_mesh_is_refined_until_the_map_is_conformal() {
    let mesh = shared().join("meshes/koala-lowres.obj");
    let (d, r) = run_256(&mesh, "koala-refine", &[]);
    let refinement = &r["metrics"]["refinement"];
    let n_in = r["input"]["triangles"].as_u64().unwrap();
    assert_eq!(refinement["mode"], "auto");
    assert_eq!(refinement["levels"], 1, "{refinement}");
    assert_eq!(refinement["triangles"].as_u64(), Some(4 * n_in));
    let by_level = refinement["angle_mean_away_by_level"].as_array().unwrap();
    let (coarse, refined) = (by_level[0].as_f64().unwrap(), by_level[1].as_f64().unwrap());
    assert!(coarse > fieldtex::REFINE_ABOVE && refined <= fieldtex::REFINE_ABOVE, "{refinement}");
    let c = &r["metrics"]["components"][0];
    assert_eq!(c["triangles"].as_u64(), Some(4 * n_in));
    let away = c["distortion"]["angle_mean_away_from_singularities"].as_f64().unwrap();
    assert!((away - refined).abs() < 1e-12, "{c}");
    assert_eq!(c["distortion"]["flipped"], 0);
    let glb = fieldtex::crates::io::read_mesh(&d.join("model.glb")).unwrap().mesh;
    assert_eq!(glb.n_triangles() as u64, 4 * n_in);
    assert!(glb.vertex_normals.is_some());
    // The user is told why the output has more triangles.
    let told = r["warnings"].as_array().unwrap().iter().any(|w| w["code"] == "conformal-refined");
    assert!(told, "{}", r["warnings"]);

    let (_, r0) = run_256(&mesh, "koala-refine-0", &["--refine", "0"]);
    assert_eq!(r0["metrics"]["refinement"]["levels"], 0);
    assert_eq!(r0["metrics"]["components"][0]["triangles"].as_u64(), Some(n_in));
    let away0 = r0["metrics"]["components"][0]["distortion"]["angle_mean_away_from_singularities"]
        .as_f64()
        .unwrap();
    assert!((away0 - coarse).abs() < 1e-12);

    for bad in ["4", "-1", "lots"] {
        let out =
            conformal(&mesh, &pebbles(), &tmp("koala-refine-bad"), &["--quiet", "--refine", bad]);
        assert_eq!(out.status.code(), Some(2), "--refine {bad}");
    }
    // 7K × 4³ stays below the hard limit; the horse (97K) × 4³ does not.
    let horse = shared().join("meshes/horse.ply");
    let out = conformal(&horse, &pebbles(), &tmp("horse-refine-3"), &["--quiet", "--refine", "3"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--refine 3"));
}

/// `auto` weighs components by area: a smooth torus (9 216 triangles, 1.027 away from
/// singularities) beside a small box split into 192 triangles (a slit cylinder at 1.22)
/// is not refined, although the box alone is far above the threshold.
#[test]
fn a_small_distorted_part_does_not_refine_the_scene() {
    let d = tmp("scene-refine");
    let mut text = torus_obj(96, 48, false);
    let base = 96 * 48;
    // A box of side 0.3 at x = 3, each face a 4 × 4 grid of quads; shared vertices by
    // their rounded coordinates.
    let (k, side) = (4usize, 0.3f64);
    let mut ids: std::collections::BTreeMap<[i64; 3], usize> = Default::default();
    let mut verts: Vec<[f64; 3]> = Vec::new();
    let mut id = |p: [f64; 3]| -> usize {
        let key = p.map(|c| (c * 1e6).round() as i64);
        *ids.entry(key).or_insert_with(|| {
            verts.push(p);
            verts.len() - 1
        })
    };
    let mut faces = Vec::new();
    for axis in 0..3 {
        for s in [0.0, 1.0] {
            for i in 0..k {
                for j in 0..k {
                    let mut at = |a: usize, b: usize| {
                        let mut q = [0.0; 3];
                        q[axis] = s * side;
                        q[(axis + 1) % 3] = a as f64 * side / k as f64;
                        q[(axis + 2) % 3] = b as f64 * side / k as f64;
                        id([q[0] + 3.0, q[1], q[2]])
                    };
                    let (a, b, c, e) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                    if s == 0.0 {
                        faces.extend([[a, c, b], [a, e, c]]);
                    } else {
                        faces.extend([[a, b, c], [a, c, e]]);
                    }
                }
            }
        }
    }
    for p in &verts {
        text += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for f in &faces {
        text += &format!("f {} {} {}\n", f[0] + base + 1, f[1] + base + 1, f[2] + base + 1);
    }
    let mesh = d.join("scene.obj");
    std::fs::write(&mesh, text).unwrap();
    let (_, r) = run_256(&mesh, "scene-refine-out", &[]);
    let comps = r["metrics"]["components"].as_array().unwrap();
    let away = |c: &serde_json::Value| {
        c["distortion"]["angle_mean_away_from_singularities"].as_f64().unwrap()
    };
    assert_eq!(comps.len(), 2);
    let (torus, bx) =
        if comps[0]["triangles"] == 192 { (&comps[1], &comps[0]) } else { (&comps[0], &comps[1]) };
    assert_eq!(bx["triangles"], 192, "{bx}");
    assert!(away(bx) > 1.1 && away(torus) < fieldtex::REFINE_ABOVE, "{comps:?}");
    let refinement = &r["metrics"]["refinement"];
    assert_eq!(refinement["levels"], 0, "{refinement}");
    let mean = refinement["angle_mean_away_by_level"][0].as_f64().unwrap();
    assert!(mean > away(torus) && mean < fieldtex::REFINE_ABOVE, "{refinement}");
}

/// `auto` also refines where components have no valid map on the input's triangles: the
/// painted stool (676 triangles in 13 parts, eight of them 8-triangle boxes whose map has
/// nothing to solve and a seat whose map folds) keeps less of its surface on the
/// fallback atlas after refinement, and that atlas's seams are continued.
#[test]
fn unmapped_parts_are_refined_until_they_map() {
    let mesh = shared().join("textured/painted_wooden_stool/painted_wooden_stool_1k.gltf");
    let (d, r) = run_256(&mesh, "stool-refine", &[]);
    let refinement = &r["metrics"]["refinement"];
    let levels = refinement["levels"].as_u64().unwrap() as usize;
    assert!(levels >= 1, "{refinement}");
    let unmapped: Vec<f64> = refinement["unmapped_area_share_by_level"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(unmapped[0] > 0.1 && unmapped[levels] < unmapped[0] - 0.1, "{refinement}");
    let failed = |r: &serde_json::Value| {
        r["metrics"]["components"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|c| c["method"] == "failed")
            .count()
    };
    let (_, r0) = run_256(&mesh, "stool-refine-0", &["--refine", "0"]);
    assert!(failed(&r) < failed(&r0));
    assert_eq!(r["metrics"]["distortion_all_faces"]["flipped_triangles"], 0);
    // The seat that still has no map is textured through a chart atlas whose seams'
    // margins are linked like the patches' (one more component), so the colour jump
    // across seams stays within the target (3.1× before the margins were linked).
    let comps = r["metrics"]["components"].as_array().unwrap();
    let atlas: Vec<_> = comps.iter().filter(|c| c["method"] == "chart-atlas").collect();
    assert_eq!(atlas.len(), 1, "{comps:?}");
    assert!(atlas[0]["margin_links"].as_u64().unwrap() > 0, "{}", atlas[0]);
    let jump = r["metrics"]["seams"]["ratio"].as_f64().unwrap();
    assert!(jump < 1.5, "seam colour jump ratio {jump}");
    // Refinement and the linked atlas give the same bytes on one thread.
    let (d1, _) = run_256(&mesh, "stool-refine-1-thread", &["--threads", "1"]);
    assert_eq!(
        std::fs::read(d.join("model.glb")).unwrap(),
        std::fs::read(d1.join("model.glb")).unwrap(),
        "model.glb differs between thread counts"
    );
}

/// A finer level whose layout has much longer seams is dropped: blub's one refinement
/// lowers σ1/σ2 (1.059 → 1.035) but cuts its surface into patches with 1.7× the seam
/// length, so `auto` keeps its triangles and reports both levels.
#[test]
fn refinement_that_lengthens_the_seams_is_dropped() {
    let (_, r) = run_256(&shared().join("textured/blub/blub.obj"), "blub-refine", &[]);
    let refinement = &r["metrics"]["refinement"];
    let nums = |k: &str| -> Vec<f64> {
        refinement[k].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
    };
    let (angle, seam) = (nums("angle_mean_away_by_level"), nums("seam_length_by_level"));
    assert_eq!((angle.len(), seam.len()), (2, 2), "{refinement}");
    assert!(angle[1] < angle[0] - 0.002, "{refinement}");
    assert!(seam[1] > fieldtex::REFINE_SEAM_GROWTH * seam[0], "{refinement}");
    assert_eq!(refinement["levels"], 0, "{refinement}");
    assert_eq!(refinement["triangles"], r["input"]["triangles"]);
    let told = r["warnings"].as_array().unwrap().iter().any(|w| w["code"] == "conformal-refined");
    assert!(!told);
}
