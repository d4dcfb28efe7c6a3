//! What E-ENF reads: an event file or events in memory, opened the same way by every pass
//! over it (the flicker map, the trace, `inspect`).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::Result;
use eenf_events::{EventBatch, EventReader, OpenOptions};

/// What E-ENF reads: an event file, or events already in memory (arrays from another
/// library), which take the same path as a file's events.
#[derive(Debug, Clone)]
pub enum Recording {
    /// An event file (any format `eenf_events` reads; `-` is stdin).
    File(PathBuf),
    /// Events in memory from a sensor of `width` × `height` pixels, named `name` in messages.
    Memory {
        /// What errors and the trace call them.
        name: PathBuf,
        /// The events, in time order.
        events: Arc<EventBatch>,
        /// Sensor width, pixels.
        width: u16,
        /// Sensor height, pixels.
        height: u16,
    },
}

impl Recording {
    /// The recording of the file at `path`.
    pub fn file(path: &Path) -> Self {
        Recording::File(path.to_path_buf())
    }

    /// Its name in messages and in the trace.
    pub fn name(&self) -> &Path {
        match self {
            Recording::File(p) => p,
            Recording::Memory { name, .. } => name,
        }
    }

    /// Opens it from the start, as `open` says.
    pub fn open(&self, open: &OpenOptions) -> Result<Box<dyn EventReader>> {
        Ok(match self {
            Recording::File(p) => eenf_events::open_with(p, open)?,
            Recording::Memory {
                name,
                events,
                width,
                height,
            } => eenf_events::open_events(events.clone(), *width, *height, name, open)?,
        })
    }
}

/// A reader whose first batch was looked at (to tell how the camera stamps its events) and is
/// handed out again first, so that the look costs no second opening of the file.
pub struct Peeked {
    first: Option<EventBatch>,
    inner: Box<dyn EventReader>,
}

impl Peeked {
    /// Reads the first batch of `inner` (`None`: the stream is empty or ended at damage).
    pub fn new(mut inner: Box<dyn EventReader>) -> Result<Self> {
        let first = inner.next_batch()?;
        Ok(Peeked { first, inner })
    }

    /// The first batch, still to be handed out.
    pub fn first(&self) -> Option<&EventBatch> {
        self.first.as_ref()
    }
}

impl EventReader for Peeked {
    fn info(&self) -> &eenf_events::StreamInfo {
        self.inner.info()
    }

    fn next_batch(&mut self) -> eenf_events::Result<Option<EventBatch>> {
        match self.first.take() {
            Some(b) => Ok(Some(b)),
            None => self.inner.next_batch(),
        }
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        self.inner.skipped()
    }

    fn batch_offset(&self) -> Option<u64> {
        self.inner.batch_offset()
    }

    fn damage(&self) -> Option<&eenf_events::Damage> {
        self.inner.damage()
    }
}
