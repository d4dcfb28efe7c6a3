//! Shared plumbing of the word readers (Prophesee and jAER): text headers (`%`, `#`), chunked
//! reading of whole words with constant memory over any byte [`Source`], skip counts and
//! counter unwrapping.

use std::io::{BufRead, BufReader, Read, Seek, SeekFrom};

use crate::{EventBatch, EventReader, Source, StreamInfo};
use std::path::{Path, PathBuf};

use crate::error::{io_err, EventError, Result};

/// Bytes read per chunk.
const CHUNK: usize = 1 << 18;
/// Longest header accepted (a file whose "header" runs longer is not an event file).
const MAX_HEADER: usize = 1 << 20;

/// Header lines (without their prefix and line ending) and where the data starts.
pub(crate) struct TextHeader {
    pub lines: Vec<String>,
    pub data_start: u64,
}

/// Reads the lines that start with `prefix` at the top of `src` (named `path` in errors).
/// `end_marker`, when given, is a line that ends the header (and belongs to it).
pub(crate) fn read_text_header(
    src: &mut dyn Source,
    path: &Path,
    prefix: &[u8],
    end_marker: Option<&[u8]>,
    format: &'static str,
) -> Result<TextHeader> {
    src.seek(SeekFrom::Start(0)).map_err(|e| io_err(path, e))?;
    let mut r = BufReader::new(src);
    let mut lines = Vec::new();
    let mut pos = 0u64;
    let mut line = Vec::new();
    loop {
        let buf = r.fill_buf().map_err(|e| io_err(path, e))?;
        if buf.is_empty() || !buf.starts_with(&prefix[..prefix.len().min(buf.len())]) {
            break;
        }
        if buf.len() < prefix.len() {
            break;
        }
        line.clear();
        let n = r
            .by_ref()
            .take(MAX_HEADER as u64)
            .read_until(b'\n', &mut line)
            .map_err(|e| io_err(path, e))?;
        if n == 0 || line.last() != Some(&b'\n') {
            return Err(EventError::Truncated {
                path: path.to_path_buf(),
                format,
                offset: pos,
                reason: "header line without an end".into(),
            });
        }
        pos += n as u64;
        if pos as usize > MAX_HEADER {
            return Err(EventError::Corrupt {
                path: path.to_path_buf(),
                format,
                offset: pos,
                reason: "header longer than 1 MiB".into(),
            });
        }
        let text = String::from_utf8_lossy(&line[prefix.len()..]);
        let text = text.trim_end_matches(['\r', '\n']).trim().to_string();
        let is_end = end_marker.is_some_and(|m| line.starts_with(m));
        lines.push(text);
        if is_end {
            break;
        }
    }
    Ok(TextHeader {
        lines,
        data_start: pos,
    })
}

/// Reads a file from an offset in chunks that hold whole words of `word` bytes.
pub(crate) struct WordReader {
    pub path: PathBuf,
    file: Box<dyn Source>,
    buf: Vec<u8>,
    /// Unconsumed bytes are `buf[start..end]`.
    start: usize,
    end: usize,
    /// File offset of `buf[start]`.
    offset: u64,
    /// File offset of the last chunk handed out.
    chunk_offset: u64,
    word: usize,
    eof: bool,
    done: bool,
    format: &'static str,
}

impl WordReader {
    pub(crate) fn new(
        mut file: Box<dyn Source>,
        path: &Path,
        start: u64,
        word: usize,
        format: &'static str,
    ) -> Result<Self> {
        file.seek(SeekFrom::Start(start))
            .map_err(|e| io_err(path, e))?;
        Ok(WordReader {
            path: path.to_path_buf(),
            file,
            buf: vec![0; CHUNK],
            start: 0,
            end: 0,
            offset: start,
            chunk_offset: start,
            word,
            eof: false,
            done: false,
            format,
        })
    }

    /// Ends the reading: the next chunk is `None`.
    pub(crate) fn stop(&mut self) {
        self.done = true;
    }

    /// File offset of the first byte of the last chunk.
    pub(crate) fn chunk_offset(&self) -> u64 {
        self.chunk_offset
    }

    /// The next chunk of whole words, `None` at the end. A partial word at the end of the file
    /// is reported as truncation, after the whole words before it.
    pub(crate) fn next_chunk(&mut self) -> Result<Option<&[u8]>> {
        if self.done {
            return Ok(None);
        }
        self.buf.copy_within(self.start..self.end, 0);
        self.end -= self.start;
        self.start = 0;
        while self.end < self.buf.len() && !self.eof {
            match self.file.read(&mut self.buf[self.end..]) {
                Ok(0) => self.eof = true,
                Ok(n) => self.end += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(io_err(&self.path, e)),
            }
        }
        let whole = self.end / self.word * self.word;
        if whole == 0 {
            self.done = true;
            if self.end == 0 {
                return Ok(None);
            }
            return Err(EventError::Truncated {
                path: self.path.clone(),
                format: self.format,
                offset: self.offset,
                reason: format!(
                    "{} trailing bytes, less than one {}-byte word",
                    self.end, self.word
                ),
            });
        }
        self.chunk_offset = self.offset;
        self.offset += whole as u64;
        self.start = whole;
        Ok(Some(&self.buf[..whole]))
    }
}

