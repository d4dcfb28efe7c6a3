//! Time: absolute instants (Unix seconds, UTC strings), time zones (IANA names with their
//! summer time, or fixed UTC offsets), and the local wall-clock times that file names and
//! archives carry. Calendar arithmetic and the time zone database are jiff's (the system's
//! zoneinfo, or the copy built in where a machine has none).

use crate::error::{error, fail, Context, Error, Result};
use jiff::civil::{DateTime, Weekday};
use jiff::tz::{AmbiguousOffset, Offset, TimeZone};
use jiff::Timestamp;

/// A local wall-clock time (no zone), to the second, as a file name states it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct LocalTime(DateTime);

impl LocalTime {
    /// The time of a date and clock, if they exist in the calendar.
    pub fn new(year: i16, month: i8, day: i8, hour: i8, minute: i8, second: i8) -> Option<Self> {
        DateTime::new(year, month, day, hour, minute, second, 0)
            .ok()
            .map(LocalTime)
    }

    /// The wall-clock time `seconds` after 1970-01-01 00:00 (local time, no zone).
    pub fn from_local_seconds(seconds: i64) -> Self {
        let ts = Timestamp::from_second(
            seconds.clamp(Timestamp::MIN.as_second(), Timestamp::MAX.as_second()),
        )
        .unwrap_or(Timestamp::UNIX_EPOCH);
        LocalTime(Offset::UTC.to_datetime(ts))
    }

    /// Seconds after 1970-01-01 00:00 of this wall-clock time.
    pub fn local_seconds(&self) -> i64 {
        Offset::UTC
            .to_timestamp(self.0)
            .map(|t| t.as_second())
            .unwrap_or(0)
    }

    /// The calendar year.
    pub fn year(&self) -> i16 {
        self.0.year()
    }
    /// Month, 1–12.
    pub fn month(&self) -> i8 {
        self.0.month()
    }
    /// Day of the month, 1–31.
    pub fn day(&self) -> i8 {
        self.0.day()
    }
    /// Hour, 0–23.
    pub fn hour(&self) -> i8 {
        self.0.hour()
    }
    /// Minute, 0–59.
    pub fn minute(&self) -> i8 {
        self.0.minute()
    }
    /// Second, 0–59.
    pub fn second(&self) -> i8 {
        self.0.second()
    }

    /// Seconds into the hour.
    pub fn second_of_hour(&self) -> u32 {
        self.minute() as u32 * 60 + self.second() as u32
    }

    /// The hour this time falls in (minutes and seconds dropped).
    pub fn hour_start(&self) -> LocalTime {
        LocalTime::from_local_seconds(self.local_seconds().div_euclid(3600) * 3600)
    }

    /// Whole hours since 1970-01-01 00:00.
    pub fn hour_index(&self) -> i64 {
        self.local_seconds().div_euclid(3600)
    }

    /// The date as `YYYY_MM_DD`.
    pub fn date(&self) -> String {
        self.0.strftime("%Y_%m_%d").to_string()
    }

    /// `Mon`…`Sun`.
    pub fn weekday(&self) -> &'static str {
        match self.0.weekday() {
            Weekday::Monday => "Mon",
            Weekday::Tuesday => "Tue",
            Weekday::Wednesday => "Wed",
            Weekday::Thursday => "Thu",
            Weekday::Friday => "Fri",
            Weekday::Saturday => "Sat",
            Weekday::Sunday => "Sun",
        }
    }

    /// The instant of this wall-clock time at `tz_s` seconds east of UTC, Unix seconds.
    pub fn unix_seconds(&self, tz_s: f64) -> f64 {
        self.local_seconds() as f64 - tz_s
    }
}

/// A time zone: an IANA name (`Europe/Berlin`, whose offset follows summer time) or a fixed
/// UTC offset (`+08:00`, `Z`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Zone(TimeZone);

/// What a local wall-clock time is in a zone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LocalInstant {
    /// One instant, Unix seconds.
    Unique(f64),
    /// A time the clocks passed twice (the hour repeated when summer time ends): the first
    /// and the second passage, Unix seconds.
    Repeated(f64, f64),
    /// A time the clocks skipped (the hour missing when summer time starts).
    Missing,
}

impl Zone {
    /// UTC.
    pub fn utc() -> Self {
        Zone(TimeZone::UTC)
    }

    /// A fixed offset, seconds east of UTC.
    pub fn fixed(seconds: f64) -> Result<Self> {
        let s = seconds.round();
        if s.is_nan() || s.abs() > 18.0 * 3600.0 {
            fail!(Input, "{seconds} s: not a UTC offset (at most 18 hours)");
        }
        Ok(Zone(TimeZone::fixed(Offset::from_seconds(s as i32)?)))
    }

