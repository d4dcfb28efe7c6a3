//! Grid operators' JSON answers, read as the frequency tables the importer reads: what
//! `refdb fetch` downloads from the operators that publish JSON, and the same files given to
//! `refdb build`.
//!
//! - Svenska kraftnät's control room (`…/controlroom/v2/freq`): `{"Data": [{"x": unix_ms,
//!   "y": hz}, …]}`. Unix milliseconds are UTC by definition.
//! - Swissgrid's current frequency chart: `{"data": {"series": [{"data": [[ms, hz], …]}]}}`.
//!   Chart libraries often encode a local wall-clock time as if it were UTC, so its times are
//!   read as wall-clock times whose zone the reader states (`--tz`; `refdb fetch` tells it
//!   from the time of retrieval).
//! - Fingrid's open data API (`/api/datasets/{id}/data`): `{"data": [{"startTime":
//!   "2024-06-01T00:00:00.000Z", "value": hz}, …], "pagination": {…}}`.

use std::io::Read;
use std::path::Path;

use crate::error::{fail, Context, Result};

/// The largest JSON answer read (a Swedish hour at 1 s is about 100 kB, a Fingrid page of
/// 20,000 rows about 1.5 MB): a larger file is not one of these answers.
const MAX_JSON_BYTES: u64 = 32 << 20;

/// Which operator's JSON a file is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OperatorJson {
    /// Svenska kraftnät's control-room frequency.
    Svk,
    /// Swissgrid's current frequency chart.
    Swissgrid,
    /// Fingrid's open data API.
    Fingrid,
}

impl OperatorJson {
    /// How it is named in reports.
    pub fn describe(self) -> &'static str {
        match self {
            OperatorJson::Svk => "Svenska kraftnät control-room JSON (Data: x = Unix ms, y = Hz)",
            OperatorJson::Swissgrid => {
                "Swissgrid chart JSON (data.series[0].data: [ms, Hz], wall-clock times)"
            }
            OperatorJson::Fingrid => "Fingrid open data JSON (data: startTime, value)",
        }
    }
}

/// Whether the file starts like a JSON object (after white space).
pub(super) fn looks_like_json(head: &[u8]) -> bool {
    head.iter()
        .find(|b| !b.is_ascii_whitespace())
        .is_some_and(|&b| b == b'{')
}

/// The operator whose JSON `path` holds, `None` when it is JSON of another kind (an eenf
/// trace) or not JSON.
pub fn kind_of(path: &Path) -> Option<OperatorJson> {
    let value = read_value(path).ok()?;
    kind(&value)
}

fn kind(v: &serde_json::Value) -> Option<OperatorJson> {
    if v.get("Data").is_some() {
        Some(OperatorJson::Svk)
    } else if v.pointer("/data/series").is_some() {
        Some(OperatorJson::Swissgrid)
    } else if v
        .get("data")
        .and_then(|d| d.as_array())
        .is_some_and(|rows| {
            rows.first()
                .is_none_or(|r| r.get("startTime").is_some() || r.get("datasetId").is_some())
        })
    {
        Some(OperatorJson::Fingrid)
    } else {
        None
    }
}

fn read_value(path: &Path) -> Result<serde_json::Value> {
    let name = path.display();
    let f = std::fs::File::open(path).with_context(|| format!("{name}"))?;
    let mut text = Vec::new();
    f.take(MAX_JSON_BYTES + 1)
        .read_to_end(&mut text)
        .with_context(|| format!("{name}"))?;
    if text.len() as u64 > MAX_JSON_BYTES {
        fail!(
            Archive,
            "{name}: a JSON file over {} MB: not an operator's answer",
            MAX_JSON_BYTES >> 20
        );
    }
    serde_json::from_slice(&text).with_context(|| format!("{name}: not readable JSON"))
}

