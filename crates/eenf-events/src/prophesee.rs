//! Prophesee RAW (EVT 2.0, EVT 2.1, EVT 3.0) and DAT readers. See `docs/formats.md`.

use std::path::Path;

use crate::stream::{read_text_header, Skips, TextHeader, Unwrap, WordDecoder, WordStream};
use crate::{EventBatch, EventError, EventReader, Result, Source, StreamInfo};

/// Which Prophesee encoding a file uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProphFormat {
    /// EVT 2.0 (32-bit words).
    Evt2,
    /// EVT 2.1 (64-bit vector words); `legacy` swaps the 32-bit halves.
    Evt21 {
        /// `endianness=legacy` in the header.
        legacy: bool,
    },
    /// EVT 3.0 (16-bit words).
    Evt3,
    /// DAT (8-byte records).
    Dat,
}

/// The encoding named by a `% ` header, if any.
pub(crate) fn format_from_header(lines: &[String]) -> Option<ProphFormat> {
    let mut found = None;
    let legacy = lines
        .iter()
        .any(|l| l.to_ascii_lowercase().contains("endianness=legacy"));
    for l in lines {
        let lower = l.to_ascii_lowercase();
        let name = if let Some(v) = lower.strip_prefix("evt ") {
            v.trim().to_string()
        } else if let Some(v) = lower.strip_prefix("format ") {
            v.split(';').next().unwrap_or("").trim().to_string()
        } else {
            continue;
        };
        found = match name.as_str() {
            "2.0" | "evt2" => Some(ProphFormat::Evt2),
            "2.1" | "evt21" => Some(ProphFormat::Evt21 { legacy }),
            "3.0" | "evt3" => Some(ProphFormat::Evt3),
            _ => found,
        };
    }
    if found.is_none()
        && lines.iter().any(|l| {
            let l = l.to_ascii_lowercase();
            l.starts_with("version") || l.contains("data file containing")
        })
    {
        return Some(ProphFormat::Dat);
    }
    found
}

fn header_info(lines: &[String], format: &'static str) -> StreamInfo {
    let (width, height) = prophesee_geometry(lines);
    StreamInfo {
        format,
        width,
        height,
        ..StreamInfo::default()
    }
}

/// Opens a Prophesee RAW or DAT file (the encoding is read from its header).
pub fn open(path: &Path) -> Result<Box<dyn EventReader>> {
    let mut src: Box<dyn Source> =
        Box::new(std::fs::File::open(path).map_err(|e| crate::error::io_err(path, e))?);
    let header = read_text_header(src.as_mut(), path, b"%", None, "Prophesee")?;
    let Some(kind) = format_from_header(&header.lines) else {
        return Err(EventError::UnknownFormat {
            path: path.to_path_buf(),
            reason: "a Prophesee-style % header that names no EVT encoding or DAT version".into(),
            supported: crate::SUPPORTED,
        });
    };
    from_header(src, path, header, kind)
}

/// The `% ` header at the top of `src`, which names the encoding.
pub(crate) fn read_header(src: &mut dyn Source, path: &Path) -> Result<TextHeader> {
    read_text_header(src, path, b"%", None, "Prophesee")
}

/// The `kind` reader of `src` (named `path` in errors) whose `% ` header has been read.
pub(crate) fn from_header(
    src: Box<dyn Source>,
    path: &Path,
    header: TextHeader,
    kind: ProphFormat,
) -> Result<Box<dyn EventReader>> {
    let start = header.data_start;
    let offset = time_offset(&header.lines);
    let info = |name| header_info(&header.lines, name);
    Ok(match kind {
        ProphFormat::Evt2 => Box::new(
            WordStream::new(src, path, start, Evt2::default(), info("EVT 2.0"))?
                .with_offset(offset),
        ),
        ProphFormat::Evt21 { legacy } => {
            let dec = Evt21 {
                legacy,
                ..Evt21::default()
            };
            Box::new(WordStream::new(src, path, start, dec, info("EVT 2.1"))?.with_offset(offset))
        }
        ProphFormat::Evt3 => Box::new(
            WordStream::new(src, path, start, Evt3::default(), info("EVT 3.0"))?
                .with_offset(offset),
        ),
        ProphFormat::Dat => open_dat(src, path, start, &header.lines)?,
    })
}