    /// `Z`, `UTC`, an offset (`+08:00`, `-0500`, `+8`) or an IANA name (`Europe/Berlin`,
    /// `America/New_York`).
    pub fn parse(s: &str) -> Result<Self> {
        let s = s.trim();
        if s.is_empty() || s == "Z" || s.eq_ignore_ascii_case("utc") {
            return Ok(Zone::utc());
        }
        if s.starts_with(['+', '-']) {
            return Zone::fixed(tz_offset(s)?);
        }
        match TimeZone::get(s) {
            Ok(tz) => Ok(Zone(tz)),
            Err(_) => fail!(
                Input,
                "{s:?}: not a time zone: give an IANA name (Europe/Berlin, America/New_York, \
                 Asia/Shanghai), an offset (+08:00) or Z for UTC"
            ),
        }
    }

    /// Its name: the IANA name, `UTC`, or the offset (`+08:00`).
    pub fn name(&self) -> String {
        if let Some(n) = self.0.iana_name() {
            return n.to_string();
        }
        let o = self.0.to_offset(Timestamp::UNIX_EPOCH).seconds();
        if o == 0 {
            "UTC".into()
        } else {
            offset_label(o as f64)
        }
    }

    /// Whether its offset never changes (UTC or a fixed offset).
    pub fn is_fixed(&self) -> bool {
        self.0.iana_name().is_none() || self.0.iana_name() == Some("UTC")
    }

    /// Its offset at an instant, seconds east of UTC.
    pub fn offset_at(&self, unix_s: f64) -> f64 {
        self.0.to_offset(timestamp(unix_s)).seconds() as f64
    }

    /// The instant(s) of a wall-clock time given as seconds after 1970-01-01 00:00 of the
    /// wall clock (see [`LocalTime::local_seconds`]).
    pub fn instant(&self, local_seconds: i64) -> LocalInstant {
        let dt = LocalTime::from_local_seconds(local_seconds).0;
        let l = local_seconds as f64;
        match self.0.to_ambiguous_timestamp(dt).offset() {
            AmbiguousOffset::Unambiguous { offset } => {
                LocalInstant::Unique(l - offset.seconds() as f64)
            }
            AmbiguousOffset::Fold { before, after } => {
                LocalInstant::Repeated(l - before.seconds() as f64, l - after.seconds() as f64)
            }
            AmbiguousOffset::Gap { .. } => LocalInstant::Missing,
        }
    }

    /// An instant as the wall-clock time of this zone with its offset:
    /// `2022-08-17 16:10:00 +08:00`.
    pub fn local(&self, unix_s: f64) -> String {
        local(unix_s, self.offset_at(unix_s))
    }
}

impl std::str::FromStr for Zone {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Zone::parse(s)
    }
}

fn timestamp(unix_s: f64) -> Timestamp {
    let s = unix_s.floor().clamp(
        Timestamp::MIN.as_second() as f64,
        Timestamp::MAX.as_second() as f64,
    );
    Timestamp::from_second(s as i64).unwrap_or(Timestamp::UNIX_EPOCH)
}

/// `+08:00`, `-05:30`.
fn offset_label(seconds: f64) -> String {
    let minutes = (seconds / 60.0).round() as i64;
    let sign = if minutes < 0 { '-' } else { '+' };
    format!("{sign}{:02}:{:02}", minutes.abs() / 60, minutes.abs() % 60)
}

