//! The reference store: one time-indexed ENF series per grid, kept as 32-bit integers
//! (µHz deviation from the nominal frequency; a year at 1 s is 126 MB), gaps kept as gaps.
//!
//! Layout: `DIR/<grid>.json`, the grid's manifest (metadata and its parts), and the parts it
//! names, `DIR/<grid>.<generation>.i32`: little-endian values, one per step, each part holding
//! the values of one stretch of [`PART_VALUES`] steps counted from the Unix epoch (48.5 days at
//! 1 s), with its first index and CRC-32 in the manifest. Stretches without a part are gaps;
//! `i32::MIN` marks a gap inside one. Adding a month to a decade rewrites the two or three
//! parts it touches, not the decade. Stores written before parts name one values file
//! (`values_file`, or `DIR/<grid>.i32` before generations): it is read as one part, and split
//! into parts at its first change.
//!
//! A change commits in one atomic step: changed parts go to new files, then the manifest is
//! renamed over the old one, then the files it no longer names are removed. A kill at any
//! moment leaves the old store or the new one. Builds hold an exclusive lock on
//! `DIR/.eenf-store.lock` for their whole read-merge-write, so that two builds into one store
//! follow each other; readers take it shared.

mod edit;
mod values;

pub use edit::GridEdit;
pub use values::{GridSummary, GridValues};

use eenf_core::spelling::switch;
use std::fs::File;
use std::path::{Path, PathBuf};

use eenf_core::Grid;

use crate::error::{fail, Context, Result};

/// The value that marks a missing second.
pub const GAP: i32 = i32::MIN;
/// Longest series accepted: ten years at 1 s.
const MAX_VALUES: usize = 10 * 366 * 86_400;
/// The lock file of a store.
const LOCK_FILE: &str = ".eenf-store.lock";

/// Metadata of one grid's series.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct RefMeta {
    /// Grid name.
    pub grid: String,
    /// Nominal frequency, Hz.
    pub nominal_hz: f64,
    /// Seconds between values.
    pub step_s: f64,
    /// Time of the first value, s since the Unix epoch (UTC).
    pub start_unix_s: f64,
    /// Number of values.
    pub count: usize,
    /// How values are stored.
    pub encoding: String,
    /// The file (in the store) that holds the values; `<grid>.i32` when absent (older stores).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub values_file: Option<String>,
    /// CRC-32 (IEEE) of the values file's bytes; absent in older stores.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub values_crc32: Option<u32>,
    /// The files holding the values, in order; absent in stores with one values file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parts: Option<Vec<Part>>,
    /// Where values were fetched from (`refdb fetch`): each source and the files it gave.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fetched: Vec<FetchedFrom>,
}

/// A grid operator's source that values of a grid were fetched from, and every file it gave.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FetchedFrom {
    /// The source's name (`gb`, `se`, `ch`), as `refdb fetch` takes it.
    pub source: String,
    /// The address asked (the operator's, or a mirror's given with `--endpoint`); `refdb
    /// update` asks it again.
    pub endpoint: String,
    /// The files, one per address; a file fetched again replaces its entry.
    pub files: Vec<FetchedFile>,
}

/// One file fetched from a grid operator.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FetchedFile {
    /// Its address.
    pub url: String,
    /// When it was retrieved, UTC (RFC 3339).
    pub retrieved_utc: String,
    /// SHA-256 of its bytes, hex.
    pub sha256: String,
    /// Its size, bytes.
    pub bytes: u64,
}

impl FetchedFrom {
    /// Adds `other`'s files, replacing those with the same address.
    pub fn absorb(&mut self, other: &FetchedFrom) {
        for f in &other.files {
            match self.files.iter_mut().find(|g| g.url == f.url) {
                Some(g) => *g = f.clone(),
                None => self.files.push(f.clone()),
            }
        }
    }
}

impl RefMeta {
    /// Records that values were fetched from `from` (merged with earlier fetches from the
    /// same source and address).
    pub fn record_fetch(&mut self, from: &FetchedFrom) {
        match self
            .fetched
            .iter_mut()
            .find(|f| f.source == from.source && f.endpoint == from.endpoint)
        {
            Some(f) => f.absorb(from),
            None => self.fetched.push(from.clone()),
        }
    }

