//! Grid frequency archives: the mains frequency as grid operators and measurement sites
//! publish it, placed on the reference store's steps.
//!
//! Each archive is a timestamped CSV (plain, gzip'd, or a month of daily files in a zip or 7z
//! archive, read as streams). Its layout is sniffed from the header and the first rows: the
//! separator, a date-time column (or a date and a time in two columns, Unix seconds or
//! milliseconds, or year;month;day;hour;minute;second columns), and the value, in Hz or as a
//! deviation in mHz or Hz. Named layouts ([`ArchiveFormat`]) fix what a sniff cannot tell, such
//! as the order of day and month or the zone an operator publishes in.
//!
//! Times without a zone are local wall-clock times: a [`Zone`] places them in UTC, summer time
//! included (the hour that repeats in autumn is read as its first then its second passage; a
//! time in the hour skipped in spring does not exist and is dropped, counted). Such times are
//! never taken as UTC unless the layout says the publisher writes UTC.
//!
//! Values are averaged over each step of the store ([`eenf_dsp::resample::StepAverager`]):
//! 0.1 s archives become means over each second, repeated rows merge, coarser archives are
//! interpolated between neighbouring rows, and values outside the grid's operating range
//! (0 Hz dropouts, say) are dropped as gaps and counted.

use std::fmt;
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use anyhow::{bail, Context, Result};
use eenf_dsp::resample::{StepAverager, Steps};

use crate::time::{days_from_civil, days_in_month, LocalInstant, Zone};

/// The longest line read: a CSV row is short; a "line" longer than this is not a CSV.
const MAX_LINE: usize = 1 << 16;
/// Rows read to sniff a layout.
const SNIFF_ROWS: usize = 64;
/// Farthest a value may lie from the nominal frequency, Hz: the grid's operating limits
/// (47.5–52.5 Hz at 50 Hz); beyond them a row is a dropout or a fault of the meter.
const PLAUSIBLE_HZ: f64 = 2.5;
/// Longest span one input may cover (its steps are allocated only where rows fall).
const MAX_SPAN_S: f64 = 400.0 * 86_400.0;
/// A gap longer than this splits the series into pieces: a stray row far from the rest costs
/// one value, not the steps between.
const PIECE_GAP_S: f64 = 6.0 * 3600.0;
/// A piece shorter than this, beside a longer one, is a stray row (a mistyped date), dropped
/// and counted with the rows far outside the file's span.
const MIN_PIECE_S: f64 = 60.0;
/// Rows in a row that bring no later time (repeats, rows going back, rows that are not a
/// time and a frequency) after which the rest of a file is not read: no meter writes a
/// million of them, and a compressed file can hold billions.
pub const MAX_STALE_ROWS: u64 = 1_000_000;
/// The coarsest step an archive may have, s.
const MAX_STEP_S: f64 = 60.0;
/// Years an archive's dates may name.
const YEARS: std::ops::RangeInclusive<i64> = 1970..=2100;

/// A named layout of grid frequency archive, or `auto` (sniffed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ArchiveFormat {
    /// Sniffed from the header and the first rows.
    #[default]
    Auto,
    /// UK National Grid ESO "system frequency data": `dtm,f`, 1 s, in UTC; dates as
    /// `2022-08-17 08:00:00` or (older files) `17/08/2022 09:00:00`.
    Ngeso,
    /// Fingrid (Finland) frequency history: `Time,Value`, 0.1 s, a CSV per day in monthly
    /// zip or 7z archives; the zone is the archive's to state (give `--tz`).
    Fingrid,
    /// TransnetBW (Germany): `DD.MM.YYYY HH:MM:SS` and the frequency in Hz, 1 s, monthly
    /// CSVs; German local time unless the file says otherwise (give `--tz`).
    Transnetbw,
    /// The OSF power grid frequency database (WETI): `year;month;day;hour;minute;second;value`,
    /// no header, GPS time in UTC.
    Osf,
}

impl ArchiveFormat {
    /// Names accepted by `--format`.
    pub const NAMES: [&'static str; 5] = ["auto", "ngeso", "fingrid", "transnetbw", "osf"];

    /// Its name.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The zone its publisher writes times in, when the layout fixes one.
    fn zone(self) -> Option<&'static str> {
        match self {
            ArchiveFormat::Ngeso => Some("UTC, as National Grid ESO publishes"),
            ArchiveFormat::Osf => Some("UTC, the database's GPS time"),
            _ => None,
        }
    }

    /// The zone to suggest when a file of this layout needs one.
    fn zone_hint(self) -> &'static str {
        match self {
            ArchiveFormat::Fingrid => "--tz Europe/Helsinki for Finnish time, --tz Z for UTC",
            ArchiveFormat::Transnetbw => "--tz Europe/Berlin for German time, --tz Z for UTC",
            _ => "e.g. --tz Europe/Berlin, --tz America/New_York, --tz +08:00, or --tz Z for UTC",
        }
    }

    /// The grid its publisher measures (all named layouts are European, 50 Hz).
    fn nominal(self) -> Option<f64> {
        (self != ArchiveFormat::Auto).then_some(50.0)
    }

    /// The order of day and month it writes.
    fn date_order(self) -> Option<DateOrder> {
        match self {
            ArchiveFormat::Ngeso | ArchiveFormat::Transnetbw => Some(DateOrder::Dmy),
            _ => None,
        }
    }
}

impl std::str::FromStr for ArchiveFormat {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let all = [
            ArchiveFormat::Auto,
            ArchiveFormat::Ngeso,
            ArchiveFormat::Fingrid,
            ArchiveFormat::Transnetbw,
            ArchiveFormat::Osf,
        ];
        all.into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("{s:?}: expected one of {}", Self::NAMES.join(", ")))
    }
}

/// What an archive's value column holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ValueUnit {
    /// Told from the header and the values: near 50 or 60 is Hz; a deviation needs its unit
    /// stated in the header.
    #[default]
    Auto,
    /// The frequency, Hz.
    Hz,
    /// The deviation from the nominal frequency, mHz.
    MilliHzDeviation,
    /// The deviation from the nominal frequency, Hz.
    HzDeviation,
}

impl ValueUnit {
    /// Names accepted by `--value-unit`.
    pub const NAMES: [&'static str; 4] = ["auto", "hz", "mhz-deviation", "hz-deviation"];

    /// Its name.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    fn to_hz(self, v: f64, nominal: f64) -> f64 {
        match self {
            ValueUnit::Auto | ValueUnit::Hz => v,
            ValueUnit::MilliHzDeviation => nominal + v * 1e-3,
            ValueUnit::HzDeviation => nominal + v,
        }
    }
}

