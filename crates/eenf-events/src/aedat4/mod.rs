//! iniVation AEDAT 4.0: reader and writer.
//!
//! Layout (see `docs/formats.md`): magic, u32 header length, IOHeader FlatBuffer, then packets
//! `{i32 stream, i32 size, body}` whose bodies are compressed size-prefixed FlatBuffers, and an
//! optional FileDataTable at the end.

pub mod flatbuf;
pub mod lz4;
mod writer;

use std::collections::VecDeque;
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use crate::error::{io_err, EventError, Result};
use crate::{EventBatch, EventReader, Source, StreamDesc, StreamInfo};
use flatbuf::Table;
pub use writer::Aedat4Writer;

/// The 14-byte magic that starts every AEDAT 4.0 file.
pub const MAGIC: &[u8; 14] = b"#!AER-DAT4.0\r\n";
const FORMAT: &str = "AEDAT 4.0";
/// Largest header, packet body or decompressed packet accepted (64 MiB: 4 M events in one
/// packet). DV and dv-processing write a packet per camera read-out (a few to a few thousand
/// events, at most tens of milliseconds); a packet past this is damage, so that a small file
/// that expands hugely (a ZSTD frame of zeros, a frame header that lies) cannot exhaust memory.
pub const MAX_PACKET: u64 = 64 << 20;
/// Bytes of one event in an EventPacket.
const EVENT_SIZE: usize = 16;
/// Packets decompressed together in parallel, at most.
const PACKETS_PER_ROUND: usize = 16;
/// A round holds packets until their decompressed sizes (as far as their headers bound them)
/// reach this: with [`MAX_PACKET`] and [`BATCH_EVENTS`] it bounds what is in flight to a few
/// hundred MiB whatever the file holds.
const ROUND_BYTES: u64 = 32 << 20;
/// Batches handed out hold at most this many events (a larger packet is split), so that the
/// read-ahead queue's batches stay small.
const BATCH_EVENTS: usize = 1 << 18;

/// Packet compression of an AEDAT4 file (IOHeader field 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compression {
    /// Stored as is.
    None,
    /// LZ4 frame, fast mode.
    Lz4,
    /// LZ4 frame, high-compression mode.
    Lz4High,
    /// Zstandard frame, default level.
    Zstd,
    /// Zstandard frame, high level.
    ZstdHigh,
}

impl Compression {
    /// From the IOHeader's integer code.
    pub fn from_code(code: i32) -> Option<Self> {
        Some(match code {
            0 => Compression::None,
            1 => Compression::Lz4,
            2 => Compression::Lz4High,
            3 => Compression::Zstd,
            4 => Compression::ZstdHigh,
            _ => return None,
        })
    }

    /// The IOHeader's integer code.
    pub fn code(self) -> i32 {
        match self {
            Compression::None => 0,
            Compression::Lz4 => 1,
            Compression::Lz4High => 2,
            Compression::Zstd => 3,
            Compression::ZstdHigh => 4,
        }
    }

    /// The name used by the DV software (`NONE`, `LZ4`, `LZ4_HIGH`, `ZSTD`, `ZSTD_HIGH`).
    pub fn name(self) -> &'static str {
        match self {
            Compression::None => "NONE",
            Compression::Lz4 => "LZ4",
            Compression::Lz4High => "LZ4_HIGH",
            Compression::Zstd => "ZSTD",
            Compression::ZstdHigh => "ZSTD_HIGH",
        }
    }

    /// Every codec, by its command-line name.
    pub const NAMES: [&'static str; 5] = ["none", "lz4", "lz4_high", "zstd", "zstd_high"];
}

impl std::fmt::Display for Compression {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A name as [`Compression::name`] prints it, case-insensitive, with `-` or `_`.
impl std::str::FromStr for Compression {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let upper = s.to_ascii_uppercase().replace('-', "_");
        (0..5)
            .filter_map(Compression::from_code)
            .find(|c| c.name() == upper)
            .ok_or_else(|| format!("{s:?}: expected none, lz4, lz4_high, zstd or zstd_high"))
    }
}

