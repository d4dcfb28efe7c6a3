//! A grid's values read where needed: what `match` searches and `refdb info` sums up, a
//! stretch at a time, so that a decade is never held in memory.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

use rayon::prelude::*;

use eenf_dsp::matching::{MatchError, ReferenceValues};

use super::{manifest, part_path, Part, RefMeta, StoredGrid, GAP, MAX_VALUES};
use crate::error::{fail, Context, Result};

/// Values read per request while checking and summing up a part.
const STRETCH: usize = 1 << 20;

/// One grid of a store, opened for reading: its manifest and its parts' files.
pub struct GridValues {
    /// The manifest.
    pub meta: RefMeta,
    parts: Vec<(Part, PathBuf, File)>,
    /// The mean of its values in Hz: from the manifest's sums, or once
    /// [`GridValues::check`] has read them.
    mean_hz: Option<f64>,
    /// Whether the checks wait for a search's pass (see [`GridValues::open_for_search`]).
    pending: AtomicBool,
    /// What that pass has read of each part so far.
    pieces: Mutex<Vec<Piece>>,
}

/// What one read of a search's pass read as its own of one part: from its value `at`,
/// `count` values, their CRC-32, and how many are not gaps and their sum.
#[derive(PartialEq)]
struct Piece {
    part: usize,
    at: usize,
    count: usize,
    crc32: u32,
    finite: usize,
    sum: i64,
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

/// The mean in Hz of `finite` values summing to `sum` (stored units); 0 when there are none.
fn mean_of(nominal_hz: f64, finite: usize, sum: i128) -> f64 {
    if finite > 0 {
        nominal_hz + sum as f64 / finite as f64 * 1e-6
    } else {
        0.0
    }
}

/// Fails unless a part's values, read whole, gave the checksum and the sums its manifest
/// gives (where it gives them).
fn check_part(part: &Part, path: &Path, crc32: u32, finite: usize, sum: i128) -> Result<()> {
    if let Some(want) = part.crc32 {
        if crc32 != want {
            fail!(
                Store,
                "{}: the values do not match their checksum (CRC-32 {crc32:08x}, the manifest \
                 says {want:08x}): they were damaged on disk; build this grid again from its \
                 sources",
                path.display()
            );
        }
    }
    let sums_match =
        part.finite.is_none_or(|n| n == finite) && part.sum_uhz.is_none_or(|s| s as i128 == sum);
    if !sums_match {
        fail!(
            Store,
            "{}: the values do not match the sums the manifest gives ({finite} values summing \
             to {sum} where it says {:?} and {:?}): the store was damaged; build this grid \
             again from its sources",
            path.display(),
            part.finite,
            part.sum_uhz
        );
    }
    Ok(())
}

/// How many of the stored values in `bytes` are not gaps, and their sum, in one loop built
/// for the processor.
fn stretch_sums(bytes: &[u8]) -> (usize, i64) {
    eenf_dsp::simd::fast(|| {
        let values = bytes.as_chunks::<4>().0.iter();
        super::finite_sum(values.map(|c| i32::from_le_bytes(*c)))
    })
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
            pending: AtomicBool::new(false),
            pieces: Mutex::new(Vec::new()),
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
                    let (finite, sum) = stretch_sums(raw);
                    let gaps = raw.len() / 4 - finite;
                    s.finite += finite;
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
                check_part(part, path, h.finalize(), s.finite, s.sum)?;
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
        Ok((summary, mean_of(self.meta.nominal_hz, finite, sum)))
    }

    /// Opens one grid for searching. When the manifest gives every part's sums, the mean is
    /// theirs and the checks (checksums and sums) wait for the search's pass over every value
    /// ([`ReferenceValues::read_in_pass`], [`ReferenceValues::end_pass`]): the values are
    /// read once, not twice. Otherwise (a store written before the sums) every value is
    /// checked now. A read before a pass has ended checks them all first.
    pub fn open_for_search(dir: &Path, grid: &str) -> Result<Self> {
        let mut g = Self::open(dir, grid)?;
        let sums = g
            .parts
            .iter()
            .try_fold((0usize, 0i128), |(n, s), (p, _, _)| {
                let (finite, sum) = (p.finite?, p.sum_uhz?);
                // what values of its count could sum to, no more
                let plausible = finite <= p.count
                    && sum.unsigned_abs() <= finite as u64 * (i32::MIN.unsigned_abs() as u64);
                plausible.then_some((n + finite, s + sum as i128))
            });
        match sums {
            Some((finite, sum)) if g.parts.iter().all(|p| p.0.crc32.is_some()) => {
                g.mean_hz = Some(mean_of(g.meta.nominal_hz, finite, sum));
                g.pending = AtomicBool::new(true);
            }
            _ => g.mean_hz = Some(g.check_and_mean()?.1),
        }
        Ok(g)
    }

    /// Checks every value now if a search's pass has not: what any read but the pass's
    /// calls first.
    fn ensure_checked(&self) -> Result<()> {
        if self.pending.load(Ordering::Acquire) {
            self.check_and_mean()?;
            self.pending.store(false, Ordering::Release);
        }
        Ok(())
    }

