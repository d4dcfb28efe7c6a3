//! ROS 1 bags (format 2.0, <http://wiki.ros.org/Bags/Format/2.0>) of event messages, read as a
//! stream: `#ROSBAG V2.0\n`, then records, each a header (`u32` length, fields `u32 len` +
//! `name=value`, `op` naming the record) and its data (`u32` length + bytes). The bag header
//! (op 3) points at the index section, whose connection records (op 7) name every topic and its
//! type; messages (op 2) sit in chunks (op 5), uncompressed, bz2 or lz4 (frame format).
//!
//! The messages are those of [`crate::rosmsg`], in the ROS 1 serialisation.
//!
//! The first topic of an event type is read, or the one [`crate::OpenOptions::topic`] names.
//! Sizes read from the file bound reads (never allocations): a chunk can hold no more than
//! the file has left, and expands to at most [`MAX_CHUNK`].

use eenf_core::spelling::option;
use std::collections::HashMap;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use crate::error::{io_err, EventError, Result};
use crate::held::Held;
use crate::rosmsg::{kind_of, MessageDecoder, Serialization};
use crate::{EventBatch, EventReader, Source, StreamDesc, StreamInfo};

/// The line every ROS 1 bag starts with.
pub const MAGIC: &[u8] = b"#ROSBAG V2.0\n";
const FORMAT: &str = "ROS 1 bag";
/// The largest record header accepted.
const MAX_HEADER: u32 = 1 << 20;
/// The largest chunk (or other record) accepted, expanded: rosbag writes chunks of 768 KiB,
/// larger only by one message, and a message of 64 MiB holds millions of events. It keeps a
/// chunk, its expansion and its events under 200 MB.
pub const MAX_CHUNK: u64 = 64 << 20;

/// Record opcodes (the `op` header field) of the ROS bag 2.0 format: a message's data.
pub const OP_MSG_DATA: u8 = 0x02;
/// Record opcode: the bag header.
pub const OP_BAG_HEADER: u8 = 0x03;
/// Record opcode: a chunk of records, perhaps compressed.
pub const OP_CHUNK: u8 = 0x05;
/// Record opcode: the index of a chunk's connections.
pub const OP_CHUNK_INFO: u8 = 0x06;
/// Record opcode: a connection (topic and message type).
pub const OP_CONNECTION: u8 = 0x07;

/// The header fields of a record.
fn fields(h: &[u8]) -> HashMap<&[u8], &[u8]> {
    let mut out = HashMap::new();
    let mut i = 0;
    while i + 4 <= h.len() {
        let n = u32::from_le_bytes([h[i], h[i + 1], h[i + 2], h[i + 3]]) as usize;
        i += 4;
        let Some(f) = h.get(i..i.saturating_add(n)) else {
            break;
        };
        i += n;
        if let Some(eq) = f.iter().position(|&b| b == b'=') {
            out.insert(&f[..eq], &f[eq + 1..]);
        }
    }
    out
}

fn u32_of(f: &HashMap<&[u8], &[u8]>, name: &[u8]) -> Option<u32> {
    let v = f.get(name)?;
    Some(u32::from_le_bytes(v.get(..4)?.try_into().ok()?))
}

fn u64_of(f: &HashMap<&[u8], &[u8]>, name: &[u8]) -> Option<u64> {
    let v = f.get(name)?;
    Some(u64::from_le_bytes(v.get(..8)?.try_into().ok()?))
}

/// A record read from the file: its header fields and its data.
struct Record {
    op: u8,
    header: Vec<u8>,
    data: Vec<u8>,
}

