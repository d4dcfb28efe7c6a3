//! A grid's values read where needed: what `match` searches and `refdb info` sums up, a
//! stretch at a time, so that a decade is never held in memory.

use std::fs::File;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use eenf_dsp::matching::{MatchError, ReferenceValues};

use super::{manifest, part_path, to_hz, Part, RefMeta, StoredGrid, GAP, MAX_VALUES};
use crate::error::{fail, Context, Result};

/// Values read per request while checking and summing up a part.
const STRETCH: usize = 1 << 20;

/// One grid of a store, opened for reading: its manifest and its parts' files.
pub struct GridValues {
    /// The manifest.
    pub meta: RefMeta,
    parts: Vec<(Part, PathBuf, File)>,
    /// The mean of its values in Hz, once [`GridValues::check`] has read them.
    mean_hz: Option<f64>,
}

/// What a grid holds, from reading every value once.
#[derive(Debug, Clone)]
pub struct GridSummary {
    /// Values (gaps included).
    pub values: usize,
    /// Gaps.
    pub gaps: usize,
    /// Runs of gaps.
    pub gap_runs: usize,
    /// Parts, and how many of them carry a checksum (all verified).
    pub parts: usize,
    /// See `parts`.
    pub checksummed: usize,
    /// Bytes of its parts on disk.
    pub bytes: u64,
}

/// What one part holds: the values that are not gaps, their sum in stored units, runs of
/// gaps inside it, and whether it starts and ends with a gap.
#[derive(Default)]
struct PartSums {
    finite: usize,
    sum: i128,
    gap_runs: usize,
    starts_gap: bool,
    ends_gap: bool,
}

/// Reads a part file's bytes from value `at` into `bytes`.
pub(super) fn read_bytes(file: &File, at: usize, bytes: &mut [u8]) -> std::io::Result<()> {
    let offset = at as u64 * 4;
    #[cfg(unix)]
    std::os::unix::fs::FileExt::read_exact_at(file, bytes, offset)?;
    #[cfg(not(unix))]
    {
        use std::io::{Read, Seek};
        let mut f = file.try_clone()?;
        f.seek(std::io::SeekFrom::Start(offset))?;
        f.read_exact(bytes)?;
    }
    Ok(())
}

/// Little-endian values from their bytes.
pub(super) fn decode(bytes: &[u8], dst: &mut [i32]) {
    for (d, c) in dst.iter_mut().zip(bytes.chunks_exact(4)) {
        *d = i32::from_le_bytes([c[0], c[1], c[2], c[3]]);
    }
}

/// Reads `dst.len()` values of a part's file from value `at`.
pub(super) fn read_part(file: &File, at: usize, dst: &mut [i32]) -> std::io::Result<()> {
    let mut bytes = vec![0u8; dst.len() * 4];
    read_bytes(file, at, &mut bytes)?;
    decode(&bytes, dst);
    Ok(())
}

impl GridValues {
    /// Opens one grid: its manifest, and each part's file, whose size must be what the
    /// manifest announces. The checksums are verified by [`GridValues::check`].
    pub fn open(dir: &Path, grid: &str) -> Result<Self> {
        let meta = StoredGrid::load_meta(dir, grid)?;
        let damaged = |what: String| -> Result<()> {
            fail!(
                Store,
                "{what}: the store was damaged (a build interrupted before eenf committed its \
                 changes atomically, or an edit by hand); build this grid again from its sources"
            )
        };
        if meta.count > MAX_VALUES {
            damaged(format!(
                "{}: {} values, more than ten years",
                manifest(dir, grid).display(),
                meta.count
            ))?;
        }
        let mut parts = Vec::new();
        let mut end = 0;
        for part in meta.parts_listed() {
            let path = part_path(dir, grid, &part)?;
            if part.first < end || part.first + part.count > meta.count {
                damaged(format!(
                    "{}: its parts overlap or pass the series' end",
                    manifest(dir, grid).display()
                ))?;
            }
            end = part.first + part.count;
            let file = File::open(&path).with_context(|| format!("{}", path.display()))?;
            let len = file
                .metadata()
                .with_context(|| format!("{}", path.display()))?
                .len();
            if len != part.count as u64 * 4 {
                damaged(format!(
                    "{}: {len} bytes where the manifest announces {} values",
                    path.display(),
                    part.count
                ))?;
            }
            parts.push((part, path, file));
        }
        Ok(GridValues {
            meta,
            parts,
            mean_hz: None,
        })
    }

    /// Reads every part once, in parallel: verifies each checksum and sums the grid up.
    pub fn check(&self) -> Result<GridSummary> {
        self.check_and_mean().map(|(s, _)| s)
    }

