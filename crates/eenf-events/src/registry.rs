//! The formats eenf reads, each registered once by its own module (as Symphonia's readers
//! register their probes): how its first bytes are recognised, and how its reader is opened.
//! [`crate::probe_source`] tries them in the order of `FORMATS` (in `lib.rs`): the formats
//! with a signature first, then text, then the headerless ATIS words (content that random
//! bytes rarely have), so that a new format goes in by adding its module's entry there.

use std::path::Path;

use crate::{EventReader, Format, OpenOptions, Result, Source};

/// The head of a stream, as probes see it.
pub struct Head<'a> {
    /// The first bytes (up to 4 KiB).
    pub bytes: &'a [u8],
    /// Whether the stream is longer than `bytes` (its last line may be cut).
    pub cut: bool,
}

impl Head<'_> {
    /// Whether the head starts with `magic`.
    pub fn starts_with(&self, magic: &[u8]) -> bool {
        self.bytes.starts_with(magic)
    }
}

/// What a probe found: the format, and the Prophesee `% ` header when it read one (handed on
/// so that it is read once).
pub struct Probed {
    /// The format.
    pub format: Format,
    pub(crate) header: Option<crate::stream::TextHeader>,
}

impl Probed {
    /// `format`, with nothing read on the way.
    pub fn of(format: Format) -> Self {
        Probed {
            format,
            header: None,
        }
    }
}

/// Recognises a format from the head of `src` (named `path` in errors): `Ok(None)` when it is
/// not this one. May read from `src`; the stream is rewound after each probe.
pub type ProbeFn = fn(&Head, &mut dyn Source, &Path) -> Result<Option<Probed>>;

/// Opens the reader of a stream its probe recognised.
pub type OpenFn = fn(Box<dyn Source>, &Path, &OpenOptions, Probed) -> Result<Box<dyn EventReader>>;

/// One format: its probe and its reader (the entry's doc comment names the format).
pub struct Registered {
    /// Recognises it.
    pub probe: ProbeFn,
    /// Opens its reader.
    pub open: OpenFn,
}

/// A probe that recognises `magic` at the start as `format`.
pub fn by_magic(head: &Head, magic: &[u8], format: Format) -> Option<Probed> {
    head.starts_with(magic).then(|| Probed::of(format))
}
