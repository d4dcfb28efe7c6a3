//! An archive's layout, told from its first lines: separator, header, the columns giving a
//! row's time and its value, the value's unit, the decimal mark, the date order and the zone.

use eenf_core::spelling::{option, option_with};
use eenf_core::Grid;
use std::path::Path;

use crate::error::{fail, Error, Missing, Result};

use super::dates::{civil_seconds, parse_clock, parse_date, parse_date_time, DateShape};
use super::{ArchiveFormat, ArchiveOptions, DateOrder, ValueUnit, MAX_STEP_S, YEARS};
use crate::time::Zone;

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
    pub(super) fn describe(&self) -> String {
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

    pub(super) fn zone_text(&self) -> String {
        match &self.zone {
            ZoneRule::InRows => "with their own UTC offsets".into(),
            ZoneRule::Utc(why) => format!("in {why}"),
            ZoneRule::Given(z) if z.name() == "UTC" => format!("in UTC ({})", option("tz")),
            ZoneRule::Given(z) => format!("local to {} ({})", z.name(), option("tz")),
        }
    }

    pub(super) fn split<'a>(&self, line: &'a [u8]) -> impl Iterator<Item = &'a [u8]> + 'a {
        let d = self.delimiter;
        line.split(move |&b| b == d).map(clean)
    }

    pub(super) fn number(&self, s: &[u8]) -> Option<f64> {
        number(s, self.decimal_comma)
    }

    /// The row's wall-clock time (seconds after 1970-01-01 00:00 of its clock, with their
    /// fraction) and its UTC offset when it carries one; or its Unix time.
    pub(super) fn time_of(&self, f: &[&[u8]]) -> Option<(f64, Option<f64>)> {
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
    pub(super) fn nominal(&self, lines: &[String], label: &str) -> Result<Grid> {
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
                    Ok(Grid::Hz50)
                } else if (55.0..65.0).contains(&m) {
                    Ok(Grid::Hz60)
                } else {
                    fail!(Archive, "{label}: its values (median {m}) are not near 50 or 60 Hz")
                }
            }
            _ => fail!(Archive,
                "{label}: its values are deviations from the nominal frequency: give it with {} or {}",
                option_with("nominal", "50"),
                option_with("nominal", "60")
            ),
        }
    }

    /// The median spacing of the first rows' times, s (1 when they do not tell).
    pub(super) fn native_step(&self, lines: &[String]) -> f64 {
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

pub(super) fn median(mut v: Vec<f64>) -> Option<f64> {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

/// A field without its spaces and quotes.
pub(super) fn clean(f: &[u8]) -> &[u8] {
    let f = f.trim_ascii();
    let f = f.strip_prefix(b"\"").unwrap_or(f);
    let f = f.strip_suffix(b"\"").unwrap_or(f);
    f.trim_ascii()
}

pub(super) fn number(s: &[u8], decimal_comma: bool) -> Option<f64> {
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

/// What one field of the sampled rows is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum FieldKind {
    DateTime,
    Date,
    Clock,
    Number,
    Text,
}

pub(super) fn kind_of(f: &[u8], decimal_comma: bool) -> FieldKind {
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
        .or_fail(Error::Archive, || {
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
        fail!(Archive, "{name}: a header ({shown:?}) and no rows");
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
            fail!(Archive, "{name}: not the osf layout (expected year;month;day;hour;minute;second;value rows without a header), first line {shown:?}");
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
        fail!(
            Archive,
            "{name}: no time column: expected {expected}; first line {shown:?}"
        );
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
        .or_fail(Error::Archive, || {
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
                fail!(Archive,
                    "{name}: column {} ({:?}) is not near 50 or 60 Hz and its header does not say it is a deviation: give {} hz, mhz-deviation or hz-deviation",
                    value + 1,
                    names[value],
                    option("value_unit")
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
                fail!(Archive,
                    "{name}: dates such as {:?} can be read day/month or month/day: give {} dmy or mdy",
                    String::from_utf8_lossy(field(c)),
                    option("date_order")
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
        fail!(
            Archive,
            "{name}: its times ({:?}) carry no zone and none is assumed: give it with {} ({})",
            String::from_utf8_lossy(field(date_col.unwrap_or(0))),
            option("tz"),
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
