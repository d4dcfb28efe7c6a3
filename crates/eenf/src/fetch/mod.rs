//! References fetched from grid operators: `refdb fetch` and `refdb update`.
//!
//! A fetch plans the files a span needs ([`sources`]), downloads them into a cache folder
//! (resumable, retried, polite: [`http`]), then adds them to the store through the same
//! archive importer and build as `refdb build` ([`crate::reference::build_store`]), with
//! where they came from recorded in the grid's manifest ([`crate::refdb::FetchedFrom`]).
//! Nothing touches the store until every file is in: a failure leaves it as it was.

mod http;
mod sources;

pub use crate::time::parse_day_or_time;
pub use sources::Source;

use std::path::{Path, PathBuf};
use std::time::Duration;

use eenf_core::Grid;

use crate::archive::{ArchiveOptions, ValueUnit};
use crate::error::{error, fail, Result};
use crate::progress::Progress;
use crate::refdb::{FetchedFile, FetchedFrom, StoredGrid};
use crate::reference::{build_store, StoreBuild, StoreBuilt};
use crate::time::utc;

use http::Http;
use sources::Download;

/// What to fetch and where it goes.
#[derive(Debug, Clone)]
pub struct FetchRequest {
    /// The operator's data.
    pub source: Source,
    /// Start of the span, Unix seconds.
    pub from_unix_s: f64,
    /// End of the span (exclusive), Unix seconds; at most now.
    pub to_unix_s: f64,
    /// The store (created when missing).
    pub store: PathBuf,
    /// Where downloads are kept (and resumed from).
    pub cache: PathBuf,
    /// The address to ask instead of the operator's (a mirror, a test).
    pub endpoint: Option<String>,
    /// The grid's name in the store (default: the source's, e.g. `gb`).
    pub grid: Option<String>,
    /// Retries after a failure that may pass.
    pub retries: u32,
    /// Wait for another build that holds the store (else fail at once).
    pub wait: bool,
    /// The API key of a source that needs one (Fingrid); never recorded in the store.
    pub api_key: Option<String>,
}

/// One file a fetch used.
#[derive(Debug, Clone)]
pub struct FetchedPath {
    /// Its address.
    pub url: String,
    /// Where the cache keeps it.
    pub path: PathBuf,
    /// True when a final copy was already in the cache (not downloaded again).
    pub cached: bool,
}

/// What a fetch did.
#[derive(Debug, Clone)]
pub struct Fetched {
    /// The source.
    pub source: Source,
    /// The grid it went into.
    pub grid: String,
    /// The files used, in time order.
    pub files: Vec<FetchedPath>,
    /// What the build did with them.
    pub built: StoreBuilt,
    /// What to tell the user: months not published, the span a source could give.
    pub notes: Vec<String>,
}

impl Fetched {
    /// As JSON: the source, the grid, each file (address, cache path, whether it came from the
    /// cache), the grids changed and the notes.
    pub fn to_json(&self) -> serde_json::Value {
        let files: Vec<_> = self
            .files
            .iter()
            .map(|f| serde_json::json!({"url": f.url, "path": f.path, "cached": f.cached}))
            .collect();
        let grids: Vec<_> = self
            .built
            .grids
            .iter()
            .map(|g| serde_json::json!({"grid": g.grid, "values": g.values}))
            .collect();
        serde_json::json!({
            "source": self.source.name(), "grid": self.grid, "files": files,
            "grids": grids, "notes": self.notes,
        })
    }
}

impl Source {
    /// The source named `s`, or an error naming the sources there are.
    pub fn parse(s: &str) -> Result<Source> {
        Source::from_name(s).ok_or_else(|| {
            error!(
                Input,
                "{s:?}: not a source to fetch from: expected one of {}",
                Source::NAMES.join(", ")
            )
        })
    }
}

/// The default cache folder: `$XDG_CACHE_HOME/eenf/fetch`, else `~/.cache/eenf/fetch`.
pub fn default_cache() -> PathBuf {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    base.join("eenf").join("fetch")
}

/// The environment variable that holds a Fingrid API key when `--api-key` is not given.
pub const FINGRID_KEY_VAR: &str = "FINGRID_API_KEY";

/// Now, Unix seconds.
fn now_s() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