    /// Time of the last value, Unix seconds (the start when empty).
    pub fn end_unix_s(&self) -> f64 {
        self.start_unix_s + self.count.saturating_sub(1) as f64 * self.step_s
    }
}

/// One file of a grid's values: `count` values from index `first` of the series.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Part {
    /// Its file name in the store.
    pub file: String,
    /// Index of its first value in the series.
    pub first: usize,
    /// Values it holds.
    pub count: usize,
    /// CRC-32 (IEEE) of its bytes; absent in stores written before checksums.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crc32: Option<u32>,
    /// Its values that are not gaps, and `sum_uhz` their sum (stored units): the grid's mean
    /// without reading it, checked as a search reads the values. Absent in stores written
    /// before them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub finite: Option<usize>,
    /// See `finite`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sum_uhz: Option<i64>,
}

/// Values per part: 2^22, 48.5 days at 1 s (16 MB).
pub const PART_VALUES: usize = 1 << 22;

impl RefMeta {
    /// The parts that hold the values: those the manifest lists, or the one values file of an
    /// older store.
    pub fn parts_listed(&self) -> Vec<Part> {
        match &self.parts {
            Some(p) => p.clone(),
            None => vec![Part {
                file: self
                    .values_file
                    .clone()
                    .unwrap_or_else(|| format!("{}.i32", self.grid)),
                first: 0,
                count: self.count,
                crc32: self.values_crc32,
                finite: None,
                sum_uhz: None,
            }],
        }
    }

    /// Index 0's place on the steps counted from the Unix epoch (parts' stretches are counted
    /// there, so that moving the start earlier moves no boundary).
    fn origin(&self) -> i64 {
        (self.start_unix_s / self.step_s).round() as i64
    }

    /// Places `n` values that start at `start_unix_s` on this series: the index of the first,
    /// and how many gaps were put before the old first value (the start moved earlier). The
    /// series' count grows to hold them.
    fn place(&mut self, start_unix_s: f64, n: usize, empty: bool) -> Result<(usize, usize)> {
        let step = self.step_s;
        if empty {
            self.start_unix_s = start_unix_s;
            self.count = 0;
        }
        let mut first = ((start_unix_s - self.start_unix_s) / step).round() as i64;
        let mut pad = 0;
        if first < 0 {
            pad = (-first) as usize;
            if pad + self.count > MAX_VALUES {
                fail!(Store, "the series would span more than ten years");
            }
            self.start_unix_s -= pad as f64 * step;
            self.count += pad;
            first = 0;
        }
        let end = first as usize + n;
        if end > MAX_VALUES {
            fail!(Store, "the series would span more than ten years");
        }
        self.count = self.count.max(end);
        Ok((first as usize, pad))
    }
}

/// A frequency as stored: µHz from `nominal_hz`, `None` for a gap.
fn to_stored(hz: f64, nominal_hz: f64) -> Option<i32> {
    hz.is_finite().then(|| {
        ((hz - nominal_hz) * 1e6)
            .round()
            .clamp(-(i32::MAX as f64), i32::MAX as f64) as i32
    })
}

/// A stored value in Hz, NaN for a gap.
#[inline(always)]
fn to_hz(v: i32, nominal_hz: f64) -> f64 {
    if v == GAP {
        f64::NAN
    } else {
        nominal_hz + v as f64 * 1e-6
    }
}

/// One grid's series held in memory: its metadata and values (what a folder of hourly WAVs
/// becomes for `match`, and a whole grid read by [`StoredGrid::load`]).
#[derive(Debug, Clone)]
pub struct StoredGrid {
    /// Metadata.
    pub meta: RefMeta,
    /// Values (µHz from nominal, `GAP` for none).
    pub values: Vec<i32>,
}

