//! What a reader holds back between calls: the batch it read ahead while opening (the first
//! message gives the sensor's size), and the damage that ended a read, which is handed out
//! after the good events read before it.

use crate::{EventBatch, EventError, Result};

/// A batch read ahead and an error held back, handed out in that order.
#[derive(Default)]
pub(crate) struct Held {
    batch: Option<EventBatch>,
    error: Option<EventError>,
}

impl Held {
    /// Holds the outcome of the read made while opening.
    pub(crate) fn hold(&mut self, read: Result<Option<EventBatch>>) {
        match read {
            Ok(b) => self.batch = b,
            Err(e) => self.error = Some(e),
        }
    }

    /// Whether an error is held.
    pub(crate) fn failed(&self) -> bool {
        self.error.is_some()
    }

    /// What is held, next: the batch, then the error; `None` when nothing is.
    pub(crate) fn take(&mut self) -> Option<Result<Option<EventBatch>>> {
        if let Some(b) = self.batch.take() {
            return Some(Ok(Some(b)));
        }
        self.error.take().map(Err)
    }

    /// Ends a read at `e`: the events of `batch` now, when there are any, and `e` next.
    pub(crate) fn fail(&mut self, e: EventError, batch: EventBatch) -> Result<Option<EventBatch>> {
        if batch.is_empty() {
            return Err(e);
        }
        self.error = Some(e);
        Ok(Some(batch))
    }
}
