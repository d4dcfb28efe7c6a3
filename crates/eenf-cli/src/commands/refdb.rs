//! `eenf refdb build|fetch|update|info`: the reference store.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use eenf::fetch::{self, Source};
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
    /// Fetch a span of a grid operator's frequency data into a store (created when missing):
    /// gb (National Grid ESO / NESO, monthly files, 1 s, UTC), se (Svenska kraftnät's control
    /// room, an hour per request, UTC), ch (Swissgrid, its last minutes only), osf (a file of
    /// the OSF/WETI database, at the address given with --endpoint), fi (Fingrid's open data
    /// API, a free key). Downloads are kept in a
    /// cache and resumed when cut; the store changes only when all are in.
    Fetch(FetchArgs),
    /// Bring every fetched grid of a store up to now, from the sources its manifest records.
    Update(UpdateArgs),
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

/// Arguments of `eenf refdb fetch`.
#[derive(Debug, clap::Args)]
pub struct FetchArgs {
    /// The source: gb, se, ch, osf or fi.
    #[arg(value_parser = source_name)]
    pub source: Source,
    /// Start: a day (2024-06-01, from its start in UTC) or a time with its zone.
    #[arg(long)]
    pub from: String,
    /// End: a day (2024-06-30, to its end in UTC) or a time with its zone (default: now).
    #[arg(long)]
    pub to: Option<String>,
    /// The store (a folder; created when missing).
    #[arg(long, default_value = "references")]
    pub store: PathBuf,
    /// Ask this address instead of the operator's (a mirror; its files must be in the
    /// operator's format).
    #[arg(long)]
    pub endpoint: Option<String>,
    /// The grid's name in the store (default: the source's: gb, se, ch, ce, fi).
    #[arg(long)]
    pub grid: Option<String>,
    #[command(flatten)]
    pub download: DownloadArgs,
}

/// Arguments of `eenf refdb update`.
#[derive(Debug, clap::Args)]
pub struct UpdateArgs {
    /// The store (a folder).
    pub store: PathBuf,
    #[command(flatten)]
    pub download: DownloadArgs,
}

/// How downloads are made.
#[derive(Debug, clap::Args)]
pub struct DownloadArgs {
    /// Where downloads are kept and resumed from (default: ~/.cache/eenf/fetch).
    #[arg(long)]
    pub cache: Option<PathBuf>,
    /// Retries after a failure that may pass (no connection, a cut, a server error, 429).
    #[arg(long, default_value_t = 3)]
    pub retries: u32,
    /// Fail at once when another build is changing the store, instead of waiting for it.
    #[arg(long)]
    pub no_wait: bool,
    /// The API key of a source that needs one (fi: Fingrid's, free from data.fingrid.fi; else
    /// the environment variable FINGRID_API_KEY). It is sent, never stored.
    #[arg(long)]
    pub api_key: Option<String>,
}

impl DownloadArgs {
    fn cache(&self) -> PathBuf {
        self.cache.clone().unwrap_or_else(fetch::default_cache)
    }
}

fn source_name(s: &str) -> Result<Source, String> {
    Source::parse(s).map_err(|e| e.to_string())
}

fn report_fetch(f: &fetch::Fetched, store: &Path) {
    for p in &f.files {
        eprintln!(
            "{}: {} {}",
            f.source.name(),
            if p.cached {
                "in the cache:"
            } else {
                "downloaded"
            },
            p.url
        );
    }
    for n in &f.notes {
        eprintln!("note: {n}");
    }
    report_built(&f.built, store);
}

fn report_built(built: &eenf::reference::StoreBuilt, store: &Path) {
    for (path, report) in &built.archives {
        eprintln!("{}: {report}", path.display());
        for w in &report.warnings {
            eprintln!("warning: {w}");
        }
    }
    for g in &built.grids {
        eprintln!(
            "{}: grid {} now holds {} values",
            store.display(),
            g.grid,
            g.values
        );
    }
}

fn fetch_into(a: FetchArgs, progress: Progress) -> Result<()> {
    let req = fetch::FetchRequest {
        source: a.source,
        from_unix_s: fetch::parse_day_or_time(&a.from, false)?,
        to_unix_s: match &a.to {
            Some(t) => fetch::parse_day_or_time(t, true)?,
            None => f64::INFINITY,
        },
        store: a.store.clone(),
        cache: a.download.cache(),
        endpoint: a.endpoint.clone(),
        grid: a.grid.clone(),
        retries: a.download.retries,
        wait: !a.download.no_wait,
        api_key: a.download.api_key.clone(),
    };
    let fetched = fetch::fetch(&req, &progress)?;
    report_fetch(&fetched, &a.store);
    info(&a.store, None)
}

fn update(a: UpdateArgs, progress: Progress) -> Result<()> {
    let done = fetch::update(
        &a.store,
        &a.download.cache(),
        a.download.retries,
        !a.download.no_wait,
        a.download.api_key.as_deref(),
        &progress,
    )?;
    if done.is_empty() {
        eprintln!("{}: every fetched grid is up to date", a.store.display());
    }
    for f in &done {
        report_fetch(f, &a.store);
    }
    info(&a.store, None)
}

fn build(a: BuildArgs, progress: Progress) -> Result<()> {
    let build = a.how.build(a.inputs.clone())?;
    let built = build_store(&a.store, &build, &progress, || {
        eprintln!(
            "{}: another build is changing this store; waiting for it",
            a.store.display()
        )
    })?;
    report_built(&built, &a.store);
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
        for f in &m.fetched {
            let described = Source::from_name(&f.source)
                .map(|s| s.describe())
                .unwrap_or("an unknown source");
            outln!("fetched     {} from {} ({described})", f.source, f.endpoint);
            let last = f.files.iter().map(|x| x.retrieved_utc.as_str()).max();
            outln!(
                "            {} file{}, {:.1} MB, last retrieved {}",
                f.files.len(),
                if f.files.len() == 1 { "" } else { "s" },
                f.files.iter().map(|x| x.bytes).sum::<u64>() as f64 / 1e6,
                last.unwrap_or("-")
            );
            // the latest few; every one is in the manifest
            let shown = f.files.len().saturating_sub(12);
            if shown > 0 {
                outln!(
                    "            ({shown} earlier files listed in {}.json)",
                    m.grid
                );
            }
            for x in &f.files[shown..] {
                outln!(
                    "            {}  sha256 {}  {} bytes  {}",
                    x.retrieved_utc,
                    x.sha256,
                    x.bytes,
                    x.url
                );
            }
        }
        outln!();
    }
    Ok(())
}

/// Runs `eenf refdb`.
pub fn run(cmd: Cmd, progress: Progress) -> Result<()> {
    match cmd {
        Cmd::Build(a) => build(a, progress),
        Cmd::Fetch(a) => fetch_into(a, progress),
        Cmd::Update(a) => update(a, progress),
        Cmd::Info { store, tz } => info(&store, tz.as_ref()),
    }
}