/// A store's lock, held until dropped.
pub struct StoreLock(#[allow(dead_code)] Option<File>);

impl StoreLock {
    /// The exclusive lock of the store at `dir` (created if need be), for a change. When
    /// another process holds it, calls `on_wait` and waits for it, or with `wait` false fails
    /// saying so.
    pub fn exclusive(dir: &Path, wait: bool, on_wait: impl FnOnce()) -> Result<Self> {
        std::fs::create_dir_all(dir).with_context(|| format!("{}", dir.display()))?;
        let path = dir.join(LOCK_FILE);
        let file = open_lock_file(&path).with_context(|| format!("{}", path.display()))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) if wait => {
                on_wait();
                file.lock().with_context(|| format!("{}", path.display()))?;
            }
            Err(std::fs::TryLockError::WouldBlock) => fail!(
                Store,
                "{}: another build is changing this store (without {}, this one waits)",
                dir.display(),
                switch("no_wait")
            ),
            Err(std::fs::TryLockError::Error(e)) => {
                return Err(e).with_context(|| format!("{}", path.display()))
            }
        }
        Ok(StoreLock(Some(file)))
    }

    /// The shared lock of the store at `dir`, for reading: a build's commit cannot remove a
    /// values file while it is read. A store that cannot hold a lock file (read-only) is read
    /// without one.
    pub fn shared(dir: &Path) -> Result<Self> {
        let path = dir.join(LOCK_FILE);
        let file = open_lock_file(&path).or_else(|_| File::open(&path));
        let Ok(file) = file else {
            return Ok(StoreLock(None));
        };
        file.lock_shared()
            .with_context(|| format!("{}", path.display()))?;
        Ok(StoreLock(Some(file)))
    }
}

/// The lock file, created when missing (never truncated: it holds nothing).
fn open_lock_file(path: &Path) -> std::io::Result<File> {
    File::options()
        .create(true)
        .truncate(false)
        .write(true)
        .open(path)
}

/// Refuses a grid name that is not a plain name: it becomes file names in the store, and a
/// store's metadata must not make a build write elsewhere (`../x`, `/abs`).
pub fn check_grid_name(grid: &str) -> Result<()> {
    let plain = !grid.is_empty()
        && grid.len() <= 64
        && grid
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        && !grid.starts_with('-');
    if !plain {
        fail!(
            Store,
            "{grid:?} is not a grid name: letters, digits, _ and - only (at most 64), e.g. grid50"
        );
    }
    Ok(())
}

fn manifest(dir: &Path, grid: &str) -> PathBuf {
    dir.join(format!("{grid}.json"))
}

/// The file of `part` in the store at `dir`, refused when the manifest names anything but a
/// plain file of the store (a manifest must not make eenf read or write elsewhere).
fn part_path(dir: &Path, grid: &str, part: &Part) -> Result<PathBuf> {
    let name = &part.file;
    if name.is_empty() || name.contains(['/', '\\']) || name.starts_with('.') {
        fail!(
            Store,
            "{}: names {name:?} as its values, not a file of the store",
            manifest(dir, grid).display()
        );
    }
    Ok(dir.join(name))
}

/// How many of `values` are not gaps, and their sum.
#[inline(always)]
fn finite_sum(values: impl Iterator<Item = i32>) -> (usize, i64) {
    values.fold((0, 0), |(n, s), v| {
        let gap = v == GAP;
        (n + usize::from(!gap), s + if gap { 0 } else { v as i64 })
    })
}

/// The CRC-32 of values as the store writes them.
fn crc_of(bytes: &[u8]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    h.update(bytes);
    h.finalize()
}

impl StoredGrid {
    /// An empty series named `name`, of the grid `grid`.
    pub fn new(name: &str, grid: Grid, step_s: f64, start_unix_s: f64) -> Self {
        StoredGrid {
            meta: RefMeta {
                grid: name.to_string(),
                nominal_hz: grid.hz(),
                step_s,
                start_unix_s,
                count: 0,
                encoding: "i32 little-endian, µHz deviation from nominal_hz, -2147483648 = gap"
                    .into(),
                values_file: None,
                values_crc32: None,
                parts: None,
                fetched: Vec::new(),
            },
            values: Vec::new(),
        }
    }

    /// The grids stored in `dir`: manifests `<grid>.json` with a values file `<grid>….i32`
    /// beside them (other JSON files, e.g. in a folder of hourly WAVs, are not grids).
    pub fn grids(dir: &Path) -> Result<Vec<String>> {
        let mut names = Vec::new();
        for e in std::fs::read_dir(dir).with_context(|| format!("{}", dir.display()))? {
            names.push(e?.file_name().to_string_lossy().into_owned());
        }
        let mut out: Vec<String> = names
            .iter()
            .filter_map(|n| n.strip_suffix(".json"))
            .filter(|stem| check_grid_name(stem).is_ok())
            .filter(|stem| {
                let prefix = format!("{stem}.");
                names
                    .iter()
                    .any(|n| n.starts_with(&prefix) && n.ends_with(".i32"))
            })
            .map(str::to_string)
            .collect();
        out.sort();
        Ok(out)
    }

