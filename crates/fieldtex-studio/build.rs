//! Embeds the three.js modules that `scripts/setup-studio` copies into `web/vendor/`
//! (git-ignored). Without them the binary still builds: the mesh pages then say which
//! command to run. Generates `$OUT_DIR/vendor.rs` with
//! `VENDOR: &[(&str /* URL path */, &[u8])]` and `VENDOR_VERSION: Option<&str>`.

use std::path::Path;

/// URL path under `/vendor/` ← file under `web/vendor/`.
const FILES: [&str; 6] = [
    "three.module.js",
    "three.core.js",
    "addons/controls/OrbitControls.js",
    "addons/loaders/GLTFLoader.js",
    "addons/utils/BufferGeometryUtils.js",
    "addons/utils/SkeletonUtils.js",
];

fn main() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let vendor = Path::new(&manifest).join("web").join("vendor");
    // A directory is scanned recursively by cargo, so adding or refreshing the vendor
    // folder (inside `web/`) re-runs this script.
    println!("cargo:rerun-if-changed=web");
    println!("cargo:rerun-if-changed=build.rs");
    let complete = FILES.iter().all(|f| vendor.join(f).is_file());
    let mut code = String::from("pub const VENDOR: &[(&str, &[u8])] = &[\n");
    let mut version = "None".to_string();
    if complete {
        for f in FILES {
            let p = vendor.join(f);
            code.push_str(&format!(
                "    (\"/vendor/{f}\", include_bytes!({:?})),\n",
                p.display().to_string()
            ));
        }
        if let Ok(v) = std::fs::read_to_string(vendor.join("VERSION")) {
            version = format!("Some({:?})", v.trim());
        }
    }
    code.push_str("];\n");
    code.push_str(&format!("pub const VENDOR_VERSION: Option<&str> = {version};\n"));
    let out = Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("vendor.rs");
    std::fs::write(out, code).expect("write vendor.rs");
}