impl std::str::FromStr for ValueUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let all = [
            ValueUnit::Auto,
            ValueUnit::Hz,
            ValueUnit::MilliHzDeviation,
            ValueUnit::HzDeviation,
        ];
        all.into_iter()
            .find(|u| u.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("{s:?}: expected one of {}", Self::NAMES.join(", ")))
    }
}

/// The order of day and month in dates such as `05/06/2022`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DateOrder {
    /// From the dates (a field above 12 is the day) or the layout; refused when neither tells.
    #[default]
    Auto,
    /// Day, month, year (Europe).
    Dmy,
    /// Month, day, year (USA).
    Mdy,
}

impl DateOrder {
    /// Names accepted by `--date-order`.
    pub const NAMES: [&'static str; 3] = ["auto", "dmy", "mdy"];
}

impl std::str::FromStr for DateOrder {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "auto" => Ok(DateOrder::Auto),
            "dmy" => Ok(DateOrder::Dmy),
            "mdy" => Ok(DateOrder::Mdy),
            _ => Err(format!("{s:?}: expected auto, dmy or mdy")),
        }
    }
}

/// How an archive is read.
#[derive(Debug, Clone, Default)]
pub struct ArchiveOptions {
    /// Its layout (auto: sniffed).
    pub format: ArchiveFormat,
    /// The zone of its local times; none is assumed.
    pub zone: Option<Zone>,
    /// What its value column holds.
    pub unit: ValueUnit,
    /// The order of day and month in its dates.
    pub date_order: DateOrder,
    /// The grid's nominal frequency (needed for deviations; else told from the values).
    pub nominal_hz: Option<f64>,
}

/// An archive read onto regular steps.
#[derive(Debug, Clone)]
pub struct ArchiveImport {
    /// The frequency, Hz, at Unix times `start + i·step` (NaN: a gap), in time order; a new
    /// piece starts after a gap of more than six hours.
    pub steps: Vec<Steps>,
    /// The grid's nominal frequency, Hz.
    pub nominal_hz: f64,
    /// What was read, and what was dropped.
    pub report: ImportReport,
}

/// What an import read and what it dropped, for the examiner.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct ImportReport {
    /// The layout as read: its name, columns, date style and unit.
    pub layout: String,
    /// Where the times' zone came from.
    pub zone: String,
    /// Files read (a zip or 7z holds several).
    pub files: usize,
    /// Data rows seen.
    pub rows: u64,
    /// Rows whose value went into a step.
    pub used: u64,
    /// Rows whose value lies outside the grid's operating range (dropped as gaps).
    pub implausible: u64,
    /// Rows that could not be read (the first is quoted in `warnings`).
    pub unreadable: u64,
    /// Rows at the same time as the row before (merged into one step).
    pub repeated: u64,
    /// Rows at wall-clock times that do not exist in the zone (the hour skipped in spring).
    pub missing_times: u64,
    /// Rows in an hour the clocks passed twice, read as its second passage.
    pub second_passage: u64,
    /// The hours that repeated or were skipped, as the zone's wall clock gives them.
    pub clock_changes: Vec<String>,
    /// Rows too far from the rest of the input (a wild time).
    pub far: u64,
    /// The archive's own step, s (the median spacing of its first rows).
    pub native_step_s: f64,
    /// Other notes: damage, skipped members, the first unreadable row.
    pub warnings: Vec<String>,
}

impl fmt::Display for ImportReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}; times {}; {} rows in {} file{}, step {} s",
            self.layout,
            self.zone,
            self.rows,
            self.files,
            if self.files == 1 { "" } else { "s" },
            self.native_step_s
        )?;
        let mut dropped = Vec::new();
        if self.implausible > 0 {
            dropped.push(format!(
                "{} outside the grid's range dropped as gaps",
                self.implausible
            ));
        }
        if self.unreadable > 0 {
            dropped.push(format!("{} unreadable", self.unreadable));
        }
        if self.repeated > 0 {
            dropped.push(format!("{} repeated times merged", self.repeated));
        }
        if self.missing_times > 0 {
            dropped.push(format!(
                "{} at times the clocks skipped dropped",
                self.missing_times
            ));
        }
        if self.far > 0 {
            dropped.push(format!("{} far outside the file's span dropped", self.far));
        }
        if !dropped.is_empty() {
            write!(f, "; {}", dropped.join(", "))?;
        }
        for c in &self.clock_changes {
            write!(f, "; {c}")?;
        }
        Ok(())
    }
}

/// Whether `path` looks like a grid archive rather than an eenf trace: a zip, 7z or gzip
/// file, or a CSV whose first rows carry dates or Unix times.
pub fn is_archive(path: &Path) -> bool {
    let Ok(mut f) = File::open(path) else {
        return false;
    };
    let mut head = [0u8; 6];
    let n = f.read(&mut head).unwrap_or(0);
    if container_of(&head[..n]) != Container::Text {
        return true;
    }
    let Ok(f) = File::open(path) else {
        return false;
    };
    let Ok(lines) = first_lines(&mut BufReader::new(f), 8) else {
        return false;
    };
    if lines
        .first()
        .is_some_and(|l| l.trim_start().starts_with('{'))
    {
        return false; // an eenf JSON trace
    }
    let header = lines
        .first()
        .map(|l| l.to_ascii_lowercase())
        .unwrap_or_default();
    if header.contains("time_s") || header.contains("enf_hz") {
        return false;
    }
    // zone and date order do not matter to whether it is an archive
    let probe = ArchiveOptions {
        zone: Some(Zone::utc()),
        date_order: DateOrder::Dmy,
        unit: ValueUnit::Hz,
        ..ArchiveOptions::default()
    };
    sniff(&lines, &probe, Path::new("")).is_ok()
}

