//! Writers for every output format, behind one trait, over any seekable byte sink. Writing a
//! file whole or not at all (a temporary file renamed into place) is the caller's job.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::{io_err, EventError, Result};
use crate::{Aedat4Writer, Compression, EventBatch, Sink};

/// A sink for event batches.
pub trait EventWriter {
    /// Appends events (in time order).
    fn write(&mut self, batch: &EventBatch) -> Result<()>;
    /// Completes the file and flushes it; returns the number of events written.
    fn finish(self: Box<Self>) -> Result<u64>;
}

/// Output formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// iniVation AEDAT 4.0 with the given packet compression.
    Aedat4(Compression),
    /// Prophesee EVT 2.0.
    Evt2,
    /// Prophesee EVT 3.0 (vectorised).
    Evt3,
    /// Prophesee DAT v2.
    Dat,
    /// Text `t x y p` (µs, 0/1).
    Text,
}

/// `aedat4` (LZ4; see [`OutputFormat::with_compression`]), `evt2`, `evt3`, `dat`, `text`.
impl std::str::FromStr for OutputFormat {
    type Err = String;
    fn from_str(name: &str) -> std::result::Result<Self, String> {
        Ok(match name.to_ascii_lowercase().as_str() {
            "aedat4" | "aedat" => OutputFormat::Aedat4(Compression::Lz4),
            "evt2" | "evt2.0" => OutputFormat::Evt2,
            "evt3" | "evt3.0" => OutputFormat::Evt3,
            "dat" => OutputFormat::Dat,
            "text" | "txt" => OutputFormat::Text,
            _ => {
                return Err(format!(
                    "{name:?}: expected aedat4, evt2, evt3, dat or text"
                ))
            }
        })
    }
}

/// A short name for messages, e.g. `AEDAT 4.0 LZ4`, `EVT 3.0`.
impl std::fmt::Display for OutputFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OutputFormat::Aedat4(c) => write!(f, "AEDAT 4.0 {}", c.name()),
            OutputFormat::Evt2 => f.write_str("EVT 2.0"),
            OutputFormat::Evt3 => f.write_str("EVT 3.0"),
            OutputFormat::Dat => f.write_str("DAT"),
            OutputFormat::Text => f.write_str("text"),
        }
    }
}

impl OutputFormat {
    /// Every format, by its command-line name.
    pub const NAMES: [&'static str; 5] = ["aedat4", "evt2", "evt3", "dat", "text"];

    /// The same format with AEDAT4 packets compressed by `compression`.
    pub fn with_compression(self, compression: Compression) -> Self {
        match self {
            OutputFormat::Aedat4(_) => OutputFormat::Aedat4(compression),
            other => other,
        }
    }

    /// The format a file name asks for: `.aedat4`, `.raw` (EVT 3.0), `.dat`, `.txt`/`.csv`.
    pub fn from_extension(path: &Path, compression: Compression) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "aedat4" => OutputFormat::Aedat4(compression),
            "raw" => OutputFormat::Evt3,
            "dat" => OutputFormat::Dat,
            "txt" | "csv" => OutputFormat::Text,
            _ => return None,
        })
    }
}

/// Creates a plain file at `path` and a writer for `format` into it, for a sensor of
/// `width` × `height`.
pub fn create(
    path: &Path,
    format: OutputFormat,
    width: u16,
    height: u16,
) -> Result<Box<dyn EventWriter>> {
    let file = std::fs::File::create(path).map_err(|e| io_err(path, e))?;
    writer(Box::new(file), path, format, width, height)
}

/// A writer for `format` into `out` (named `name` in errors), for a sensor of
/// `width` × `height`.
pub fn writer(
    out: Box<dyn Sink>,
    name: &Path,
    format: OutputFormat,
    width: u16,
    height: u16,
) -> Result<Box<dyn EventWriter>> {
    let file = Output::new(out, name);
    Ok(match format {
        OutputFormat::Aedat4(c) => Box::new(Aedat4Writer::new(file.out, name, c, width, height)?),
        OutputFormat::Evt2 => Box::new(WordWriter::new(file, width, height, Evt2Enc::default())),
        OutputFormat::Evt3 => Box::new(WordWriter::new(file, width, height, Evt3Enc::default())),
        OutputFormat::Dat => Box::new(WordWriter::new(file, width, height, DatEnc)),
        OutputFormat::Text => Box::new(TextWriter::new(file)?),
    })
}

