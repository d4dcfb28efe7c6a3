//! Dates, clocks and offsets as archives write them, parsed from bytes without allocating.

use super::{DateOrder, YEARS};
use crate::time::{days_from_civil, days_in_month};

/// Seconds after 1970-01-01 00:00 of a date's midnight, when the date exists.
pub(super) fn civil_seconds(y: i64, m: u32, d: u32) -> Option<i64> {
    if !YEARS.contains(&y) || !(1..=12).contains(&m) || d == 0 || d > days_in_month(y, m) {
        return None;
    }
    Some(days_from_civil(y, m, d) * 86_400)
}

/// Digits as a number (1 to 4 of them).
pub(super) fn digits(s: &[u8]) -> Option<u32> {
    if s.is_empty() || s.len() > 4 || !s.iter().all(u8::is_ascii_digit) {
        return None;
    }
    Some(s.iter().fold(0, |a, &b| a * 10 + (b - b'0') as u32))
}

/// How a date is written: year first, or year last after two fields whose order the layout
/// must tell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum DateShape {
    YearFirst,
    YearLast { first: u32, second: u32 },
}

/// A date `YYYY-MM-DD`, `YYYY/MM/DD`, `DD.MM.YYYY`, `DD/MM/YYYY` or `MM/DD/YYYY`, `DD-MM-YYYY`.
pub(super) fn parse_date(s: &[u8], order: DateOrder) -> Option<((i64, u32, u32), DateShape)> {
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
pub(super) fn parse_clock(s: &[u8]) -> Option<(f64, Option<f64>)> {
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
pub(super) fn parse_offset(z: &[u8]) -> Option<Option<f64>> {
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