/// Reads the archive at `path` onto steps of `step_s` seconds (when `None`: 1 s, or the
/// archive's own step when coarser).
pub fn import(path: &Path, opts: &ArchiveOptions, step_s: Option<f64>) -> Result<ArchiveImport> {
    let name = path.display().to_string();
    let mut state: Option<ImportState> = None;
    let mut report = ImportReport::default();
    let warnings = for_each_member(path, &mut |member, reader| {
        let label = match member {
            Some(m) => format!("{name} ({m})"),
            None => name.clone(),
        };
        let lines = match first_lines(reader, SNIFF_ROWS) {
            Ok(l) => l,
            // a damaged member after good ones: what came before is kept
            Err(e) if state.is_some() => {
                report
                    .warnings
                    .push(format!("{label}: {e}; the members before it are kept"));
                return Ok(());
            }
            Err(e) => return Err(e.context(label)),
        };
        if lines.is_empty() {
            report.warnings.push(format!("{label}: empty"));
            return Ok(());
        }
        let layout = sniff(&lines, opts, Path::new(&label))?;
        if state.is_none() {
            let nominal = match opts.nominal_hz {
                Some(f) => f,
                None => layout.nominal(&lines, &label)?,
            };
            let native = layout.native_step(&lines);
            let step = step_s.unwrap_or(if native > 1.0 {
                (native * 1000.0).round() / 1000.0
            } else {
                1.0
            });
            report.layout = layout.describe();
            report.zone = layout.zone_text();
            report.native_step_s = (native * 1000.0).round() / 1000.0;
            state = Some(ImportState::new(nominal, step, native));
        }
        let Some(st) = state.as_mut() else {
            return Ok(());
        };
        report.files += 1;
        for line in &lines[layout.first_data..] {
            st.row(&layout, line.as_bytes(), &mut report, &label);
        }
        let mut buf = Vec::new();
        loop {
            if st.stale > MAX_STALE_ROWS {
                report.warnings.push(format!(
                    "{label}: {MAX_STALE_ROWS} rows in a row bring no later time; the rest of it is not read"
                ));
                break;
            }
            buf.clear();
            match read_line(reader, &mut buf) {
                Ok(0) => break,
                Ok(_) => st.row(&layout, &buf, &mut report, &label),
                Err(e) => {
                    report
                        .warnings
                        .push(format!("{label}: {e}; the rows before it are kept"));
                    break;
                }
            }
        }
        Ok(())
    })?;
    report.warnings.extend(warnings);
    let Some(st) = state else {
        bail!("{name}: holds no frequency rows");
    };
    if report.used == 0 {
        bail!(
            "{name}: none of its {} rows holds a plausible frequency{}",
            report.rows,
            report
                .warnings
                .first()
                .map(|w| format!(" ({w})"))
                .unwrap_or_default()
        );
    }
    for (instant, count) in &st.clock_notes {
        report.clock_changes.push(match instant {
            ClockNote::Repeated(label) if *count == 0 => format!(
                "the hour from {label} passed twice; the archive gives it once, read as the first passage"
            ),
            ClockNote::Repeated(label) => format!(
                "the hour from {label} passed twice: read as its first then its second passage ({count} rows in the second)"
            ),
            ClockNote::Missing(label) => {
                format!("{count} rows in the hour from {label}, which the clocks skipped")
            }
        });
    }
    let nominal = st.nominal;
    let step = st.acc.step();
    let interpolate = if st.native > st.acc.step() * 1.01 {
        st.native * 1.5
    } else {
        0.0
    };
    let mut pieces = st
        .acc
        .finish_pieces(interpolate, (PIECE_GAP_S / step).ceil() as u64);
    let min_len = (MIN_PIECE_S / step).ceil() as usize;
    if pieces.iter().any(|p| p.values.len() >= min_len) {
        pieces.retain(|p| {
            let keep = p.values.len() >= min_len;
            if !keep {
                report.far += p.values.iter().filter(|v| v.is_finite()).count() as u64;
            }
            keep
        });
    }
    Ok(ArchiveImport {
        steps: pieces,
        nominal_hz: nominal,
        report,
    })
}

/// What an archive's container is, from its first bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Container {
    Zip,
    SevenZip,
    Gzip,
    Text,
}

fn container_of(head: &[u8]) -> Container {
    if head.starts_with(b"PK\x03\x04") {
        Container::Zip
    } else if head.starts_with(b"7z\xBC\xAF\x27\x1C") {
        Container::SevenZip
    } else if head.starts_with(b"\x1f\x8b") {
        Container::Gzip
    } else {
        Container::Text
    }
}

/// Whether a member of a zip or 7z archive is a table to read.
fn is_table(name: &str) -> bool {
    let n = name.to_ascii_lowercase();
    [".csv", ".txt", ".tsv", ".dat"]
        .iter()
        .any(|e| n.ends_with(e))
}

type MemberFn<'a> = dyn FnMut(Option<&str>, &mut dyn BufRead) -> Result<()> + 'a;

/// Calls `each` with every table `path` holds, in name order for zips and in stored order
/// for 7z. Damage stops the reading with a warning (returned); what was read is kept.
fn for_each_member(path: &Path, each: &mut MemberFn<'_>) -> Result<Vec<String>> {
    let name = path.display();
    let open = || File::open(path).with_context(|| format!("{name}"));
    if path.is_dir() {
        bail!("{name}: a folder, not a grid archive");
    }
    let mut head = [0u8; 6];
    let n = open()?.read(&mut head).with_context(|| format!("{name}"))?;
    let mut warnings = Vec::new();
    match container_of(&head[..n]) {
        Container::Text => each(None, &mut BufReader::new(open()?))?,
        Container::Gzip => {
            let gz = flate2::read::MultiGzDecoder::new(BufReader::new(open()?));
            each(None, &mut BufReader::new(gz))?;
        }
        Container::Zip => {
            let mut zip = match zip::ZipArchive::new(BufReader::new(open()?)) {
                Ok(z) => z,
                // no directory at the end (a download cut short): the members in order
                Err(e) => return zip_in_order(path, each, e),
            };
            let mut names: Vec<String> = zip
                .file_names()
                .filter_map(|n| n.ok().map(|n| n.into_owned()))
                .collect();
            names.sort();
            let skipped: Vec<&String> = names
                .iter()
                .filter(|n| !is_table(n) && !n.ends_with('/'))
                .collect();
            if !skipped.is_empty() {
                warnings.push(format!(
                    "{name}: skipped {} member(s) that are not tables (e.g. {})",
                    skipped.len(),
                    skipped[0]
                ));
            }
            let tables: Vec<String> = names.iter().filter(|n| is_table(n)).cloned().collect();
            if tables.is_empty() {
                bail!("{name}: a zip archive with no CSV or text table in it");
            }
            for m in &tables {
                let entry = match zip.by_name(m) {
                    Ok(e) => e,
                    Err(e) => {
                        warnings.push(format!(
                            "{name}: member {m} is damaged ({e}); stopped there, the members before it are kept"
                        ));
                        break;
                    }
                };
                each(Some(m), &mut BufReader::new(entry))?;
            }
        }
        Container::SevenZip => {
            let mut reader = sevenz_rust2::ArchiveReader::new(
                BufReader::new(open()?),
                sevenz_rust2::Password::empty(),
            )
            .map_err(|e| anyhow::anyhow!("{name}: not a readable 7z archive: {e}"))?;
            let mut failure: Option<anyhow::Error> = None;
            let mut tables = 0usize;
            let walked = reader.for_each_entries(|entry, r| {
                if entry.is_directory || !is_table(&entry.name) {
                    return Ok(true);
                }
                tables += 1;
                match each(Some(&entry.name), &mut BufReader::new(r)) {
                    Ok(()) => Ok(true),
                    Err(e) => {
                        failure = Some(e);
                        Ok(false)
                    }
                }
            });
            if let Some(e) = failure {
                return Err(e);
            }
            if let Err(e) = walked {
                warnings.push(format!(
                    "{name}: damaged ({e}); stopped there, the members before it are kept"
                ));
            }
            if tables == 0 {
                bail!("{name}: a 7z archive with no CSV or text table in it");
            }
        }
    }
    Ok(warnings)
}