/// The rows of an operator's JSON file as a CSV table (`time,frequency_hz`), and which
/// operator's it is. A JSON file of none of the known shapes, or one whose rows are not
/// what its operator documents, is refused naming what was expected.
pub fn to_table(path: &Path) -> Result<(OperatorJson, String)> {
    let name = path.display();
    let v = read_value(path)?;
    let Some(kind) = kind(&v) else {
        fail!(
            Archive,
            "{name}: JSON, but neither Svenska kraftnät's ({{\"Data\": [{{x, y}}]}}), \
             Swissgrid's (data.series[0].data) nor Fingrid's (data: [{{startTime, value}}])"
        );
    };
    let mut out = String::from("time,frequency_hz\n");
    let mut push = |time: &str, hz: f64| {
        out.push_str(time);
        out.push(',');
        out.push_str(&hz.to_string());
        out.push('\n');
    };
    let changed = |what: &str| -> crate::error::Error {
        crate::error::Error::Archive(format!(
            "{name}: {} but {what}: the format may have changed",
            kind.describe()
        ))
    };
    match kind {
        OperatorJson::Svk => {
            let rows = v["Data"]
                .as_array()
                .ok_or_else(|| changed("Data is not a list"))?;
            for r in rows {
                let (Some(x), Some(y)) = (r.get("x"), r.get("y")) else {
                    return Err(changed("a row has no x or y"));
                };
                let (Some(ms), Some(hz)) = (x.as_f64(), number(y)) else {
                    return Err(changed("a row's x or y is not a number"));
                };
                push(
                    &format!("{}Z", clock(ms).ok_or_else(|| changed("x is no time"))?),
                    hz,
                );
            }
        }
        OperatorJson::Swissgrid => {
            let rows = v
                .pointer("/data/series/0/data")
                .and_then(|d| d.as_array())
                .ok_or_else(|| changed("data.series[0].data is not a list"))?;
            for r in rows {
                let pair = r.as_array().filter(|p| p.len() >= 2);
                let Some(p) = pair else {
                    return Err(changed("a row is not a [ms, Hz] pair"));
                };
                let (Some(ms), Some(hz)) = (p[0].as_f64(), number(&p[1])) else {
                    return Err(changed("a row's time or value is not a number"));
                };
                push(
                    &clock(ms).ok_or_else(|| changed("a time is out of range"))?,
                    hz,
                );
            }
        }
        OperatorJson::Fingrid => {
            for r in v["data"].as_array().into_iter().flatten() {
                let t = r.get("startTime").and_then(|t| t.as_str());
                let (Some(t), Some(hz)) = (t, r.get("value").and_then(number)) else {
                    return Err(changed("a row has no startTime or value"));
                };
                if t.contains([',', '\n', '"']) {
                    return Err(changed("a startTime is not a time"));
                }
                push(t, hz);
            }
        }
    }
    Ok((kind, out))
}

/// A JSON number, or a number written as a string.
fn number(v: &serde_json::Value) -> Option<f64> {
    v.as_f64()
        .or_else(|| v.as_str().and_then(|s| s.trim().parse().ok()))
        .filter(|x: &f64| x.is_finite())
}

/// Milliseconds after 1970-01-01 00:00 as the clock `YYYY-MM-DDTHH:MM:SS.ffffff`, no zone.
fn clock(ms: f64) -> Option<String> {
    // the calendar's years (-9999 to 9999), as before; the importer drops rows outside its own
    if !ms.is_finite() || ms.abs() > 2.5e14 {
        return None;
    }
    let text = crate::time::utc_micros((ms * 1000.0).round() as i64);
    Some(text.trim_end_matches('Z').to_string())
}

/// The first and last time (ms, as written) of a Swissgrid chart answer, `None` when it holds
/// no points.
pub fn swissgrid_span(path: &Path) -> Option<(f64, f64)> {
    let v = read_value(path).ok()?;
    let rows = v.pointer("/data/series/0/data")?.as_array()?;
    let time = |r: &serde_json::Value| r.get(0).and_then(|t| t.as_f64());
    Some((time(rows.first()?)?, time(rows.last()?)?))
}
