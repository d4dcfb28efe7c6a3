//! References: where a reference comes from ([`ReferenceSource`]: a store, a folder of hourly
//! mains WAVs, one WAV, a trace file), the reference of one recording from a dataset's hourly
//! WAVs, and the long series that `match` searches.

use eenf_core::spelling::{option, option_with};
use std::path::{Path, PathBuf};

use crate::error::{fail, Error, Missing, Result};
use eenf_dsp::matching::{match_trace, MatchError, MatchOptions, MatchResult, ReferenceValues};
use eenf_dsp::{reference_enf, EnfParams};

use crate::archive::{ArchiveImport, ArchiveOptions};
use crate::audio::read_wav;
use crate::dataset::hourly_references;
use crate::mains::{mains_nominal, reference_file};
use crate::progress::Progress;
use crate::refdb::{check_grid_name, GridEdit, GridValues, StoreLock, StoredGrid};
use crate::time::{LocalInstant, LocalTime, Zone};
use crate::trace::Trace;
use crate::wav::is_wav;
use eenf_core::{Grid, Nominal};

/// Where a reference comes from, told from what is at its path: the one place that decides.
/// `compare` takes a window of it, `match` searches it, `refdb build` adds it to a store.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReferenceSource {
    /// A store from `refdb build`: one long series per grid.
    Store(PathBuf),
    /// A folder of hourly mains WAVs named by their local start (`2022_08_17_Wed_16_00_00.wav`).
    HourlyFolder(PathBuf),
    /// One mains WAV.
    Wav(PathBuf),
    /// A grid operator's or measurement site's frequency archive: timestamped CSVs, plain or
    /// in a zip, 7z or gzip file ([`crate::archive`]).
    Archive(PathBuf),
    /// A trace file: eenf CSV or JSON, or an `index,value` CSV.
    Trace(PathBuf),
}

impl ReferenceSource {
    /// What `path` holds: a folder with grid manifests is a store, any other folder a folder of
    /// hourly WAVs, a RIFF/WAVE file a WAV, a table of dates and frequencies (or a zip, 7z or
    /// gzip file) an archive, anything else a trace file.
    pub fn open(path: &Path) -> Result<Self> {
        let p = path.to_path_buf();
        Ok(if path.is_dir() {
            if StoredGrid::grids(path)?.is_empty() {
                ReferenceSource::HourlyFolder(p)
            } else {
                ReferenceSource::Store(p)
            }
        } else if is_wav(path) {
            ReferenceSource::Wav(p)
        } else if crate::archive::is_archive(path) {
            ReferenceSource::Archive(p)
        } else {
            ReferenceSource::Trace(p)
        })
    }

    /// Its path.
    pub fn path(&self) -> &Path {
        match self {
            ReferenceSource::Store(p)
            | ReferenceSource::HourlyFolder(p)
            | ReferenceSource::Wav(p)
            | ReferenceSource::Archive(p)
            | ReferenceSource::Trace(p) => p,
        }
    }
}