/// The members of a zip whose central directory cannot be read, in the order they are stored,
/// up to the damage (a cut-short download keeps its first days).
fn zip_in_order(
    path: &Path,
    each: &mut MemberFn<'_>,
    why: zip::result::ZipError,
) -> Result<Vec<String>> {
    let name = path.display();
    let mut r = BufReader::new(File::open(path).with_context(|| format!("{name}"))?);
    let mut tables = 0usize;
    let mut warnings = Vec::new();
    loop {
        match zip::read::read_zipfile_from_stream(&mut r) {
            Ok(Some(entry)) => {
                let member = entry.name().map(|n| n.into_owned()).unwrap_or_default();
                if is_table(&member) {
                    tables += 1;
                    each(Some(&member), &mut BufReader::new(entry))?;
                }
            }
            Ok(None) => break,
            Err(e) => {
                if tables > 0 {
                    warnings.push(format!(
                        "{name}: a damaged zip archive ({why}; then {e}): the members before the damage are kept"
                    ));
                }
                break;
            }
        }
    }
    if tables == 0 {
        bail!("{name}: not a readable zip archive ({why}), and no whole table at its start");
    }
    Ok(warnings)
}

/// Reads one line (without its end) into `buf`: the bytes read, 0 at the end. A line longer
/// than [`MAX_LINE`] is an error: the file is no table.
fn read_line(r: &mut dyn BufRead, buf: &mut Vec<u8>) -> Result<usize> {
    let mut total = 0;
    loop {
        let chunk = r.fill_buf()?;
        if chunk.is_empty() {
            return Ok(total);
        }
        let (take, done) = match chunk.iter().position(|&b| b == b'\n') {
            Some(i) => (i + 1, true),
            None => (chunk.len(), false),
        };
        buf.extend_from_slice(&chunk[..take]);
        r.consume(take);
        total += take;
        if buf.len() > MAX_LINE {
            bail!("a line longer than {} KiB: not a table", MAX_LINE >> 10);
        }
        if done {
            while buf.last().is_some_and(|&b| b == b'\n' || b == b'\r') {
                buf.pop();
            }
            return Ok(total);
        }
    }
}

/// The first `n` lines that hold something (not blank, not `#` comments), as text; a UTF-8
/// byte order mark is dropped.
fn first_lines(r: &mut dyn BufRead, n: usize) -> Result<Vec<String>> {
    let mut out = Vec::new();
    let mut buf = Vec::new();
    while out.len() < n {
        buf.clear();
        if read_line(r, &mut buf)? == 0 {
            break;
        }
        if out.is_empty() && buf.starts_with(b"\xEF\xBB\xBF") {
            buf.drain(..3);
        }
        if buf.starts_with(b"\xFF\xFE") || buf.starts_with(b"\xFE\xFF") {
            bail!("UTF-16 text: save it as UTF-8");
        }
        let line = String::from_utf8_lossy(&buf).into_owned();
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        out.push(line);
    }
    Ok(out)
}

/// The columns that give a row's time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeColumns {
    /// A date and time in one field.
    DateTime(usize),
    /// A date and a time in two fields.
    DateAndTime(usize, usize),
    /// Unix time, in units of `scale` seconds.
    Unix(usize, f64),
    /// year, month, day, hour, minute, second (with its fraction) in six fields.
    Fields(usize),
}

/// Where the times' zone comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum ZoneRule {
    /// Each time carries its offset (`…Z`, `…+02:00`).
    InRows,
    /// UTC, for the reason given.
    Utc(&'static str),
    /// Local times in this zone (`--tz`).
    Given(Zone),
}

/// An archive's layout, as sniffed.
#[derive(Debug, Clone)]
pub struct Layout {
    /// The operator's layout it was recognised as.
    pub format: ArchiveFormat,
    /// The field separator.
    pub delimiter: u8,
    /// The header line, when there is one.
    pub header: Option<String>,
    /// The index of the first data line.
    pub first_data: usize,
    /// Fields per data line.
    pub fields: usize,
    /// Where each row's time is.
    pub time: TimeColumns,
    /// The field holding the frequency.
    pub value: usize,
    /// The frequency's unit.
    pub unit: ValueUnit,
    /// Numbers are written with a decimal comma.
    pub decimal_comma: bool,
    /// The order of day, month and year in dates.
    pub order: DateOrder,
    /// Where the times' zone comes from.
    pub zone: ZoneRule,
}

impl Layout {
    fn describe(&self) -> String {
        let name = match self.format {
            ArchiveFormat::Auto => "sniffed layout".to_string(),
            f => format!("{} layout", f.name()),
        };
        let cols = match &self.header {
            Some(h) => format!("columns {}", h.trim()),
            None => format!("{} columns, no header", self.fields),
        };
        let time = match self.time {
            TimeColumns::DateTime(c) => format!("date-time in column {}", c + 1),
            TimeColumns::DateAndTime(d, t) => {
                format!("date in column {}, time in {}", d + 1, t + 1)
            }
            TimeColumns::Unix(c, s) => format!(
                "Unix {} in column {}",
                if s == 1.0 { "seconds" } else { "milliseconds" },
                c + 1
            ),
            TimeColumns::Fields(c) => format!("year to second in columns {}–{}", c + 1, c + 6),
        };
        let order = match self.order {
            DateOrder::Dmy => ", day before month",
            DateOrder::Mdy => ", month before day",
            DateOrder::Auto => "",
        };
        let unit = match self.unit {
            ValueUnit::Auto | ValueUnit::Hz => "Hz",
            ValueUnit::MilliHzDeviation => "mHz from nominal",
            ValueUnit::HzDeviation => "Hz from nominal",
        };
        format!(
            "{name} ({cols}; {time}{order}; frequency in column {} in {unit}{})",
            self.value + 1,
            if self.decimal_comma {
                ", decimal comma"
            } else {
                ""
            }
        )
    }

