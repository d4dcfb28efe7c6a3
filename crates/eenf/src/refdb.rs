//! The reference store: one time-indexed ENF series per grid, kept as 32-bit integers
//! (µHz deviation from the nominal frequency; a year at 1 s is 126 MB), gaps kept as gaps.
//!
//! Layout: `DIR/<grid>.json` (metadata) and `DIR/<grid>.i32` (little-endian values, one per
//! step from `start_unix_s`; `i32::MIN` marks a gap).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use crate::output::write_atomic;

/// The value that marks a missing second.
pub const GAP: i32 = i32::MIN;
/// Longest series accepted: ten years at 1 s.
const MAX_VALUES: usize = 10 * 366 * 86_400;

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
}

/// One grid's series in memory.
#[derive(Debug, Clone)]
pub struct RefSeries {
    /// Metadata.
    pub meta: RefMeta,
    /// Values (µHz from nominal, `GAP` for none).
    pub values: Vec<i32>,
}

fn paths(dir: &Path, grid: &str) -> (PathBuf, PathBuf) {
    (
        dir.join(format!("{grid}.json")),
        dir.join(format!("{grid}.i32")),
    )
}

impl RefSeries {
    /// An empty series.
    pub fn new(grid: &str, nominal_hz: f64, step_s: f64, start_unix_s: f64) -> Self {
        RefSeries {
            meta: RefMeta {
                grid: grid.to_string(),
                nominal_hz,
                step_s,
                start_unix_s,
                count: 0,
                encoding: "i32 little-endian, µHz deviation from nominal_hz, -2147483648 = gap"
                    .into(),
            },
            values: Vec::new(),
        }
    }

    /// The grids stored in `dir`.
    pub fn grids(dir: &Path) -> Result<Vec<String>> {
        let mut out = Vec::new();
        for e in std::fs::read_dir(dir).with_context(|| format!("{}", dir.display()))? {
            let p = e?.path();
            if p.extension().and_then(|e| e.to_str()) == Some("json")
                && p.with_extension("i32").exists()
            {
                out.push(p.file_stem().unwrap().to_string_lossy().into_owned());
            }
        }
        out.sort();
        Ok(out)
    }

    /// Reads one grid's metadata.
    pub fn load_meta(dir: &Path, grid: &str) -> Result<RefMeta> {
        let (json, _) = paths(dir, grid);
        let text = std::fs::read_to_string(&json).with_context(|| format!("{}", json.display()))?;
        serde_json::from_str(&text)
            .with_context(|| format!("{}: not an eenf reference store", json.display()))
    }

    /// Loads one grid.
    pub fn load(dir: &Path, grid: &str) -> Result<Self> {
        let meta = Self::load_meta(dir, grid)?;
        let (_, data) = paths(dir, grid);
        let len = std::fs::metadata(&data)
            .with_context(|| format!("{}", data.display()))?
            .len();
        if len != meta.count as u64 * 4 || meta.count > MAX_VALUES {
            bail!(
                "{}: {len} bytes where the metadata announces {} values",
                data.display(),
                meta.count
            );
        }
        let bytes = std::fs::read(&data).with_context(|| format!("{}", data.display()))?;
        let values = bytes
            .chunks_exact(4)
            .map(|c| i32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        Ok(RefSeries { meta, values })
    }

    /// Writes both files (each whole or not at all).
    pub fn save(&mut self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir).with_context(|| format!("{}", dir.display()))?;
        self.meta.count = self.values.len();
        let (json, data) = paths(dir, &self.meta.grid);
        write_atomic(&data, |w| {
            let mut buf = Vec::with_capacity(1 << 20);
            for chunk in self.values.chunks(1 << 18) {
                buf.clear();
                for v in chunk {
                    buf.extend_from_slice(&v.to_le_bytes());
                }
                w.write_all(&buf)?;
            }
            Ok(())
        })?;
        write_atomic(&json, |w| {
            serde_json::to_writer_pretty(&mut *w, &self.meta)?;
            Ok(())
        })
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
        let vals = eenf_dsp::matching::resample(hz, step_s, self.meta.step_s);
        let step = self.meta.step_s;
        if self.values.is_empty() {
            self.meta.start_unix_s = start_unix_s;
        }
        let mut first = ((start_unix_s - self.meta.start_unix_s) / step).round() as i64;
        if first < 0 {
            let pad = (-first) as usize;
            if pad + self.values.len() > MAX_VALUES {
                bail!("the series would span more than ten years");
            }
            let mut v = vec![GAP; pad];
            v.extend_from_slice(&self.values);
            self.values = v;
            self.meta.start_unix_s -= pad as f64 * step;
            first = 0;
        }
        let end = first as usize + vals.len();
        if end > MAX_VALUES {
            bail!("the series would span more than ten years");
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn series_merge_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let mut s = RefSeries::new("g", 50.0, 1.0, 0.0);
        s.merge(100.0, 1.0, &[50.01, 49.99, f64::NAN]).unwrap();
        s.merge(110.0, 2.0, &[50.0, 50.002]).unwrap(); // resampled to 1 s: 3 values
        s.merge(98.0, 1.0, &[50.003]).unwrap(); // before the start: prepends a gap
        s.save(dir.path()).unwrap();
        let l = RefSeries::load(dir.path(), "g").unwrap();
        assert_eq!(l.meta.start_unix_s, 98.0);
        let hz = l.hz();
        assert_eq!(hz.len(), 15);
        assert!((hz[0] - 50.003).abs() < 1e-9 && hz[1].is_nan());
        assert!((hz[2] - 50.01).abs() < 1e-9 && (hz[3] - 49.99).abs() < 1e-9 && hz[4].is_nan());
        assert!((hz[13] - 50.001).abs() < 1e-9, "{hz:?}");
        assert_eq!(RefSeries::grids(dir.path()).unwrap(), vec!["g".to_string()]);
    }
}
