//! A change to one grid of a store: values merged a part at a time, only the parts they touch
//! rewritten, and everything committed in one atomic step.

use std::fs::File;
use std::path::{Path, PathBuf};

use eenf_core::Grid;

use super::values::{decode, read_bytes, read_part, GridValues};
use super::{
    crc_of, finite_sum, manifest, part_path, to_stored, Part, RefMeta, StoredGrid, GAP, PART_VALUES,
};
use crate::error::{fail, Context, Result};
use crate::output::write_atomic;

/// Parts held in memory at once while merging (16 MB each); more are written out early,
/// still uncommitted.
const OPEN_PARTS: usize = 8;

/// One grid being changed. Nothing is visible in the store until [`GridEdit::commit`]; files
/// written before it are removed when the edit is dropped uncommitted.
pub struct GridEdit {
    dir: PathBuf,
    /// The manifest as it will be committed.
    pub meta: RefMeta,
    /// The series' parts as edited so far, in order.
    parts: Vec<Part>,
    /// Stretches being changed (numbered from the Unix epoch), with their values.
    open: Vec<(i64, Vec<i32>)>,
    /// Files this edit wrote, removed unless committed.
    written: Vec<PathBuf>,
    /// Files the commit stops naming, removed after it.
    retired: Vec<PathBuf>,
    /// Names this edit's files: its time and process, and a counter.
    stamp: u128,
    written_count: usize,
}

impl GridEdit {
    fn with(dir: &Path, meta: RefMeta, parts: Vec<Part>) -> Self {
        let stamp = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        GridEdit {
            dir: dir.to_path_buf(),
            meta,
            parts,
            open: Vec::new(),
            written: Vec::new(),
            retired: Vec::new(),
            stamp,
            written_count: 0,
        }
    }

    /// A new grid `name` of `grid` in the store at `dir`, one value per `step_s`.
    pub fn new(dir: &Path, name: &str, grid: Grid, step_s: f64, start_unix_s: f64) -> Self {
        let meta = StoredGrid::new(name, grid, step_s, start_unix_s).meta;
        Self::with(dir, meta, Vec::new())
    }

    /// The grid `grid` of the store at `dir`, to change. Its parts' sizes are checked; a store
    /// written with one values file has its checksum verified here (that file is split into
    /// parts where the edit touches it), the others' as the edit reads them.
    pub fn open(dir: &Path, grid: &str) -> Result<Self> {
        let values = GridValues::open(dir, grid)?;
        let meta = values.meta.clone();
        if meta.parts.is_none() {
            values.check()?;
        }
        let parts = meta.parts_listed();
        let parts = parts.into_iter().filter(|p| p.count > 0).collect();
        Ok(Self::with(dir, meta, parts))
    }

    /// Values in the series (gaps included).
    pub fn len(&self) -> usize {
        self.meta.count
    }

    /// True when the series holds no value yet.
    pub fn is_empty(&self) -> bool {
        self.meta.count == 0
    }

    /// The index range of stretch `c`, clipped to the series.
    fn span(&self, c: i64) -> (usize, usize) {
        let origin = self.meta.origin();
        let lo = (c * PART_VALUES as i64 - origin).max(0) as usize;
        let hi = ((c + 1) * PART_VALUES as i64 - origin).max(0) as usize;
        (lo.min(self.meta.count), hi.min(self.meta.count))
    }

    /// The stretch holding index `i`, and the place of `i` in it.
    fn stretch_of(&self, i: usize) -> (i64, usize) {
        let g = self.meta.origin() + i as i64;
        let c = g.div_euclid(PART_VALUES as i64);
        (c, (g - c * PART_VALUES as i64) as usize)
    }

    /// Places `hz` (one value per `step_s` from `start_unix_s`) into the series, resampled to
    /// the series' step; the series grows (with gaps) as needed, and new values replace old.
    pub fn merge(&mut self, start_unix_s: f64, step_s: f64, hz: &[f64]) -> Result<()> {
        let vals = eenf_dsp::resample::resample(hz, step_s, self.meta.step_s);
        let empty = self.meta.count == 0 && self.parts.is_empty() && self.open.is_empty();
        let (first, pad) = self.meta.place(start_unix_s, vals.len(), empty)?;
        // the start moved earlier: every index moves on, every stretch stays
        for p in &mut self.parts {
            p.first += pad;
        }
        let f0 = self.meta.nominal_hz;
        let mut i = 0;
        while i < vals.len() {
            let (c, off) = self.stretch_of(first + i);
            let n = (PART_VALUES - off).min(vals.len() - i);
            let new = &vals[i..i + n];
            if new.iter().any(|v| v.is_finite()) {
                let buf = self.stretch(c)?;
                for (slot, v) in buf[off..off + n].iter_mut().zip(new) {
                    if let Some(x) = to_stored(*v, f0) {
                        *slot = x;
                    }
                }
            }
            i += n;
        }
        Ok(())
    }