/// Turns chunks of whole words into events, keeping the format's state between chunks.
pub(crate) trait WordDecoder: Send {
    /// Bytes per word.
    const WORD: usize;
    /// Decodes `chunk` (whole words) into `out`.
    fn decode(&mut self, chunk: &[u8], out: &mut EventBatch) -> std::result::Result<(), String>;
    /// Words that were not events, by kind.
    fn skipped(&self) -> Vec<(&'static str, u64)>;
    /// At the end of the data: what an event begun and not finished lacks (a file cut short
    /// inside an event of a byte-wise format), if any.
    fn unfinished(&self) -> Option<String> {
        None
    }
}

/// A reader made of a [`WordReader`] and a format's [`WordDecoder`].
pub(crate) struct WordStream<D: WordDecoder> {
    words: WordReader,
    decoder: D,
    info: StreamInfo,
    format: &'static str,
    /// Added to every timestamp (eenf's `% eenf_time_offset_us` header line).
    offset: i64,
    /// The damage found in the chunk whose events before it were handed out last.
    failed: Option<EventError>,
    /// The end of the data was reported.
    ended: bool,
}

impl<D: WordDecoder> WordStream<D> {
    pub(crate) fn new(
        src: Box<dyn Source>,
        path: &Path,
        start: u64,
        decoder: D,
        info: StreamInfo,
    ) -> Result<Self> {
        Ok(WordStream {
            words: WordReader::new(src, path, start, D::WORD, info.format)?,
            decoder,
            format: info.format,
            info,
            offset: 0,
            failed: None,
            ended: false,
        })
    }

    /// Adds `offset` µs to every timestamp.
    pub(crate) fn with_offset(mut self, offset: i64) -> Self {
        self.offset = offset;
        self
    }
}

impl<D: WordDecoder> EventReader for WordStream<D> {
    fn info(&self) -> &StreamInfo {
        &self.info
    }

    fn batch_offset(&self) -> Option<u64> {
        Some(self.words.chunk_offset())
    }

    fn next_batch(&mut self) -> Result<Option<EventBatch>> {
        if let Some(e) = self.failed.take() {
            return Err(e);
        }
        loop {
            let Some(chunk) = self.words.next_chunk()? else {
                if let Some(reason) = self.decoder.unfinished().filter(|_| !self.ended) {
                    self.ended = true;
                    return Err(EventError::Truncated {
                        path: self.words.path.clone(),
                        format: self.format,
                        offset: self.words.chunk_offset(),
                        reason,
                    });
                }
                return Ok(None);
            };
            let mut batch = EventBatch::with_capacity(chunk.len() / D::WORD);
            if let Err(reason) = self.decoder.decode(chunk, &mut batch) {
                self.words.stop();
                let e = EventError::Corrupt {
                    path: self.words.path.clone(),
                    format: self.format,
                    offset: self.words.chunk_offset(),
                    reason,
                };
                // the events before the damage first, then the error
                if batch.is_empty() {
                    return Err(e);
                }
                self.failed = Some(e);
            }
            if !batch.is_empty() {
                if self.offset != 0 {
                    batch.t.iter_mut().for_each(|t| *t += self.offset);
                }
                return Ok(Some(batch));
            }
        }
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        self.decoder.skipped()
    }
}

/// Counts of skipped words, for `info`.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct Skips {
    pub triggers: u64,
    pub other: u64,
    pub before_time: u64,
    pub unknown: u64,
    pub other_camera: u64,
}

impl Skips {
    pub(crate) fn list(&self) -> Vec<(&'static str, u64)> {
        [
            ("trigger", self.triggers),
            ("other (IMU/APS/system)", self.other),
            ("before the first time word", self.before_time),
            ("unknown type", self.unknown),
            ("the other camera's", self.other_camera),
        ]
        .into_iter()
        .filter(|(_, n)| *n > 0)
        .collect()
    }
}

/// Undoes the wrap-around of a counter of `bits` bits: a value that drops by more than half the
/// range starts a new loop.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct Unwrap {
    last: Option<u64>,
    loops: u64,
}

impl Unwrap {
    pub(crate) fn next(&mut self, raw: u64, bits: u32) -> u64 {
        if let Some(last) = self.last {
            if raw < last && last - raw > 1u64 << (bits - 1) {
                self.loops += 1;
            }
        }
        self.last = Some(raw);
        (self.loops << bits) | raw
    }
}