    /// Ends a search's pass: each part's pieces must tile it, and together give its
    /// checksum and sums; then every value has been checked. Pieces that do not tile a part
    /// (a pass cut short) leave the checks to a full read.
    fn end_search_pass(&self) -> Result<()> {
        if !self.pending.load(Ordering::Acquire) {
            return Ok(());
        }
        let mut pieces =
            std::mem::take(&mut *self.pieces.lock().unwrap_or_else(|e| e.into_inner()));
        pieces.sort_by_key(|p| (p.part, p.at));
        // a block read again (its keys asked for again) gives the same piece
        pieces.dedup();
        let mut from = 0;
        for (k, (part, path, _)) in self.parts.iter().enumerate() {
            let to = from + pieces[from..].partition_point(|p| p.part == k);
            let (mut h, mut next, mut finite, mut sum) = (crc32fast::Hasher::new(), 0, 0, 0);
            for p in &pieces[from..to] {
                if p.at != next {
                    break;
                }
                h.combine(&crc32fast::Hasher::new_with_initial_len(
                    p.crc32,
                    p.count as u64 * 4,
                ));
                (next, finite, sum) = (next + p.count, finite + p.finite, sum + p.sum);
            }
            if next != part.count {
                return self.ensure_checked();
            }
            check_part(part, path, h.finalize(), finite, sum as i128)?;
            from = to;
        }
        self.pending.store(false, Ordering::Release);
        Ok(())
    }

    /// Calls `read(k, file, path, at, lo, hi)` for each part `k` holding some of values
    /// `start .. end`: the part's values `lo .. hi` of the series, from value `at` of its file.
    fn each_part_in(
        &self,
        start: usize,
        end: usize,
        mut read: impl FnMut(usize, &File, &Path, usize, usize, usize) -> Result<()>,
    ) -> Result<()> {
        let from = self
            .parts
            .partition_point(|(p, _, _)| p.first + p.count <= start);
        for (k, (part, path, file)) in self.parts.iter().enumerate().skip(from) {
            if part.first >= end {
                break;
            }
            let lo = part.first.max(start);
            let hi = (part.first + part.count).min(end);
            read(k, file, path, lo - part.first, lo, hi)?;
        }
        Ok(())
    }

    /// Stored values `start .. start + dst.len()` (within the series), [`GAP`] where no part
    /// holds them.
    pub fn read_stored(&self, start: usize, dst: &mut [i32]) -> Result<()> {
        self.ensure_checked()?;
        dst.fill(GAP);
        self.each_part_in(start, start + dst.len(), |_, file, path, at, lo, hi| {
            read_part(file, at, &mut dst[lo - start..hi - start])
                .with_context(|| format!("{}", path.display()))
        })
    }

    /// Values `start .. start + dst.len()` (within the series) in Hz, NaN where no part holds
    /// them: what a search reads, a block at a time.
    pub fn read_hz(&self, start: usize, dst: &mut [f64]) -> Result<()> {
        self.ensure_checked()?;
        self.read_hz_in(start, dst, None)
    }

    /// [`Self::read_hz`], the bytes going straight to Hz through one buffer per thread; with
    /// `own`, a search's pass that reads the first `own` values as its own, whose pieces it
    /// keeps for [`Self::end_search_pass`].
    fn read_hz_in(&self, start: usize, dst: &mut [f64], own: Option<usize>) -> Result<()> {
        thread_local! {
            static BYTES: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        let f0 = self.meta.nominal_hz;
        dst.fill(f64::NAN);
        BYTES.with_borrow_mut(|bytes| {
            self.each_part_in(start, start + dst.len(), |k, file, path, at, lo, hi| {
                if bytes.len() < (hi - lo) * 4 {
                    bytes.resize((hi - lo) * 4, 0);
                }
                let raw = &mut bytes[..(hi - lo) * 4];
                read_bytes(file, at, raw).with_context(|| format!("{}", path.display()))?;
                let out = &mut dst[lo - start..hi - start];
                eenf_dsp::simd::fast(|| {
                    for (d, c) in out.iter_mut().zip(raw.as_chunks::<4>().0) {
                        // to_hz's value, computed for a gap too, then chosen (no branch)
                        let v = i32::from_le_bytes(*c);
                        let hz = f0 + v as f64 * 1e-6;
                        *d = if v == GAP { f64::NAN } else { hz };
                    }
                });
                // the values of this part the pass reads as its own (`lo` ≥ `start`)
                let owned = own.map_or(0, |n| (start + n).min(hi).saturating_sub(lo));
                if owned > 0 {
                    let mine = &raw[..owned * 4];
                    let (finite, sum) = stretch_sums(mine);
                    let piece = Piece {
                        part: k,
                        at,
                        count: owned,
                        crc32: super::crc_of(mine),
                        finite,
                        sum,
                    };
                    self.pieces
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .push(piece);
                }
                Ok(())
            })
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

    fn read_in_pass(
        &self,
        start: usize,
        dst: &mut [f64],
        own: usize,
    ) -> std::result::Result<(), MatchError> {
        let pending = self.pending.load(Ordering::Acquire);
        self.read_hz_in(start, dst, pending.then_some(own))
            .map_err(|e| MatchError::Read(e.to_string()))
    }

    fn end_pass(&self) -> std::result::Result<(), MatchError> {
        self.end_search_pass()
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