/// Reads one record from `r` (`left` bytes remain in the file); `None` at the end.
fn read_record(r: &mut dyn Read, left: u64, path: &Path, at: u64) -> Result<Option<Record>> {
    let corrupt = |reason: String| EventError::Corrupt {
        path: path.to_path_buf(),
        format: FORMAT,
        offset: at,
        reason,
    };
    let truncated = |reason: &str| EventError::Truncated {
        path: path.to_path_buf(),
        format: FORMAT,
        offset: at,
        reason: reason.into(),
    };
    if left == 0 {
        return Ok(None);
    }
    let mut len = [0u8; 4];
    read_exact(r, &mut len, path).map_err(|_| truncated("a record's header length"))?;
    let hlen = u32::from_le_bytes(len);
    if hlen > MAX_HEADER || hlen as u64 + 8 > left {
        return Err(corrupt(format!("a record header of {hlen} bytes")));
    }
    let mut header = vec![0u8; hlen as usize];
    read_exact(r, &mut header, path).map_err(|_| truncated("a record's header"))?;
    read_exact(r, &mut len, path).map_err(|_| truncated("a record's data length"))?;
    let dlen = u32::from_le_bytes(len) as u64;
    if dlen > MAX_CHUNK {
        return Err(corrupt(format!(
            "a record of {dlen} bytes (eenf reads records up to {} MiB)",
            MAX_CHUNK >> 20
        )));
    }
    if dlen + hlen as u64 + 8 > left {
        return Err(truncated(&format!(
            "a record announces {dlen} bytes of data, more than the file has left"
        )));
    }
    let op = fields(&header)
        .get(&b"op"[..])
        .and_then(|v| v.first().copied())
        .ok_or_else(|| corrupt("a record without an op field".into()))?;
    // the length is bounded by the file: reading grows the buffer as bytes arrive
    let mut data = Vec::new();
    r.take(dlen)
        .read_to_end(&mut data)
        .map_err(|e| io_err(path, e))?;
    if (data.len() as u64) < dlen {
        return Err(truncated("a record's data"));
    }
    Ok(Some(Record { op, header, data }))
}

fn read_exact(r: &mut dyn Read, buf: &mut [u8], path: &Path) -> Result<()> {
    r.read_exact(buf).map_err(|e| io_err(path, e))
}

/// A chunk's records, expanded.
fn expand(rec: &Record, path: &Path, at: u64) -> Result<Vec<u8>> {
    let f = fields(&rec.header);
    let compression = f.get(&b"compression"[..]).copied().unwrap_or(b"none");
    let size = u32_of(&f, b"size").unwrap_or(0) as u64;
    let corrupt = |reason: String| EventError::Corrupt {
        path: path.to_path_buf(),
        format: FORMAT,
        offset: at,
        reason,
    };
    if size > MAX_CHUNK {
        return Err(corrupt(format!(
            "a chunk of {size} bytes (eenf reads chunks up to {} MiB)",
            MAX_CHUNK >> 20
        )));
    }
    let mut out = Vec::new();
    let bound = size.max(1) + 1;
    let result = match compression {
        b"none" => return Ok(rec.data.clone()),
        b"bz2" => bzip2::read::BzDecoder::new(&rec.data[..])
            .take(bound)
            .read_to_end(&mut out),
        b"lz4" => lz4_flex::frame::FrameDecoder::new(&rec.data[..])
            .take(bound)
            .read_to_end(&mut out),
        other => {
            return Err(corrupt(format!(
                "a chunk compressed with {:?}, which eenf does not read",
                String::from_utf8_lossy(other)
            )))
        }
    };
    result.map_err(|e| corrupt(format!("a chunk that does not expand: {e}")))?;
    if out.len() as u64 != size {
        return Err(corrupt(format!(
            "a chunk that expands to {} bytes where its header says {size}",
            out.len()
        )));
    }
    Ok(out)
}

/// A topic of the bag.
#[derive(Debug, Clone)]
struct Topic {
    name: String,
    msg_type: String,
}

/// The reader of one topic of a ROS 1 bag.
pub struct BagReader {
    path: PathBuf,
    src: BufReader<Box<dyn Source>>,
    /// File offset of the next record, and the file's length.
    pos: u64,
    len: u64,
    /// Where the index section starts (records from there on are not chunks).
    index_pos: u64,
    /// The chunk being read: its expanded records and the offset of the next one.
    chunk: Vec<u8>,
    in_chunk: usize,
    chunk_at: u64,
    /// Connection ids of the topic read, and how its messages are decoded.
    conns: Vec<u32>,
    decoder: MessageDecoder,
    info: StreamInfo,
    /// The first batch, read on opening (the sensor's size is in the messages).
    held: Held,
    done: bool,
}

