//! `eenf refdb build|info`: the reference store.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use eenf::progress::Progress;
use eenf::refdb::{check_grid_name, RefSeries, StoreLock, GAP};
use eenf::reference::{reference_file, wav_start};
use eenf::time::{parse_time, tz_offset, utc};
use eenf::trace::Trace;
use eenf::wav::is_wav;
use eenf_core::Nominal;
use eenf_dsp::EnfParams;

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
    /// Inputs: hourly mains WAVs, or trace CSVs (`time_s,enf_hz`, or `index,freq_hz` with
    /// --step). A CSV may carry its start as `FILE@2022-08-01T00:00:00Z`; otherwise the first
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
    let tz = a.tz.as_deref().map(tz_offset).transpose()?;
    if let Some(g) = &a.grid {
        check_grid_name(g)?;
    }
    // the whole read-merge-write under the store's lock: a second build waits for this one
    let _lock = StoreLock::exclusive(&a.store, !a.no_wait, || {
        eprintln!(
            "{}: another build is changing this store; waiting for it",
            a.store.display()
        )
    })?;
    let bar = progress.steps(a.inputs.len() as u64, "adding references");
    let mut series: Vec<RefSeries> = Vec::new();
    let mut next_start = a.start.as_deref().map(parse_time).transpose()?;
    for input in &a.inputs {
        let (path, at) = match input.rsplit_once('@') {
            Some((p, t)) if !Path::new(input).exists() => (PathBuf::from(p), Some(parse_time(t)?)),
            _ => (PathBuf::from(input), None),
        };
        let (start, trace) = if is_wav(&path) {
            let trace = reference_file(&path, Nominal::Auto, &EnfParams::default())?;
            (at.unwrap_or(wav_start(&path, tz)?), trace)
        } else {
            let trace = read_series(&path, a.step)?;
            let start = at.or(next_start).with_context(|| {
                format!(
                    "{}: give its start as FILE@TIME or with --start",
                    path.display()
                )
            })?;
            (start, trace)
        };
        let (step, values) = (trace.step_s, &trace.enf_hz);
        next_start = Some(start + values.len() as f64 * step);
        let f0 = nominal_of(&trace, &path)?;
        let grid = a
            .grid
            .clone()
            .unwrap_or_else(|| format!("grid{}", f0 as u32));
        let idx = match series.iter().position(|s| s.meta.grid == grid) {
            Some(i) => i,
            None => {
                let s = if a.store.join(format!("{grid}.json")).exists() {
                    RefSeries::load(&a.store, &grid)?
                } else {
                    RefSeries::new(&grid, f0, step, start)
                };
                series.push(s);
                series.len() - 1
            }
        };
        let s = &mut series[idx];
        if s.meta.nominal_hz != f0 {
            bail!(
                "{}: a {f0} Hz trace cannot go into grid {grid:?}, which is {} Hz (50 and 60 Hz are never mixed)",
                path.display(),
                s.meta.nominal_hz
            );
        }
        s.merge(start, step, values)?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    for s in &mut series {
        s.save(&a.store)?;
        RefSeries::remove_orphans(&a.store, &s.meta.grid)?;
        eprintln!(
            "{}: grid {} now holds {} values",
            a.store.display(),
            s.meta.grid,
            s.values.len()
        );
    }
    drop(_lock);
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

/// A trace CSV (`time_s,enf_hz`) or, with `step`, an `index,value` CSV.
fn read_series(path: &Path, step: Option<f64>) -> Result<Trace> {
    let text = eenf::trace::read_text(path)?;
    let header = text.lines().next().unwrap_or("").to_ascii_lowercase();
    if step.is_none() && !header.contains("time_s") {
        bail!("{}: an index CSV needs --step", path.display());
    }
    Trace::parse(&text, path, step)
}

/// The grid of a trace's values, 50 or 60 Hz.
fn nominal_of(trace: &Trace, path: &Path) -> Result<f64> {
    if trace.finite().next().is_none() {
        bail!("{}: no values", path.display());
    }
    trace.grid_hz().with_context(|| {
        format!(
            "{}: mean {:.3} Hz is neither a 50 nor a 60 Hz grid",
            path.display(),
            trace.mean_hz()
        )
    })
}

/// Runs `eenf refdb`.
pub fn run(cmd: Cmd, progress: Progress) -> Result<()> {
    match cmd {
        Cmd::Build(a) => build(a, progress),
        Cmd::Info { store } => info(&store),
    }
}
