//! Long signals kept on disk: a day of sound decimated for its hum is 95 M samples (760 MB
//! as f64), more than a laptop should hold for one trace. The samples go to an unnamed
//! temporary file as they are decimated (Linux's `O_TMPFILE`, or a file removed at once
//! elsewhere: nothing is left behind, however the process ends) and are read back a block at
//! a time ([`eenf_dsp::blocks`]).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::ops::Range;

use eenf_dsp::blocks::BlockSource;
use eenf_dsp::DspError;

use crate::error::{Context, Result};

/// Bytes per sample on disk (f64, little-endian: the samples read back are the ones written).
const SAMPLE: usize = 8;

/// A signal on disk, at `fs`.
#[derive(Debug)]
pub struct Spool {
    file: File,
    len: usize,
    /// Sampling rate, Hz.
    pub fs: f64,
}

/// Writes a [`Spool`]: the first `skip` samples pushed are dropped (a decimator's delay), and
/// at most `limit` are kept.
pub struct SpoolWriter {
    out: BufWriter<File>,
    skip: usize,
    limit: usize,
    len: usize,
    fs: f64,
}

impl SpoolWriter {
    /// A new, empty spool at `fs`.
    pub fn new(fs: f64) -> Result<Self> {
        let file = tempfile::tempfile().context("a temporary file for the decimated sound")?;
        Ok(SpoolWriter {
            out: BufWriter::with_capacity(1 << 20, file),
            skip: 0,
            limit: usize::MAX,
            len: 0,
            fs,
        })
    }

    /// Drops the first `n` samples pushed from here on.
    pub fn skip(mut self, n: usize) -> Self {
        self.skip = n;
        self
    }

    /// Keeps at most `n` samples.
    pub fn limit(mut self, n: usize) -> Self {
        self.limit = n;
        self
    }

    /// Samples kept so far.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when no sample is kept yet.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Appends `v`.
    pub fn push(&mut self, v: &[f64]) -> Result<()> {
        let dropped = self.skip.min(v.len());
        self.skip -= dropped;
        let keep = (v.len() - dropped).min(self.limit - self.len);
        let bytes: Vec<u8> = v[dropped..dropped + keep]
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        self.out
            .write_all(&bytes)
            .context("writing the decimated sound to its temporary file")?;
        self.len += keep;
        Ok(())
    }

    /// The spool written.
    pub fn finish(self) -> Result<Spool> {
        let file = self
            .out
            .into_inner()
            .map_err(|e| e.into_error())
            .context("writing the decimated sound to its temporary file")?;
        Ok(Spool {
            file,
            len: self.len,
            fs: self.fs,
        })
    }
}

impl Spool {
    /// Samples `range` (within the spool).
    pub fn read(&self, range: Range<usize>) -> Result<Vec<f64>> {
        read_at(&self.file, range)
            .context("reading the decimated sound back from its temporary file")
    }

    /// Every sample: for what needs the whole signal at once (a clip, edits).
    pub fn to_vec(&self) -> Result<Vec<f64>> {
        self.read(0..self.len)
    }

    /// Length in samples.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when it holds no sample.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Length in seconds.
    pub fn duration_s(&self) -> f64 {
        self.len as f64 / self.fs
    }
}

fn read_at(file: &File, range: Range<usize>) -> std::io::Result<Vec<f64>> {
    let mut bytes = vec![0u8; range.len() * SAMPLE];
    let at = (range.start * SAMPLE) as u64;
    #[cfg(unix)]
    std::os::unix::fs::FileExt::read_exact_at(file, &mut bytes, at)?;
    #[cfg(not(unix))]
    {
        use std::io::{Read, Seek};
        let mut f = file.try_clone()?;
        f.seek(std::io::SeekFrom::Start(at))?;
        f.read_exact(&mut bytes)?;
    }
    Ok(bytes
        .chunks_exact(SAMPLE)
        .map(|b| f64::from_le_bytes(b.try_into().unwrap_or_default()))
        .collect())
}

impl BlockSource for Spool {
    fn len(&self) -> usize {
        self.len
    }
    fn read(&self, range: Range<usize>) -> std::result::Result<Vec<f64>, DspError> {
        read_at(&self.file, range).map_err(|e| DspError::Read(e.to_string()))
    }
}
