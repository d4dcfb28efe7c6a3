//! Time: absolute instants (Unix seconds, UTC strings), UTC offsets, and the local wall-clock
//! times that EV-ENFD file names carry. Calendar arithmetic is jiff's.

use anyhow::{bail, Context, Result};
use jiff::civil::{DateTime, Weekday};
use jiff::tz::Offset;
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

/// Parses a time: Unix seconds (`1660723800`), or ISO 8601 / RFC 3339 with its UTC offset
/// (`2022-08-17T16:10:00+08:00`, `2022-08-17T08:10:00Z`). A time without a zone is refused,
/// never taken as UTC. Unix seconds.
pub fn parse_time(s: &str) -> Result<f64> {
    if let Ok(v) = s.parse::<f64>() {
        return Ok(v);
    }
    let s = s.trim();
    let bad = || {
        anyhow::anyhow!(
            "{s:?}: expected a time like 2022-08-17T16:10:00Z or 2022-08-17T16:10:00+08:00"
        )
    };
    let ts = match s.parse::<Timestamp>() {
        Ok(ts) => ts,
        Err(_) => {
            if s.parse::<DateTime>().is_ok() {
                bail!("{s:?} names no time zone: add Z for UTC or the offset, e.g. {s}+08:00");
            }
            return Err(bad());
        }
    };
    Ok(ts.as_second() as f64 + ts.subsec_nanosecond() as f64 * 1e-9)
}

/// `Z`, `UTC`, `+08:00`, `-0500`, `+8` → seconds east of UTC.
pub fn tz_offset(tz: &str) -> Result<f64> {
    if tz.is_empty() || tz == "Z" || tz.eq_ignore_ascii_case("utc") {
        return Ok(0.0);
    }
    let sign = match tz.as_bytes()[0] {
        b'+' => 1.0,
        b'-' => -1.0,
        _ => bail!("{tz:?}: expected a UTC offset like +08:00"),
    };
    let digits: String = tz[1..].chars().filter(|c| c.is_ascii_digit()).collect();
    let (h, m) = match digits.len() {
        1 | 2 => (digits.parse::<f64>()?, 0.0),
        4 => (digits[..2].parse::<f64>()?, digits[2..].parse::<f64>()?),
        _ => bail!("{tz:?}: expected a UTC offset like +08:00"),
    };
    if h > 18.0 || m >= 60.0 {
        bail!("{tz:?}: expected a UTC offset like +08:00");
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
    let minutes = (tz_s / 60.0).round() as i64;
    let sign = if minutes < 0 { '-' } else { '+' };
    format!(
        "{} {sign}{:02}:{:02}",
        shifted.trim_end_matches('Z').replace('T', " "),
        minutes.abs() / 60,
        minutes.abs() % 60
    )
}

/// A µs Unix timestamp as ISO 8601 UTC with microseconds, e.g. `2022-08-17T08:10:00.000000Z`.
pub fn utc_micros(us: i64) -> String {
    let secs = us.div_euclid(1_000_000);
    let micros = us.rem_euclid(1_000_000);
    let t = LocalTime::from_local_seconds(secs);
    format!("{}.{micros:06}Z", t.0.strftime("%Y-%m-%dT%H:%M:%S"))
}

/// Unix seconds as ISO 8601 UTC, microseconds shown only when not zero:
/// `2022-08-17T08:10:00Z`.
pub fn utc(unix_s: f64) -> String {
    utc_micros((unix_s * 1e6).round() as i64).replace(".000000Z", "Z")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_formatting() {
        assert_eq!(utc_micros(0), "1970-01-01T00:00:00.000000Z");
        assert_eq!(
            utc_micros(1_660_723_800_000_001),
            "2022-08-17T08:10:00.000001Z"
        );
    }

    #[test]
    fn times_parse() {
        assert_eq!(parse_time("1970-01-02T00:00:00Z").unwrap(), 86_400.0);
        assert_eq!(
            parse_time("2022-08-17T16:00:00+08:00").unwrap(),
            parse_time("2022-08-17T08:00:00Z").unwrap()
        );
        assert_eq!(parse_time("12.5").unwrap(), 12.5);
        assert!(parse_time("yesterday").is_err());
        assert_eq!(utc(1_660_723_200.0), "2022-08-17T08:00:00Z");
        assert_eq!(
            parse_time("2022-08-01T00:00:00-04:00").unwrap(),
            parse_time("2022-08-01T04:00:00Z").unwrap()
        );
        assert_eq!(tz_offset("+08:00").unwrap(), 28_800.0);
        assert_eq!(tz_offset("-0500").unwrap(), -18_000.0);
        assert_eq!(offset_of("2022-08-17T16:10:00+08:00").unwrap(), 28_800.0);
        assert_eq!(offset_of("2022-08-17T16:10:00").unwrap(), 0.0);
    }

    #[test]
    fn civil_days() {
        let day = |y, m, d| LocalTime::new(y, m, d, 0, 0, 0).unwrap().local_seconds() / 86_400;
        assert_eq!(day(1970, 1, 1), 0);
        assert_eq!(day(2022, 8, 17), 19_221);
        assert_eq!(day(2000, 3, 1), 11_017);
        let leap = LocalTime::from_local_seconds(day(2024, 2, 29) * 86_400 + 3661);
        assert_eq!(
            (leap.month(), leap.day(), leap.hour(), leap.minute()),
            (2, 29, 1, 1)
        );
        assert_eq!(leap.weekday(), "Thu");
    }
}
