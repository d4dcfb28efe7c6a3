//! Reading ahead: a reader (with its guard) runs on a thread of its own, a few batches ahead
//! of whoever consumes the events, so that decoding overlaps with what the consumer does with
//! them (sampling, mapping, converting). Used for AEDAT4, whose packets decode in parallel.

use std::sync::mpsc::{sync_channel, Receiver};

use crate::{Damage, EventBatch, EventError, EventReader, Result, StreamInfo};

/// Batches decoded ahead: enough to keep the consumer fed across a round of AEDAT4 packets,
/// few enough that memory stays that of a few packets.
const DEPTH: usize = 16;

/// What the reading thread hands over.
enum Msg {
    /// A batch and the byte offset it starts at.
    Batch(EventBatch, Option<u64>),
    /// The end of the stream: what was skipped, and why it ended early, if it did.
    End(Vec<(&'static str, u64)>, Option<Damage>),
    /// The error that ended the stream.
    Failed(EventError),
}

/// The consumer's side of a reader running ahead.
struct Prefetched {
    info: StreamInfo,
    rx: Receiver<Msg>,
    at: Option<u64>,
    skipped: Vec<(&'static str, u64)>,
    damage: Option<Damage>,
    done: bool,
}

/// Runs `inner` on its own thread. The thread ends at the stream's end, at its error, or when
/// the returned reader is dropped (its next hand-over fails).
pub(crate) fn read_ahead(
    mut inner: Box<dyn EventReader>,
    path: &std::path::Path,
) -> Result<Box<dyn EventReader>> {
    let info = inner.info().clone();
    let (tx, rx) = sync_channel(DEPTH);
    std::thread::Builder::new()
        .name("eenf-read-ahead".into())
        .spawn(move || loop {
            let msg = match inner.next_batch() {
                Ok(Some(b)) => Msg::Batch(b, inner.batch_offset()),
                Ok(None) => Msg::End(inner.skipped(), inner.damage().cloned()),
                Err(e) => Msg::Failed(e),
            };
            let last = !matches!(msg, Msg::Batch(..));
            if tx.send(msg).is_err() || last {
                return;
            }
        })
        .map_err(|e| crate::error::io_err(path, e))?;
    Ok(Box::new(Prefetched {
        info,
        rx,
        at: None,
        skipped: Vec::new(),
        damage: None,
        done: false,
    }))
}

impl EventReader for Prefetched {
    fn info(&self) -> &StreamInfo {
        &self.info
    }

    fn next_batch(&mut self) -> Result<Option<EventBatch>> {
        if self.done {
            return Ok(None);
        }
        match self.rx.recv() {
            Ok(Msg::Batch(b, at)) => {
                self.at = at;
                Ok(Some(b))
            }
            Ok(Msg::End(skipped, damage)) => {
                self.done = true;
                self.skipped = skipped;
                self.damage = damage;
                Ok(None)
            }
            Ok(Msg::Failed(e)) => {
                self.done = true;
                Err(e)
            }
            // the reading thread cannot vanish without a message unless it panicked
            Err(_) => {
                self.done = true;
                Err(EventError::Unfit {
                    path: std::path::PathBuf::from(self.info.format),
                    reason: "the reading thread stopped without a word".into(),
                })
            }
        }
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        self.skipped.clone()
    }

    fn batch_offset(&self) -> Option<u64> {
        self.at
    }

    fn damage(&self) -> Option<&Damage> {
        self.damage.as_ref()
    }
}