impl EventWriter for Aedat4Writer {
    fn write(&mut self, batch: &EventBatch) -> Result<()> {
        Aedat4Writer::write(self, batch)
    }
    fn finish(self: Box<Self>) -> Result<u64> {
        Aedat4Writer::finish(*self)
    }
}

/// A named, buffered sink.
struct Output {
    path: PathBuf,
    out: Box<dyn Sink>,
}

/// The buffered form of [`Output`].
struct Buffered {
    path: PathBuf,
    out: BufWriter<Box<dyn Sink>>,
}

impl Output {
    fn new(out: Box<dyn Sink>, name: &Path) -> Self {
        Output {
            path: name.to_path_buf(),
            out,
        }
    }

    fn buffered(self) -> Buffered {
        Buffered {
            path: self.path,
            out: BufWriter::with_capacity(1 << 20, self.out),
        }
    }
}

impl Buffered {
    fn write_all(&mut self, bytes: &[u8]) -> Result<()> {
        self.out.write_all(bytes).map_err(|e| io_err(&self.path, e))
    }

    fn commit(mut self) -> Result<()> {
        self.out.flush().map_err(|e| io_err(&self.path, e))
    }
}

/// Writes text events.
struct TextWriter {
    file: Buffered,
    line: String,
    count: u64,
}

impl TextWriter {
    /// Starts a text file in `out`.
    fn new(out: Output) -> Result<Self> {
        let mut file = out.buffered();
        file.write_all(b"# t_us x y p\n")?;
        Ok(TextWriter {
            file,
            line: String::new(),
            count: 0,
        })
    }
}

impl EventWriter for TextWriter {
    fn write(&mut self, b: &EventBatch) -> Result<()> {
        use std::fmt::Write as _;
        self.line.clear();
        for i in 0..b.len() {
            let _ = writeln!(
                self.line,
                "{} {} {} {}",
                b.t[i], b.x[i], b.y[i], b.p[i] as u8
            );
        }
        self.count += b.len() as u64;
        self.file.write_all(self.line.as_bytes())
    }

    fn finish(self: Box<Self>) -> Result<u64> {
        let n = self.count;
        self.file.commit()?;
        Ok(n)
    }
}

/// Encodes events as a word format's bytes.
trait WordEncoder {
    /// Header lines (without the `% ` prefix and line end); the last is `end` where the format
    /// has one.
    fn header(&self, width: u16, height: u16, offset: i64) -> String;
    /// Bytes after the header (DAT's type and size).
    fn preamble(&self) -> &'static [u8] {
        &[]
    }
    /// Appends the encoding of `b` (times already relative to the offset).
    fn encode(
        &mut self,
        b: &EventBatch,
        t: &[u64],
        out: &mut Vec<u8>,
    ) -> std::result::Result<(), String>;
    /// Name for messages.
    fn name(&self) -> &'static str;
}

/// Times stored relative to this offset when the first event does not fit the format's clock.
const DIRECT_TIME_LIMIT: i64 = 1 << 24;

struct WordWriter<E: WordEncoder> {
    file: Buffered,
    enc: E,
    width: u16,
    height: u16,
    offset: Option<i64>,
    buf: Vec<u8>,
    rel: Vec<u64>,
    count: u64,
}

impl<E: WordEncoder> WordWriter<E> {
    fn new(out: Output, width: u16, height: u16, enc: E) -> Self {
        WordWriter {
            file: out.buffered(),
            enc,
            width,
            height,
            offset: None,
            buf: Vec::new(),
            rel: Vec::new(),
            count: 0,
        }
    }

    fn start(&mut self, first_t: i64) -> Result<()> {
        let offset = if (0..DIRECT_TIME_LIMIT).contains(&first_t) {
            0
        } else {
            first_t
        };
        self.offset = Some(offset);
        let header = self.enc.header(self.width, self.height, offset);
        self.file.write_all(header.as_bytes())?;
        let pre = self.enc.preamble();
        self.file.write_all(pre)
    }

