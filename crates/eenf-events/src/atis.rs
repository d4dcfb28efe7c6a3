//! The ATIS `.bin` of N-MNIST and N-Caltech101 (Orchard et al. 2015): no header, 5 bytes an
//! event, big-endian bit fields: x (bits 39–32), y (31–24), polarity (23, 1 = ON) and the time
//! in µs (22–0). A word with y = 240 is not an event: it marks that the time counter's
//! upper bits advanced, and adds 2^13 µs to every later time (as the data sets' own readers do).
//!
//! Having no header, the format is recognised by its content: whole 5-byte words whose times,
//! with those marks, never go back.

use std::path::Path;

use crate::error::Result;
use crate::stream::{WordDecoder, WordStream};
use crate::{EventBatch, EventReader, Source, StreamInfo};

const FORMAT: &str = "ATIS .bin (N-MNIST)";
/// The y of a time-overflow mark.
pub const OVERFLOW_Y: u8 = 240;
/// What one mark adds to later times, µs.
const OVERFLOW_US: i64 = 1 << 13;
/// Words looked at to recognise the format.
const PROBE_WORDS: usize = 256;
/// The fewest words a file must have to be recognised.
const MIN_WORDS: usize = 32;

#[derive(Default)]
struct AtisDecoder {
    /// µs added by the overflow marks so far.
    added: i64,
    marks: u64,
}

fn fields(w: &[u8]) -> (u8, u8, bool, i64) {
    let t = ((w[2] as i64 & 0x7F) << 16) | ((w[3] as i64) << 8) | w[4] as i64;
    (w[0], w[1], w[2] & 0x80 != 0, t)
}

impl WordDecoder for AtisDecoder {
    const WORD: usize = 5;

    fn decode(&mut self, chunk: &[u8], out: &mut EventBatch) -> std::result::Result<(), String> {
        for w in chunk.chunks_exact(5) {
            let (x, y, p, t) = fields(w);
            if y == OVERFLOW_Y {
                self.added += OVERFLOW_US;
                self.marks += 1;
                continue;
            }
            out.push(t + self.added, x as u16, y as u16, p);
        }
        Ok(())
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        if self.marks > 0 {
            vec![("time-overflow marks", self.marks)]
        } else {
            Vec::new()
        }
    }
}

/// Whether `head` (the file's first bytes; `len` its size) looks like an ATIS `.bin`: whole
/// words, y at most 240, and times (with overflow marks) that never go back.
pub fn looks_like(head: &[u8], len: u64) -> bool {
    // enough words to judge, and not text (a cut-short header of another format)
    if len < 5 * MIN_WORDS as u64 || !len.is_multiple_of(5) {
        return false;
    }
    if head
        .iter()
        .take(64)
        .all(|b| b.is_ascii_graphic() || b.is_ascii_whitespace())
    {
        return false;
    }
    let words: Vec<&[u8]> = head.chunks_exact(5).take(PROBE_WORDS).collect();
    if words.len() < 2 {
        return false;
    }
    let (mut added, mut last, mut events) = (0i64, -1i64, 0usize);
    for w in words {
        let (_, y, _, t) = fields(w);
        if y > OVERFLOW_Y {
            return false;
        }
        if y == OVERFLOW_Y {
            added += OVERFLOW_US;
            continue;
        }
        let t = t + added;
        if t < last {
            return false;
        }
        last = t;
        events += 1;
    }
    events >= MIN_WORDS / 2
}

/// A reader of an ATIS `.bin` file.
pub fn reader(src: Box<dyn Source>, path: &Path) -> Result<Box<dyn EventReader>> {
    let info = StreamInfo {
        format: FORMAT,
        notes: vec![
            "the file gives no sensor size (N-MNIST: 34×34, N-Caltech101: up to 240×180)".into(),
        ],
        ..StreamInfo::default()
    };
    Ok(Box::new(WordStream::new(
        src,
        path,
        0,
        AtisDecoder::default(),
        info,
    )?))
}

/// The headerless ATIS `.bin` for probing ([`crate::registry`]), last: whole 5-byte words
/// whose times never go back.
pub const REGISTERED: crate::Registered = crate::Registered {
    probe: |head, src, path| {
        let len = src
            .seek(std::io::SeekFrom::End(0))
            .map_err(|e| crate::error::io_err(path, e))?;
        let found = looks_like(head.bytes, len);
        Ok(found.then(|| crate::Probed::of(crate::Format::AtisBin)))
    },
    open: |src, path, _, _| reader(src, path),
};