/// Streams declared in the IOHeader's XML `infoNode`: (id, type identifier, width, height, source).
pub fn parse_streams(xml: &str) -> Vec<StreamDesc> {
    // A tolerant scan instead of an XML parser: nodes are entered and left, and each `attr`
    // belongs to the innermost enclosing node whose name is a stream number. Node paths differ
    // between writers, so they are not used.
    let mut stack: Vec<Option<i32>> = Vec::new();
    let mut streams: Vec<StreamDesc> = Vec::new();
    let mut rest = xml;
    while let Some(lt) = rest.find('<') {
        rest = &rest[lt..];
        let end = rest.find('>').unwrap_or(rest.len());
        let tag = &rest[..end];
        if tag.starts_with("</node") {
            stack.pop();
        } else if tag.starts_with("<node") {
            let id = attr_value(tag, "name").and_then(|n| n.parse::<i32>().ok());
            if !tag.ends_with('/') {
                stack.push(id);
            }
        } else if tag.starts_with("<attr") {
            let key = attr_value(tag, "key").unwrap_or_default();
            let value_end = rest.find("</attr>").unwrap_or(end);
            let value = rest.get(end + 1..value_end).unwrap_or("").trim();
            if let Some(id) = stack.iter().rev().find_map(|s| *s) {
                let idx = match streams.iter().position(|s| s.id == id) {
                    Some(i) => i,
                    None => {
                        streams.push(StreamDesc {
                            id,
                            ..StreamDesc::default()
                        });
                        streams.len() - 1
                    }
                };
                let s = &mut streams[idx];
                match key.as_str() {
                    "typeIdentifier" => s.kind = value.to_string(),
                    "sizeX" => s.width = value.parse().ok(),
                    "sizeY" => s.height = value.parse().ok(),
                    "source" => s.source = Some(value.to_string()),
                    _ => {}
                }
            }
        }
        rest = &rest[end.min(rest.len())..];
        if rest.len() <= 1 {
            break;
        }
        rest = &rest[1..];
    }
    streams.sort_by_key(|s| s.id);
    streams
}

fn attr_value(tag: &str, name: &str) -> Option<String> {
    let key = format!("{name}=\"");
    let start = tag.find(&key)? + key.len();
    let len = tag[start..].find('"')?;
    Some(tag[start..start + len].to_string())
}

thread_local! {
    /// Each decoding thread's decompression buffer: warm in its cache and grown once, where a
    /// buffer per rayon job would be allocated, zero-filled and faulted in again and again.
    static SCRATCH: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// A thread keeps its buffer up to this size (packets decompress to a few hundred KiB); one
/// grown by an outsized packet is freed, so that a thread does not hold it for the process's life.
const SCRATCH_KEPT: usize = 16 << 20;

/// Decompresses one packet body into `scratch` (reused between packets, so it is zero-filled
/// only when it grows) and returns the decompressed bytes. The output may not pass
/// [`MAX_PACKET`]: a frame that claims or produces more is an error, found before allocating
/// where the frame header says its size.
fn decompress<'a>(
    codec: Compression,
    body: &'a [u8],
    scratch: &'a mut Vec<u8>,
) -> std::result::Result<&'a [u8], String> {
    match codec {
        Compression::None => Ok(body),
        Compression::Lz4 | Compression::Lz4High => {
            let n = lz4::decode_frames(body, scratch)?;
            Ok(&scratch[..n])
        }
        Compression::Zstd | Compression::ZstdHigh => {
            let fail = |e: &dyn std::fmt::Display| format!("ZSTD decompression failed: {e}");
            match zstd::zstd_safe::get_frame_content_size(body) {
                Ok(Some(size)) if size > MAX_PACKET => Err(over_limit(size)),
                Ok(Some(size)) if body.len() >= 4 => {
                    let size = size as usize;
                    if scratch.len() < size {
                        scratch.resize(size, 0);
                    }
                    let n = zstd::bulk::decompress_to_buffer(body, &mut scratch[..size])
                        .map_err(|e| fail(&e))?;
                    Ok(&scratch[..n])
                }
                _ => {
                    // no size in the frame header: stream it
                    scratch.clear();
                    zstd::stream::read::Decoder::new(body)
                        .and_then(|d| d.take(MAX_PACKET + 1).read_to_end(scratch))
                        .map_err(|e| fail(&e))?;
                    if scratch.len() as u64 > MAX_PACKET {
                        return Err(over_limit(scratch.len() as u64));
                    }
                    Ok(&scratch[..])
                }
            }
        }
    }
}

/// The error for a packet that decompresses past [`MAX_PACKET`].
fn over_limit(size: u64) -> String {
    format!(
        "a packet decompresses to {} bytes or more, over the {} MiB limit of a packet",
        size,
        MAX_PACKET >> 20
    )
}

