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

use eenf_core::spelling::option_with;
use eenf_core::Grid;
use std::fmt;
use std::fs::File;
use std::io::{BufReader, Read};
use std::path::Path;

use crate::error::{fail, Result};
use eenf_dsp::resample::Steps;

use crate::time::Zone;

mod container;
mod dates;
mod layout;
mod operator_json;
mod state;

pub use dates::parse_date_time;
pub use layout::{sniff, Layout, TimeColumns, ZoneRule};
pub use operator_json::{swissgrid_span, OperatorJson};

use container::{container_of, first_lines, for_each_member, read_line, Container};
use state::{ClockNote, ImportState};

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
    fn zone_hint(self) -> String {
        let tz = |zone: &str| option_with("tz", zone);
        match self {
            ArchiveFormat::Fingrid => {
                format!(
                    "{} for Finnish time, {} for UTC",
                    tz("Europe/Helsinki"),
                    tz("Z")
                )
            }
            ArchiveFormat::Transnetbw => {
                format!(
                    "{} for German time, {} for UTC",
                    tz("Europe/Berlin"),
                    tz("Z")
                )
            }
            _ => format!(
                "e.g. {}, {}, {}, or {} for UTC",
                tz("Europe/Berlin"),
                tz("America/New_York"),
                tz("+08:00"),
                tz("Z")
            ),
        }
    }

    /// The grid its publisher measures (all named layouts are European, 50 Hz).
    fn nominal(self) -> Option<Grid> {
        (self != ArchiveFormat::Auto).then_some(Grid::Hz50)
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
    /// The grid (needed for deviations; else told from the values).
    pub grid: Option<Grid>,
}

/// An archive read onto regular steps.
#[derive(Debug, Clone)]
pub struct ArchiveImport {
    /// The frequency, Hz, at Unix times `start + i·step` (NaN: a gap), in time order; a new
    /// piece starts after a gap of more than six hours.
    pub steps: Vec<Steps>,
    /// The grid.
    pub grid: Grid,
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
    if operator_json::looks_like_json(&head[..n]) {
        // an operator's JSON answer (one long line), or an eenf JSON trace
        return operator_json::kind_of(path).is_some();
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
        return operator_json::kind_of(path).is_some();
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
            let nominal = match opts.grid {
                Some(g) => g,
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
        fail!(Archive, "{name}: holds no frequency rows");
    };
    if report.used == 0 {
        fail!(
            Archive,
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
    let grid = st.grid;
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
        grid,
        report,
    })
}
