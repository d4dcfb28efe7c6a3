//! Named temporary copies, for the readers that open files by name (SQLite, HDF5) when what
//! they are given has none (a pipe) or must be expanded first (a `.db3.zstd`). A copy is
//! registered with [`eenf_core::cleanup`], so a signal removes it too, and it stops at a limit
//! (what the content states, and never closer than [`KEEP_FREE`] to a full disk).

use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;

use eenf_core::cleanup::InProgress;

/// Free space a copy leaves on its disk.
pub const KEEP_FREE: u64 = 1 << 30;
/// How many times its compressed size a file compressed whole may expand to, plus
/// [`EXPANSION_SLACK`]: event data compresses a few times, zeros (a bomb) thousands of times.
pub const MAX_RATIO: u64 = 100;
/// Bytes any compressed file may expand to, whatever its size.
pub const EXPANSION_SLACK: u64 = 64 << 20;

/// The most a file of `compressed` bytes may expand to.
pub fn expansion_bound(compressed: u64) -> u64 {
    compressed
        .saturating_mul(MAX_RATIO)
        .saturating_add(EXPANSION_SLACK)
}

/// A reader that fails once more than `limit` bytes came through (`why` says whose limit).
pub struct Bounded<R> {
    inner: R,
    left: u64,
    limit: u64,
    why: &'static str,
}

impl<R> Bounded<R> {
    /// `inner`, failing past `limit` bytes.
    pub fn new(inner: R, limit: u64, why: &'static str) -> Self {
        Bounded {
            inner,
            left: limit,
            limit,
            why,
        }
    }
}

impl<R: Read> Read for Bounded<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        if n as u64 > self.left {
            return Err(std::io::Error::other(format!(
                "it expands past {} bytes ({})",
                self.limit, self.why
            )));
        }
        self.left -= n as u64;
        Ok(n)
    }
}

/// A named temporary file, removed when dropped and when a signal ends the program.
pub struct NamedCopy {
    // dropped in this order: the file, then its registration
    path: tempfile::TempPath,
    _registered: InProgress,
}

impl NamedCopy {
    /// Where the copy is.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// The bytes the temporary folder can take while leaving [`KEEP_FREE`] free.
pub fn room() -> u64 {
    let dir = std::env::temp_dir();
    match rustix::fs::statvfs(&dir) {
        Ok(s) => (s.f_bavail.saturating_mul(s.f_frsize)).saturating_sub(KEEP_FREE),
        Err(_) => u64::MAX,
    }
}

/// `first`, then what `rest` holds, copied to a named temporary file: the copy and the file
/// open at its start. More than `stated` bytes (the size the content's header states), or than
/// [`room`], is an error that says so; whatever was written is removed.
pub fn spool(
    first: &[u8],
    rest: &mut dyn Read,
    stated: Option<u64>,
) -> std::io::Result<(NamedCopy, File)> {
    let room = room();
    let (limit, why) = match stated {
        Some(n) if n <= room => (n, "the size its header states"),
        _ => (room, "all but 1 GiB of the free disk space"),
    };
    let tmp = tempfile::NamedTempFile::new()?;
    let registered = InProgress::new(tmp.path());
    let (mut file, path) = tmp.into_parts();
    let copy = NamedCopy {
        path,
        _registered: registered,
    };
    file.write_all(first)?;
    let mut written = first.len() as u64;
    let mut buf = vec![0u8; 1 << 20];
    loop {
        let n = match rest.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        written += n as u64;
        if written > limit {
            return Err(std::io::Error::other(format!(
                "it holds more than {limit} bytes ({why})"
            )));
        }
        file.write_all(&buf[..n])?;
    }
    file.seek(SeekFrom::Start(0))?;
    Ok((copy, file))
}
