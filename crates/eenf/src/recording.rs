//! What E-ENF reads: an event file or events in memory, opened the same way by every pass
//! over it (the flicker map, the trace, `inspect`).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::Result;
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
