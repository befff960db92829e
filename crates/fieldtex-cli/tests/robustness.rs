//! Regression tests for the robustness gaps found from outside (issue 17, point 4):
//! each test is named after the bug it pins. `docs/first-hour.md` lists them.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::{bin, code, shared, stderr};

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("fieldtex-robustness", name)
}

fn run(args: &[&str], limit: Duration) -> Output {
    common::run_limited(args, limit)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn quick(args: &[&str]) -> Output {
    run(args, Duration::from_secs(30))
}

/// `orient --preset whorl --exemplar EXEMPLAR --out OUT EXTRA…` within 30 s.
fn orient_whorl(exemplar: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["orient", "--preset", "whorl", "--exemplar", s(exemplar), "--out", s(out)];
    args.extend_from_slice(extra);
    quick(&args)
}

/// `atlas MESH --out OUT --size 128 --quiet`, which must succeed.
fn atlas_128(mesh: &Path, out: &Path) {
    let o = quick(&["atlas", s(mesh), "--out", s(out), "--size", "128", "--quiet"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A small closed mesh (the shared torus, 4.6K triangles) copied into `dir`.
fn torus_in(dir: &Path) -> PathBuf {
    let p = dir.join("torus.obj");
    std::fs::copy(shared().join("meshes/torus.obj"), &p).unwrap();
    p
}

/// A 32×32 stripes PNG written by the tool itself (`render` of a plane would do too).
fn exemplar_in(dir: &Path, name: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::copy(shared().join("exemplars/stripes_Fabric071.png"), &p).unwrap();
    p
}

/// Exit 2 with a message that says `has` and not `lacks`.
fn assert_refused_naming(o: &Output, has: &str, lacks: &str) {
    assert_eq!(code(o), 2, "{}", stderr(o));
    let e = stderr(o);
    assert!(e.contains(has) && !e.contains(lacks), "{e}");
}

fn assert_refused_unchanged(o: &Output, file: &Path, before: &[u8]) {
    assert_eq!(code(o), 2, "{}", stderr(o));
    assert!(stderr(o).contains("refusing to overwrite an input"), "{}", stderr(o));
    assert_eq!(std::fs::read(file).unwrap(), before, "{} was modified", file.display());
}

#[test]
fn crest_preview_onto_the_mesh_replaced_the_mesh() {
    let d = tmp("crest-preview");
    let m = torus_in(&d);
    let before = std::fs::read(&m).unwrap();
    let o = quick(&["crest", s(&m), "--out", s(&d.join("c.obj")), "--preview", s(&m), "--quiet"]);
    assert_refused_unchanged(&o, &m, &before);
    assert!(!d.join("c.obj").exists(), "refused before writing anything");
}

#[test]
fn eval_out_onto_the_image_replaced_the_image() {
    let d = tmp("eval-out");
    let img = exemplar_in(&d, "i.png");
    let ex = exemplar_in(&d, "e.png");
    let before = std::fs::read(&img).unwrap();
    let o = quick(&["eval", s(&img), "--exemplar", s(&ex), "--out", s(&img), "--quiet"]);
    assert_refused_unchanged(&o, &img, &before);
}

#[test]
fn orient_out_dir_holding_the_exemplar_replaced_it() {
    let d = tmp("orient-out");
    let ex = exemplar_in(&d, "texture.png");
    let before = std::fs::read(&ex).unwrap();
    let t0 = Instant::now();
    let o = quick(&["orient", "--preset", "whorl", "--exemplar", s(&ex), "--out", s(&d)]);
    assert_refused_unchanged(&o, &ex, &before);
    assert!(t0.elapsed() < Duration::from_secs(10), "refused before the synthesis");
}

#[test]
fn atlas_out_dir_holding_the_mesh_replaced_it() {
    let d = tmp("atlas-out");
    let m = torus_in(&d);
    let first = d.join("first");
    atlas_128(&m, &first);
    let glb = first.join("model.glb");
    let before = std::fs::read(&glb).unwrap();
    let o = quick(&["atlas", s(&glb), "--out", s(&first), "--size", "128", "--quiet"]);
    assert_refused_unchanged(&o, &glb, &before);
}

#[test]
fn mtl_texture_in_the_out_dir_was_replaced() {
    // The OBJ's map_Kd is `preview.png` in the output folder: an input of the command.
    let d = tmp("mtl-texture");
    std::fs::copy(shared().join("meshes/torus.obj"), d.join("m_body.obj")).unwrap();
    let body = std::fs::read_to_string(d.join("m_body.obj")).unwrap();
    std::fs::write(d.join("m.obj"), format!("mtllib m.mtl\nusemtl a\n{body}")).unwrap();
    std::fs::write(d.join("m.mtl"), "newmtl a\nmap_Kd preview.png\n").unwrap();
    let tex = exemplar_in(&d, "preview.png");
    let before = std::fs::read(&tex).unwrap();
    let o = quick(&["atlas", s(&d.join("m.obj")), "--out", s(&d), "--size", "128", "--quiet"]);
    assert_refused_unchanged(&o, &tex, &before);
}

#[cfg(unix)]
#[test]
fn fifo_named_like_a_mesh_blocked_the_reader() {
    let d = tmp("fifo");
    let fifo = d.join("x.obj");
    let ok = Command::new("mkfifo").arg(&fifo).status().map(|s| s.success()).unwrap_or(false);
    if !ok {
        eprintln!("mkfifo unavailable; FIFO case covered by fieldtex-io unit tests only");
        return;
    }
    let o = run(&["inspect", s(&fifo)], Duration::from_secs(10));
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("not a regular file"), "{}", stderr(&o));
}

#[cfg(unix)]
#[test]
fn symlink_to_dev_zero_read_gigabytes() {
    let d = tmp("devzero");
    let link = d.join("z.obj");
    std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
    let o = run(&["inspect", s(&link)], Duration::from_secs(10));
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("not a regular file"), "{}", stderr(&o));
}

#[test]
fn mtllib_and_map_kd_naming_dev_urandom_hung() {
    let d = tmp("mtl-urandom");
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::fs::write(d.join("u.obj"), format!("mtllib /dev/urandom\n{tri}")).unwrap();
    std::fs::write(d.join("k.obj"), format!("mtllib k.mtl\nusemtl a\n{tri}")).unwrap();
    std::fs::write(d.join("k.mtl"), "newmtl a\nmap_Kd ../../../../../../dev/urandom\n").unwrap();
    for m in ["u.obj", "k.obj"] {
        let o = run(&["inspect", s(&d.join(m))], Duration::from_secs(10));
        assert_eq!(code(&o), 0, "{}", stderr(&o));
        assert!(stderr(&o).contains("refused"), "{m}: {}", stderr(&o));
    }
}

#[test]
fn gltf_uri_leaving_the_folder_was_read_and_echoed() {
    let d = tmp("gltf-uri");
    for (name, uri) in
        [("p.gltf", "../../../../../../etc/passwd"), ("r.gltf", "../../../../dev/urandom")]
    {
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"{uri}","byteLength":36}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
            "min":[0,0,0],"max":[1,1,1]}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
            "nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}]}}"#
        );
        std::fs::write(d.join(name), json).unwrap();
        let o = run(&["inspect", s(&d.join(name))], Duration::from_secs(10));
        assert_eq!(code(&o), 2, "{}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("leaves the asset's folder"), "{e}");
        assert!(!e.contains("root:") && !e.contains("/bin/"), "content echoed: {e}");
    }
    // A buffer is read up to its byteLength only: a longer file inside the folder is fine.
    let mut bin: Vec<u8> =
        [0f32, 0., 0., 1., 0., 0., 0., 1., 0.].iter().flat_map(|x| x.to_le_bytes()).collect();
    bin.extend(std::iter::repeat_n(7u8, 4096));
    std::fs::write(d.join("b.bin"), bin).unwrap();
    let text = std::fs::read_to_string(d.join("p.gltf")).unwrap();
    std::fs::write(d.join("ok.gltf"), text.replace("../../../../../../etc/passwd", "b.bin"))
        .unwrap();
    let o = quick(&["inspect", s(&d.join("ok.gltf"))]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(stdout(&o).contains("triangles: 1"), "{}", stdout(&o));
}

#[test]
fn threads_100000_hung_or_aborted() {
    let o =
        run(&["demo", "--out", "/nonexistent/x", "--threads", "100000"], Duration::from_secs(10));
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("--threads"), "{}", stderr(&o));
}

