//! What each grid operator publishes, where, and how a span of time becomes requests.

use std::path::{Path, PathBuf};

use crate::archive::ArchiveFormat;
use crate::error::{fail, Result};
use crate::time::{days_from_civil, days_in_month, utc, Zone};

/// A grid operator's frequency data that `refdb fetch` can ask for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// Great Britain: National Grid ESO / NESO "system frequency data", monthly CSV or zip
    /// files (`dtm,f`, 1 s, UTC) listed by the data set's datapackage JSON.
    Gb,
    /// Sweden (Nordic grid): Svenska kraftnät's control-room frequency JSON, at most an hour
    /// per request (Unix milliseconds, UTC).
    Se,
    /// Switzerland (Continental Europe): Swissgrid's current frequency chart, its last
    /// minutes only.
    Ch,
    /// Continental Europe: a file of the OSF power grid frequency database (WETI), at the
    /// address given with `--endpoint`.
    Osf,
    /// Finland (Nordic grid): Fingrid's open data API, a data set's values a day per request
    /// (pages of 20,000 rows), with a free API key.
    Fi,
}

impl Source {
    /// Names `refdb fetch` takes.
    pub const NAMES: [&'static str; 5] = ["gb", "se", "ch", "osf", "fi"];

    /// Its name.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The source of a name.
    pub fn from_name(s: &str) -> Option<Source> {
        [Source::Gb, Source::Se, Source::Ch, Source::Osf, Source::Fi]
            .into_iter()
            .find(|x| x.name().eq_ignore_ascii_case(s))
    }

    /// The operator and the data, for messages and `refdb info`.
    pub fn describe(self) -> &'static str {
        match self {
            Source::Gb => "National Grid ESO / NESO system frequency data (GB, 1 s, UTC)",
            Source::Se => "Svenska kraftnät control-room frequency (Nordic grid, UTC)",
            Source::Ch => "Swissgrid current frequency (Continental Europe, last minutes only)",
            Source::Osf => "OSF power grid frequency database file (Continental Europe, UTC)",
            Source::Fi => "Fingrid open data API (Nordic grid, UTC)",
        }
    }

    /// The operator's address asked unless `--endpoint` gives another.
    pub fn default_endpoint(self) -> Option<&'static str> {
        match self {
            Source::Gb => Some(
                "https://api.neso.energy/api/3/action/datapackage_show?id=system-frequency-data",
            ),
            Source::Se => Some("https://www.svk.se/services/controlroom/v2/freq"),
            Source::Ch => Some(
                "https://www.swissgrid.ch/content/swissgrid/en/home/operation/regulation/frequency.apicache.html?path=/content/swissgrid/en/home/operation/regulation/frequency/jcr:content/parsys/chart_copy",
            ),
            Source::Osf => None,
            // data set 177: "Frequency - real time data"
            Source::Fi => Some("https://data.fingrid.fi/api/datasets/177/data"),
        }
    }

    /// The grid's name in the store unless `--grid` gives another.
    pub fn default_grid(self) -> &'static str {
        match self {
            Source::Gb => "gb",
            Source::Se => "se",
            Source::Ch => "ch",
            Source::Osf => "ce",
            Source::Fi => "fi",
        }
    }

    /// Least time between two requests: the operators publish no limit for these files;
    /// this keeps a long fetch polite.
    pub(super) fn pause_s(self) -> f64 {
        match self {
            Source::Gb | Source::Osf => 0.5,
            Source::Se => 0.5,
            Source::Ch => 0.0,
            // Fingrid allows 10 requests a minute per key
            Source::Fi => 6.0,
        }
    }

    /// The layout its files are read with.
    pub(super) fn format(self) -> ArchiveFormat {
        match self {
            Source::Gb => ArchiveFormat::Ngeso,
            Source::Osf => ArchiveFormat::Osf,
            Source::Se | Source::Ch | Source::Fi => ArchiveFormat::Auto,
        }
    }
}

