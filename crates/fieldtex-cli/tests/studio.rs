//! `fieldtex studio`: the binary starts a server that answers, and warns for a
//! non-loopback `--host`.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};

fn start(args: &[&str]) -> (std::process::Child, String, Vec<String>) {
    let ws = std::env::temp_dir().join(format!("fieldtex-cli-studio-{}", std::process::id()));
    std::fs::create_dir_all(&ws).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_fieldtex"))
        .args(["studio", "--port", "0", "--workspace"])
        .arg(&ws)
        .args(args)
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let mut lines = Vec::new();
    let mut reader = BufReader::new(child.stderr.take().unwrap());
    loop {
        let mut line = String::new();
        if reader.read_line(&mut line).unwrap() == 0 {
            break;
        }
        let done = line.contains("http://");
        lines.push(line.trim().to_string());
        if done {
            break;
        }
    }
    let url = lines
        .iter()
        .find_map(|l| l.split_whitespace().find(|w| w.starts_with("http://")))
        .unwrap_or_else(|| panic!("no URL in {lines:?}"))
        .to_string();
    (child, url, lines)
}

fn get(url: &str, path: &str) -> String {
    let hostport = url.trim_start_matches("http://").trim_end_matches('/');
    let mut s = TcpStream::connect(hostport).unwrap();
    write!(s, "GET {path} HTTP/1.1\r\nHost: {hostport}\r\n\r\n").unwrap();
    let mut out = String::new();
    s.read_to_string(&mut out).unwrap();
    out
}

#[test]
fn studio_serves_the_page_and_the_api() {
    let (mut child, url, lines) = start(&[]);
    assert!(url.starts_with("http://127.0.0.1:"), "{lines:?}");
    let page = get(&url, "/");
    assert!(page.starts_with("HTTP/1.1 200") && page.contains("fieldtex studio"), "{page}");
    let info = get(&url, "/api/info");
    assert!(info.contains("\"presets\""), "{info}");
    child.kill().unwrap();
    let _ = child.wait();
}

#[test]
fn studio_warns_for_a_network_host() {
    let (mut child, _url, lines) = start(&["--host", "0.0.0.0"]);
    assert!(lines.iter().any(|l| l.starts_with("warning:") && l.contains("network")), "{lines:?}");
    child.kill().unwrap();
    let _ = child.wait();
}