/// An upper bound of the size `body` decompresses to, read from its frame headers without
/// decompressing (`MAX_PACKET` where they do not say: the decoder enforces it).
fn decoded_bound(codec: Compression, body: &[u8]) -> u64 {
    let bound = match codec {
        Compression::None => body.len() as u64,
        Compression::Lz4 | Compression::Lz4High => lz4::decoded_bound(body),
        Compression::Zstd | Compression::ZstdHigh => {
            match zstd::zstd_safe::get_frame_content_size(body) {
                Ok(Some(size)) => size,
                _ => MAX_PACKET,
            }
        }
    };
    bound.min(MAX_PACKET)
}

/// One 16-byte event record: two little-endian u64 loads instead of five field loads.
#[inline(always)]
fn unpack(e: &[u8]) -> (i64, u16, u16, bool) {
    let lo = u64::from_le_bytes(e[0..8].try_into().unwrap());
    let hi = u64::from_le_bytes(e[8..16].try_into().unwrap());
    (
        lo as i64,
        hi as u16,
        (hi >> 16) as u16,
        (hi >> 32) as u8 != 0,
    )
}

/// Decodes a decompressed packet body. `Ok(None)` when the packet is not an event packet.
fn decode_event_packet(body: &[u8]) -> std::result::Result<Option<EventBatch>, String> {
    if body.get(8..12) != Some(b"EVTS") {
        return Ok(None);
    }
    let table = Table::size_prefixed_root(body, Some(b"EVTS")).map_err(|e| e.0)?;
    let Some((n, bytes)) = table.struct_vector(0, EVENT_SIZE).map_err(|e| e.0)? else {
        return Ok(Some(EventBatch::default()));
    };
    // One pass over the 16-byte records (t i64; x i16, y i16, on bool, 3 pad as one u64),
    // writing the four columns side by side while the record is in a register, in runs of
    // RUN records of fixed size so that the compiler drops the bounds checks and unrolls
    // (a quarter faster than a plain zipped loop, a third of the time of four column passes).
    const RUN: usize = 16;
    let mut batch = EventBatch {
        t: vec![0; n],
        x: vec![0; n],
        y: vec![0; n],
        p: vec![false; n],
    };
    let runs = bytes
        .chunks_exact(EVENT_SIZE * RUN)
        .zip(batch.t.chunks_exact_mut(RUN))
        .zip(batch.x.chunks_exact_mut(RUN))
        .zip(batch.y.chunks_exact_mut(RUN))
        .zip(batch.p.chunks_exact_mut(RUN));
    for ((((e, t), x), y), p) in runs {
        let e: &[u8; EVENT_SIZE * RUN] = e.try_into().unwrap();
        let t: &mut [i64; RUN] = t.try_into().unwrap();
        let x: &mut [u16; RUN] = x.try_into().unwrap();
        let y: &mut [u16; RUN] = y.try_into().unwrap();
        let p: &mut [bool; RUN] = p.try_into().unwrap();
        for i in 0..RUN {
            (t[i], x[i], y[i], p[i]) = unpack(&e[EVENT_SIZE * i..EVENT_SIZE * (i + 1)]);
        }
    }
    for i in n / RUN * RUN..n {
        let e = &bytes[EVENT_SIZE * i..EVENT_SIZE * (i + 1)];
        (batch.t[i], batch.x[i], batch.y[i], batch.p[i]) = unpack(e);
    }
    Ok(Some(batch))
}

/// Summary of the FileDataTable for one stream.
#[derive(Debug, Clone, Copy, Default)]
struct TableSummary {
    events: u64,
    first_t: Option<i64>,
    last_t: Option<i64>,
}

/// Reads an AEDAT 4.0 file packet by packet; memory is bounded by a few packets.
pub struct Aedat4Reader {
    path: PathBuf,
    file: BufReader<Box<dyn Source>>,
    pos: u64,
    end: u64,
    codec: Compression,
    /// Stream ids whose packets may hold events (from the XML; empty = check every packet).
    event_streams: Vec<i32>,
    info: StreamInfo,
    /// Decoded batches, each with the byte offset of its packet.
    pending: VecDeque<(u64, EventBatch)>,
    /// Byte offset of the packet of the batch handed out last.
    batch_at: Option<u64>,
    failed: Option<EventError>,
    /// Packets read and waiting to be decoded (the first `ready` slots).
    current: Vec<Slot>,
    ready: usize,
    /// The error that stopped reading `current`, reported after its packets.
    read_error: Option<EventError>,
    /// Buffers the next round is read into while `current` decodes.
    next: Vec<Slot>,
}