    fn invalid(&self, reason: String) -> EventError {
        EventError::Corrupt {
            path: self.file.path.clone(),
            format: self.enc.name(),
            offset: 0,
            reason: format!("cannot write: {reason}"),
        }
    }
}

impl<E: WordEncoder> EventWriter for WordWriter<E> {
    fn write(&mut self, b: &EventBatch) -> Result<()> {
        if b.is_empty() {
            return Ok(());
        }
        if self.offset.is_none() {
            self.start(b.t[0])?;
        }
        let offset = self.offset.unwrap();
        self.rel.clear();
        for &t in &b.t {
            if t < offset {
                return Err(self.invalid(format!(
                    "timestamp {t} µs precedes the first event ({offset} µs)"
                )));
            }
            self.rel.push((t - offset) as u64);
        }
        self.buf.clear();
        let rel = std::mem::take(&mut self.rel);
        let res = self.enc.encode(b, &rel, &mut self.buf);
        self.rel = rel;
        res.map_err(|r| self.invalid(r))?;
        self.count += b.len() as u64;
        let buf = std::mem::take(&mut self.buf);
        let res = self.file.write_all(&buf);
        self.buf = buf;
        res
    }

    fn finish(mut self: Box<Self>) -> Result<u64> {
        if self.offset.is_none() {
            self.start(0)?;
        }
        let n = self.count;
        self.file.commit()?;
        Ok(n)
    }
}

fn prophesee_header(evt: &str, format: &str, w: u16, h: u16, offset: i64) -> String {
    let mut s =
        format!("% evt {evt}\n% format {format};height={h};width={w}\n% geometry {w}x{h}\n");
    if offset != 0 {
        s.push_str(&format!("% eenf_time_offset_us {offset}\n"));
    }
    s.push_str("% end\n");
    s
}

fn check_xy(x: u16, y: u16, limit: u16) -> std::result::Result<(), String> {
    if x >= limit || y >= limit {
        return Err(format!(
            "pixel ({x}, {y}) does not fit the format's {limit}-value coordinates"
        ));
    }
    Ok(())
}

/// EVT 2.0: a TIME_HIGH word whenever t[33:6] changes, then one CD word per event.
#[derive(Default)]
struct Evt2Enc {
    last_th: Option<u64>,
}

impl WordEncoder for Evt2Enc {
    fn header(&self, w: u16, h: u16, offset: i64) -> String {
        prophesee_header("2.0", "EVT2", w, h, offset)
    }

    fn name(&self) -> &'static str {
        "EVT 2.0"
    }

    fn encode(
        &mut self,
        b: &EventBatch,
        t: &[u64],
        out: &mut Vec<u8>,
    ) -> std::result::Result<(), String> {
        out.reserve(b.len() * 4 + 64);
        for (i, &ti) in t.iter().enumerate().take(b.len()) {
            check_xy(b.x[i], b.y[i], 2048)?;
            let th = ti >> 6;
            if self.last_th != Some(th) {
                // across a long gap, intermediate TIME_HIGH words let readers count loops
                if let Some(last) = self.last_th {
                    let mut step = last;
                    while th > step && th - step > 1 << 26 {
                        step += 1 << 26;
                        out.extend_from_slice(
                            &((0x8 << 28) | (step & 0x0FFF_FFFF) as u32).to_le_bytes(),
                        );
                    }
                }
                out.extend_from_slice(&((0x8u32 << 28) | (th & 0x0FFF_FFFF) as u32).to_le_bytes());
                self.last_th = Some(th);
            }
            let w = ((b.p[i] as u32) << 28)
                | (((ti & 0x3F) as u32) << 22)
                | ((b.x[i] as u32) << 11)
                | b.y[i] as u32;
            out.extend_from_slice(&w.to_le_bytes());
        }
        Ok(())
    }
}

/// EVT 3.0: TIME_HIGH/TIME_LOW/ADDR_Y when they change; runs of events with one timestamp,
/// row and polarity become VECT_BASE_X + VECT_12 words where two or more fall within 12 pixels.
#[derive(Default)]
struct Evt3Enc {
    th: Option<u64>,
    tl: Option<u64>,
    y: Option<u16>,
    xs: Vec<u16>,
}