/// The reference trace for a recording that starts at `start` (local time from its name) and
/// lasts `seconds` estimates, from a folder of hourly WAVs. Windows near the recording's ends
/// see the mains before and after it, continuing into the next hour's file when needed.
pub fn reference_for_recording(
    dir: &Path,
    start: LocalTime,
    seconds: usize,
    nominal: Nominal,
    params: &EnfParams,
) -> Result<Trace> {
    let files = hourly_references(dir)?;
    let first = start.hour_index();
    let Some(pos) = files.iter().position(|(t, _)| t.hour_index() == first) else {
        fail!(
            Reference,
            "{}: no reference for {} hour {:02} (expected a file like {}_Day_{:02}_00_00.wav)",
            dir.display(),
            start.date(),
            start.hour(),
            start.date(),
            start.hour()
        );
    };
    let margin = (params.window_s / 2.0).ceil() as usize + 2;
    let from = start.second_of_hour() as usize;
    let need_until = from + seconds + margin;
    let mut samples = Vec::new();
    let mut fs = 0.0;
    let mut f0 = None;
    for (k, (t, path)) in files[pos..].iter().enumerate() {
        if t.hour_index() != first + k as i64 {
            break;
        }
        let sig = read_wav(path)?;
        if k == 0 {
            fs = sig.fs;
            f0 = Some(mains_nominal(&sig, nominal, path)?);
        } else if sig.fs != fs {
            fail!(
                Reference,
                "{}: sample rate {} Hz differs from the previous hour's {fs} Hz",
                path.display(),
                sig.fs
            );
        }
        samples.extend_from_slice(&sig.samples);
        if samples.len() as f64 / fs >= need_until as f64 {
            break;
        }
    }
    let f0 = f0.or_fail(Error::Reference, || "no reference loaded")?;
    let have_s = samples.len() as f64 / fs;
    if (from + seconds) as f64 > have_s + 1.0 {
        fail!(Reference,
            "{}: the references cover {:.0} s from {}_{:02}:00:00; the recording needs {} s from second {from}",
            dir.display(),
            have_s,
            start.date(),
            start.hour(),
            seconds
        );
    }
    // track a slice starting on a whole second so frames fall on the hour's seconds
    let a = from.saturating_sub(margin);
    let b = ((need_until as f64 * fs) as usize).min(samples.len());
    let p = EnfParams {
        nominal_hz: f0.hz(),
        ..params.clone()
    };
    let slice = &samples[(a as f64 * fs) as usize..b];
    let trace = reference_enf(slice, fs, &p).map_err(|e| Error::from(e).context(dir.display()))?;
    let off = from - a;
    let out: Vec<f64> = (0..seconds)
        .map(|i| trace.get(off + i).copied().unwrap_or(f64::NAN))
        .collect();
    Ok(Trace::from_mains(dir, f0, &p, out))
}

/// Unix time of an hourly reference's name read as local time in `zone`. The names carry no
/// zone, so none is assumed: without one it is an error that says how to give it. An hour the
/// clocks passed twice is read as its first passage (the name cannot tell), an hour they
/// skipped is refused.
pub fn wav_start(path: &Path, zone: Option<&Zone>) -> Result<f64> {
    let t = crate::dataset::reference_hour(path).or_fail(Error::Input, || {
        format!(
            "{}: the name gives no start time (expected 2022_08_17_Wed_16_00_00.wav)",
            path.display()
        )
    })?;
    let Some(zone) = zone else {
        fail!(
            Reference,
            "{}: its name gives a local time ({}-{:02}-{:02} {:02}:00) but not its zone: give the \
             zone with {} (e.g. {} or +08:00 where it was recorded in China, {} for UTC)",
            path.display(),
            t.year(),
            t.month(),
            t.day(),
            t.hour(),
            option("tz"),
            option_with("tz", "Asia/Shanghai"),
            option_with("tz", "Z")
        );
    };
    match zone.instant(t.local_seconds()) {
        LocalInstant::Unique(u) | LocalInstant::Repeated(u, _) => Ok(u),
        LocalInstant::Missing => fail!(
            Reference,
            "{}: {}-{:02}-{:02} {:02}:00 does not exist in {} (the clocks skipped that hour)",
            path.display(),
            t.year(),
            t.month(),
            t.day(),
            t.hour(),
            zone.name()
        ),
    }
}

/// A long reference series that `match` searches: a store's grid, a folder of hourly WAVs, one
/// WAV, or a trace.
pub struct ReferenceSeries {
    /// Its name in results: the grid's, for a store's series; else the file's.
    pub name: String,
    /// The store's grid it is, when it is one.
    pub grid: Option<String>,
    /// Time of the first value: Unix seconds when `absolute`, else seconds of the trace.
    pub start: f64,
    /// Whether `start` is an absolute time.
    pub absolute: bool,
    /// The zone its times are also shown in, when one was given.
    pub zone: Option<Zone>,
    /// Seconds between values.
    pub step: f64,
    /// The values.
    pub values: SeriesValues,
    /// What reading it noted (an archive's layout, zone and dropped rows).
    pub notes: Vec<String>,
}

/// Reference values: in Hz in memory, or a store's grid read from its files where needed.
pub enum SeriesValues {
    /// Frequencies, Hz (NaN = gap).
    Hz(Vec<f64>),
    /// A store's grid, checked (checksums and sums) as it is read.
    Stored(Box<GridValues>),
}