/// One packet body, in a buffer reused from round to round.
#[derive(Default)]
struct Slot {
    at: u64,
    body: Vec<u8>,
    size: usize,
}

impl Aedat4Reader {
    /// Opens the file and reads its header (and FileDataTable, when present).
    pub fn open(path: &Path) -> Result<Self> {
        Self::new(
            Box::new(File::open(path).map_err(|e| io_err(path, e))?),
            path,
        )
    }

    /// Reads AEDAT 4.0 from `src` (named `path` in errors): its header, and its FileDataTable
    /// when present.
    pub fn new(mut src: Box<dyn Source>, path: &Path) -> Result<Self> {
        let file_len = src.seek(SeekFrom::End(0)).map_err(|e| io_err(path, e))?;
        src.seek(SeekFrom::Start(0)).map_err(|e| io_err(path, e))?;
        let mut file = BufReader::with_capacity(1 << 20, src);
        let trunc = |offset: u64, reason: &str| EventError::Truncated {
            path: path.to_path_buf(),
            format: FORMAT,
            offset,
            reason: reason.to_string(),
        };
        let corrupt = |offset: u64, reason: String| EventError::Corrupt {
            path: path.to_path_buf(),
            format: FORMAT,
            offset,
            reason,
        };
        let mut head = [0u8; 18];
        read_exact_or(&mut file, &mut head, path, || trunc(0, "file header"))?;
        if &head[..14] != MAGIC {
            return Err(corrupt(0, "missing #!AER-DAT4.0 magic".into()));
        }
        let hlen = u32::from_le_bytes(head[14..18].try_into().unwrap()) as u64;
        if hlen > MAX_PACKET || 18 + hlen > file_len {
            return Err(trunc(18, &format!("IOHeader of {hlen} bytes")));
        }
        let mut header = vec![0u8; hlen as usize];
        read_exact_or(&mut file, &mut header, path, || trunc(18, "IOHeader"))?;
        let t = Table::root(&header, Some(b"IOHE")).map_err(|e| corrupt(18, e.0))?;
        let code = t.i32_field(0, 0).map_err(|e| corrupt(18, e.0))?;
        let codec = Compression::from_code(code)
            .ok_or_else(|| corrupt(18, format!("unknown compression code {code}")))?;
        let table_pos = t.i64_field(1, -1).map_err(|e| corrupt(18, e.0))?;
        let xml = t.str_field(2).map_err(|e| corrupt(18, e.0))?.unwrap_or("");
        let streams = parse_streams(xml);
        let event_streams: Vec<i32> = streams
            .iter()
            .filter(|s| s.kind == "EVTS")
            .map(|s| s.id)
            .take(1)
            .collect();
        let data_start = 18 + hlen;
        let has_table = table_pos >= data_start as i64 && (table_pos as u64) < file_len;
        let end = if has_table {
            table_pos as u64
        } else {
            file_len
        };
        let evs = streams.iter().find(|s| s.kind == "EVTS");
        let mut info = StreamInfo {
            format: FORMAT,
            codec: Some(codec.name().to_string()),
            width: evs.and_then(|s| s.width),
            height: evs.and_then(|s| s.height),
            streams: streams.clone(),
            indexed: false,
            ..StreamInfo::default()
        };
        if has_table {
            // A damaged table only costs the up-front summary; the packets are still readable.
            if let Ok(summary) = read_table(
                &mut file,
                table_pos as u64,
                file_len,
                codec,
                event_streams.first().copied().unwrap_or(0),
            ) {
                info.event_count = Some(summary.events);
                info.first_t = summary.first_t;
                info.last_t = summary.last_t;
                info.indexed = true;
            }
            file.seek(SeekFrom::Start(data_start))
                .map_err(|e| io_err(path, e))?;
        }
        Ok(Aedat4Reader {
            path: path.to_path_buf(),
            file,
            pos: data_start,
            end,
            codec,
            event_streams,
            info,
            pending: VecDeque::new(),
            batch_at: None,
            failed: None,
            current: Vec::new(),
            ready: 0,
            read_error: None,
            next: Vec::new(),
        })
    }