    fn zone_text(&self) -> String {
        match &self.zone {
            ZoneRule::InRows => "with their own UTC offsets".into(),
            ZoneRule::Utc(why) => format!("in {why}"),
            ZoneRule::Given(z) if z.name() == "UTC" => "in UTC (--tz)".into(),
            ZoneRule::Given(z) => format!("local to {} (--tz)", z.name()),
        }
    }

    fn split<'a>(&self, line: &'a [u8]) -> impl Iterator<Item = &'a [u8]> + 'a {
        let d = self.delimiter;
        line.split(move |&b| b == d).map(clean)
    }

    fn number(&self, s: &[u8]) -> Option<f64> {
        number(s, self.decimal_comma)
    }

    /// The row's wall-clock time (seconds after 1970-01-01 00:00 of its clock, with their
    /// fraction) and its UTC offset when it carries one; or its Unix time.
    fn time_of(&self, f: &[&[u8]]) -> Option<(f64, Option<f64>)> {
        match self.time {
            TimeColumns::DateTime(c) => parse_date_time(f.get(c)?, self.order),
            TimeColumns::DateAndTime(d, t) => {
                let (y, m, dd) = parse_date(f.get(d)?, self.order)?.0;
                let (secs, off) = parse_clock(f.get(t)?)?;
                Some((civil_seconds(y, m, dd)? as f64 + secs, off))
            }
            TimeColumns::Unix(c, scale) => Some((self.number(f.get(c)?)? * scale, Some(0.0))),
            TimeColumns::Fields(c) => {
                let n = |i: usize| self.number(f.get(c + i)?);
                let (y, mo, d, h, mi, s) = (n(0)?, n(1)?, n(2)?, n(3)?, n(4)?, n(5)?);
                if [y, mo, d, h, mi].iter().any(|v| v.fract() != 0.0)
                    || !(0.0..=24.0).contains(&h)
                    || !(0.0..60.0).contains(&mi)
                    || !(0.0..=120.0).contains(&s)
                {
                    return None;
                }
                // WETI seconds run past 60 at the minute's end: they count from the minute
                let day = civil_seconds(y as i64, mo as u32, d as u32)?;
                Some((day as f64 + h * 3600.0 + mi * 60.0 + s, None))
            }
        }
    }

    /// The nominal frequency from the first rows' values.
    fn nominal(&self, lines: &[String], label: &str) -> Result<f64> {
        let vals: Vec<f64> = lines[self.first_data..]
            .iter()
            .filter_map(|l| {
                let f: Vec<&[u8]> = self.split(l.as_bytes()).collect();
                self.number(f.get(self.value)?)
            })
            .collect();
        if let Some(f) = self.format.nominal() {
            return Ok(f);
        }
        match self.unit {
            ValueUnit::Auto | ValueUnit::Hz => {
                let m = median(vals).unwrap_or(f64::NAN);
                if (45.0..55.0).contains(&m) {
                    Ok(50.0)
                } else if (55.0..65.0).contains(&m) {
                    Ok(60.0)
                } else {
                    bail!("{label}: its values (median {m}) are not near 50 or 60 Hz")
                }
            }
            _ => bail!(
                "{label}: its values are deviations from the nominal frequency: give it with --nominal 50 or --nominal 60"
            ),
        }
    }

    /// The median spacing of the first rows' times, s (1 when they do not tell).
    fn native_step(&self, lines: &[String]) -> f64 {
        let times: Vec<f64> = lines[self.first_data..]
            .iter()
            .filter_map(|l| {
                let f: Vec<&[u8]> = self.split(l.as_bytes()).collect();
                self.time_of(&f).map(|(t, _)| t)
            })
            .collect();
        let diffs: Vec<f64> = times
            .windows(2)
            .map(|w| w[1] - w[0])
            .filter(|d| *d > 1e-6)
            .collect();
        // an archive steps by 0.1 s to a minute: wild rows among the first must not make a
        // step of years
        median(diffs)
            .filter(|d| d.is_finite() && *d > 0.0)
            .unwrap_or(1.0)
            .clamp(0.001, MAX_STEP_S)
    }
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

/// A field without its spaces and quotes.
fn clean(f: &[u8]) -> &[u8] {
    let f = f.trim_ascii();
    let f = f.strip_prefix(b"\"").unwrap_or(f);
    let f = f.strip_suffix(b"\"").unwrap_or(f);
    f.trim_ascii()
}

fn number(s: &[u8], decimal_comma: bool) -> Option<f64> {
    if s.is_empty() || s.len() > 40 {
        return None;
    }
    let text = std::str::from_utf8(s).ok()?;
    let v = if decimal_comma && text.contains(',') {
        text.replace(',', ".").parse::<f64>().ok()?
    } else {
        text.parse::<f64>().ok()?
    };
    v.is_finite().then_some(v)
}

/// Seconds after 1970-01-01 00:00 of a date's midnight, when the date exists.
fn civil_seconds(y: i64, m: u32, d: u32) -> Option<i64> {
    if !YEARS.contains(&y) || !(1..=12).contains(&m) || d == 0 || d > days_in_month(y, m) {
        return None;
    }
    Some(days_from_civil(y, m, d) * 86_400)
}

/// Digits as a number (1 to 4 of them).
fn digits(s: &[u8]) -> Option<u32> {
    if s.is_empty() || s.len() > 4 || !s.iter().all(u8::is_ascii_digit) {
        return None;
    }
    Some(s.iter().fold(0, |a, &b| a * 10 + (b - b'0') as u32))
}

/// How a date is written: year first, or year last after two fields whose order the layout
/// must tell.
#[derive(Debug, Clone, Copy, PartialEq)]
enum DateShape {
    YearFirst,
    YearLast { first: u32, second: u32 },
}