/// EVT 2.0 decoder state.
#[derive(Default)]
pub(crate) struct Evt2 {
    time_high: Option<u64>,
    unwrap: Unwrap,
    skips: Skips,
}

impl WordDecoder for Evt2 {
    const WORD: usize = 4;

    fn decode(&mut self, chunk: &[u8], out: &mut EventBatch) -> std::result::Result<(), String> {
        for w in chunk.chunks_exact(4) {
            let w = u32::from_le_bytes(w.try_into().unwrap());
            match w >> 28 {
                t @ (0 | 1) => match self.time_high {
                    Some(th) => out.push(
                        (th | ((w >> 22) & 0x3F) as u64) as i64,
                        ((w >> 11) & 0x7FF) as u16,
                        (w & 0x7FF) as u16,
                        t == 1,
                    ),
                    None => self.skips.before_time += 1,
                },
                // TIME_HIGH: t[33:6]; the 34-bit clock loops
                0x8 => self.time_high = Some(self.unwrap.next((w & 0x0FFF_FFFF) as u64, 28) << 6),
                kind => self.skips.count_prophesee(kind as u64),
            }
        }
        Ok(())
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        self.skips.list()
    }
}

/// EVT 2.1 decoder state.
#[derive(Default)]
pub(crate) struct Evt21 {
    legacy: bool,
    time_high: Option<u64>,
    unwrap: Unwrap,
    skips: Skips,
}

impl WordDecoder for Evt21 {
    const WORD: usize = 8;

    fn decode(&mut self, chunk: &[u8], out: &mut EventBatch) -> std::result::Result<(), String> {
        for w in chunk.chunks_exact(8) {
            let lo = u32::from_le_bytes(w[0..4].try_into().unwrap()) as u64;
            let hi = u32::from_le_bytes(w[4..8].try_into().unwrap()) as u64;
            // legacy files store the high half first
            let w = if self.legacy {
                (lo << 32) | hi
            } else {
                (hi << 32) | lo
            };
            match w >> 60 {
                t @ (0 | 1) => match self.time_high {
                    Some(th) => {
                        let ts = (th | ((w >> 54) & 0x3F)) as i64;
                        let xbase = ((w >> 43) & 0x7FF) as u16;
                        let y = ((w >> 32) & 0x7FF) as u16;
                        let mut mask = w as u32;
                        while mask != 0 {
                            let i = mask.trailing_zeros() as u16;
                            out.push(ts, xbase + i, y, t == 1);
                            mask &= mask - 1;
                        }
                    }
                    None => self.skips.before_time += 1,
                },
                0x8 => self.time_high = Some(self.unwrap.next((w >> 32) & 0x0FFF_FFFF, 28) << 6),
                kind => self.skips.count_prophesee(kind),
            }
        }
        Ok(())
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        self.skips.list()
    }
}

/// EVT 3.0 decoder state.
#[derive(Default)]
pub(crate) struct Evt3 {
    y: u16,
    x_base: u16,
    vect_on: bool,
    time_high: Option<u64>,
    time_low: u64,
    loops: u64,
    skips: Skips,
}

impl Evt3 {
    #[inline]
    fn time(&self) -> Option<i64> {
        self.time_high
            .map(|th| ((self.loops << 24) | (th << 12) | self.time_low) as i64)
    }
}

impl WordDecoder for Evt3 {
    const WORD: usize = 2;

