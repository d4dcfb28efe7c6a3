//! `eenf serve`: the local web page (crate `eenf-serve`).

use std::net::IpAddr;
use std::path::PathBuf;

use anyhow::Result;
use eenf_serve::{serve, ServeOptions, DEFAULT_MAX_UPLOAD};

/// Arguments of `eenf serve`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A reference store (`eenf refdb build`) to search for when each upload was recorded;
    /// give it again for more.
    #[arg(long = "store", value_name = "DIR")]
    pub stores: Vec<PathBuf>,
    /// The address to listen on. Another than 127.0.0.1 lets other machines reach the page
    /// (still only with its token).
    #[arg(long, default_value = "127.0.0.1")]
    pub bind: IpAddr,
    /// The port (0: any free one).
    #[arg(long, default_value_t = 8750)]
    pub port: u16,
    /// The largest upload taken, MB.
    #[arg(long, value_name = "MB", default_value_t = DEFAULT_MAX_UPLOAD >> 20)]
    pub max_upload: u64,
    /// Analyses run at once (the rest wait); by default one per core.
    #[arg(long)]
    pub workers: Option<usize>,
    /// Open the page in the desktop's browser.
    #[arg(long)]
    pub open: bool,
}

/// Runs `eenf serve`: prints the page's URL (with its token) as its first line, then serves
/// until Ctrl-C.
pub fn run(a: Args) -> Result<()> {
    let mut opts = ServeOptions {
        stores: a.stores,
        bind: a.bind,
        port: a.port,
        max_upload: a.max_upload.saturating_mul(1 << 20),
        ..ServeOptions::default()
    };
    if let Some(w) = a.workers {
        opts.workers = w.max(1);
    }
    let open = a.open;
    serve(opts, |server| {
        outln!("{}", server.url());
        if !server.addr().ip().is_loopback() {
            eprintln!(
                "warning: listening on {}: other machines can reach the page, with its token",
                server.addr()
            );
        }
        eprintln!("serving the page; Ctrl-C stops it");
        if open {
            if let Err(e) = std::process::Command::new("xdg-open")
                .arg(server.url())
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::null())
                .spawn()
            {
                eprintln!("warning: cannot open a browser (xdg-open: {e}); open the URL above");
            }
        }
    })?;
    Ok(())
}
