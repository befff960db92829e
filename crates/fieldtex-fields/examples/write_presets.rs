//! Writes the built-in fingerprint presets as TOML design files into
//! `crates/fieldtex-fields/presets/` (512 × 512 px, 128-cell grid).
//!
//! `cargo run --release -p fieldtex-fields --example write_presets [-- OUT_DIR]`

use fieldtex_fields::presets::{PRESET_NAMES, preset};

fn main() {
    let dir = std::env::args()
        .nth(1)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("presets"));
    std::fs::create_dir_all(&dir).expect("create the presets directory");
    for name in PRESET_NAMES {
        let design = preset(name, 512.0, 512.0, 128).expect("built-in preset");
        let text = format!(
            "# Fingerprint preset `{name}` (512 × 512 px; pixel coordinates, origin top-left,\n\
             # y down; angles in degrees from +x towards +y). Generated from the built-in preset\n\
             # by `cargo run --release -p fieldtex-fields --example write_presets`; a test\n\
             # checks that the two agree. See crates/fieldtex-fields/src/presets.rs.\n\n{}",
            design.to_toml_string()
        );
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, text).expect("write preset");
        println!("wrote {}", path.display());
    }
}