impl SeriesValues {
    /// Number of values.
    pub fn len(&self) -> usize {
        match self {
            SeriesValues::Hz(v) => v.len(),
            SeriesValues::Stored(g) => g.meta.count,
        }
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Values `start .. start + n` in Hz (NaN = gap), as far as the series goes.
    pub fn window(&self, start: usize, n: usize) -> Result<Vec<f64>> {
        match self {
            SeriesValues::Hz(v) => v[..].window(start, n),
            SeriesValues::Stored(g) => g.window(start, n),
        }
        .map_err(Error::from)
    }

    /// Where `q` (at this series' step) fits.
    pub fn search(&self, q: &[f64], opts: &MatchOptions) -> Result<MatchResult, MatchError> {
        match self {
            SeriesValues::Hz(v) => match_trace(q, &v[..], opts),
            SeriesValues::Stored(g) => match_trace(q, &**g, opts),
        }
    }
}

impl ReferenceSeries {
    /// The time of value `offset` (fractional steps allowed): UTC, or seconds of a trace.
    pub fn time_label(&self, offset: f64) -> String {
        let t = self.start + offset * self.step;
        if self.absolute {
            match &self.zone {
                Some(z) if z.name() != "UTC" => {
                    format!("{} ({})", crate::time::utc(t), z.local(t))
                }
                _ => crate::time::utc(t),
            }
        } else {
            format!("{t:.1} s")
        }
    }

    /// The series of `grid` at `path`: a store (its grids of that frequency), a folder of
    /// hourly WAVs (traced, local names in `zone`), a WAV, a grid archive (local times in
    /// `zone`), or a trace file.
    pub fn load(
        path: &Path,
        grid: Grid,
        zone: Option<&Zone>,
        progress: &Progress,
    ) -> Result<Vec<Self>> {
        let nominal = grid.hz();
        let source = ReferenceSource::open(path)?;
        if matches!(
            source,
            ReferenceSource::Store(_) | ReferenceSource::HourlyFolder(_)
        ) {
            let grids = StoredGrid::grids(path)?;
            if let ReferenceSource::Store(_) = source {
                let _lock = StoreLock::shared(path)?;
                let mut out = Vec::new();
                for g in grids {
                    let meta = StoredGrid::load_meta(path, &g)?;
                    if meta.nominal_hz != nominal {
                        continue; // 50 and 60 Hz are never mixed
                    }
                    let values = GridValues::open_for_search(path, &g)?;
                    out.push(ReferenceSeries {
                        name: g.clone(),
                        grid: Some(g),
                        start: meta.start_unix_s,
                        absolute: true,
                        zone: zone.cloned(),
                        step: meta.step_s,
                        values: SeriesValues::Stored(Box::new(values)),
                        notes: Vec::new(),
                    });
                }
                if out.is_empty() {
                    fail!(
                        Reference,
                        "{}: the store holds no {nominal} Hz grid",
                        path.display()
                    );
                }
                return Ok(out);
            }
            // a folder of hourly WAVs, assembled in memory
            let files = hourly_references(path)?;
            let bar = progress.steps(files.len() as u64, "tracking the references");
            let mut series = StoredGrid::new("folder", grid, 1.0, 0.0);
            for (_, f) in &files {
                let trace = reference_file(f, Nominal::Auto, &EnfParams::default())?;
                if trace.nominal_hz == Some(nominal) {
                    series.merge(wav_start(f, zone)?, 1.0, &trace.enf_hz)?;
                }
                bar.inc(1);
            }
            bar.finish_and_clear();
            if series.values.is_empty() {
                fail!(Reference, "{}: no {nominal} Hz references", path.display());
            }
            return Ok(vec![ReferenceSeries {
                name: path.display().to_string(),
                grid: None,
                start: series.meta.start_unix_s,
                absolute: true,
                zone: zone.cloned(),
                step: 1.0,
                values: SeriesValues::Hz(series.hz()),
                notes: Vec::new(),
            }]);
        }
        if let ReferenceSource::Archive(_) = source {
            let opts = ArchiveOptions {
                zone: zone.cloned(),
                grid: Some(grid),
                ..ArchiveOptions::default()
            };
            let imp = crate::archive::import(path, &opts, None)?;
            let mut notes = vec![format!("{}: {}", path.display(), imp.report)];
            notes.extend(imp.report.warnings.iter().cloned());
            // pieces far apart are stored apart; the notes go with the first
            return Ok(imp
                .steps
                .into_iter()
                .enumerate()
                .map(|(i, piece)| ReferenceSeries {
                    notes: if i == 0 { notes.clone() } else { Vec::new() },
                    name: path.display().to_string(),
                    grid: None,
                    start: piece.start,
                    absolute: true,
                    zone: zone.cloned(),
                    step: piece.step,
                    values: SeriesValues::Hz(piece.values),
                })
                .collect());
        }
        let (start, absolute, step, hz) = if let ReferenceSource::Wav(_) = source {
            let trace = reference_file(path, Nominal::Grid(grid), &EnfParams::default())?;
            if crate::dataset::reference_hour(path).is_some() {
                (wav_start(path, zone)?, true, 1.0, trace.enf_hz)
            } else {
                (0.0, false, 1.0, trace.enf_hz)
            }
        } else {
            let t = Trace::read(path, None)?;
            (
                t.time_s.first().copied().unwrap_or(0.0),
                false,
                t.step_s,
                t.enf_hz,
            )
        };
        Ok(vec![ReferenceSeries {
            name: path.display().to_string(),
            grid: None,
            start,
            absolute,
            zone: zone.cloned(),
            step,
            values: SeriesValues::Hz(hz),
            notes: Vec::new(),
        }])
    }
}

/// What `refdb build` adds to a store, and how.
#[derive(Debug, Clone)]
pub struct StoreBuild {
    /// Inputs: hourly mains WAVs, folders of them, or trace CSVs; a CSV may carry its start as
    /// `FILE@2022-08-01T00:00:00Z`.
    pub inputs: Vec<String>,
    /// Grid name (default: `grid50` or `grid60` from the data).
    pub grid: Option<String>,
    /// Zone of the local times in WAV names and in archives that carry none.
    pub zone: Option<Zone>,
    /// How grid archives are read (their zone is `zone`).
    pub archive: ArchiveOptions,
    /// Start of the first trace CSV without its own, Unix seconds; each next one continues
    /// where the previous ended.
    pub start: Option<f64>,
    /// Seconds between the values of `index,value` CSVs.
    pub index_step_s: Option<f64>,
    /// Wait for another build that holds the store (else fail at once).
    pub wait: bool,
    /// Where the inputs were fetched from, recorded in the manifest of every grid they go
    /// into (`refdb fetch`).
    pub fetched: Option<crate::refdb::FetchedFrom>,
}

/// A grid a build changed: its name and how many values it now holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GridBuilt {
    /// The grid's name.
    pub grid: String,
    /// Values it holds after the build.
    pub values: usize,
}

