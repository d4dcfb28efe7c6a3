//! The reference store: one time-indexed ENF series per grid, kept as 32-bit integers
//! (µHz deviation from the nominal frequency; a year at 1 s is 126 MB), gaps kept as gaps.
//!
//! Layout: `DIR/<grid>.json`, the grid's manifest (metadata, the name of its values file and
//! the values' CRC-32), and the values file it names, `DIR/<grid>.<generation>.i32`
//! (little-endian values, one per step from `start_unix_s`; `i32::MIN` marks a gap). Stores
//! written before generations (no `values_file`) keep their values in `DIR/<grid>.i32`.
//!
//! A change commits in one atomic step: the new values go to a new file, then the manifest is
//! renamed over the old one, then the old values file is removed. A kill at any moment leaves
//! the old store or the new one. Builds hold an exclusive lock on `DIR/.eenf-store.lock` for
//! their whole read-merge-write, so that two builds into one store follow each other; readers
//! take it shared.

use eenf_core::spelling::switch;
use std::fs::File;
use std::path::{Path, PathBuf};

use eenf_core::Grid;

use crate::error::{fail, Context, Result};

use crate::output::write_atomic;

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
}

/// One grid of a store, read into memory: its metadata and values (what `match` loads its
/// reference series from).
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
        // a manifest is a few hundred bytes: a large one is not read into memory
        let size = std::fs::metadata(&json)
            .with_context(|| format!("{}", json.display()))?
            .len();
        if size > 1 << 20 {
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

    /// The values file a manifest names (a plain file name in the store).
    fn values_path(dir: &Path, meta: &RefMeta) -> Result<PathBuf> {
        let name = meta
            .values_file
            .clone()
            .unwrap_or_else(|| format!("{}.i32", meta.grid));
        if name.contains(['/', '\\']) || name.starts_with('.') {
            fail!(
                Store,
                "{}: names {name:?} as its values, not a file of the store",
                manifest(dir, &meta.grid).display()
            );
        }
        Ok(dir.join(name))
    }

    /// Loads one grid, checking the values against the manifest's count and checksum.
    pub fn load(dir: &Path, grid: &str) -> Result<Self> {
        let meta = Self::load_meta(dir, grid)?;
        let data = Self::values_path(dir, &meta)?;
        let len = std::fs::metadata(&data)
            .with_context(|| format!("{}", data.display()))?
            .len();
        if len != meta.count as u64 * 4 || meta.count > MAX_VALUES {
            fail!(
                Store,
                "{}: {len} bytes where the manifest announces {} values: the store was damaged \
                 (a build interrupted before eenf committed its changes atomically); build this \
                 grid again from its sources",
                data.display(),
                meta.count
            );
        }
        let bytes = std::fs::read(&data).with_context(|| format!("{}", data.display()))?;
        if let Some(want) = meta.values_crc32 {
            let got = crc_of(&bytes);
            if got != want {
                fail!(
                    Store,
                    "{}: the values do not match their checksum (CRC-32 {got:08x}, the manifest \
                     says {want:08x}): they were damaged on disk; build this grid again from its \
                     sources",
                    data.display()
                );
            }
        }
        let values = bytes
            .chunks_exact(4)
            .map(|c| i32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        Ok(StoredGrid { meta, values })
    }

    /// Commits the series: a new values file, then the manifest that names it renamed over
    /// the old one (the commit), then the old values file removed. Call it under
    /// [`StoreLock::exclusive`].
    pub fn save(&mut self, dir: &Path) -> Result<()> {
        check_grid_name(&self.meta.grid)?;
        std::fs::create_dir_all(dir).with_context(|| format!("{}", dir.display()))?;
        let json = manifest(dir, &self.meta.grid);
        let old = Self::load_meta(dir, &self.meta.grid)
            .ok()
            .and_then(|m| Self::values_path(dir, &m).ok());
        let mut bytes = Vec::with_capacity(self.values.len() * 4);
        for v in &self.values {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        // a new name for every commit: the old file stays whole until the manifest moves on
        let stamp = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        let name = format!("{}.{stamp:x}.{}.i32", self.meta.grid, std::process::id());
        let data = dir.join(&name);
        write_atomic(&data, |w| {
            w.write_all(&bytes)?;
            Ok(())
        })?;
        File::open(&data)
            .and_then(|f| f.sync_all())
            .with_context(|| format!("{}", data.display()))?;
        self.meta.count = self.values.len();
        self.meta.values_file = Some(name);
        self.meta.values_crc32 = Some(crc_of(&bytes));
        write_atomic(&json, |w| {
            serde_json::to_writer_pretty(&mut *w, &self.meta)?;
            Ok(())
        })?;
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
        if let Some(old) = old.filter(|o| *o != data) {
            let _ = std::fs::remove_file(old);
        }
        Ok(())
    }

    /// Removes values files of `grid` that its manifest does not name (left by builds killed
    /// before their commit). Call it under [`StoreLock::exclusive`].
    pub fn remove_orphans(dir: &Path, grid: &str) -> Result<usize> {
        let named = Self::load_meta(dir, grid)
            .ok()
            .and_then(|m| Self::values_path(dir, &m).ok());
        let prefix = format!("{grid}.");
        let mut removed = 0;
        for e in std::fs::read_dir(dir).with_context(|| format!("{}", dir.display()))? {
            let p = e?.path();
            let file = p.file_name().unwrap_or_default().to_string_lossy();
            let generation = file
                .strip_prefix(&prefix)
                .and_then(|r| r.strip_suffix(".i32"))
                .is_some_and(|g| g.contains('.'));
            if generation && Some(&p) != named.as_ref() && std::fs::remove_file(&p).is_ok() {
                removed += 1;
            }
        }
        Ok(removed)
    }

    /// Values in Hz, NaN for gaps.
    pub fn hz(&self) -> Vec<f64> {
        let f0 = self.meta.nominal_hz;
        self.values
            .iter()
            .map(|&v| {
                if v == GAP {
                    f64::NAN
                } else {
                    f0 + v as f64 * 1e-6
                }
            })
            .collect()
    }

    /// Places `hz` (one value per `step_s` from `start_unix_s`) into the series, resampled to
    /// the series' step; the series grows (with gaps) as needed, and new values replace old.
    pub fn merge(&mut self, start_unix_s: f64, step_s: f64, hz: &[f64]) -> Result<()> {
        let vals = eenf_dsp::resample::resample(hz, step_s, self.meta.step_s);
        let step = self.meta.step_s;
        if self.values.is_empty() {
            self.meta.start_unix_s = start_unix_s;
        }
        let mut first = ((start_unix_s - self.meta.start_unix_s) / step).round() as i64;
        if first < 0 {
            let pad = (-first) as usize;
            if pad + self.values.len() > MAX_VALUES {
                fail!(Store, "the series would span more than ten years");
            }
            let mut v = vec![GAP; pad];
            v.extend_from_slice(&self.values);
            self.values = v;
            self.meta.start_unix_s -= pad as f64 * step;
            first = 0;
        }
        let end = first as usize + vals.len();
        if end > MAX_VALUES {
            fail!(Store, "the series would span more than ten years");
        }
        if self.values.len() < end {
            self.values.resize(end, GAP);
        }
        let f0 = self.meta.nominal_hz;
        for (slot, v) in self.values[first as usize..end].iter_mut().zip(&vals) {
            if v.is_finite() {
                *slot = ((v - f0) * 1e6)
                    .round()
                    .clamp(-(i32::MAX as f64), i32::MAX as f64) as i32;
            }
        }
        self.meta.count = self.values.len();
        Ok(())
    }
}