    /// Reads one grid's manifest; a grid name in it that is not the manifest's own is damage.
    pub fn load_meta(dir: &Path, grid: &str) -> Result<RefMeta> {
        check_grid_name(grid)?;
        let json = manifest(dir, grid);
        // a manifest is a few kB (a fetched decade's files, a few hundred kB): a large one is
        // not read into memory
        let size = std::fs::metadata(&json)
            .with_context(|| format!("{}", json.display()))?
            .len();
        if size > 8 << 20 {
            fail!(
                Store,
                "{}: {size} bytes: not an eenf reference store manifest",
                json.display()
            );
        }
        let text = std::fs::read_to_string(&json).with_context(|| format!("{}", json.display()))?;
        let meta: RefMeta = serde_json::from_str(&text)
            .with_context(|| format!("{}: not an eenf reference store", json.display()))?;
        if meta.grid != grid {
            fail!(
                Store,
                "{}: names grid {:?}, but it is the manifest of {grid:?}: the store is damaged \
                 or was edited by hand",
                json.display(),
                meta.grid
            );
        }
        if !(meta.step_s.is_finite() && meta.step_s > 0.0 && meta.start_unix_s.is_finite()) {
            fail!(
                Store,
                "{}: a damaged manifest (step or start)",
                json.display()
            );
        }
        Ok(meta)
    }

    /// Loads one grid whole, checking its parts against the manifest and their checksums.
    pub fn load(dir: &Path, grid: &str) -> Result<Self> {
        let g = GridValues::open(dir, grid)?;
        g.check()?;
        let values = g.read_all()?;
        Ok(StoredGrid {
            meta: g.meta,
            values,
        })
    }

    /// Removes values files of `grid` that its manifest does not name (left by builds killed
    /// before their commit). Call it under [`StoreLock::exclusive`].
    pub fn remove_orphans(dir: &Path, grid: &str) -> Result<usize> {
        let named: Vec<String> = Self::load_meta(dir, grid)
            .map(|m| m.parts_listed().into_iter().map(|p| p.file).collect())
            .unwrap_or_default();
        let prefix = format!("{grid}.");
        let mut removed = 0;
        for e in std::fs::read_dir(dir).with_context(|| format!("{}", dir.display()))? {
            let p = e?.path();
            let file = p.file_name().unwrap_or_default().to_string_lossy();
            let generation = file
                .strip_prefix(&prefix)
                .and_then(|r| r.strip_suffix(".i32"))
                .is_some_and(|g| g.contains('.'));
            if generation && !named.iter().any(|n| *n == file) && std::fs::remove_file(&p).is_ok() {
                removed += 1;
            }
        }
        Ok(removed)
    }

    /// Values in Hz, NaN for gaps.
    pub fn hz(&self) -> Vec<f64> {
        let f0 = self.meta.nominal_hz;
        self.values.iter().map(|&v| to_hz(v, f0)).collect()
    }

    /// Places `hz` (one value per `step_s` from `start_unix_s`) into the series, resampled to
    /// the series' step; the series grows (with gaps) as needed, and new values replace old.
    pub fn merge(&mut self, start_unix_s: f64, step_s: f64, hz: &[f64]) -> Result<()> {
        let vals = eenf_dsp::resample::resample(hz, step_s, self.meta.step_s);
        let empty = self.values.is_empty();
        let (first, pad) = self.meta.place(start_unix_s, vals.len(), empty)?;
        if pad > 0 {
            self.values.splice(0..0, std::iter::repeat_n(GAP, pad));
        }
        self.values.resize(self.meta.count, GAP);
        let f0 = self.meta.nominal_hz;
        for (slot, v) in self.values[first..].iter_mut().zip(&vals) {
            if let Some(x) = to_stored(*v, f0) {
                *slot = x;
            }
        }
        Ok(())
    }
}