/// Fetches `req`'s span from its operator into its store. A span the operator has
/// published nothing for is refused, naming what it has.
pub fn fetch(req: &FetchRequest, progress: &Progress) -> Result<Fetched> {
    match fetch_published(req, progress)? {
        Ok(f) => Ok(f),
        Err(notes) => fail!(
            Fetch,
            "{}: nothing published from {} to {}{}",
            req.source.name(),
            utc(req.from_unix_s),
            utc(req.to_unix_s.min(now_s())),
            notes.first().map(|n| format!(" ({n})")).unwrap_or_default()
        ),
    }
}

/// [`fetch`], with a span the operator has published nothing for given as its notes.
fn fetch_published(
    req: &FetchRequest,
    progress: &Progress,
) -> Result<std::result::Result<Fetched, Vec<String>>> {
    let source = req.source;
    let name = source.name();
    let endpoint = match (&req.endpoint, source.default_endpoint()) {
        (Some(e), _) => e.clone(),
        (None, Some(e)) => e.to_string(),
        (None, None) => fail!(
            Fetch,
            "{name}: give the file's address with --endpoint ({} has no fixed address)",
            source.describe()
        ),
    };
    let now = now_s();
    let to = req.to_unix_s.min(now);
    // (a NaN bound is refused too)
    if req.from_unix_s.partial_cmp(&to) != Some(std::cmp::Ordering::Less) {
        fail!(
            Fetch,
            "{name}: nothing to fetch from {} to {}",
            utc(req.from_unix_s),
            utc(to)
        );
    }
    let grid = req
        .grid
        .clone()
        .unwrap_or_else(|| source.default_grid().to_string());
    crate::refdb::check_grid_name(&grid)?;
    let cache = req.cache.join(name);
    let mut http = Http::new(name, req.retries, Duration::from_secs_f64(source.pause_s()));
    if source == Source::Fi {
        let key = req
            .api_key
            .clone()
            .or_else(|| std::env::var(FINGRID_KEY_VAR).ok())
            .filter(|k| !k.trim().is_empty());
        let Some(key) = key else {
            fail!(
                Fetch,
                "fi: Fingrid's API needs a free key (data.fingrid.fi): give it with --api-key or {FINGRID_KEY_VAR}"
            );
        };
        http = http.with_header("x-api-key", key.trim().to_string());
    }
    let mut notes = Vec::new();
    let mut zone = None;
    let plan = match source {
        Source::Gb => {
            let index = http.get_small(&endpoint)?;
            sources::gb_plan(
                &index,
                &endpoint,
                req.from_unix_s,
                to,
                now,
                &cache,
                &mut notes,
            )?
        }
        Source::Se => sources::se_plan(&endpoint, req.from_unix_s, to, now, &cache),
        Source::Ch => vec![Download {
            url: endpoint.clone(),
            path: cache.join(format!("{}.json", (now * 1000.0) as i64)),
            reuse: false,
        }],
        Source::Fi => sources::fi_plan(&endpoint, req.from_unix_s, to, now, &cache),
        Source::Osf => vec![Download {
            url: endpoint.clone(),
            path: cache.join(format!(
                "{}-{}",
                sources::tag(&endpoint),
                file_name(&endpoint)
            )),
            reuse: true,
        }],
    };
    if plan.is_empty() {
        return Ok(Err(notes));
    }
    let bar = progress.steps(plan.len() as u64, &format!("fetching from {name}"));
    let mut files = Vec::new();
    let mut provenance = FetchedFrom {
        source: name.to_string(),
        endpoint: endpoint.clone(),
        files: Vec::new(),
    };
    // (a download, whether the plan named it: the pages after a first page are found on the way)
    let mut queue: std::collections::VecDeque<(Download, bool)> =
        plan.iter().map(|d| (d.clone(), true)).collect();
    while let Some((d, planned)) = queue.pop_front() {
        let cached = d.reuse && d.path.is_file();
        if !cached {
            http.download(&d.url, &d.path)?;
        }
        if source == Source::Fi {
            if let Some(next) = sources::fi_next_page(&d, &endpoint, &cache)? {
                queue.push_front((next, false));
            }
        }
        let (sha256, bytes) = http::sha256_of(&d.path)?;
        let retrieved = std::fs::metadata(&d.path)
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
            .map(|d| d.as_secs_f64())
            .unwrap_or(now);
        provenance.files.push(FetchedFile {
            url: d.url.clone(),
            retrieved_utc: utc(retrieved.floor()),
            sha256,
            bytes,
        });
        files.push(FetchedPath {
            url: d.url.clone(),
            path: d.path.clone(),
            cached,
        });
        if planned {
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    if source == Source::Ch {
        let path = &plan[0].path;
        let Some((first, last)) = crate::archive::swissgrid_span(path) else {
            fail!(
                Fetch,
                "ch: {}: no data.series[0].data points (expected [[ms, Hz], …]): the format may have changed",
                path.display()
            );
        };
        zone = Some(sources::ch_zone(last, now)?);
        let z = zone.as_ref().map(|z| z.name()).unwrap_or_default();
        notes.push(format!(
            "ch: Swissgrid gives its last minutes only; its times were read as {z} (told from the time of retrieval)"
        ));
        let off = zone.as_ref().map(|z| z.offset_at(now)).unwrap_or(0.0);
        let (first, last) = (first / 1000.0 - off, last / 1000.0 - off);
        if last < req.from_unix_s || first > to {
            fail!(
                Fetch,
                "ch: Swissgrid gives {} to {} only, not {} to {}",
                utc(first),
                utc(last),
                utc(req.from_unix_s),
                utc(to)
            );
        }
    }
    let build = StoreBuild {
        inputs: files.iter().map(|f| f.path.display().to_string()).collect(),
        grid: Some(grid.clone()),
        zone,
        archive: ArchiveOptions {
            format: source.format(),
            zone: None,
            unit: ValueUnit::Hz,
            date_order: Default::default(),
            grid: Some(Grid::Hz50),
        },
        start: None,
        index_step_s: None,
        wait: req.wait,
        fetched: Some(provenance),
    };
    let built = build_store(&req.store, &build, progress, || {}).map_err(|e| {
        e.context(format!(
            "{name}: adding what was fetched to {}",
            req.store.display()
        ))
    })?;
    Ok(Ok(Fetched {
        source,
        grid,
        files,
        built,
        notes,
    }))
}

/// A file name from an address's last path segment (plain characters only).
fn file_name(url: &str) -> String {
    let last = url
        .split(['?', '#'])
        .next()
        .unwrap_or("")
        .rsplit('/')
        .next()
        .unwrap_or("");
    let clean: String = last
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-'))
        .collect();
    let clean = clean.trim_start_matches('.');
    if clean.is_empty() {
        "file".into()
    } else {
        clean.to_string()
    }
}

/// Brings every fetched grid of the store at `store` up to now: for each source recorded in
/// a grid's manifest, what lies after its last value. Grids that were built, not fetched, are
/// left alone.
pub fn update(
    store: &Path,
    cache: &Path,
    retries: u32,
    wait: bool,
    api_key: Option<&str>,
    progress: &Progress,
) -> Result<Vec<Fetched>> {
    let mut done = Vec::new();
    let grids = StoredGrid::grids(store)?;
    let mut any = false;
    for grid in grids {
        let meta = StoredGrid::load_meta(store, &grid)?;
        for from in &meta.fetched {
            any = true;
            let Some(source) = Source::from_name(&from.source) else {
                fail!(
                    Fetch,
                    "{}: grid {grid} was fetched from {:?}, a source this eenf does not know",
                    store.display(),
                    from.source
                );
            };
            let req = FetchRequest {
                source,
                from_unix_s: meta.end_unix_s() + meta.step_s,
                to_unix_s: now_s(),
                store: store.to_path_buf(),
                cache: cache.to_path_buf(),
                endpoint: Some(from.endpoint.clone()),
                grid: Some(grid.clone()),
                retries,
                wait,
                api_key: api_key.map(str::to_string),
            };
            if req.from_unix_s >= req.to_unix_s - 1.0 || source == Source::Osf {
                continue; // up to date, or a fixed file
            }
            if let Ok(f) = fetch_published(&req, progress)? {
                done.push(f);
            }
        }
    }
    if !any {
        fail!(
            Fetch,
            "{}: no grid here was fetched from an operator (refdb fetch records its sources)",
            store.display()
        );
    }
    Ok(done)
}