/// A date `YYYY-MM-DD`, `YYYY/MM/DD`, `DD.MM.YYYY`, `DD/MM/YYYY` or `MM/DD/YYYY`, `DD-MM-YYYY`.
fn parse_date(s: &[u8], order: DateOrder) -> Option<((i64, u32, u32), DateShape)> {
    let sep = *s.iter().find(|b| matches!(b, b'-' | b'/' | b'.'))?;
    let mut parts = s.split(|&b| b == sep);
    let (a, b, c) = (parts.next()?, parts.next()?, parts.next()?);
    if parts.next().is_some() {
        return None;
    }
    if a.len() == 4 {
        let (y, m, d) = (digits(a)? as i64, digits(b)?, digits(c)?);
        if b.len() > 2 || c.len() > 2 {
            return None;
        }
        civil_seconds(y, m, d)?;
        return Some(((y, m, d), DateShape::YearFirst));
    }
    if c.len() != 4 || a.len() > 2 || b.len() > 2 {
        return None;
    }
    let (x, z, y) = (digits(a)?, digits(b)?, digits(c)? as i64);
    let shape = DateShape::YearLast {
        first: x,
        second: z,
    };
    let (d, m) = match order {
        DateOrder::Mdy => (z, x),
        // while sniffing (Auto), any reading that exists will do
        DateOrder::Dmy | DateOrder::Auto => {
            if order == DateOrder::Auto && x <= 12 && z > 12 {
                (z, x)
            } else {
                (x, z)
            }
        }
    };
    civil_seconds(y, m, d)?;
    Some(((y, m, d), shape))
}

/// A clock time `HH:MM[:SS[.fff]]`, with an optional offset after it (`Z`, `UTC`, `+02:00`,
/// `+0200`, `+02`): seconds into the day and the offset in seconds east of UTC.
fn parse_clock(s: &[u8]) -> Option<(f64, Option<f64>)> {
    // the clock ends where the offset starts
    let end = s
        .iter()
        .position(|b| matches!(b, b'Z' | b'z' | b'+' | b'-' | b' ' | b'U' | b'G'))
        .unwrap_or(s.len());
    let (clock, zone) = s.split_at(end);
    let mut it = clock.splitn(3, |&b| b == b':');
    let h = digits(it.next()?)?;
    let m = it.next().and_then(digits)?;
    let sec = match it.next() {
        None => 0.0,
        Some(x) => {
            let t = std::str::from_utf8(x).ok()?.replace(',', ".");
            if t.is_empty() || !t.bytes().next()?.is_ascii_digit() {
                return None;
            }
            t.parse::<f64>().ok()?
        }
    };
    if h > 24 || m > 59 || !(0.0..61.0).contains(&sec) || (h == 24 && (m > 0 || sec > 0.0)) {
        return None;
    }
    let offset = parse_offset(zone.trim_ascii())?;
    Some((h as f64 * 3600.0 + m as f64 * 60.0 + sec, offset))
}

/// `""` → no offset; `Z`, `UTC`, `GMT` → 0; `+02:00`, `-0530`, `+02` → seconds east.
#[allow(clippy::option_option)]
fn parse_offset(z: &[u8]) -> Option<Option<f64>> {
    if z.is_empty() {
        return Some(None);
    }
    if z.eq_ignore_ascii_case(b"z")
        || z.eq_ignore_ascii_case(b"utc")
        || z.eq_ignore_ascii_case(b"gmt")
    {
        return Some(Some(0.0));
    }
    let z = z
        .strip_prefix(b"UTC")
        .or_else(|| z.strip_prefix(b"GMT"))
        .unwrap_or(z);
    let sign = match z.first()? {
        b'+' => 1.0,
        b'-' => -1.0,
        _ => return None,
    };
    let d: Vec<u8> = z[1..].iter().copied().filter(|b| *b != b':').collect();
    let (h, m) = match d.len() {
        1 | 2 => (digits(&d)?, 0),
        4 => (digits(&d[..2])?, digits(&d[2..])?),
        _ => return None,
    };
    if h > 18 || m > 59 {
        return None;
    }
    Some(Some(sign * (h as f64 * 3600.0 + m as f64 * 60.0)))
}

/// A date and time in one field (`2022-08-17 08:00:00`, `2022-08-17T08:00:00.100+02:00`,
/// `17/08/2022 09:00:00`).
pub fn parse_date_time(s: &[u8], order: DateOrder) -> Option<(f64, Option<f64>)> {
    let split = s.iter().position(|&b| b == b' ' || b == b'T')?;
    let (date, rest) = (&s[..split], s[split + 1..].trim_ascii_start());
    let ((y, m, d), _) = parse_date(date, order)?;
    let (secs, off) = parse_clock(rest)?;
    Some((civil_seconds(y, m, d)? as f64 + secs, off))
}

/// What one field of the sampled rows is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum FieldKind {
    DateTime,
    Date,
    Clock,
    Number,
    Text,
}

fn kind_of(f: &[u8], decimal_comma: bool) -> FieldKind {
    if parse_date_time(f, DateOrder::Auto).is_some() {
        FieldKind::DateTime
    } else if parse_date(f, DateOrder::Auto).is_some() {
        FieldKind::Date
    } else if f.contains(&b':') && parse_clock(f).is_some() {
        FieldKind::Clock
    } else if number(f, decimal_comma).is_some() {
        FieldKind::Number
    } else {
        FieldKind::Text
    }
}