impl Evt3Enc {
    fn word(out: &mut Vec<u8>, kind: u16, payload: u16) {
        out.extend_from_slice(&((kind << 12) | payload).to_le_bytes());
    }

    fn set_time(&mut self, t: u64, out: &mut Vec<u8>) {
        let th = t >> 12;
        if self.th != Some(th) {
            if let Some(last) = self.th {
                // a jump of 2048 or more 4096-µs steps would hide a loop: step through it
                let mut step = last;
                while th > step && th - step >= 2048 {
                    step += 1024;
                    Self::word(out, 0x8, (step & 0xFFF) as u16);
                }
            }
            Self::word(out, 0x8, (th & 0xFFF) as u16);
            self.th = Some(th);
            self.tl = None;
        }
        let tl = t & 0xFFF;
        if self.tl != Some(tl) {
            Self::word(out, 0x6, tl as u16);
            self.tl = Some(tl);
        }
    }
}

impl WordEncoder for Evt3Enc {
    fn header(&self, w: u16, h: u16, offset: i64) -> String {
        prophesee_header("3.0", "EVT3", w, h, offset)
    }

    fn name(&self) -> &'static str {
        "EVT 3.0"
    }

    fn encode(
        &mut self,
        b: &EventBatch,
        t: &[u64],
        out: &mut Vec<u8>,
    ) -> std::result::Result<(), String> {
        out.reserve(b.len() * 2 + 64);
        let n = b.len();
        let mut i = 0;
        while i < n {
            check_xy(b.x[i], b.y[i], 2048)?;
            // a run: same time, row and polarity
            let mut j = i + 1;
            while j < n && t[j] == t[i] && b.y[j] == b.y[i] && b.p[j] == b.p[i] {
                check_xy(b.x[j], b.y[j], 2048)?;
                j += 1;
            }
            self.set_time(t[i], out);
            if self.y != Some(b.y[i]) {
                Self::word(out, 0x0, b.y[i]);
                self.y = Some(b.y[i]);
            }
            let pol = (b.p[i] as u16) << 11;
            self.xs.clear();
            self.xs.extend_from_slice(&b.x[i..j]);
            self.xs.sort_unstable();
            let mut k = 0;
            while k < self.xs.len() {
                let base = self.xs[k];
                let mut mask = 0u16;
                let mut m = k;
                while m < self.xs.len()
                    && self.xs[m] < base + 12
                    && mask & (1 << (self.xs[m] - base)) == 0
                {
                    mask |= 1 << (self.xs[m] - base);
                    m += 1;
                }
                if m - k >= 2 {
                    Self::word(out, 0x3, base | pol);
                    Self::word(out, 0x4, mask);
                } else {
                    Self::word(out, 0x2, base | pol);
                    m = k + 1;
                }
                k = m;
            }
            i = j;
        }
        Ok(())
    }
}

/// DAT v2: 8-byte records, 32-bit time (wrapping), x 14 bits, y 14 bits, polarity 4 bits.
struct DatEnc;

impl WordEncoder for DatEnc {
    fn header(&self, w: u16, h: u16, offset: i64) -> String {
        let mut s =
            format!("% Data file containing CD events.\n% Version 2\n% Width {w}\n% Height {h}\n");
        if offset != 0 {
            s.push_str(&format!("% eenf_time_offset_us {offset}\n"));
        }
        s
    }

    fn preamble(&self) -> &'static [u8] {
        &[0, 8]
    }

    fn name(&self) -> &'static str {
        "DAT"
    }

    fn encode(
        &mut self,
        b: &EventBatch,
        t: &[u64],
        out: &mut Vec<u8>,
    ) -> std::result::Result<(), String> {
        out.reserve(b.len() * 8);
        for (i, &ti) in t.iter().enumerate().take(b.len()) {
            check_xy(b.x[i], b.y[i], 1 << 14)?;
            out.extend_from_slice(&(ti as u32).to_le_bytes());
            let d = (b.x[i] as u32) | ((b.y[i] as u32) << 14) | ((b.p[i] as u32) << 28);
            out.extend_from_slice(&d.to_le_bytes());
        }
        Ok(())
    }
}