/// A reader of the event topic of the bag in `src` (named `path`): `topic`, or the first topic
/// of an event type.
pub fn reader(
    mut src: Box<dyn Source>,
    path: &Path,
    topic: Option<&str>,
) -> Result<Box<dyn EventReader>> {
    let io = |e| io_err(path, e);
    let len = src.seek(SeekFrom::End(0)).map_err(io)?;
    src.seek(SeekFrom::Start(MAGIC.len() as u64)).map_err(io)?;
    let mut r = BufReader::with_capacity(1 << 16, src);
    let start = MAGIC.len() as u64;
    let head = read_record(&mut r, len.saturating_sub(start), path, start)?.ok_or_else(|| {
        EventError::Truncated {
            path: path.to_path_buf(),
            format: FORMAT,
            offset: start,
            reason: "no bag header record".into(),
        }
    })?;
    if head.op != OP_BAG_HEADER {
        return Err(EventError::Corrupt {
            path: path.to_path_buf(),
            format: FORMAT,
            offset: start,
            reason: format!("the first record is op {}, not the bag header", head.op),
        });
    }
    let hf = fields(&head.header);
    let first_record = start + 8 + head.header.len() as u64 + head.data.len() as u64;
    let index_pos = u64_of(&hf, b"index_pos").unwrap_or(0);
    // the connections, from the index section when the bag was closed properly
    let mut topics: Vec<(u32, Topic)> = Vec::new();
    // messages by connection, from the chunk info records (op 6) after the connections
    let mut counts: Option<HashMap<u32, u64>> = None;
    if index_pos > first_record && index_pos < len {
        r.seek(SeekFrom::Start(index_pos)).map_err(io)?;
        let mut at = index_pos;
        while let Ok(Some(rec)) = read_record(&mut r, len.saturating_sub(at), path, at) {
            at += 8 + rec.header.len() as u64 + rec.data.len() as u64;
            if rec.op == OP_CONNECTION {
                if let Some(t) = connection(&rec) {
                    topics.push(t);
                }
            }
            if rec.op == OP_CHUNK_INFO {
                let counts = counts.get_or_insert_with(HashMap::new);
                for pair in rec.data.chunks_exact(8) {
                    let conn = u32::from_le_bytes([pair[0], pair[1], pair[2], pair[3]]);
                    let n = u32::from_le_bytes([pair[4], pair[5], pair[6], pair[7]]);
                    *counts.entry(conn).or_insert(0) += n as u64;
                }
            }
        }
    }
    r.seek(SeekFrom::Start(first_record)).map_err(io)?;
    let wanted = |t: &Topic| match topic {
        Some(name) => t.name == name,
        None => kind_of(&t.msg_type).is_some(),
    };
    let chosen: Vec<&(u32, Topic)> = topics.iter().filter(|(_, t)| wanted(t)).collect();
    let listing = || {
        let mut names: Vec<String> = topics
            .iter()
            .map(|(_, t)| format!("{} ({})", t.name, t.msg_type))
            .collect();
        names.dedup();
        names.join(", ")
    };
    let Some((_, first)) = chosen.first() else {
        return Err(EventError::Unfit {
            path: path.to_path_buf(),
            reason: match topic {
                Some(name) => format!("no topic {name:?} in the bag; it has: {}", listing()),
                None if topics.is_empty() => format!("a bag without an index (not closed properly): give {}, or reindex it with `rosbag reindex`", option("topic")),
                None => format!("no topic of event messages ({}) in the bag; it has: {}", crate::rosmsg::TYPES, listing()),
            },
        });
    };
    let Some(kind) = kind_of(&first.msg_type) else {
        return Err(EventError::Unfit {
            path: path.to_path_buf(),
            reason: format!(
                "topic {} carries {}, not event messages eenf reads",
                first.name, first.msg_type
            ),
        });
    };
    let name = first.name.clone();
    let conns: Vec<u32> = topics
        .iter()
        .filter(|(_, t)| t.name == name)
        .map(|(c, _)| *c)
        .collect();
    let info = StreamInfo {
        format: FORMAT,
        within: Some(format!("topic {} ({})", name, first.msg_type)),
        streams: topics
            .iter()
            .map(|(c, t)| StreamDesc {
                id: *c as i32,
                kind: t.msg_type.clone(),
                source: Some(t.name.clone()),
                messages: counts.as_ref().map(|n| n.get(c).copied().unwrap_or(0)),
                ..StreamDesc::default()
            })
            .collect(),
        ..StreamInfo::default()
    };
    let mut bag = BagReader {
        path: path.to_path_buf(),
        src: r,
        pos: first_record,
        len,
        index_pos: if index_pos > first_record {
            index_pos
        } else {
            len
        },
        chunk: Vec::new(),
        in_chunk: 0,
        chunk_at: first_record,
        conns,
        decoder: MessageDecoder::new(kind),
        info,
        held: Held::default(),
        done: false,
    };
    // the sensor's size comes with the first message: read it now, hand it out first
    let first = bag.read_batch();
    bag.held.hold(first);
    Ok(Box::new(bag))
}

