//! Minimal MTL (OBJ material library) reader: material names and their diffuse texture
//! (`map_Kd`). Texture options (`-s 1 1 1`, `-bm 0.5`, ...) are skipped; the rest of the
//! line is the file name (spaces allowed, `\` read as `/`). Everything else is ignored.

/// `(material name, map_Kd file name)` for every material, in file order (`None` when a
/// material has no diffuse texture).
pub fn parse_mtl(bytes: &[u8]) -> Vec<(String, Option<String>)> {
    let mut out: Vec<(String, Option<String>)> = Vec::new();
    for line in bytes.split(|&b| b == b'\n') {
        let line = String::from_utf8_lossy(line);
        let line = line.trim();
        let mut tok = line.split_whitespace();
        match tok.next() {
            Some("newmtl") => {
                let name = line["newmtl".len()..].trim().to_string();
                out.push((name, None));
            }
            Some(kw) if kw.eq_ignore_ascii_case("map_Kd") => {
                let rest: Vec<&str> = tok.collect();
                let file = texture_file_name(&rest);
                if let (Some(last), false) = (out.last_mut(), file.is_empty()) {
                    last.1 = Some(file);
                }
            }
            _ => {}
        }
    }
    out
}

/// Skips texture options and returns the file name.
fn texture_file_name(tokens: &[&str]) -> String {
    let mut i = 0;
    while i < tokens.len() && tokens[i].starts_with('-') {
        let n_args = match tokens[i] {
            "-blendu" | "-blendv" | "-cc" | "-clamp" | "-imfchan" | "-boost" | "-texres"
            | "-bm" => 1,
            "-mm" => 2,
            "-o" | "-s" | "-t" => {
                // one to three numbers
                let mut k = 0;
                while k < 3 && tokens.get(i + 1 + k).is_some_and(|t| t.parse::<f64>().is_ok()) {
                    k += 1;
                }
                k
            }
            _ => 0,
        };
        i += 1 + n_args;
    }
    tokens.get(i..).unwrap_or(&[]).join(" ").replace('\\', "/")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_names_and_textures_with_options() {
        let m = parse_mtl(
            b"newmtl a\nKd 1 1 1\nmap_Kd -s 1 1 1 -bm 0.5 tex dir\\my tex.png\nnewmtl b\n",
        );
        assert_eq!(m, vec![("a".into(), Some("tex dir/my tex.png".into())), ("b".into(), None)]);
    }
}
