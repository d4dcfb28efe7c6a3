//! `eenf refdb build|info`: the reference store.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use eenf::archive::{ArchiveFormat, ArchiveOptions, DateOrder, ValueUnit};
use eenf::progress::Progress;
use eenf::refdb::{RefSeries, StoreLock, GAP};
use eenf::reference::{build_store, StoreBuild};
use eenf::time::{parse_time, utc, Zone};

use crate::args::one_of;

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
    /// Grid name (default: `grid50` or `grid60` from the data).
    #[arg(long)]
    pub grid: Option<String>,
    /// Zone of local times (in WAV names and in archives whose times carry none): an IANA
    /// name (Europe/Berlin, America/New_York; summer time followed) or a UTC offset (+08:00,
    /// Z). Local times need it: none is assumed.
    #[arg(long, allow_hyphen_values = true)]
    pub tz: Option<Zone>,
    /// Layout of grid archives: auto (sniffed from the header and first rows), ngeso (UK,
    /// `dtm,f`, UTC), fingrid (Finland, `Time,Value`, 0.1 s), transnetbw (Germany,
    /// `DD.MM.YYYY HH:MM:SS`), osf (`year;month;day;hour;minute;second;value`, UTC).
    #[arg(long, default_value = "auto", value_parser = one_of::<ArchiveFormat>(&ArchiveFormat::NAMES))]
    pub format: ArchiveFormat,
    /// What an archive's value column holds: auto (Hz when near 50 or 60; a deviation when
    /// the header says so), hz, mhz-deviation or hz-deviation.
    #[arg(long, default_value = "auto", value_parser = one_of::<ValueUnit>(&ValueUnit::NAMES))]
    pub value_unit: ValueUnit,
    /// The order of day and month in an archive's dates like 05/06/2022: auto, dmy or mdy.
    #[arg(long, default_value = "auto", value_parser = one_of::<DateOrder>(&DateOrder::NAMES))]
    pub date_order: DateOrder,
    /// Nominal grid frequency of archives that give deviations: 50 or 60.
    #[arg(long, value_parser = crate::args::number_in(40.0, 70.0))]
    pub nominal: Option<f64>,
    /// Start time of the first trace CSV (UTC, or with an offset).
    #[arg(long)]
    pub start: Option<String>,
    /// Fail at once when another build is changing the store, instead of waiting for it.
    #[arg(long)]
    pub no_wait: bool,
    /// Seconds between values of `index,value` CSVs.
    #[arg(long, alias = "step", value_parser = crate::args::number_in(0.001, 3600.0))]
    pub index_step: Option<f64>,
}

/// What `refdb build` is asked to do, as the library takes it.
pub fn store_build(a: &BuildArgs) -> Result<StoreBuild> {
    Ok(StoreBuild {
        inputs: a.inputs.clone(),
        grid: a.grid.clone(),
        zone: a.tz.clone(),
        archive: ArchiveOptions {
            format: a.format,
            zone: None,
            unit: a.value_unit,
            date_order: a.date_order,
            nominal_hz: a.nominal,
        },
        start: a.start.as_deref().map(parse_time).transpose()?,
        index_step_s: a.index_step,
        wait: !a.no_wait,
    })
}

fn build(a: BuildArgs, progress: Progress) -> Result<()> {
    let build = store_build(&a)?;
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
    info(&a.store, a.tz.as_ref())
}

fn info(store: &Path, zone: Option<&Zone>) -> Result<()> {
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
        let when = |t: f64| match zone {
            Some(z) => format!("{}  ({})", utc(t), z.local(t)),
            None => utc(t),
        };
        outln!("from        {}", when(m.start_unix_s));
        outln!("to          {}", when(end));
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
        Cmd::Info { store, tz } => info(&store, tz.as_ref()),
    }
}