/// Days from 1970-01-01 to a date of the proleptic Gregorian calendar (no check that the
/// date exists: callers check month and day). Cheap enough for every row of an archive.
pub fn days_from_civil(year: i64, month: u32, day: u32) -> i64 {
    // H. Hinnant's algorithm: years counted from March, in 400-year eras
    let y = if month <= 2 { year - 1 } else { year };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let m = month as i64;
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + day as i64 - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// Days in a month of a year.
pub fn days_in_month(year: i64, month: u32) -> u32 {
    match month {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if (year % 4 == 0 && year % 100 != 0) || year % 400 == 0 => 29,
        2 => 28,
        _ => 0,
    }
}

/// Parses a time: Unix seconds (`1660723800`), or ISO 8601 / RFC 3339 with its UTC offset
/// (`2022-08-17T16:10:00+08:00`, `2022-08-17T08:10:00Z`). A time without a zone is refused,
/// never taken as UTC. Unix seconds.
pub fn parse_time(s: &str) -> Result<f64> {
    if let Ok(v) = s.parse::<f64>() {
        return Ok(v);
    }
    let s = s.trim();
    let bad = || {
        error!(
            Input,
            "{s:?}: expected a time like 2022-08-17T16:10:00Z or 2022-08-17T16:10:00+08:00"
        )
    };
    let ts = match s.parse::<Timestamp>() {
        Ok(ts) => ts,
        Err(_) => {
            if s.parse::<DateTime>().is_ok() {
                fail!(
                    Input,
                    "{s:?} names no time zone: add Z for UTC or the offset, e.g. {s}+08:00"
                );
            }
            return Err(bad());
        }
    };
    Ok(ts.as_second() as f64 + ts.subsec_nanosecond() as f64 * 1e-9)
}

/// A day (`2024-06-01`: its start in UTC, or with `end_of_day` its end) or a time with its
/// zone ([`parse_time`]), Unix seconds.
pub fn parse_day_or_time(s: &str, end_of_day: bool) -> Result<f64> {
    let day = s.trim();
    let is_day = day.len() == 10 && day.as_bytes()[4] == b'-' && day.as_bytes()[7] == b'-';
    if let Some(d) = is_day
        .then(|| day.parse::<jiff::civil::Date>().ok())
        .flatten()
    {
        let start =
            days_from_civil(d.year() as i64, d.month() as u32, d.day() as u32) as f64 * 86_400.0;
        return Ok(if end_of_day { start + 86_400.0 } else { start });
    }
    parse_time(s)
}

/// `Z`, `UTC`, `+08:00`, `-0500`, `+8` → seconds east of UTC.
pub fn tz_offset(tz: &str) -> Result<f64> {
    if tz.is_empty() || tz == "Z" || tz.eq_ignore_ascii_case("utc") {
        return Ok(0.0);
    }
    let sign = match tz.as_bytes()[0] {
        b'+' => 1.0,
        b'-' => -1.0,
        _ => fail!(Input, "{tz:?}: expected a UTC offset like +08:00"),
    };
    let digits: String = tz[1..].chars().filter(|c| c.is_ascii_digit()).collect();
    let (h, m) = match digits.len() {
        1 | 2 => (digits.parse::<f64>()?, 0.0),
        4 => (digits[..2].parse::<f64>()?, digits[2..].parse::<f64>()?),
        _ => fail!(Input, "{tz:?}: expected a UTC offset like +08:00"),
    };
    if h > 18.0 || m >= 60.0 {
        fail!(Input, "{tz:?}: expected a UTC offset like +08:00");
    }
    Ok(sign * (h * 3600.0 + m * 60.0))
}

/// The UTC offset at the end of a time string such as `2022-08-17T16:10:00+08:00` (UTC when
/// it names none).
pub fn offset_of(s: &str) -> Result<f64> {
    let tail = s
        .rfind(['+', 'Z'])
        .filter(|&i| i > 10)
        .or_else(|| s.rfind('-').filter(|&i| i > 10))
        .map(|i| &s[i..])
        .unwrap_or("Z");
    tz_offset(tail).context("the time's UTC offset")
}

/// Unix seconds as the wall-clock time at `tz_s` seconds east of UTC, with its offset:
/// `2022-08-17 16:10:00 +08:00`.
pub fn local(unix_s: f64, tz_s: f64) -> String {
    let shifted = utc(unix_s + tz_s);
    format!(
        "{} {}",
        shifted.trim_end_matches('Z').replace('T', " "),
        offset_label(tz_s)
    )
}

/// A µs Unix timestamp as ISO 8601 UTC with microseconds, e.g. `2022-08-17T08:10:00.000000Z`.
pub fn utc_micros(us: i64) -> String {
    let secs = us.div_euclid(1_000_000);
    let micros = us.rem_euclid(1_000_000);
    let t = LocalTime::from_local_seconds(secs);
    format!("{}.{micros:06}Z", t.0.strftime("%Y-%m-%dT%H:%M:%S"))
}

/// The earliest event time read as a date (2000-01-01): cameras that count from their own start
/// (Prophesee's `.raw`, N-CARS, jAER's relative stamps) give times before it, which name no
/// wall-clock date.
pub const WALL_CLOCK_FROM_US: i64 = 946_684_800_000_000;

/// An event time in µs as a reader says it: ISO 8601 UTC when it is a wall-clock time, else
/// the seconds on the camera's own clock (`12.5 s on the camera's clock, no date`).
pub fn clock_text(us: i64) -> String {
    if us >= WALL_CLOCK_FROM_US {
        utc_micros(us)
    } else {
        format!("{:.6} s on the camera's clock, no date", us as f64 / 1e6)
    }
}

/// Unix seconds as ISO 8601 UTC, microseconds shown only when not zero:
/// `2022-08-17T08:10:00Z`.
pub fn utc(unix_s: f64) -> String {
    utc_micros((unix_s * 1e6).round() as i64).replace(".000000Z", "Z")
}