/// A connection record's id, topic and type.
fn connection(rec: &Record) -> Option<(u32, Topic)> {
    let f = fields(&rec.header);
    let conn = u32_of(&f, b"conn")?;
    let d = fields(&rec.data);
    let name = String::from_utf8_lossy(f.get(&b"topic"[..])?).into_owned();
    let msg_type =
        String::from_utf8_lossy(d.get(&b"type"[..]).copied().unwrap_or(b"")).into_owned();
    Some((conn, Topic { name, msg_type }))
}

impl BagReader {
    fn fail(&mut self, e: EventError, batch: EventBatch) -> Result<Option<EventBatch>> {
        self.done = true;
        self.held.fail(e, batch)
    }
}

impl BagReader {
    /// The sensor's size, once a message gave it.
    fn note_size(&mut self) {
        if self.info.width.is_none() {
            self.info.width = self.decoder.width;
            self.info.height = self.decoder.height;
        }
        self.decoder.describe(&mut self.info.within);
    }
}

impl EventReader for BagReader {
    fn info(&self) -> &StreamInfo {
        &self.info
    }

    fn next_batch(&mut self) -> Result<Option<EventBatch>> {
        match self.held.take() {
            Some(held) => held,
            None => self.read_batch(),
        }
    }

    fn batch_offset(&self) -> Option<u64> {
        Some(self.chunk_at)
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        self.decoder.skipped()
    }
}

impl BagReader {
    /// The next batch of the topic's events, `None` at the end.
    fn read_batch(&mut self) -> Result<Option<EventBatch>> {
        let mut batch = EventBatch::default();
        while batch.len() < 1 << 16 && !self.done {
            // the next record of the chunk being read
            if self.in_chunk < self.chunk.len() {
                let at = self.chunk_at;
                let left = (self.chunk.len() - self.in_chunk) as u64;
                let mut r = &self.chunk[self.in_chunk..];
                let rec = match read_record(&mut r, left, &self.path, at) {
                    Ok(Some(rec)) => rec,
                    Ok(None) => break,
                    Err(e) => return self.fail(e, batch),
                };
                self.in_chunk += 8 + rec.header.len() + rec.data.len();
                if rec.op == OP_MSG_DATA {
                    let conn = u32_of(&fields(&rec.header), b"conn");
                    if conn.is_some_and(|c| self.conns.contains(&c)) {
                        let decoded =
                            self.decoder
                                .decode(&rec.data, Serialization::Ros1, &mut batch);
                        self.note_size();
                        if let Err(fault) = decoded {
                            let e = fault.into_error(&self.path, |reason| EventError::Corrupt {
                                path: self.path.clone(),
                                format: FORMAT,
                                offset: at,
                                reason,
                            });
                            return self.fail(e, batch);
                        }
                    }
                }
                continue;
            }
            if self.pos >= self.index_pos {
                self.done = true;
                break;
            }
            let at = self.pos;
            let rec = match read_record(&mut self.src, self.len.saturating_sub(at), &self.path, at)
            {
                Ok(Some(rec)) => rec,
                Ok(None) => {
                    self.done = true;
                    break;
                }
                Err(e) => return self.fail(e, batch),
            };
            self.pos += 8 + rec.header.len() as u64 + rec.data.len() as u64;
            if rec.op == OP_CHUNK {
                match expand(&rec, &self.path, at) {
                    Ok(c) => {
                        self.chunk = c;
                        self.in_chunk = 0;
                        self.chunk_at = at;
                    }
                    Err(e) => return self.fail(e, batch),
                }
            }
        }
        Ok((!batch.is_empty()).then_some(batch))
    }
}

/// ROS 1 bags for probing ([`crate::registry`]): the `#ROSBAG V2.0` line.
pub const REGISTERED: crate::Registered = crate::Registered {
    probe: |head, _, _| {
        Ok(crate::registry::by_magic(
            head,
            MAGIC,
            crate::Format::RosBag,
        ))
    },
    open: |src, path, opts, _| reader(src, path, opts.topic.as_deref()),
};