    fn check_and_mean(&self) -> Result<(GridSummary, f64)> {
        let sums = self
            .parts
            .par_iter()
            .map(|(part, path, file)| -> Result<PartSums> {
                let mut h = crc32fast::Hasher::new();
                let mut s = PartSums::default();
                let mut bytes = vec![0u8; STRETCH * 4];
                let mut prev_gap = false;
                for lo in (0..part.count).step_by(STRETCH) {
                    let raw = &mut bytes[..STRETCH.min(part.count - lo) * 4];
                    read_bytes(file, lo, raw).with_context(|| format!("{}", path.display()))?;
                    h.update(raw);
                    // gaps and the sum of the rest in one loop the compiler vectorises
                    let (mut gaps, mut sum) = (0usize, 0i64);
                    for c in raw.chunks_exact(4) {
                        let v = i32::from_le_bytes([c[0], c[1], c[2], c[3]]);
                        let gap = v == GAP;
                        gaps += usize::from(gap);
                        sum += if gap { 0 } else { v as i64 };
                    }
                    let n = raw.len() / 4;
                    s.finite += n - gaps;
                    s.sum += sum as i128;
                    if gaps == 0 {
                        if lo == 0 {
                            s.starts_gap = false;
                        }
                        prev_gap = false;
                        continue;
                    }
                    for (i, c) in raw.chunks_exact(4).enumerate() {
                        let gap = i32::from_le_bytes([c[0], c[1], c[2], c[3]]) == GAP;
                        if gap && !prev_gap && (lo + i) > 0 {
                            s.gap_runs += 1;
                        }
                        if lo + i == 0 {
                            s.starts_gap = gap;
                        }
                        prev_gap = gap;
                    }
                }
                s.ends_gap = prev_gap;
                if let Some(want) = part.crc32 {
                    let got = h.finalize();
                    if got != want {
                        fail!(
                            Store,
                            "{}: the values do not match their checksum (CRC-32 {got:08x}, the \
                             manifest says {want:08x}): they were damaged on disk; build this \
                             grid again from its sources",
                            path.display()
                        );
                    }
                }
                Ok(s)
            })
            .collect::<Result<Vec<_>>>()?;
        // gaps between parts, and runs across their borders
        let (mut finite, mut sum, mut runs, mut end, mut prev_gap) = (0, 0i128, 0, 0, false);
        for ((part, _, _), s) in self.parts.iter().zip(&sums) {
            if part.first > end {
                runs += usize::from(!prev_gap);
                prev_gap = true;
            }
            if part.count > 0 {
                runs += s.gap_runs + usize::from(s.starts_gap && !prev_gap);
                prev_gap = s.ends_gap;
            }
            finite += s.finite;
            sum += s.sum;
            end = part.first + part.count;
        }
        if self.meta.count > end && !prev_gap {
            runs += 1;
        }
        let summary = GridSummary {
            values: self.meta.count,
            gaps: self.meta.count - finite,
            gap_runs: runs,
            parts: self.parts.len(),
            checksummed: self.parts.iter().filter(|p| p.0.crc32.is_some()).count(),
            bytes: self.parts.iter().map(|p| p.0.count as u64 * 4).sum(),
        };
        let mean = if finite > 0 {
            self.meta.nominal_hz + sum as f64 / finite as f64 * 1e-6
        } else {
            0.0
        };
        Ok((summary, mean))
    }

    /// Opens one grid for searching: every checksum verified, and the mean kept.
    pub fn open_checked(dir: &Path, grid: &str) -> Result<Self> {
        let mut g = Self::open(dir, grid)?;
        g.mean_hz = Some(g.check_and_mean()?.1);
        Ok(g)
    }

    /// Stored values `start .. start + dst.len()` (within the series), [`GAP`] where no part
    /// holds them.
    pub fn read_stored(&self, start: usize, dst: &mut [i32]) -> Result<()> {
        dst.fill(GAP);
        let end = start + dst.len();
        let from = self
            .parts
            .partition_point(|(p, _, _)| p.first + p.count <= start);
        for (part, path, file) in &self.parts[from..] {
            if part.first >= end {
                break;
            }
            let lo = part.first.max(start);
            let hi = (part.first + part.count).min(end);
            read_part(file, lo - part.first, &mut dst[lo - start..hi - start])
                .with_context(|| format!("{}", path.display()))?;
        }
        Ok(())
    }

    /// Values `start .. start + dst.len()` (within the series) in Hz, NaN where no part holds
    /// them, through one buffer per thread (this is what a search reads, a block at a time).
    pub fn read_hz(&self, start: usize, dst: &mut [f64]) -> Result<()> {
        thread_local! {
            static VALUES: std::cell::RefCell<Vec<i32>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        let f0 = self.meta.nominal_hz;
        VALUES.with_borrow_mut(|values| {
            values.resize(dst.len(), GAP);
            self.read_stored(start, values)?;
            for (d, &v) in dst.iter_mut().zip(values.iter()) {
                *d = to_hz(v, f0);
            }
            Ok(())
        })
    }

    /// Every value, in memory (for small grids and tests).
    pub fn read_all(&self) -> Result<Vec<i32>> {
        let mut out = vec![GAP; self.meta.count];
        self.read_stored(0, &mut out)?;
        Ok(out)
    }
}

impl ReferenceValues for GridValues {
    fn len(&self) -> usize {
        self.meta.count
    }

    fn read(&self, start: usize, dst: &mut [f64]) -> std::result::Result<(), MatchError> {
        self.read_hz(start, dst)
            .map_err(|e| MatchError::Read(e.to_string()))
    }

    fn finite_mean(&self) -> std::result::Result<f64, MatchError> {
        match self.mean_hz {
            Some(m) => Ok(m),
            None => self
                .check_and_mean()
                .map(|(_, m)| m)
                .map_err(|e| MatchError::Read(e.to_string())),
        }
    }
}
