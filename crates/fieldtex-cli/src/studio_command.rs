//! `fieldtex studio`: flags → [`fieldtex_studio::StudioOptions`], then serve.

use clap::Args;
use fieldtex::Error;
use std::path::PathBuf;

/// Flags of `fieldtex studio`.
#[derive(Args, Debug)]
pub struct StudioArgs {
    /// Port to listen on (0 picks a free one).
    #[arg(long, default_value_t = 7878)]
    port: u16,
    /// Address to bind. Default 127.0.0.1 (this machine only); anything else exposes
    /// the studio to the network and prints a warning.
    #[arg(long)]
    host: Option<String>,
    /// Directory that all reads, uploads and exports are confined to (default: the
    /// current directory).
    #[arg(long)]
    workspace: Option<PathBuf>,
    /// Extra read-only directory of exemplar images to offer (e.g. ../shared/data/exemplars).
    #[arg(long)]
    exemplars: Option<PathBuf>,
    /// Extra read-only directory of meshes to offer in the mesh modes (e.g. ../shared/data/meshes).
    #[arg(long)]
    meshes: Option<PathBuf>,
    /// Jobs (align, conformal, transfer, solid) run at once; more wait in a queue.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u16).range(1..=2))]
    max_jobs: u16,
    /// Largest upload in MiB.
    #[arg(long, default_value_t = 16)]
    max_upload_mib: usize,
    /// Open the page in the default browser (xdg-open / open / start).
    #[arg(long)]
    open: bool,
}

/// Runs the server until the process is stopped.
pub fn run(args: StudioArgs, seed: u64, quiet: bool) -> Result<(), Error> {
    let workspace = match args.workspace {
        Some(w) => w,
        None => std::env::current_dir().map_err(|e| {
            Error::bad_input(None, format!("cannot read the current directory: {e}"))
        })?,
    };
    let mut o = fieldtex_studio::StudioOptions::new(workspace);
    o.port = args.port;
    o.exemplars = args.exemplars;
    o.meshes = args.meshes;
    o.max_jobs = usize::from(args.max_jobs);
    o.max_upload_bytes = args.max_upload_mib.saturating_mul(1 << 20);
    o.seed = seed;
    if let Some(h) = args.host {
        o.host = h;
    }
    if !fieldtex_studio::is_loopback_host(&o.host) {
        eprintln!(
            "warning: --host {} exposes the studio (reads and writes in the workspace) to the network; it has no authentication",
            o.host
        );
    }
    let studio = fieldtex_studio::Studio::bind(o).map_err(|e| Error::bad_input(None, e))?;
    let addr = studio.local_addr();
    let url = if addr.ip().is_unspecified() {
        format!("http://127.0.0.1:{}/", addr.port())
    } else {
        format!("http://{addr}/")
    };
    if !quiet {
        eprintln!("fieldtex studio: {url} (Ctrl-C to stop)");
    }
    if args.open {
        open_browser(&url);
    }
    studio.run();
    Ok(())
}

fn open_browser(url: &str) {
    let cmd = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(windows) {
        "explorer"
    } else {
        "xdg-open"
    };
    if let Err(e) = std::process::Command::new(cmd).arg(url).spawn() {
        eprintln!("warning: could not open a browser ({cmd}: {e}); open {url} yourself");
    }
}