/// Tells an archive's layout from its first lines.
pub fn sniff(lines: &[String], opts: &ArchiveOptions, path: &Path) -> Result<Layout> {
    let name = path.display();
    let first = lines.first().map(String::as_str).unwrap_or("");
    let shown: String = first.chars().take(80).collect();
    // the separator: the first of ; tab , that splits every sampled line into two or more
    let delimiter = [b';', b'\t', b',']
        .into_iter()
        .find(|&d| {
            lines
                .iter()
                .take(8)
                .all(|l| l.as_bytes().split(|&b| b == d).count() >= 2)
        })
        .with_context(|| {
            format!("{name}: not a table of times and frequencies: its first line {shown:?} has no ; , or tab between columns")
        })?;
    let decimal_comma = delimiter != b',';
    let fields_of = |l: &str| -> Vec<Vec<u8>> {
        l.as_bytes()
            .split(|&b| b == delimiter)
            .map(|f| clean(f).to_vec())
            .collect()
    };
    let head = fields_of(first);
    let is_header = head
        .iter()
        .all(|f| matches!(kind_of(f, decimal_comma), FieldKind::Text) || f.is_empty())
        && head.iter().any(|f| f.iter().any(u8::is_ascii_alphabetic));
    let first_data = usize::from(is_header);
    let rows: Vec<Vec<Vec<u8>>> = lines[first_data..].iter().map(|l| fields_of(l)).collect();
    let Some(row0) = rows.first() else {
        bail!("{name}: a header ({shown:?}) and no rows");
    };
    let ncols = row0.len();
    // a sampled field of the first row, for messages
    let field = |c: usize| -> &[u8] { row0.get(c).map(Vec::as_slice).unwrap_or(b"") };
    let names: Vec<String> = if is_header {
        head.iter()
            .map(|f| String::from_utf8_lossy(f).to_ascii_lowercase())
            .collect()
    } else {
        vec![String::new(); ncols]
    };
    // a column's kind: what all sampled rows agree on
    let kinds: Vec<FieldKind> = (0..ncols)
        .map(|c| {
            let ks: Vec<FieldKind> = rows
                .iter()
                .filter_map(|r| r.get(c))
                .map(|f| kind_of(f, decimal_comma))
                .collect();
            // what three rows in four agree on (a stray row does not hide a column)
            let count = |k: FieldKind| ks.iter().filter(|x| **x == k).count();
            let kinds = [
                FieldKind::DateTime,
                FieldKind::Date,
                FieldKind::Clock,
                FieldKind::Number,
            ];
            kinds
                .into_iter()
                .find(|&k| count(k) * 4 >= ks.len() * 3)
                .unwrap_or(FieldKind::Text)
        })
        .collect();
    let numbers = |c: usize| -> Vec<f64> {
        rows.iter()
            .filter_map(|r| number(r.get(c)?, decimal_comma))
            .collect()
    };
    // the format: named, or told from what is distinctive
    let mut format = opts.format;
    if format == ArchiveFormat::Auto {
        if names.len() == 2 && names[0] == "dtm" && names[1] == "f" {
            format = ArchiveFormat::Ngeso;
        } else if !is_header
            && delimiter == b';'
            && ncols >= 7
            && kinds[..7].iter().all(|k| *k == FieldKind::Number)
        {
            format = ArchiveFormat::Osf;
        }
    }
    let expected = "a date-time like 2022-08-17 08:00:00, a date and a time in two columns, \
                    Unix seconds or milliseconds, or year;month;day;hour;minute;second columns";
    // the time
    let time = if format == ArchiveFormat::Osf {
        let ok = ncols >= 7 && {
            let y = numbers(0);
            !y.is_empty() && y.iter().all(|v| YEARS.contains(&(*v as i64)))
        };
        if !ok {
            bail!("{name}: not the osf layout (expected year;month;day;hour;minute;second;value rows without a header), first line {shown:?}");
        }
        TimeColumns::Fields(0)
    } else if let Some(c) = kinds.iter().position(|k| *k == FieldKind::DateTime) {
        TimeColumns::DateTime(c)
    } else if let Some(c) = kinds
        .windows(2)
        .position(|w| w[0] == FieldKind::Date && w[1] == FieldKind::Clock)
    {
        TimeColumns::DateAndTime(c, c + 1)
    } else if let Some((c, scale)) = (0..ncols).find_map(|c| {
        if kinds[c] != FieldKind::Number {
            return None;
        }
        let v = numbers(c);
        let named = ["unix", "epoch", "timestamp"]
            .iter()
            .any(|n| names[c].contains(n));
        let rising = v.windows(2).all(|w| w[1] >= w[0]);
        let m = median(v.clone())?;
        if !rising || !(named || !is_header || v.iter().all(|x| x.fract() == 0.0)) {
            return None;
        }
        if (1e8..1e10).contains(&m) {
            Some((c, 1.0))
        } else if (1e11..1e13).contains(&m) {
            Some((c, 1e-3))
        } else {
            None
        }
    }) {
        TimeColumns::Unix(c, scale)
    } else {
        bail!("{name}: no time column: expected {expected}; first line {shown:?}");
    };
    let time_cols: Vec<usize> = match time {
        TimeColumns::DateTime(c) | TimeColumns::Unix(c, _) => vec![c],
        TimeColumns::DateAndTime(d, t) => vec![d, t],
        TimeColumns::Fields(c) => (c..c + 6).collect(),
    };
    // the value: a named frequency column, else the column near 50 or 60 Hz, else a stated
    // deviation
    let candidates: Vec<usize> = (0..ncols)
        .filter(|c| !time_cols.contains(c) && kinds[*c] == FieldKind::Number)
        .collect();
    let looks_named = |n: &str| {
        n == "f"
            || [
                "freq",
                "frequenz",
                "value",
                "wert",
                "hz",
                "enf",
                "deviation",
                "abweichung",
            ]
            .iter()
            .any(|k| n.contains(k))
    };
    let near_grid = |c: usize| median(numbers(c)).is_some_and(|m| (40.0..70.0).contains(&m));
    let value = candidates
        .iter()
        .copied()
        .find(|&c| near_grid(c))
        .or_else(|| candidates.iter().copied().find(|&c| looks_named(&names[c])))
        .or_else(|| (candidates.len() == 1).then(|| candidates[0]))
        .with_context(|| {
            format!("{name}: no column of frequencies beside the time (expected values near 50 or 60 Hz, or a deviation the header names); first line {shown:?}")
        })?;
    let unit = match opts.unit {
        // the named layouts give the frequency in Hz
        ValueUnit::Auto if near_grid(value) || format != ArchiveFormat::Auto => ValueUnit::Hz,
        ValueUnit::Auto => {
            let n = &names[value];
            if n.contains("mhz") {
                ValueUnit::MilliHzDeviation
            } else if ["dev", "abweich", "delta", "offset", "diff"]
                .iter()
                .any(|k| n.contains(k))
            {
                ValueUnit::HzDeviation
            } else {
                bail!(
                    "{name}: column {} ({:?}) is not near 50 or 60 Hz and its header does not say it is a deviation: give --value-unit hz, mhz-deviation or hz-deviation",
                    value + 1,
                    names[value]
                );
            }
        }
        u => u,
    };
    // the order of day and month, when dates put the year last
    let mut order = opts.date_order;
    let date_col = match time {
        TimeColumns::DateTime(c) | TimeColumns::DateAndTime(c, _) => Some(c),
        _ => None,
    };
    if let Some(c) = date_col {
        let shapes: Vec<DateShape> = rows
            .iter()
            .filter_map(|r| {
                let f = r.get(c)?;
                let date = f.split(|&b| b == b' ' || b == b'T').next()?;
                parse_date(date, DateOrder::Auto).map(|x| x.1)
            })
            .collect();
        let year_last: Vec<(u32, u32)> = shapes
            .iter()
            .filter_map(|s| match s {
                DateShape::YearLast { first, second } => Some((*first, *second)),
                DateShape::YearFirst => None,
            })
            .collect();
        if !year_last.is_empty() && order == DateOrder::Auto {
            let sep_dot = field(c).contains(&b'.');
            order = if year_last.iter().any(|(a, _)| *a > 12) {
                DateOrder::Dmy
            } else if year_last.iter().any(|(_, b)| *b > 12) {
                DateOrder::Mdy
            } else if let Some(o) = format.date_order() {
                o
            } else if sep_dot {
                DateOrder::Dmy // 17.08.2022: the dotted style is day first wherever it is used
            } else {
                bail!(
                    "{name}: dates such as {:?} can be read day/month or month/day: give --date-order dmy or mdy",
                    String::from_utf8_lossy(field(c))
                );
            };
        }
    }
    // the zone
    let with_offset = rows
        .iter()
        .filter(|r| {
            let f = match time {
                TimeColumns::DateTime(c) => r.get(c),
                TimeColumns::DateAndTime(_, t) => r.get(t),
                _ => None,
            };
            f.and_then(|f| match time {
                TimeColumns::DateTime(_) => parse_date_time(f, DateOrder::Auto),
                _ => parse_clock(f),
            })
            .is_some_and(|(_, o)| o.is_some())
        })
        .count();
    let offsets_in_rows = date_col.is_some() && with_offset * 4 >= rows.len() * 3;
    let zone = if offsets_in_rows {
        ZoneRule::InRows
    } else if matches!(time, TimeColumns::Unix(..)) {
        ZoneRule::Utc("UTC (Unix time)")
    } else if let Some(z) = &opts.zone {
        ZoneRule::Given(z.clone())
    } else if let Some(why) = format.zone() {
        ZoneRule::Utc(why)
    } else {
        bail!(
            "{name}: its times ({:?}) carry no zone and none is assumed: give it with --tz ({})",
            String::from_utf8_lossy(field(date_col.unwrap_or(0))),
            format.zone_hint()
        );
    };
    Ok(Layout {
        format,
        delimiter,
        header: is_header.then(|| first.trim().to_string()),
        first_data,
        fields: ncols,
        time,
        value,
        unit,
        decimal_comma,
        order,
        zone,
    })
}

