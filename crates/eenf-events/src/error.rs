//! Errors of the readers and writers.

use std::path::PathBuf;

/// What went wrong while reading or writing an event file. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum EventError {
    /// The file could not be opened, read or written.
    // the OS message is shown once: not also as a `source` that `{:#}` would print again
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        error: std::io::Error,
    },
    /// The content is not a format eenf knows.
    #[error("{path}: not a supported event file ({reason}); supported: {supported}")]
    UnknownFormat {
        /// The file.
        path: PathBuf,
        /// What the probe saw.
        reason: String,
        /// The supported formats.
        supported: &'static str,
    },
    /// The file is in a known format but its content is damaged or inconsistent.
    #[error("{path}: corrupt {format} data at byte {offset}: {reason}")]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// The format being read.
        format: &'static str,
        /// Byte offset of the damage, as far as known.
        offset: u64,
        /// What is wrong.
        reason: String,
    },
    /// What was asked of the file does not fit it (a chip or camera it cannot have).
    #[error("{path}: {reason}")]
    Unfit {
        /// The file.
        path: PathBuf,
        /// What does not fit.
        reason: String,
    },
    /// The file ends before a structure it announces.
    #[error("{path}: truncated {format} file at byte {offset}: {reason}")]
    Truncated {
        /// The file.
        path: PathBuf,
        /// The format being read.
        format: &'static str,
        /// Where the data ran out.
        offset: u64,
        /// What was being read.
        reason: String,
    },
    /// A container (an SQLite database) reports damage where no byte offset is known.
    #[error("{path}: damaged {format}: {reason}")]
    Damaged {
        /// The file.
        path: PathBuf,
        /// The format being read.
        format: &'static str,
        /// What the container's own reader said.
        reason: String,
    },
}

/// Shorthand for results of this crate.
pub type Result<T> = std::result::Result<T, EventError>;

pub(crate) fn io_err(path: &std::path::Path, source: std::io::Error) -> EventError {
    EventError::Io {
        path: path.to_path_buf(),
        error: source,
    }
}