    fn decode(&mut self, chunk: &[u8], out: &mut EventBatch) -> std::result::Result<(), String> {
        for w in chunk.chunks_exact(2) {
            let w = u16::from_le_bytes([w[0], w[1]]);
            match w >> 12 {
                0x0 => self.y = w & 0x7FF,
                0x2 => match self.time() {
                    Some(t) => out.push(t, w & 0x7FF, self.y, (w >> 11) & 1 == 1),
                    None => self.skips.before_time += 1,
                },
                0x3 => {
                    self.x_base = w & 0x7FF;
                    self.vect_on = (w >> 11) & 1 == 1;
                }
                k @ (0x4 | 0x5) => {
                    let (mut mask, width) = if k == 0x4 {
                        (w & 0xFFF, 12)
                    } else {
                        (w & 0xFF, 8)
                    };
                    match self.time() {
                        Some(t) => {
                            while mask != 0 {
                                let i = mask.trailing_zeros() as u16;
                                out.push(t, self.x_base.wrapping_add(i), self.y, self.vect_on);
                                mask &= mask - 1;
                            }
                        }
                        None => self.skips.before_time += mask.count_ones() as u64,
                    }
                    self.x_base = self.x_base.wrapping_add(width);
                }
                0x6 => self.time_low = (w & 0xFFF) as u64,
                0x8 => {
                    let th = (w & 0xFFF) as u64;
                    if let Some(prev) = self.time_high {
                        // a real loop jumps back by (nearly) the whole 12-bit range; re-sent
                        // values and small step-backs are not loops
                        if th + 2048 <= prev {
                            self.loops += 1;
                        }
                        if th != prev {
                            self.time_low = 0;
                        }
                    }
                    self.time_high = Some(th);
                }
                0xA => self.skips.triggers += 1,
                0xE | 0x7 | 0xF => self.skips.other += 1,
                _ => self.skips.unknown += 1,
            }
        }
        Ok(())
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        self.skips.list()
    }
}

/// DAT decoder state.
pub(crate) struct Dat {
    unwrap: Unwrap,
}

impl WordDecoder for Dat {
    const WORD: usize = 8;

    fn decode(&mut self, chunk: &[u8], out: &mut EventBatch) -> std::result::Result<(), String> {
        for r in chunk.chunks_exact(8) {
            let t = u32::from_le_bytes(r[0..4].try_into().unwrap()) as u64;
            let d = u32::from_le_bytes(r[4..8].try_into().unwrap());
            out.push(
                self.unwrap.next(t, 32) as i64,
                (d & 0x3FFF) as u16,
                ((d >> 14) & 0x3FFF) as u16,
                d >> 28 != 0,
            );
        }
        Ok(())
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        Vec::new()
    }
}

fn open_dat(
    mut f: Box<dyn Source>,
    path: &Path,
    start: u64,
    lines: &[String],
) -> Result<Box<dyn EventReader>> {
    use std::io::{Read, Seek, SeekFrom};
    f.seek(SeekFrom::Start(start))
        .map_err(|e| crate::error::io_err(path, e))?;
    let mut ts = [0u8; 2];
    f.read_exact(&mut ts).map_err(|_| EventError::Truncated {
        path: path.to_path_buf(),
        format: "DAT",
        offset: start,
        reason: "missing event type and size bytes".into(),
    })?;
    if ts[0] != 0 || ts[1] != 8 {
        return Err(EventError::Corrupt {
            path: path.to_path_buf(),
            format: "DAT",
            offset: start,
            reason: format!(
                "event type {} of {} bytes; only CD events (type 0, 8 bytes) are supported",
                ts[0], ts[1]
            ),
        });
    }
    Ok(Box::new(
        WordStream::new(
            f,
            path,
            start + 2,
            Dat {
                unwrap: Unwrap::default(),
            },
            header_info(lines, "DAT"),
        )?
        .with_offset(time_offset(lines)),
    ))
}

