//! `eenf refdb build|info`: the reference store.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use eenf::progress::Progress;
use eenf::refdb::{GridValues, StoreLock, StoredGrid};
use eenf::reference::build_store;
use eenf::time::{utc, Zone};

use crate::args::StoreInputArgs;

/// `eenf refdb` subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum Cmd {
    /// Add grid archives (operators' and measurement sites' frequency CSVs, plain or in zip,
    /// 7z or gzip files), mains WAVs (named like 2022_08_17_Wed_16_00_00.wav) or trace CSVs to
    /// a store (created when missing). One series per grid; new values replace old, gaps stay
    /// gaps.
    Build(BuildArgs),
    /// Show what a store covers, in UTC and in the zone asked for.
    Info {
        /// The store (a folder).
        store: PathBuf,
        /// Also show times in this zone (IANA name such as Europe/Berlin, or +08:00).
        #[arg(long, allow_hyphen_values = true)]
        tz: Option<Zone>,
    },
}

/// Arguments of `eenf refdb build`.
#[derive(Debug, clap::Args)]
pub struct BuildArgs {
    /// The store (a folder).
    pub store: PathBuf,
    /// Inputs: grid archives (timestamped frequency CSVs: ESO, Fingrid, TransnetBW, OSF,
    /// measurement sites; plain, zip, 7z or gzip), hourly mains WAVs (or folders of them), or
    /// trace CSVs (`time_s,enf_hz`, or `index,value` with --index-step). A trace CSV may carry
    /// its start as `FILE@2022-08-01T00:00:00Z`; otherwise the first takes --start and each next
    /// one continues where the previous ended.
    #[arg(required = true)]
    pub inputs: Vec<String>,
    /// How the inputs are read and where they go.
    #[command(flatten)]
    pub how: StoreInputArgs,
}

fn build(a: BuildArgs, progress: Progress) -> Result<()> {
    let build = a.how.build(a.inputs.clone())?;
    let built = build_store(&a.store, &build, &progress, || {
        eprintln!(
            "{}: another build is changing this store; waiting for it",
            a.store.display()
        )
    })?;
    for (path, report) in &built.archives {
        eprintln!("{}: {report}", path.display());
        for w in &report.warnings {
            eprintln!("warning: {w}");
        }
    }
    for g in &built.grids {
        eprintln!(
            "{}: grid {} now holds {} values",
            a.store.display(),
            g.grid,
            g.values
        );
    }
    info(&a.store, a.how.tz.as_ref())
}

fn info(store: &Path, zone: Option<&Zone>) -> Result<()> {
    let grids = StoredGrid::grids(store)?;
    if grids.is_empty() {
        bail!("{}: no reference series here", store.display());
    }
    let _lock = StoreLock::shared(store)?;
    for g in grids {
        let values = GridValues::open(store, &g)?;
        let s = values.check()?;
        let m = &values.meta;
        let end = m.start_unix_s + (s.values.max(1) - 1) as f64 * m.step_s;
        outln!("grid        {}", m.grid);
        outln!("nominal     {} Hz", m.nominal_hz);
        outln!("step        {} s", m.step_s);
        let when = |t: f64| match zone {
            Some(z) if z.name() != "UTC" => format!("{}  ({})", utc(t), z.local(t)),
            _ => utc(t),
        };
        outln!("from        {}", when(m.start_unix_s));
        outln!("to          {}", when(end));
        outln!(
            "values      {} ({:.1} % covered, {} gaps in {} runs)",
            s.values,
            100.0 * (s.values - s.gaps) as f64 / s.values.max(1) as f64,
            s.gaps,
            s.gap_runs
        );
        outln!(
            "size        {:.1} MB in {} part{}",
            s.bytes as f64 / 1e6,
            s.parts,
            if s.parts == 1 { "" } else { "s" }
        );
        outln!(
            "checksum    {}",
            if s.checksummed == s.parts {
                "CRC-32 of each part, verified".to_string()
            } else {
                format!(
                    "{} of {} parts without one (written before checksums; build it again to add them)",
                    s.parts - s.checksummed,
                    s.parts
                )
            }
        );
        outln!();
    }
    Ok(())
}

/// Runs `eenf refdb`.
pub fn run(cmd: Cmd, progress: Progress) -> Result<()> {
    match cmd {
        Cmd::Build(a) => build(a, progress),
        Cmd::Info { store, tz } => info(&store, tz.as_ref()),
    }
}