/// One file to download: its address, where the cache keeps it, and whether a copy already
/// there is final (a past month or hour) and is used again rather than downloaded.
#[derive(Debug, Clone)]
pub(super) struct Download {
    pub url: String,
    pub path: PathBuf,
    pub reuse: bool,
}

/// A short, stable tag of an address, for cache file names.
pub(super) fn tag(url: &str) -> String {
    use sha2::Digest;
    let d = sha2::Sha256::digest(url.as_bytes());
    d[..4].iter().map(|b| format!("{b:02x}")).collect()
}

/// `url` with a query appended.
fn with_query(url: &str, query: &str) -> String {
    let sep = if url.contains('?') { '&' } else { '?' };
    format!("{url}{sep}{query}")
}

/// An index's file address as an absolute URL: as given when it has a scheme, else resolved
/// against the index's address (`/files/x.csv` from its host, `x.csv` beside it).
fn absolute(path: &str, index: &str) -> String {
    if path.contains("://") {
        return path.to_string();
    }
    let base = index.split(['?', '#']).next().unwrap_or(index);
    let host_end = base
        .find("://")
        .map(|i| i + 3)
        .and_then(|i| base[i..].find('/').map(|j| i + j))
        .unwrap_or(base.len());
    if path.starts_with('/') {
        format!("{}{path}", &base[..host_end])
    } else {
        let dir = base
            .rfind('/')
            .filter(|&i| i >= host_end)
            .unwrap_or(base.len());
        format!("{}/{path}", &base[..dir])
    }
}

const MONTHS: [&str; 12] = [
    "january",
    "february",
    "march",
    "april",
    "may",
    "june",
    "july",
    "august",
    "september",
    "october",
    "november",
    "december",
];

/// The month a GB resource's name reads like (`september_2022_-_historic_frequency_data`,
/// `f-2022-9`): a month's name and a four-digit year among its words.
fn month_of(name: &str) -> Option<(i64, u32)> {
    let lower = name.to_ascii_lowercase();
    let words: Vec<&str> = lower
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| !w.is_empty())
        .collect();
    let year = words
        .iter()
        .find(|w| w.len() == 4 && w.chars().all(|c| c.is_ascii_digit()))?
        .parse::<i64>()
        .ok()?;
    let month = words
        .iter()
        .find_map(|w| MONTHS.iter().position(|m| m == w))
        .map(|m| m as u32 + 1)?;
    Some((year, month))
}

/// Unix seconds of a month's first instant (UTC).
fn month_start(year: i64, month: u32) -> f64 {
    (days_from_civil(year, month, 1) * 86_400) as f64
}