#[test]
fn inspect_json_into_a_closed_pipe_panicked() {
    let d = tmp("pipe");
    let m = torus_in(&d);
    let mut child = Command::new(bin())
        .args(["inspect", s(&m), "--json"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // `| head -1` after one line: close our end of the pipe at once.
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
    assert_eq!(code(&o), 0, "{}", stderr(&o));
}

#[test]
fn orient_scale_1e_30_passed_validation() {
    let d = tmp("scale");
    let ex = exemplar_in(&d, "e.png");
    let o = orient_whorl(&ex, &d.join("o"), &["--scale", "1e-30"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("--scale must be in"), "{}", stderr(&o));
    assert!(!d.join("o").exists(), "validated before anything was created");
}

#[test]
fn killed_rerun_left_a_mix_of_new_and_old_outputs() {
    let d = tmp("kill");
    let m = torus_in(&d);
    let out = d.join("out");
    atlas_128(&m, &out);
    let names = ["model.glb", "preview.png", "report.json"];
    let old: Vec<Vec<u8>> = names.iter().map(|n| std::fs::read(out.join(n)).unwrap()).collect();
    // A different rerun, killed as soon as it starts writing (its staging folder exists).
    let mut child = Command::new(bin())
        .args(["atlas", s(&m), "--out", s(&out), "--size", "512", "--gutter", "2", "--quiet"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    loop {
        let staging = std::fs::read_dir(&out)
            .unwrap()
            .flatten()
            .any(|e| e.file_name().to_string_lossy().starts_with(".fieldtex-staging-"));
        if staging || child.try_wait().unwrap().is_some() || t0.elapsed() > Duration::from_secs(20)
        {
            break;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    let _ = child.kill();
    let _ = child.wait();
    let now: Vec<Vec<u8>> = names.iter().map(|n| std::fs::read(out.join(n)).unwrap()).collect();
    let all_old = now == old;
    let all_new = now.iter().zip(&old).all(|(a, b)| a != b);
    assert!(all_old || all_new, "a mix of old and new outputs after a kill");
    // The next run removes the orphaned staging folder.
    atlas_128(&m, &out);
    let left: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    let report = std::fs::read_to_string(out.join("report.json")).unwrap();
    for n in ["model.glb", "preview.png", "report.json"] {
        assert!(report.contains(&format!("\"{n}\"")), "report lists {n}");
    }
}

#[test]
fn patch_with_a_negative_first_number_was_rejected_and_a_miss_printed_debug_text() {
    let d = tmp("patch");
    let m = torus_in(&d);
    let ex = exemplar_in(&d, "e.png");
    let extra = ["--mesh", s(&m), "--patch", "-7.2,11.8,5.3,5", "--size", "64", "--no-metrics"];
    let o = orient_whorl(&ex, &d.join("o"), &extra);
    let e = stderr(&o);
    assert_eq!(code(&o), 2, "{e}");
    assert!(e.contains("no triangle centre lies within 5"), "parsed and a user message: {e}");
    assert!(!e.contains("Some(") && !e.contains("(["), "Rust debug text: {e}");
}

#[test]
fn render_out_jpg_wrote_png_bytes() {
    let d = tmp("render");
    let m = torus_in(&d);
    let jpg = d.join("x.jpg");
    let o = quick(&["render", s(&m), "--out", s(&jpg), "--size", "64", "--quiet"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert_eq!(&std::fs::read(&jpg).unwrap()[..3], &[0xFF, 0xD8, 0xFF], "JPEG magic");
    let o = quick(&["render", s(&m), "--out", s(&d.join("x.bmp")), "--size", "64"]);
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains(".png, .jpg or .jpeg"), "{}", stderr(&o));
}

#[test]
fn warnings_were_printed_twice_in_library_words() {
    let m = shared().join("meshes/defects/beetle-1972-nonmanifold.obj");
    let d = tmp("warnings");
    let o = quick(&["atlas", s(&m), "--out", s(&d), "--size", "128"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let lines: Vec<String> =
        stderr(&o).lines().filter(|l| l.starts_with("warning:")).map(str::to_string).collect();
    assert!(!lines.is_empty());
    let mut unique = lines.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), lines.len(), "a warning printed twice: {lines:#?}");
    for l in &lines {
        assert!(!l.contains("repair:"), "library code in a warning: {l}");
        assert!(!l.ends_with(')') || !l.contains(") ("), "count printed twice: {l}");
    }
    // crest prints its warnings once, inside its JSON summary.
    let o = quick(&["crest", s(&m), "--out", s(&d.join("c.obj"))]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning:"), "{}", stderr(&o));
}

#[test]
fn eval_with_a_tiny_exemplar_named_the_image() {
    let d = tmp("eval-tiny");
    let img = exemplar_in(&d, "img.png");
    let tiny = common::tiny_exemplar(&d);
    let o = quick(&["eval", s(&img), "--exemplar", s(&tiny)]);
    assert_refused_naming(&o, "tiny.png", "img.png");
}

#[test]
fn empty_png_was_told_to_reexport_the_mesh() {
    let d = tmp("empty-png");
    let empty = d.join("e.png");
    std::fs::File::create(&empty).unwrap().flush().unwrap();
    let o =
        quick(&["orient", "--preset", "whorl", "--exemplar", s(&empty), "--out", s(&d.join("o"))]);
    assert_refused_naming(&o, "image", "mesh");
}

#[test]
fn plain_inspect_printed_unbounded_lists() {
    let d = tmp("inspect-lists");
    // 300 separate triangles: 300 components, each listed before the fix.
    let mut obj = String::new();
    for k in 0..300 {
        let x = k as f64 * 2.0;
        obj.push_str(&format!("v {x} 0 0\nv {} 0 0\nv {x} 1 0\n", x + 1.0));
        let b = 3 * k + 1;
        obj.push_str(&format!("f {b} {} {}\n", b + 1, b + 2));
    }
    std::fs::write(d.join("many.obj"), obj).unwrap();
    let o = quick(&["inspect", s(&d.join("many.obj"))]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.lines().count() < 30, "{} lines:\n{text}", text.lines().count());
    assert!(text.contains("… and 290 more components"), "{text}");
}

#[test]
fn arguments_lacked_help_text_and_defaults() {
    let help = |args: &[&str]| stdout(&quick(args));
    assert!(help(&["inspect", "--help"]).contains("Mesh file"));
    let atlas = help(&["atlas", "--help"]);
    assert!(atlas.contains("Mesh file") && atlas.contains("Output directory"), "{atlas}");
    let orient = help(&["orient", "--help"]);
    assert!(orient.contains("Exemplar image") && orient.contains("default: the"), "{orient}");
    assert!(orient.contains("Output directory"), "{orient}");
    let align = help(&["align", "--help"]);
    assert!(align.contains("Mesh file") && align.contains("Exemplar image"), "{align}");
    let crest = help(&["crest", "--help"]);
    assert!(crest.contains("Default: the detector's own"), "{crest}");
}

#[test]
fn solid_cut_with_a_negative_first_number_was_rejected_by_the_parser() {
    let d = tmp("solid-cut");
    let missing = d.join("missing.obj");
    let o = quick(&[
        "solid",
        "--mesh",
        s(&missing),
        "--exemplar",
        s(&d.join("e.png")),
        "--out",
        s(&d.join("out")),
        "--cut",
        "-0.017,0.11,0,0,0,1",
    ]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    // The plane parses; the error is about the missing mesh, not the argument.
    assert!(!stderr(&o).contains("unexpected argument"), "{}", stderr(&o));
    assert!(stderr(&o).contains("missing.obj"), "{}", stderr(&o));
}

#[test]
fn negative_scale_and_depth_were_rejected_by_the_parser_instead_of_validated() {
    let d = tmp("negative-values");
    let (e, m) = (d.join("e.png"), d.join("m.obj"));
    let (o1, o2, o3) = (d.join("o1"), d.join("o2"), d.join("o3"));
    // Each negative value must reach the command's own validation (a message naming
    // the option), not clap's "unexpected argument '-1'".
    let orient =
        ["orient", "--preset", "whorl", "--exemplar", s(&e), "--out", s(&o1), "--scale", "-1"];
    let align = ["align", "--mesh", s(&m), "--exemplar", s(&e), "--out", s(&o2), "--scale", "-2"];
    let solid =
        ["solid", "--mesh", s(&m), "--exemplar", s(&e), "--out", s(&o3), "--interior-depth", "-5"];
    for (args, names) in
        [(&orient[..], "--scale"), (&align[..], ""), (&solid[..], "--interior-depth")]
    {
        let o = quick(args);
        assert_eq!(code(&o), 2, "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("unexpected argument"), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(names), "{args:?}: {}", stderr(&o));
    }
}
