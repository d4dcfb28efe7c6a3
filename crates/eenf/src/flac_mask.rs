//! A FLAC file as Symphonia is shown it: every metadata block but STREAMINFO and SEEKTABLE
//! reads as PADDING.
//!
//! Symphonia 0.5 allocates what a PICTURE, VORBIS_COMMENT, CUESHEET or APPLICATION block's
//! inner lengths say (a MIME type of 0xFFFFFFFF bytes is a 4 GiB allocation) before it checks
//! them against the block's own length, and a failed allocation aborts the process. The ENF
//! needs none of those blocks: their type byte is changed, on the fly, to PADDING (type 1),
//! which Symphonia skips by the block length. The file itself is never written.
//!
//! Layout (<https://xiph.org/flac/format.html#metadata_block_header>): `fLaC`, then blocks of
//! a 4-byte header (bit 7: last block; bits 0-6: type; 24-bit big-endian length) and content.
//! An ID3v2 tag may come first (10-byte header, syncsafe size, a 10-byte footer when flagged).

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};

use symphonia::core::io::MediaSource;

/// Metadata blocks walked at most; real files hold a handful.
const MAX_BLOCKS: usize = 4096;
/// Block types the decoder needs: STREAMINFO (0) and SEEKTABLE (3).
const KEPT: [u8; 2] = [0, 3];
/// The type every other block is shown as.
pub const PADDING: u8 = 1;

/// A file whose bytes at some offsets read as other values.
pub struct MaskedFile {
    file: File,
    len: u64,
    pos: u64,
    /// (offset, byte shown there), by offset.
    patches: Vec<(u64, u8)>,
}

/// `file` as Symphonia should see it: a FLAC file's metadata masked; any other file as it is.
/// Errors: a FLAC file with more metadata blocks than [`MAX_BLOCKS`] (a reason to show).
pub fn flac_masked(mut file: File) -> Result<MaskedFile, String> {
    let len = file.metadata().map(|m| m.len()).unwrap_or(0);
    let patches = metadata_patches(&mut file, len)?;
    file.seek(SeekFrom::Start(0)).map_err(|e| e.to_string())?;
    Ok(MaskedFile {
        file,
        len,
        pos: 0,
        patches,
    })
}

/// The type bytes to change, found by walking the metadata block headers.
fn metadata_patches(file: &mut File, len: u64) -> Result<Vec<(u64, u8)>, String> {
    let mut at = 0u64;
    let mut head = [0u8; 10];
    if read_at(file, 0, &mut head).is_err() {
        return Ok(Vec::new());
    }
    if &head[..3] == b"ID3" {
        // the size is syncsafe: 7 bits a byte (ID3v2.4 §3.1)
        let size = head[6..10]
            .iter()
            .fold(0u64, |s, &b| (s << 7) | u64::from(b & 0x7F));
        let footer = if head[5] & 0x10 != 0 { 10 } else { 0 };
        at = 10 + size + footer;
    }
    let mut magic = [0u8; 4];
    if read_at(file, at, &mut magic).is_err() || &magic != b"fLaC" {
        return Ok(Vec::new());
    }
    at += 4;
    let mut patches = Vec::new();
    for _ in 0..MAX_BLOCKS {
        let mut h = [0u8; 4];
        if at + 4 > len || read_at(file, at, &mut h).is_err() {
            return Ok(patches);
        }
        let (last, kind) = (h[0] & 0x80, h[0] & 0x7F);
        if !KEPT.contains(&kind) && kind != PADDING {
            patches.push((at, last | PADDING));
        }
        if last != 0 {
            return Ok(patches);
        }
        at += 4 + u64::from(u32::from_be_bytes([0, h[1], h[2], h[3]]));
    }
    Err(format!(
        "damaged FLAC: more than {MAX_BLOCKS} metadata blocks"
    ))
}

fn read_at(file: &mut File, at: u64, buf: &mut [u8]) -> std::io::Result<()> {
    file.seek(SeekFrom::Start(at))?;
    file.read_exact(buf)
}

impl Read for MaskedFile {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.file.read(buf)?;
        let (start, end) = (self.pos, self.pos + n as u64);
        let first = self.patches.partition_point(|&(o, _)| o < start);
        for &(o, b) in self.patches[first..].iter().take_while(|&&(o, _)| o < end) {
            buf[(o - start) as usize] = b;
        }
        self.pos = end;
        Ok(n)
    }
}

impl Seek for MaskedFile {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        self.pos = self.file.seek(to)?;
        Ok(self.pos)
    }
}

impl MediaSource for MaskedFile {
    fn is_seekable(&self) -> bool {
        true
    }

    fn byte_len(&self) -> Option<u64> {
        Some(self.len)
    }
}
