//! `eenf refdb build|info`: the reference store.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use eenf::progress::Progress;
use eenf::refdb::{RefSeries, StoreLock, GAP};
use eenf::reference::{build_store, StoreBuild};
use eenf::time::{parse_time, tz_offset, utc};

/// `eenf refdb` subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum Cmd {
    /// Add mains WAVs (named like 2022_08_17_Wed_16_00_00.wav) or trace CSVs to a store
    /// (created when missing). One series per grid; new values replace old, gaps stay gaps.
    Build(BuildArgs),
    /// Show what a store covers.
    Info {
        /// The store (a folder).
        store: PathBuf,
    },
}

/// Arguments of `eenf refdb build`.
#[derive(Debug, clap::Args)]
pub struct BuildArgs {
    /// The store (a folder).
    pub store: PathBuf,
    /// Inputs: hourly mains WAVs (or folders of them), or trace CSVs (`time_s,enf_hz`, or
    /// `index,freq_hz` with --step). A CSV may carry its start as `FILE@2022-08-01T00:00:00Z`; otherwise the first
    /// takes --start and each next one continues where the previous ended.
    #[arg(required = true)]
    pub inputs: Vec<String>,
    /// Grid name (default: `grid50` or `grid60` from the data).
    #[arg(long)]
    pub grid: Option<String>,
    /// Zone of the local times in WAV names, as a UTC offset (+08:00, Z). Names in local time
    /// need it: none is assumed.
    #[arg(long, allow_hyphen_values = true)]
    pub tz: Option<String>,
    /// Start time of the first trace CSV (UTC, or with an offset).
    #[arg(long)]
    pub start: Option<String>,
    /// Fail at once when another build is changing the store, instead of waiting for it.
    #[arg(long)]
    pub no_wait: bool,
    /// Seconds between values of `index` CSVs.
    #[arg(long, value_parser = crate::args::number_in(0.001, 3600.0))]
    pub step: Option<f64>,
}

fn build(a: BuildArgs, progress: Progress) -> Result<()> {
    let build = StoreBuild {
        inputs: a.inputs.clone(),
        grid: a.grid.clone(),
        tz_s: a.tz.as_deref().map(tz_offset).transpose()?,
        start: a.start.as_deref().map(parse_time).transpose()?,
        index_step_s: a.step,
        wait: !a.no_wait,
    };
    let built = build_store(&a.store, &build, &progress, || {
        eprintln!(
            "{}: another build is changing this store; waiting for it",
            a.store.display()
        )
    })?;
    for g in &built {
        eprintln!(
            "{}: grid {} now holds {} values",
            a.store.display(),
            g.grid,
            g.values
        );
    }
    info(&a.store)
}

fn info(store: &Path) -> Result<()> {
    let grids = RefSeries::grids(store)?;
    if grids.is_empty() {
        bail!("{}: no reference series here", store.display());
    }
    let _lock = StoreLock::shared(store)?;
    for g in grids {
        let s = RefSeries::load(store, &g)?;
        let m = &s.meta;
        let gaps = s.values.iter().filter(|&&v| v == GAP).count();
        let runs = s
            .values
            .windows(2)
            .filter(|w| w[0] != GAP && w[1] == GAP)
            .count()
            + usize::from(s.values.first() == Some(&GAP));
        let end = m.start_unix_s + (s.values.len().max(1) - 1) as f64 * m.step_s;
        outln!("grid        {}", m.grid);
        outln!("nominal     {} Hz", m.nominal_hz);
        outln!("step        {} s", m.step_s);
        outln!("from        {}", utc(m.start_unix_s));
        outln!("to          {}", utc(end));
        outln!(
            "values      {} ({:.1} % covered, {} gaps in {} runs)",
            s.values.len(),
            100.0 * (s.values.len() - gaps) as f64 / s.values.len().max(1) as f64,
            gaps,
            runs
        );
        outln!("size        {:.1} MB", s.values.len() as f64 * 4.0 / 1e6);
        outln!(
            "checksum    {}",
            match m.values_crc32 {
                Some(c) => format!("CRC-32 {c:08x}, verified"),
                None => "none (a store written before checksums; build it again to add one)".into(),
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
        Cmd::Info { store } => info(&store),
    }
}