/// Resolution from a Prophesee header: `% format …;height=H;width=W`, `% geometry WxH`,
/// `% Width W` / `% Height H`, or the sensor generation in `% plugin_name`.
fn prophesee_geometry(lines: &[String]) -> (Option<u16>, Option<u16>) {
    let (mut w, mut h) = (None, None);
    for l in lines {
        let lower = l.to_ascii_lowercase();
        if let Some(rest) = lower.strip_prefix("format ") {
            for opt in rest.split(';') {
                if let Some(v) = opt.trim().strip_prefix("width=") {
                    w = v.trim().parse().ok().or(w);
                }
                if let Some(v) = opt.trim().strip_prefix("height=") {
                    h = v.trim().parse().ok().or(h);
                }
            }
        } else if let Some(rest) = lower.strip_prefix("geometry ") {
            if let Some((a, b)) = rest.trim().split_once('x') {
                w = a.trim().parse().ok().or(w);
                h = b.trim().parse().ok().or(h);
            }
        } else if let Some(v) = lower.strip_prefix("width ") {
            w = v.trim().parse().ok().or(w);
        } else if let Some(v) = lower.strip_prefix("height ") {
            h = v.trim().parse().ok().or(h);
        }
    }
    if w.is_none() || h.is_none() {
        let plugin = lines
            .iter()
            .find_map(|l| {
                l.to_ascii_lowercase()
                    .strip_prefix("plugin_name ")
                    .map(str::to_string)
            })
            .unwrap_or_default();
        let guess =
            if plugin.contains("gen41") || plugin.contains("imx636") || plugin.contains("gen4") {
                Some((1280, 720))
            } else if plugin.contains("gen3") {
                Some((640, 480))
            } else if plugin.contains("imx8") || plugin.contains("genx320") {
                Some((320, 320))
            } else {
                None
            };
        if let Some((gw, gh)) = guess {
            w = w.or(Some(gw));
            h = h.or(Some(gh));
        }
    }
    (w, h)
}

/// The `% eenf_time_offset_us N` header line written by eenf for clocks too narrow for
/// absolute time.
fn time_offset(lines: &[String]) -> i64 {
    lines
        .iter()
        .find_map(|l| l.strip_prefix("eenf_time_offset_us "))
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(0)
}

impl Skips {
    /// Counts a Prophesee word type that is not an event or a time word: 0xA external
    /// trigger, 0xE/0xF others and continuations, anything else unknown.
    fn count_prophesee(&mut self, kind: u64) {
        match kind {
            0xA => self.triggers += 1,
            0xE | 0xF => self.other += 1,
            _ => self.unknown += 1,
        }
    }
}

/// Prophesee RAW and DAT for probing ([`crate::registry`]): a `%` header that names the
/// encoding (or a DAT whose data starts with type 0 and size 8). The header is read once and
/// handed to the reader.
pub const REGISTERED: crate::Registered = crate::Registered {
    probe: probe_registered,
    open: open_registered,
};

fn probe_registered(
    head: &crate::registry::Head,
    src: &mut dyn Source,
    path: &Path,
) -> Result<Option<crate::Probed>> {
    if !head.starts_with(b"%") {
        return Ok(None);
    }
    let header = read_header(src, path)?;
    let start = header.data_start as usize;
    let format = match format_from_header(&header.lines) {
        Some(kind) => kind,
        // a DAT header may name nothing; its data starts with type 0 and size 8
        None if head.bytes.get(start..start + 2) == Some(&[0, 8]) => ProphFormat::Dat,
        None => {
            return Err(EventError::UnknownFormat {
                path: path.to_path_buf(),
                reason: "a % header that names no EVT encoding or DAT version".into(),
                supported: crate::SUPPORTED,
            })
        }
    };
    Ok(Some(crate::Probed {
        format: crate::Format::Prophesee(format),
        header: Some(header),
    }))
}

fn open_registered(
    mut src: Box<dyn Source>,
    path: &Path,
    _: &crate::OpenOptions,
    probed: crate::Probed,
) -> Result<Box<dyn crate::EventReader>> {
    let crate::Format::Prophesee(kind) = probed.format else {
        return Err(EventError::Unfit {
            path: path.to_path_buf(),
            reason: "not a Prophesee file".into(),
        });
    };
    let header = match probed.header {
        Some(header) => header,
        None => read_header(src.as_mut(), path)?,
    };
    from_header(src, path, header, kind)
}
