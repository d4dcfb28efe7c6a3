//! Plain text events: one `t x y p` per line.
//!
//! No standard exists, so the reader is lenient: `#` comments, whitespace or comma separators,
//! time in float seconds (rounded to the nearest microsecond) or integer microseconds,
//! polarity 0/1 or -1/+1.

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use crate::error::{io_err, EventError, Result};
use crate::{EventBatch, EventReader, Source, StreamInfo};

const FORMAT: &str = "text";
/// Events per batch handed on.
pub const BATCH: usize = 1 << 16;
/// Longest line accepted: an event line is a few dozen bytes, and a line is held whole.
const MAX_LINE: usize = 4096;

/// Reads one line (with its `\n`) into `buf`, holding at most [`MAX_LINE`] + 1 bytes of it;
/// returns the bytes consumed (0 at the end).
fn read_line_bounded(r: &mut impl BufRead, buf: &mut Vec<u8>) -> std::io::Result<usize> {
    buf.clear();
    r.by_ref().take(MAX_LINE as u64 + 1).read_until(b'\n', buf)
}

/// The text of a line read by [`read_line_bounded`], or why it is not a line of text.
fn line_text(buf: &[u8]) -> std::result::Result<&str, String> {
    if buf.len() > MAX_LINE {
        return Err(format!("a line longer than {MAX_LINE} bytes"));
    }
    std::str::from_utf8(buf)
        .map(|l| l.trim_end_matches(['\n', '\r']))
        .map_err(|_| "bytes that are not UTF-8 text".into())
}

/// How the time column is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeUnit {
    /// Seconds with a fraction (`0.000123`).
    Seconds,
    /// Whole microseconds.
    Micros,
}

/// Splits a data line into fields; `None` for blank and comment lines.
fn fields(line: &str) -> Option<impl Iterator<Item = &str>> {
    let l = line.trim();
    if l.is_empty() || l.starts_with('#') || l.starts_with('%') {
        return None;
    }
    Some(
        l.split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty()),
    )
}

/// True when `line` is a row of column names (no field is a number), such as `t_us,x,y,p`.
pub(crate) fn is_column_names(line: &str) -> bool {
    match fields(line) {
        Some(f) => {
            let v: Vec<&str> = f.collect();
            (3..=5).contains(&v.len()) && v.iter().all(|s| s.parse::<f64>().is_err())
        }
        None => false,
    }
}

/// True when `line` looks like an event line (four numbers).
pub(crate) fn looks_like_event_line(line: &str) -> bool {
    match fields(line) {
        Some(f) => {
            let v: Vec<&str> = f.collect();
            v.len() == 4 && v.iter().all(|s| s.parse::<f64>().is_ok())
        }
        None => false,
    }
}

/// The largest time a text file may give, µs from its epoch.
const MAX_ABS_TIME_US: f64 = 1e17;

/// The event of one data line, its time in `unit`; `None` for blank and comment lines.
pub fn parse_line(
    line: &str,
    unit: TimeUnit,
) -> std::result::Result<Option<(i64, u16, u16, bool)>, String> {
    let Some(mut f) = fields(line) else {
        return Ok(None);
    };
    let mut next = |what: &str| f.next().ok_or_else(|| format!("missing {what} column"));
    let t = next("time")?;
    let x = next("x")?;
    let y = next("y")?;
    let p = next("polarity")?;
    // a time must be a finite number within ±10¹⁷ µs (3000 years): `nan`, `inf` and 26-digit
    // values are damage, not times
    let in_range = |us: f64| {
        if us.is_finite() && us.abs() <= MAX_ABS_TIME_US {
            Ok(us.round() as i64)
        } else {
            Err(format!("time {t:?} is not a time eenf accepts"))
        }
    };
    let t = match unit {
        TimeUnit::Micros => match t.parse::<i64>() {
            Ok(v) if v.unsigned_abs() <= MAX_ABS_TIME_US as u64 => v,
            Ok(_) => in_range(f64::INFINITY)?,
            // A float in a file of integers: still microseconds.
            Err(_) => in_range(t.parse::<f64>().map_err(|_| format!("bad time {t:?}"))?)?,
        },
        TimeUnit::Seconds => {
            let s: f64 = t.parse().map_err(|_| format!("bad time {t:?}"))?;
            in_range(s * 1e6)?
        }
    };
    let coord = |v: &str, what: &str| -> std::result::Result<u16, String> {
        v.parse::<u16>()
            .or_else(|_| {
                v.parse::<f64>()
                    .ok()
                    .filter(|f| f.fract() == 0.0 && (0.0..=65535.0).contains(f))
                    .map(|f| f as u16)
                    .ok_or(())
            })
            .map_err(|_| format!("bad {what} {v:?}"))
    };
    let x = coord(x, "x")?;
    let y = coord(y, "y")?;
    let p: f64 = p
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite())
        .ok_or_else(|| format!("bad polarity {p:?}"))?;
    Ok(Some((t, x, y, p > 0.0)))
}