/// The GB months that overlap `[from, to)`, from the datapackage index: each file's address
/// and where the cache keeps it. Months the index does not list are named in `notes`.
pub(super) fn gb_plan(
    index: &[u8],
    endpoint: &str,
    from: f64,
    to: f64,
    now: f64,
    cache: &Path,
    notes: &mut Vec<String>,
) -> Result<Vec<Download>> {
    let expected = "NESO's datapackage JSON: result.resources[] with name, path and format";
    let Ok(v) = serde_json::from_slice::<serde_json::Value>(index) else {
        fail!(Fetch, "gb: {endpoint}: not JSON (expected {expected})");
    };
    let resources = v
        .pointer("/result/resources")
        .or_else(|| v.get("resources"))
        .and_then(|r| r.as_array());
    let Some(resources) = resources else {
        fail!(
            Fetch,
            "gb: {endpoint}: no resources list (expected {expected})"
        );
    };
    let mut months = Vec::new();
    for r in resources {
        let Some((y, m)) = r.get("name").and_then(|n| n.as_str()).and_then(month_of) else {
            continue;
        };
        let url = r
            .get("path")
            .or_else(|| r.get("url"))
            .and_then(|p| p.as_str());
        let Some(url) = url else {
            fail!(
                Fetch,
                "gb: {endpoint}: the file of {y}-{m:02} has no path (expected {expected})"
            );
        };
        let kind = ["format", "mediatype", "mimetype"]
            .iter()
            .filter_map(|k| r.get(*k).and_then(|f| f.as_str()))
            .collect::<Vec<_>>()
            .join(" ")
            .to_ascii_lowercase();
        let zip = kind.contains("zip") || url.to_ascii_lowercase().ends_with(".zip");
        months.push((
            y,
            m,
            absolute(url, endpoint),
            if zip { "zip" } else { "csv" },
        ));
    }
    if months.is_empty() {
        fail!(
            Fetch,
            "gb: {endpoint}: lists no monthly frequency file (expected names like \
             september_2022_-_historic_frequency_data)"
        );
    }
    months.sort_by_key(|(y, m, _, _)| (*y, *m));
    let mut plan = Vec::new();
    let mut missing = Vec::new();
    let (mut y, mut m) = civil_month(from);
    while month_start(y, m) < to {
        let end = month_start(y, m) + days_in_month(y, m) as f64 * 86_400.0;
        match months.iter().find(|(yy, mm, _, _)| (*yy, *mm) == (y, m)) {
            Some((_, _, url, ext)) => {
                // a month not over yet grows: its file is never used again
                let done = end <= now;
                let name = format!(
                    "{y}-{m:02}-{}{}.{ext}",
                    tag(url),
                    if done { "" } else { "-partial" }
                );
                plan.push(Download {
                    url: url.clone(),
                    path: cache.join(name),
                    reuse: done,
                });
            }
            None => missing.push(format!("{y}-{m:02}")),
        }
        (y, m) = if m == 12 { (y + 1, 1) } else { (y, m + 1) };
    }
    let (fy, fm, _, _) = &months[0];
    let (ly, lm, _, _) = &months[months.len() - 1];
    let covers = format!("its files cover {fy}-{fm:02} to {ly}-{lm:02}");
    match missing.as_slice() {
        [] => {}
        [one] => notes.push(format!("gb: the index lists no file for {one} ({covers})")),
        [first, .., last] => notes.push(format!(
            "gb: the index lists no file for the {} months {first} to {last} ({covers})",
            missing.len()
        )),
    }
    Ok(plan)
}

/// The year and month of a Unix time (UTC).
fn civil_month(t: f64) -> (i64, u32) {
    let day = crate::time::LocalTime::from_local_seconds(t.floor() as i64);
    (day.year() as i64, day.month() as u32)
}

/// The Swedish hours that overlap `[from, to)`, one request each (the control room gives at
/// most an hour per request).
pub(super) fn se_plan(endpoint: &str, from: f64, to: f64, now: f64, cache: &Path) -> Vec<Download> {
    let mut plan = Vec::new();
    let mut h = (from / 3600.0).floor() as i64;
    let to = to.min(now);
    while (h as f64) * 3600.0 < to {
        let start_ms = h * 3_600_000;
        let end_ms = (((h + 1) * 3600) as f64).min(to) as i64 * 1000;
        let done = end_ms == (h + 1) * 3_600_000 && ((h + 1) * 3600) as f64 <= now - 60.0;
        // an address may carry the query as libhum's template does; else it is appended
        let url = if endpoint.contains("{from_dt}") {
            endpoint
                .replace("{from_dt}", &start_ms.to_string())
                .replace("{to_dt}", &end_ms.to_string())
        } else {
            with_query(
                endpoint,
                &format!("fromDateTime={start_ms}&toDateTime={end_ms}"),
            )
        };
        let stamp = utc((h * 3600) as f64)[..13].to_string();
        let name = if done {
            format!("{stamp}-{}.json", tag(&url))
        } else {
            format!("{stamp}-{}-partial.json", tag(&url))
        };
        plan.push(Download {
            url,
            path: cache.join(name),
            reuse: done,
        });
        h += 1;
    }
    plan
}

/// Rows per Fingrid page (the API's largest).
const FI_PAGE_ROWS: u32 = 20_000;