    /// Reads up to one round of event packets into `slots`; returns how many were read and the
    /// error that stopped the reading, if any.
    fn read_round(&mut self, slots: &mut Vec<Slot>) -> (usize, Option<EventError>) {
        let mut count = 0;
        let mut bytes = 0;
        while count < PACKETS_PER_ROUND && bytes < ROUND_BYTES && self.pos < self.end {
            let at = self.pos;
            if self.end - at < 8 {
                return (count, Some(self.truncated(at, "packet header")));
            }
            let mut hdr = [0u8; 8];
            if let Err(e) = self.file.read_exact(&mut hdr) {
                return (count, Some(io_err(&self.path, e)));
            }
            let stream = i32::from_le_bytes(hdr[0..4].try_into().unwrap());
            let size = i32::from_le_bytes(hdr[4..8].try_into().unwrap());
            if size < 0 {
                return (count, Some(self.corrupt(at, format!("packet size {size}"))));
            }
            if size as u64 > MAX_PACKET {
                let reason = format!(
                    "a packet of {size} bytes, over the {} MiB limit of a packet",
                    MAX_PACKET >> 20
                );
                return (count, Some(self.corrupt(at, reason)));
            }
            let size = size as u64;
            if size > self.end - at - 8 {
                let left = self.end - at - 8;
                return (
                    count,
                    Some(self.truncated(
                        at,
                        &format!("packet of {size} bytes, only {left} bytes left"),
                    )),
                );
            }
            self.pos = at + 8 + size;
            let wanted = self.event_streams.is_empty() || self.event_streams.contains(&stream);
            if wanted {
                if slots.len() <= count {
                    slots.push(Slot::default());
                }
                let slot = &mut slots[count];
                // grown, never shrunk: no zero-filling once warm
                if slot.body.len() < size as usize {
                    slot.body.resize(size as usize, 0);
                }
                if let Err(e) = self.file.read_exact(&mut slot.body[..size as usize]) {
                    return (count, Some(io_err(&self.path, e)));
                }
                slot.at = at;
                slot.size = size as usize;
                bytes += decoded_bound(self.codec, &slot.body[..slot.size]);
                count += 1;
            } else if let Err(e) = self.file.seek_relative(size as i64) {
                return (count, Some(io_err(&self.path, e)));
            }
        }
        (count, None)
    }

    /// Decodes the packets read last time in parallel while reading the next round.
    fn fill(&mut self) -> Result<()> {
        if self.ready == 0 && self.read_error.is_none() {
            let mut slots = std::mem::take(&mut self.current);
            let (n, err) = self.read_round(&mut slots);
            self.current = slots;
            self.ready = n;
            self.read_error = err;
        }
        let codec = self.codec;
        let ready = self.ready;
        let current = std::mem::take(&mut self.current);
        let mut next = std::mem::take(&mut self.next);
        let more = self.read_error.is_none() && self.pos < self.end;
        let (decoded, (n_next, err_next)) = rayon::join(
            || -> Vec<(u64, std::result::Result<Option<EventBatch>, String>)> {
                current[..ready]
                    .par_iter()
                    .map(|slot| {
                        let batch = SCRATCH.with_borrow_mut(|scratch| {
                            // zstd's and liblz4's wrappers are not ours: a panic there
                            // is this packet's damage
                            let batch = crate::contain(|| {
                                decompress(codec, &slot.body[..slot.size], scratch)
                                    .and_then(decode_event_packet)
                            })
                            .and_then(|r| r);
                            if scratch.capacity() > SCRATCH_KEPT {
                                *scratch = Vec::new();
                            }
                            batch
                        });
                        (slot.at, batch)
                    })
                    .collect()
            },
            || {
                if more {
                    self.read_round(&mut next)
                } else {
                    (0, None)
                }
            },
        );
        // the round just read becomes the current one
        self.next = current;
        self.current = next;
        self.ready = n_next;
        let read_error = std::mem::replace(&mut self.read_error, err_next);
        for (at, d) in decoded {
            match d {
                Ok(Some(b)) if !b.is_empty() => {
                    for part in split(b, BATCH_EVENTS) {
                        self.pending.push_back((at, part));
                    }
                }
                Ok(_) => {}
                Err(reason) => {
                    // deliver the events before the damage, then the error
                    self.failed = Some(self.corrupt(at, reason));
                    self.ready = 0;
                    self.read_error = None;
                    self.pos = self.end;
                    return Ok(());
                }
            }
        }
        if let Some(e) = read_error {
            // the packets read before the error are decoded already; report it now
            self.failed = Some(e);
            self.ready = 0;
            self.read_error = None;
            self.pos = self.end;
        }
        Ok(())
    }