/// What a build did: the grids it changed, and what it read from each archive.
#[derive(Debug, Clone)]
pub struct StoreBuilt {
    /// The grids changed.
    pub grids: Vec<GridBuilt>,
    /// Each archive read, with what was read and dropped.
    pub archives: Vec<(PathBuf, crate::archive::ImportReport)>,
}

/// Adds the references of `build` to the store at `store` (created when missing): one series
/// per grid, new values replace old, gaps stay gaps. The whole read-merge-write holds the
/// store's lock; `on_wait` is called when another build holds it and this one waits.
pub fn build_store(
    store: &Path,
    build: &StoreBuild,
    progress: &Progress,
    on_wait: impl FnOnce(),
) -> Result<StoreBuilt> {
    if let Some(g) = &build.grid {
        check_grid_name(g)?;
    }
    // each input as the files it stands for: a folder of hourly WAVs gives its hours in order
    // (file, its start when given as FILE@TIME, whether it is a grid archive)
    let mut files: Vec<(PathBuf, Option<f64>, bool)> = Vec::new();
    for input in &build.inputs {
        let (path, at) = match input.rsplit_once('@') {
            Some((p, t)) if !Path::new(input).exists() => {
                (PathBuf::from(p), Some(crate::time::parse_time(t)?))
            }
            _ => (PathBuf::from(input), None),
        };
        match ReferenceSource::open(&path)? {
            ReferenceSource::HourlyFolder(dir) => files.extend(
                hourly_references(&dir)?
                    .into_iter()
                    .map(|(_, f)| (f, None, false)),
            ),
            ReferenceSource::Store(dir) => fail!(
                Reference,
                "{}: a reference store; its series cannot be added to another store",
                dir.display()
            ),
            ReferenceSource::Archive(p) => files.push((p, at, at.is_none())),
            _ => files.push((path, at, false)),
        }
    }
    // the whole read-merge-write under the store's lock: a second build waits for this one
    let _lock = StoreLock::exclusive(store, build.wait, on_wait)?;
    let bar = progress.steps(files.len() as u64, "adding references");
    let mut series: Vec<GridEdit> = Vec::new();
    let mut next_start = build.start;
    let mut archives = Vec::new();
    for (path, at, archive) in &files {
        // an archive's pieces (far apart in time) are merged one by one
        let (pieces, f0) = if is_wav(path) {
            let trace = reference_file(path, Nominal::Auto, &EnfParams::default())?;
            let start = match at {
                Some(t) => *t,
                None => wav_start(path, build.zone.as_ref())?,
            };
            let f0 = nominal_of(&trace, path)?;
            (vec![(start, trace.step_s, trace.enf_hz)], f0)
        } else if *archive {
            let opts = ArchiveOptions {
                zone: build.zone.clone(),
                ..build.archive.clone()
            };
            let ArchiveImport {
                steps,
                grid,
                report,
            } = crate::archive::import(path, &opts, None)?;
            archives.push((path.clone(), report));
            let pieces = steps.into_iter().map(|p| (p.start, p.step, p.values));
            (pieces.collect(), grid)
        } else {
            let trace = read_series(path, build.index_step_s)?;
            let start = at.or(next_start).or_fail(Error::Input, || {
                format!(
                    "{}: give its start as FILE@TIME or with {}",
                    path.display(),
                    option("start")
                )
            })?;
            let f0 = nominal_of(&trace, path)?;
            (vec![(start, trace.step_s, trace.enf_hz)], f0)
        };
        let Some((first_start, step, _)) = pieces.first() else {
            continue;
        };
        let (start, step) = (*first_start, *step);
        if let Some((last_start, last_step, last)) = pieces.last() {
            next_start = Some(last_start + last.len() as f64 * last_step);
        }
        let grid = build.grid.clone().unwrap_or_else(|| format!("grid{f0}"));
        let idx = match series.iter().position(|s| s.meta.grid == grid) {
            Some(i) => i,
            None => {
                let s = if store.join(format!("{grid}.json")).exists() {
                    GridEdit::open(store, &grid)?
                } else {
                    GridEdit::new(store, &grid, f0, step, start)
                };
                series.push(s);
                series.len() - 1
            }
        };
        let s = &mut series[idx];
        if s.meta.nominal_hz != f0.hz() {
            fail!(Reference,
                "{}: a {f0} Hz trace cannot go into grid {grid:?}, which is {} Hz (50 and 60 Hz are never mixed)",
                path.display(),
                s.meta.nominal_hz
            );
        }
        for (start, step, values) in &pieces {
            s.merge(*start, *step, values)?;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    let mut built = Vec::new();
    for mut s in series {
        if let Some(from) = &build.fetched {
            s.meta.record_fetch(from);
        }
        let grid = s.meta.grid.clone();
        let values = s.commit()?;
        StoredGrid::remove_orphans(store, &grid)?;
        built.push(GridBuilt { grid, values });
    }
    Ok(StoreBuilt {
        grids: built,
        archives,
    })
}

/// A trace CSV (`time_s,enf_hz`) or, with `index_step_s`, an `index,value` CSV.
fn read_series(path: &Path, index_step_s: Option<f64>) -> Result<Trace> {
    let text = crate::trace::read_text(path)?;
    let header = text.lines().next().unwrap_or("").to_ascii_lowercase();
    if index_step_s.is_none() && !header.contains("time_s") {
        fail!(
            Reference,
            "{}: neither an eenf trace (time_s,enf_hz) nor a grid archive (dates or Unix times \
             and frequencies): an index,value CSV needs {} (seconds between values)",
            path.display(),
            option("index_step")
        );
    }
    Trace::parse(&text, path, index_step_s)
}

/// The grid of a trace's values, 50 or 60 Hz.
fn nominal_of(trace: &Trace, path: &Path) -> Result<Grid> {
    if trace.finite().next().is_none() {
        fail!(Reference, "{}: no values", path.display());
    }
    trace.grid_or_err(path)
}