    /// Stretch `c`'s values, read from the store the first time (verified when a part is
    /// read whole).
    fn stretch(&mut self, c: i64) -> Result<&mut Vec<i32>> {
        if let Some(k) = self.open.iter().position(|(s, _)| *s == c) {
            return Ok(&mut self.open[k].1);
        }
        if self.open.len() >= OPEN_PARTS {
            let (old, values) = self.open.remove(0);
            self.write_stretch(old, &values)?;
        }
        let mut values = vec![GAP; PART_VALUES];
        let (lo, hi) = self.span(c);
        let at = self.stretch_of(lo).1;
        for part in self
            .parts
            .iter()
            .filter(|p| p.first < hi && p.first + p.count > lo)
        {
            let (a, b) = (part.first.max(lo), (part.first + part.count).min(hi));
            let whole = a == part.first && b == part.first + part.count;
            let path = part_path(&self.dir, &self.meta.grid, part)?;
            let mut bytes = vec![0u8; (b - a) * 4];
            let file = File::open(&path).with_context(|| format!("{}", path.display()))?;
            read_bytes(&file, a - part.first, &mut bytes)
                .with_context(|| format!("{}", path.display()))?;
            if let (true, Some(want)) = (whole, part.crc32) {
                if crc_of(&bytes) != want {
                    fail!(
                        Store,
                        "{}: the values do not match their checksum: they were damaged on \
                         disk; build this grid again from its sources",
                        path.display()
                    );
                }
            }
            decode(&bytes, &mut values[at + (a - lo)..at + (b - lo)]);
        }
        self.open.push((c, values));
        Ok(&mut self.open.last_mut().expect("just pushed").1)
    }

    /// Writes stretch `c` (its values from the stretch's start) as a new part, in place of
    /// the parts it overlaps; a part that reaches past the stretch (a store's one values file)
    /// is split, its other stretches written as parts of their own.
    fn write_stretch(&mut self, c: i64, values: &[i32]) -> Result<()> {
        let (lo, hi) = self.span(c);
        let at = self.stretch_of(lo).1;
        let overlapping: Vec<Part> = self
            .parts
            .iter()
            .filter(|p| p.first < hi && p.first + p.count > lo)
            .cloned()
            .collect();
        self.parts
            .retain(|p| !(p.first < hi && p.first + p.count > lo));
        for old in overlapping {
            let path = part_path(&self.dir, &self.meta.grid, &old)?;
            // the rest of a long part, a stretch at a time
            let mut i = old.first;
            let end = old.first + old.count;
            let file = File::open(&path).with_context(|| format!("{}", path.display()))?;
            while i < end {
                let (s, off) = self.stretch_of(i);
                let n = (PART_VALUES - off).min(end - i);
                if s != c {
                    let mut vals = vec![GAP; n];
                    read_part(&file, i - old.first, &mut vals)
                        .with_context(|| format!("{}", path.display()))?;
                    self.add_part(i, &vals)?;
                }
                i += n;
            }
            self.retire(path);
        }
        self.add_part(lo, &values[at..at + (hi - lo)])
    }

    /// Writes `values` (from index `first`) as a new part, without the gaps at its ends
    /// (unless all are gaps: then nothing).
    fn add_part(&mut self, first: usize, values: &[i32]) -> Result<()> {
        let Some(a) = values.iter().position(|&v| v != GAP) else {
            return Ok(());
        };
        let b = values.iter().rposition(|&v| v != GAP).map_or(a, |b| b + 1);
        let (first, values) = (first + a, &values[a..b]);
        let mut bytes = Vec::with_capacity(values.len() * 4);
        for v in values {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        // a new name for every file: the old ones stay whole until the manifest moves on
        let file = format!(
            "{}.{:x}{:05x}.{}.i32",
            self.meta.grid,
            self.stamp,
            self.written_count,
            std::process::id()
        );
        self.written_count += 1;
        let path = self.dir.join(&file);
        self.written.push(path.clone());
        write_atomic(&path, |w| {
            w.write_all(&bytes)?;
            Ok(())
        })?;
        File::open(&path)
            .and_then(|f| f.sync_all())
            .with_context(|| format!("{}", path.display()))?;
        let (finite, sum) = finite_sum(values.iter().copied());
        let part = Part {
            file,
            first,
            count: values.len(),
            crc32: Some(crc_of(&bytes)),
            finite: Some(finite),
            sum_uhz: Some(sum),
        };
        let k = self.parts.partition_point(|p| p.first < first);
        self.parts.insert(k, part);
        Ok(())
    }

    /// A file the committed store will not name: removed now when this edit wrote it, after
    /// the commit otherwise.
    fn retire(&mut self, path: PathBuf) {
        if let Some(k) = self.written.iter().position(|w| *w == path) {
            self.written.remove(k);
            let _ = std::fs::remove_file(&path);
        } else {
            self.retired.push(path);
        }
    }

    /// Commits the change: the stretches changed written as new parts, then the manifest that
    /// names them renamed over the old one (the commit), then the files it no longer names
    /// removed. Call it under [`super::StoreLock::exclusive`]. Returns the values the grid
    /// holds.
    pub fn commit(mut self) -> Result<usize> {
        super::check_grid_name(&self.meta.grid)?;
        std::fs::create_dir_all(&self.dir).with_context(|| format!("{}", self.dir.display()))?;
        let mut open = std::mem::take(&mut self.open);
        open.sort_by_key(|(c, _)| *c);
        for (c, values) in open {
            self.write_stretch(c, &values)?;
        }
        self.meta.parts = Some(self.parts.clone());
        self.meta.values_file = None;
        self.meta.values_crc32 = None;
        let json = manifest(&self.dir, &self.meta.grid);
        write_atomic(&json, |w| {
            serde_json::to_writer_pretty(&mut *w, &self.meta)?;
            Ok(())
        })?;
        if let Ok(d) = File::open(&self.dir) {
            let _ = d.sync_all();
        }
        // committed: what this edit wrote is the store's now
        self.written.clear();
        for old in std::mem::take(&mut self.retired) {
            let _ = std::fs::remove_file(old);
        }
        Ok(self.meta.count)
    }
}

impl Drop for GridEdit {
    fn drop(&mut self) {
        for path in &self.written {
            let _ = std::fs::remove_file(path);
        }
    }
}