    fn truncated(&self, offset: u64, reason: &str) -> EventError {
        EventError::Truncated {
            path: self.path.clone(),
            format: FORMAT,
            offset,
            reason: reason.to_string(),
        }
    }

    fn corrupt(&self, offset: u64, reason: String) -> EventError {
        EventError::Corrupt {
            path: self.path.clone(),
            format: FORMAT,
            offset,
            reason,
        }
    }
}

/// `b` in batches of at most `n` events, in order.
fn split(mut b: EventBatch, n: usize) -> Vec<EventBatch> {
    let mut parts = Vec::new();
    while b.len() > n {
        let tail = EventBatch {
            t: b.t.split_off(n),
            x: b.x.split_off(n),
            y: b.y.split_off(n),
            p: b.p.split_off(n),
        };
        parts.push(std::mem::replace(&mut b, tail));
    }
    parts.push(b);
    parts
}

fn read_exact_or(
    file: &mut impl Read,
    buf: &mut [u8],
    path: &Path,
    on_eof: impl FnOnce() -> EventError,
) -> Result<()> {
    match file.read_exact(buf) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => Err(on_eof()),
        Err(e) => Err(io_err(path, e)),
    }
}

fn read_table(
    file: &mut BufReader<Box<dyn Source>>,
    pos: u64,
    file_len: u64,
    codec: Compression,
    stream: i32,
) -> std::result::Result<TableSummary, String> {
    let len = file_len - pos;
    if len > MAX_PACKET {
        return Err("FileDataTable too large".into());
    }
    file.seek(SeekFrom::Start(pos)).map_err(|e| e.to_string())?;
    let mut raw = vec![0u8; len as usize];
    file.read_exact(&mut raw).map_err(|e| e.to_string())?;
    let mut scratch = Vec::new();
    let body = crate::contain(|| decompress(codec, &raw, &mut scratch).map(<[u8]>::to_vec))
        .and_then(|r| r)?;
    let t = Table::size_prefixed_root(&body, Some(b"FTAB")).map_err(|e| e.0)?;
    let mut s = TableSummary::default();
    for entry in t.table_vector(0).map_err(|e| e.0)? {
        let header = entry.struct_field(1, 8).map_err(|e| e.0)?;
        let sid = header
            .map(|h| i32::from_le_bytes(h[0..4].try_into().unwrap()))
            .unwrap_or(0);
        if sid != stream {
            continue;
        }
        s.events += entry.i64_field(2, 0).map_err(|e| e.0)?.max(0) as u64;
        let t0 = entry.i64_field(3, 0).map_err(|e| e.0)?;
        let t1 = entry.i64_field(4, 0).map_err(|e| e.0)?;
        s.first_t = Some(s.first_t.map_or(t0, |v| v.min(t0)));
        s.last_t = Some(s.last_t.map_or(t1, |v| v.max(t1)));
    }
    Ok(s)
}

impl EventReader for Aedat4Reader {
    fn info(&self) -> &StreamInfo {
        &self.info
    }

    fn batch_offset(&self) -> Option<u64> {
        self.batch_at
    }

    fn next_batch(&mut self) -> Result<Option<EventBatch>> {
        loop {
            if let Some((at, b)) = self.pending.pop_front() {
                self.batch_at = Some(at);
                return Ok(Some(b));
            }
            if let Some(e) = self.failed.take() {
                return Err(e);
            }
            if self.pos >= self.end && self.ready == 0 && self.read_error.is_none() {
                return Ok(None);
            }
            self.fill()?;
        }
    }
}

/// AEDAT 4.0 for probing ([`crate::registry`]): its magic line.
pub const REGISTERED: crate::Registered = crate::Registered {
    probe: |head, _, _| {
        Ok(crate::registry::by_magic(
            head,
            MAGIC,
            crate::Format::Aedat4,
        ))
    },
    open: open_registered,
};

fn open_registered(
    src: Box<dyn Source>,
    path: &Path,
    _: &crate::OpenOptions,
    _: crate::Probed,
) -> Result<Box<dyn crate::EventReader>> {
    Ok(Box::new(Aedat4Reader::new(src, path)?))
}