/// A clock change met while reading, as the zone's wall clock gives its hour.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
enum ClockNote {
    Repeated(String),
    Missing(String),
}

/// The state of one import: the steps so far and the last row's instant.
struct ImportState {
    nominal: f64,
    native: f64,
    acc: StepAverager,
    last: f64,
    /// The latest instant read, and the rows since that brought no later one.
    latest: f64,
    stale: u64,
    /// Offsets of whole 15-minute stretches of wall-clock time (no change inside).
    cache: Option<(i64, f64)>,
    clock_notes: std::collections::BTreeMap<ClockNote, u64>,
}

impl ImportState {
    fn new(nominal: f64, step: f64, native: f64) -> Self {
        ImportState {
            nominal,
            native,
            acc: StepAverager::new(step, (MAX_SPAN_S / step) as usize),
            last: f64::NEG_INFINITY,
            latest: f64::NEG_INFINITY,
            stale: 0,
            cache: None,
            clock_notes: Default::default(),
        }
    }

    /// The instant of a wall-clock time in `zone`, as rows that follow each other give it:
    /// in a repeated hour, the first passage until the clock goes back.
    fn instant(&mut self, zone: &Zone, local: f64, report: &mut ImportReport) -> Option<f64> {
        let whole = local.floor() as i64;
        let frac = local - whole as f64;
        let bucket = whole.div_euclid(900);
        if let Some((b, off)) = self.cache {
            if b == bucket {
                return Some(local - off);
            }
        }
        let hour_label = |z: &Zone| {
            let h = whole.div_euclid(3600) * 3600;
            let t = crate::time::LocalTime::from_local_seconds(h);
            format!(
                "{}-{:02}-{:02} {:02}:00 ({})",
                t.year(),
                t.month(),
                t.day(),
                t.hour(),
                z.name()
            )
        };
        match zone.instant(whole) {
            LocalInstant::Unique(t) => {
                let start = bucket * 900;
                if zone.instant(start) == LocalInstant::Unique(start as f64 - (whole as f64 - t))
                    && zone.instant(start + 899)
                        == LocalInstant::Unique((start + 899) as f64 - (whole as f64 - t))
                {
                    self.cache = Some((bucket, whole as f64 - t));
                }
                Some(t + frac)
            }
            LocalInstant::Repeated(a, b) => {
                let first = a + frac >= self.last;
                let key = ClockNote::Repeated(hour_label(zone));
                let n = self.clock_notes.entry(key).or_insert(0);
                if first {
                    Some(a + frac)
                } else {
                    *n += 1;
                    report.second_passage += 1;
                    Some(b + frac)
                }
            }
            LocalInstant::Missing => {
                *self
                    .clock_notes
                    .entry(ClockNote::Missing(hour_label(zone)))
                    .or_insert(0) += 1;
                report.missing_times += 1;
                None
            }
        }
    }

    fn row(&mut self, layout: &Layout, line: &[u8], report: &mut ImportReport, label: &str) {
        let line = line.trim_ascii();
        if line.is_empty() || line.starts_with(b"#") {
            return;
        }
        report.rows += 1;
        self.stale += 1;
        let mut fields: [&[u8]; 16] = [&[]; 16];
        let mut n = 0;
        for f in layout.split(line) {
            if n < fields.len() {
                fields[n] = f;
            }
            n += 1;
        }
        let f = &fields[..n.min(fields.len())];
        let parsed = layout.time_of(f).and_then(|(t, off)| {
            let v = layout.number(f.get(layout.value)?)?;
            Some((t, off, v))
        });
        let Some((t, off, v)) = parsed else {
            report.unreadable += 1;
            if report.unreadable == 1 {
                let shown: String = String::from_utf8_lossy(line).chars().take(80).collect();
                report.warnings.push(format!(
                    "{label}: a row that is not a time and a frequency: {shown:?}"
                ));
            }
            return;
        };
        let instant = match (off, &layout.zone) {
            (Some(o), _) => Some(t - o),
            (None, ZoneRule::Utc(_)) => Some(t),
            (None, ZoneRule::Given(z)) => self.instant(z, t, report),
            // a row without the offset its neighbours carry
            (None, ZoneRule::InRows) => None,
        };
        let Some(instant) = instant else {
            if off.is_none() && layout.zone == ZoneRule::InRows {
                report.unreadable += 1;
            }
            return;
        };
        if instant == self.last {
            report.repeated += 1;
        }
        self.last = instant;
        if instant > self.latest {
            self.latest = instant;
            self.stale = 0;
        }
        let hz = layout.unit.to_hz(v, self.nominal);
        if (hz - self.nominal).abs().is_nan() || (hz - self.nominal).abs() > PLAUSIBLE_HZ {
            report.implausible += 1;
            return;
        }
        if self.acc.push(instant, hz) {
            report.used += 1;
        } else {
            report.far += 1;
        }
    }
}
