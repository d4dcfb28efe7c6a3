//! Event Stream 2.x (`.es`, neuromorphic-paris/event_stream), DVS type: a 15-byte signature and
//! version, the type byte (`0x01`), width and height (u16 LE), then a byte-wise state machine.
//!
//! In the idle state a byte is an *overflow* (`0xFF`: 127 µs pass), a *reset* (`0xFE`: skipped,
//! it resynchronises writers after bit errors) or an event's first byte: bits 7–1 the time since
//! the previous event in µs, bit 0 `is_increase`. Four bytes follow: x and y, u16 little-endian.
//! The other stream types (generic, ATIS, display, colour) are refused by name.

use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use crate::error::{io_err, EventError, Result};
use crate::stream::{WordDecoder, WordStream};
use crate::{EventBatch, EventReader, Source, StreamInfo};

/// The signature every Event Stream file starts with.
pub const MAGIC: &[u8] = b"Event Stream";
const FORMAT: &str = "Event Stream";
/// Signature, version (3 bytes), type, width and height.
const HEADER: usize = 20;

/// The state machine of DVS events, carried across chunks.
#[derive(Default)]
struct DvsDecoder {
    t: i64,
    /// Bytes of the event being read (0: idle).
    have: usize,
    bytes: [u8; 5],
    resets: u64,
}

impl WordDecoder for DvsDecoder {
    const WORD: usize = 1;

    fn decode(&mut self, chunk: &[u8], out: &mut EventBatch) -> std::result::Result<(), String> {
        for &b in chunk {
            if self.have == 0 {
                match b {
                    0xFF => self.t += 127,
                    0xFE => self.resets += 1,
                    _ => {
                        self.bytes[0] = b;
                        self.have = 1;
                    }
                }
                continue;
            }
            self.bytes[self.have] = b;
            self.have += 1;
            if self.have == 5 {
                self.have = 0;
                let e = self.bytes;
                self.t += (e[0] >> 1) as i64;
                out.push(
                    self.t,
                    u16::from_le_bytes([e[1], e[2]]),
                    u16::from_le_bytes([e[3], e[4]]),
                    e[0] & 1 == 1,
                );
            }
        }
        Ok(())
    }

    fn unfinished(&self) -> Option<String> {
        (self.have > 0).then(|| format!("the last event has {} of its 5 bytes", self.have))
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        if self.resets > 0 {
            vec![("reset bytes", self.resets)]
        } else {
            Vec::new()
        }
    }
}

/// A reader of an Event Stream file of DVS events.
pub fn reader(mut src: Box<dyn Source>, path: &Path) -> Result<Box<dyn EventReader>> {
    src.seek(SeekFrom::Start(0)).map_err(|e| io_err(path, e))?;
    let mut head = [0u8; HEADER];
    let mut n = 0;
    while n < HEADER {
        match src.read(&mut head[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(io_err(path, e)),
        }
    }
    let (major, minor, patch) = (head[12], head[13], head[14]);
    if n < 16 || major != 2 {
        return Err(EventError::Unfit {
            path: path.to_path_buf(),
            reason: if n < 16 {
                "an Event Stream header cut short".into()
            } else {
                format!("Event Stream version {major}.{minor}.{patch}: eenf reads version 2")
            },
        });
    }
    let kind = match head[15] {
        0 => "generic",
        1 => "DVS",
        2 => "ATIS",
        3 => "asynchronous display",
        4 => "colour",
        _ => "unknown",
    };
    if head[15] != 1 {
        return Err(EventError::Unfit {
            path: path.to_path_buf(),
            reason: format!(
                "an Event Stream of {kind} events (type {}): eenf reads its DVS events (type 1) only",
                head[15]
            ),
        });
    }
    if n < HEADER {
        return Err(EventError::Truncated {
            path: path.to_path_buf(),
            format: FORMAT,
            offset: n as u64,
            reason: "the header ends before the sensor's size".into(),
        });
    }
    let info = StreamInfo {
        format: FORMAT,
        codec: Some(format!("{major}.{minor}.{patch}, DVS")),
        width: Some(u16::from_le_bytes([head[16], head[17]])),
        height: Some(u16::from_le_bytes([head[18], head[19]])),
        ..StreamInfo::default()
    };
    Ok(Box::new(WordStream::new(
        src,
        path,
        HEADER as u64,
        DvsDecoder::default(),
        info,
    )?))
}

/// Event Stream for probing ([`crate::registry`]): its magic.
pub const REGISTERED: crate::Registered = crate::Registered {
    probe: |head, _, _| {
        Ok(crate::registry::by_magic(
            head,
            MAGIC,
            crate::Format::EventStream,
        ))
    },
    open: |src, path, _, _| reader(src, path),
};