/// The first page of each UTC day that overlaps `[from, to)` from Fingrid's API; the pages
/// after it come from each answer's `pagination` ([`fi_next_page`]).
pub(super) fn fi_plan(endpoint: &str, from: f64, to: f64, now: f64, cache: &Path) -> Vec<Download> {
    let mut plan = Vec::new();
    let to = to.min(now);
    let mut day = (from / 86_400.0).floor() as i64;
    while (day as f64) * 86_400.0 < to {
        let a = (day * 86_400) as f64;
        let b = (a + 86_400.0).min(to.ceil());
        // the last hour's values may still be coming: a day that reaches it is asked again
        plan.push(fi_page(
            endpoint,
            a.max(from.floor()),
            b,
            1,
            b > now - 3600.0,
            cache,
        ));
        day += 1;
    }
    plan
}

fn fi_page(endpoint: &str, a: f64, b: f64, page: u32, open: bool, cache: &Path) -> Download {
    let query = format!(
        "startTime={}&endTime={}&format=json&pageSize={FI_PAGE_ROWS}&page={page}&sortBy=startTime&sortOrder=asc",
        utc(a),
        utc(b)
    );
    let url = with_query(endpoint, &query);
    let name = format!(
        "{}-p{page}-{}{}.json",
        &utc(a)[..10],
        tag(&url),
        if open { "-partial" } else { "" }
    );
    Download {
        url,
        path: cache.join(name),
        reuse: !open,
    }
}

/// The page after `d` when the answer at `d.path` says there is one (`pagination.nextPage`).
pub(super) fn fi_next_page(d: &Download, endpoint: &str, cache: &Path) -> Result<Option<Download>> {
    let text = std::fs::read(&d.path)
        .map_err(|e| crate::error::Error::Fetch(format!("fi: {}: {e}", d.path.display())))?;
    let v: serde_json::Value = serde_json::from_slice(&text).map_err(|_| {
        crate::error::Error::Fetch(format!(
            "fi: {}: not JSON (expected Fingrid's {{\"data\": [...], \"pagination\": {{...}}}})",
            d.url
        ))
    })?;
    if !v.get("data").is_some_and(|x| x.is_array()) {
        fail!(
            Fetch,
            "fi: {}: no data list (expected Fingrid's {{\"data\": [{{startTime, value}}], \"pagination\"}}): the format may have changed",
            d.url
        );
    }
    let Some(next) = v.pointer("/pagination/nextPage").and_then(|n| n.as_u64()) else {
        return Ok(None);
    };
    let query = |k: &str| {
        d.url
            .split(['?', '&'])
            .find_map(|kv| kv.strip_prefix(&format!("{k}=")))
            .and_then(|t| crate::time::parse_time(t).ok())
    };
    let (Some(a), Some(b)) = (query("startTime"), query("endTime")) else {
        return Ok(None);
    };
    if next > 100_000 {
        fail!(
            Fetch,
            "fi: {}: names page {next} next: not a page of one day",
            d.url
        );
    }
    Ok(Some(fi_page(endpoint, a, b, next as u32, !d.reuse, cache)))
}

/// The zone Swissgrid's chart times are in, told from the time of retrieval: its latest
/// point is minutes old, so it lies near now in UTC if the milliseconds are Unix time, or
/// near now on Zurich's wall clock if they encode local time.
pub(super) fn ch_zone(last_ms: f64, retrieved: f64) -> Result<Zone> {
    let zurich = Zone::parse("Europe/Zurich")?;
    let last = last_ms / 1000.0;
    let near = |t: f64| (retrieved - t) > -120.0 && (retrieved - t) < 1800.0;
    if near(last) {
        Ok(Zone::utc())
    } else if near(last - zurich.offset_at(retrieved)) {
        Ok(zurich)
    } else {
        fail!(
            Fetch,
            "ch: its latest point ({}, read as UTC) is neither a few minutes before the time of \
             retrieval ({}) in UTC nor on Zurich's clock: the format may have changed",
            utc(last),
            utc(retrieved)
        )
    }
}