/// Streams events from a text file.
pub struct TextReader {
    path: PathBuf,
    lines: BufReader<Box<dyn Source>>,
    line: Vec<u8>,
    line_no: u64,
    /// Byte offset of the next line.
    offset: u64,
    unit: TimeUnit,
    info: StreamInfo,
    done: bool,
    seen_data: bool,
    /// Byte offset of the first line of the batch handed out last.
    batch_at: u64,
    /// The damage after the batch handed out last.
    failed: Option<EventError>,
}

impl TextReader {
    /// Opens a text event file; the time unit is decided from the first event line.
    pub fn open(path: &Path) -> Result<Self> {
        Self::new(
            Box::new(File::open(path).map_err(|e| io_err(path, e))?),
            path,
        )
    }

    /// Reads text events from `f` (named `path` in errors).
    pub fn new(mut f: Box<dyn Source>, path: &Path) -> Result<Self> {
        let mut unit = TimeUnit::Micros;
        f.seek(SeekFrom::Start(0)).map_err(|e| io_err(path, e))?;
        let mut head = BufReader::new(&mut f);
        let mut buf = Vec::new();
        for _ in 0..10_000 {
            if read_line_bounded(&mut head, &mut buf).map_err(|e| io_err(path, e))? == 0 {
                break;
            }
            // the reading below reports a bad line where it is
            let Ok(line) = line_text(&buf) else { break };
            if is_column_names(line) {
                continue;
            }
            let first = fields(line).map(|mut fs| fs.next().unwrap_or("").to_string());
            if let Some(t) = first {
                if t.contains(['.', 'e', 'E']) {
                    unit = TimeUnit::Seconds;
                }
                break;
            }
        }
        f.seek(SeekFrom::Start(0)).map_err(|e| io_err(path, e))?;
        Ok(TextReader {
            path: path.to_path_buf(),
            lines: BufReader::with_capacity(1 << 20, f),
            line: Vec::new(),
            line_no: 0,
            offset: 0,
            unit,
            info: StreamInfo {
                format: FORMAT,
                ..StreamInfo::default()
            },
            done: false,
            seen_data: false,
            batch_at: 0,
            failed: None,
        })
    }
}

impl EventReader for TextReader {
    fn info(&self) -> &StreamInfo {
        &self.info
    }

    fn batch_offset(&self) -> Option<u64> {
        Some(self.batch_at)
    }

    fn next_batch(&mut self) -> Result<Option<EventBatch>> {
        if let Some(e) = self.failed.take() {
            return Err(e);
        }
        if self.done {
            return Ok(None);
        }
        self.batch_at = self.offset;
        let mut batch = EventBatch::with_capacity(BATCH);
        while batch.len() < BATCH {
            let read = read_line_bounded(&mut self.lines, &mut self.line)
                .map_err(|e| io_err(&self.path, e))?;
            if read == 0 {
                self.done = true;
                break;
            }
            let at = self.offset;
            self.offset += read as u64;
            self.line_no += 1;
            let parsed = line_text(&self.line).and_then(|line| {
                if !self.seen_data && is_column_names(line) {
                    return Ok(None);
                }
                parse_line(line, self.unit)
            });
            match parsed {
                Ok(Some((t, x, y, p))) => {
                    self.seen_data = true;
                    batch.push(t, x, y, p)
                }
                Ok(None) => {}
                Err(reason) => {
                    self.done = true;
                    let e = EventError::Corrupt {
                        path: self.path.clone(),
                        format: FORMAT,
                        offset: at,
                        reason: format!("line {}: {reason}", self.line_no),
                    };
                    // the events before the damage first, then the error
                    if batch.is_empty() {
                        return Err(e);
                    }
                    self.failed = Some(e);
                    break;
                }
            }
        }
        Ok(if batch.is_empty() { None } else { Some(batch) })
    }
}

/// Text for probing ([`crate::registry`]): no NUL byte, and the first event line (after
/// comments and a line of column names) holds four numbers. Only complete lines are judged.
pub const REGISTERED: crate::Registered = crate::Registered {
    probe: |head, _, _| {
        let found = looks_like_text(head.bytes, head.cut);
        Ok(found.then(|| crate::Probed::of(crate::Format::Text)))
    },
    open: |src, path, _, _| Ok(Box::new(TextReader::new(src, path)?)),
};

/// Whether `head` reads as text events (`cut`: the stream goes on past it).
fn looks_like_text(head: &[u8], cut: bool) -> bool {
    if head.contains(&0) {
        return false;
    }
    let text = String::from_utf8_lossy(head);
    let complete = match text.rfind('\n') {
        Some(i) if cut => &text[..i],
        _ => &text[..],
    };
    let mut names_seen = false;
    for line in complete.lines() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        if !names_seen && is_column_names(l) {
            names_seen = true;
            continue;
        }
        return looks_like_event_line(l);
    }
    false
}
