//! `fieldtex studio`: a local web server for interactive orientation-field design
//! (Liu et al., paper D): a page places singularities and strokes on a plane, the
//! server keeps a factored [`fieldtex_fields::FieldDesign`] per design session,
//! re-solves it on every edit and returns the sampled field; textures are synthesised
//! on demand with the facade's guided synthesis, and designs, fields and textures are
//! exported into the workspace.
//!
//! The UI boundary of the workspace: it serves the embedded page (`web/`, plain
//! JavaScript modules, no build step), parses HTTP with [`http`] (std `TcpListener`,
//! one request per connection), confines every file access to the workspace
//! ([`workspace`]) and answers every failure with a 4xx/5xx JSON message; a panic in a
//! handler is caught and answered with 500, so one bad request never stops the server.
//!
//! Binding: `127.0.0.1` unless [`StudioOptions::host`] says otherwise. Requests whose
//! `Host` is not a loopback name are refused on a loopback bind (DNS rebinding), and
//! requests carrying an `Origin` other than the page's own are refused (other sites).

pub mod api;
pub mod http;
pub mod jobs;
pub mod mesh_mode;
pub mod session;
pub mod workspace;

use std::net::{SocketAddr, TcpListener};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

/// Options of [`Studio`].
#[derive(Debug, Clone)]
pub struct StudioOptions {
    /// Address to bind. Default `127.0.0.1`.
    pub host: String,
    /// Port; 0 picks a free one. Default 7878.
    pub port: u16,
    /// The directory all reads and writes are confined to.
    pub workspace: PathBuf,
    /// An extra read-only directory of exemplar images (e.g. the shared exemplars).
    pub exemplars: Option<PathBuf>,
    /// An extra read-only directory of meshes (e.g. the shared meshes).
    pub meshes: Option<PathBuf>,
    /// Jobs (align, conformal, transfer, solid) run at once; more wait. Default 1.
    pub max_jobs: usize,
    /// Largest upload in bytes. Default 16 MiB.
    pub max_upload_bytes: usize,
    /// Largest JSON body in bytes. Default 4 MiB.
    pub max_json_bytes: usize,
    /// Most connections handled at once; more are answered 503. Default 64.
    pub max_connections: usize,
    /// Most design sessions kept; the oldest is dropped beyond. Default 32.
    pub max_sessions: usize,
    /// Seed of the synthesis (the page may override it per request). Default 1.
    pub seed: u64,
}

impl StudioOptions {
    pub fn new(workspace: PathBuf) -> Self {
        Self {
            host: "127.0.0.1".into(),
            port: 7878,
            workspace,
            exemplars: None,
            meshes: None,
            max_jobs: 1,
            max_upload_bytes: 16 << 20,
            max_json_bytes: 4 << 20,
            max_connections: 64,
            max_sessions: 32,
            seed: 1,
        }
    }
}

/// Whether `host` names the loopback interface.
pub fn is_loopback_host(host: &str) -> bool {
    matches!(host, "127.0.0.1" | "localhost" | "::1" | "[::1]")
        || host.parse::<std::net::IpAddr>().is_ok_and(|ip| ip.is_loopback())
}

/// A bound studio server.
pub struct Studio {
    listener: TcpListener,
    state: Arc<api::State>,
}

impl Studio {
    /// Opens the workspace and binds the listener.
    pub fn bind(options: StudioOptions) -> Result<Self, String> {
        let state = Arc::new(api::State::new(&options)?);
        let addr = format!("{}:{}", options.host, options.port);
        let addr = if options.host.contains(':') && !options.host.starts_with('[') {
            format!("[{}]:{}", options.host, options.port)
        } else {
            addr
        };
        let listener =
            TcpListener::bind(&addr).map_err(|e| format!("cannot listen on {addr}: {e}"))?;
        Ok(Self { listener, state })
    }

    /// The bound address.
    pub fn local_addr(&self) -> SocketAddr {
        self.listener.local_addr().expect("a bound listener has an address")
    }

    /// Serves forever: one thread per connection, at most `max_connections` at once.
    pub fn run(self) {
        let active = Arc::new(AtomicUsize::new(0));
        for stream in self.listener.incoming() {
            let Ok(mut stream) = stream else { continue };
            let _ = stream.set_read_timeout(Some(Duration::from_secs(15)));
            let _ = stream.set_write_timeout(Some(Duration::from_secs(30)));
            let _ = stream.set_nodelay(true);
            if active.fetch_add(1, Ordering::SeqCst) >= self.state.max_connections {
                active.fetch_sub(1, Ordering::SeqCst);
                http::write_response(
                    &mut stream,
                    &http::Response::error(503, "server busy; retry"),
                );
                continue;
            }
            let state = self.state.clone();
            let done = active.clone();
            let spawned = std::thread::Builder::new().name("studio-conn".into()).spawn(move || {
                api::handle_connection(&state, stream);
                done.fetch_sub(1, Ordering::SeqCst);
            });
            if spawned.is_err() {
                // The closure (and its decrement) was dropped with the error.
                active.fetch_sub(1, Ordering::SeqCst);
            }
        }
    }

    /// Serves on a background thread (tests, benchmarks); returns the address.
    pub fn spawn(self) -> SocketAddr {
        let addr = self.local_addr();
        std::thread::spawn(move || self.run());
        addr
    }
}
