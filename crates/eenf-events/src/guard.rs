//! What every reader does with damage and wild timestamps: the events before them are the
//! evidence, so they are kept, and what stopped the reading is reported as [`Damage`].
//!
//! A file cut short (a camera unplugged mid-recording) or damaged inside ends the stream where
//! the damage starts. A timestamp that jumps by more than a limit, forwards or backwards, ends
//! it too: one flipped bit must not stretch a one-second recording into two days. With
//! [`OpenOptions::strict`](crate::OpenOptions) both are errors instead.

use eenf_core::spelling::{option, switch};
use std::fmt;
use std::path::PathBuf;

use crate::error::{EventError, Result};
use crate::{EventBatch, EventReader, StreamInfo};

/// The default limit of a timestamp's step between two events, µs: a mains-lit scene makes
/// events every few milliseconds, and no format's clock steps back by seconds.
pub const DEFAULT_MAX_GAP_US: i64 = 5_000_000;

/// What ended a stream before its end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DamageKind {
    /// The file ends inside a structure it announces.
    Truncated,
    /// The content is damaged.
    Corrupt,
    /// A timestamp jumps forwards or backwards by more than the limit.
    TimeJump,
}

impl fmt::Display for DamageKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            DamageKind::Truncated => "truncated",
            DamageKind::Corrupt => "corrupt",
            DamageKind::TimeJump => "time jump",
        })
    }
}

/// Where and why a stream ended early; the events before it were delivered.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Damage {
    /// What it is.
    pub kind: DamageKind,
    /// Byte offset of the damage; for a time jump, of the block of data that holds it.
    pub offset: u64,
    /// Events delivered before it.
    pub events_before: u64,
    /// The reader's words for it, naming the file.
    pub message: String,
}

impl fmt::Display for Damage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}; the {} events before it are read ({} refuses the file)",
            self.message,
            self.events_before,
            switch("strict")
        )
    }
}

/// A reader that ends its stream at damage or at a wild timestamp (see the module comment).
pub(crate) struct Guarded {
    inner: Box<dyn EventReader>,
    path: PathBuf,
    strict: bool,
    max_gap: u64,
    last_t: Option<i64>,
    events: u64,
    damage: Option<Damage>,
    ended: bool,
}

impl Guarded {
    pub(crate) fn new(
        inner: Box<dyn EventReader>,
        path: &std::path::Path,
        strict: bool,
        max_gap_us: i64,
    ) -> Self {
        Guarded {
            inner,
            path: path.to_path_buf(),
            strict,
            max_gap: max_gap_us.max(0) as u64,
            last_t: None,
            events: 0,
            damage: None,
            ended: false,
        }
    }

    /// The first event whose step from the one before exceeds the limit.
    fn first_wild(&self, t: &[i64]) -> Option<usize> {
        if let Some(last) = self.last_t {
            if t[0].abs_diff(last) > self.max_gap {
                return Some(0);
            }
        }
        // a pass the compiler vectorises on any x86-64 (sub, add, or): with 2^m the largest
        // power of two within the limit, every step inside (-2^m, 2^m) sets no bit from m + 1
        // up once shifted by 2^m; only a batch where some step does is looked at step by step
        let m = 63 - self.max_gap.max(1).leading_zeros();
        let half = 1u64 << m;
        let bits = t[1..]
            .iter()
            .zip(&t[..t.len() - 1])
            .fold(0u64, |acc, (&b, &a)| {
                acc | (b.wrapping_sub(a) as u64).wrapping_add(half)
            });
        if bits >> (m + 1) == 0 {
            return None;
        }
        t.windows(2)
            .position(|w| w[1].abs_diff(w[0]) > self.max_gap)
            .map(|i| i + 1)
    }
}

impl EventReader for Guarded {
    fn info(&self) -> &StreamInfo {
        self.inner.info()
    }

    fn next_batch(&mut self) -> Result<Option<EventBatch>> {
        if self.ended {
            return Ok(None);
        }
        let mut batch = match self.inner.next_batch() {
            Ok(Some(b)) => b,
            Ok(None) => {
                self.ended = true;
                return Ok(None);
            }
            Err(e) => {
                self.ended = true;
                let (kind, offset) = match &e {
                    EventError::Truncated { offset, .. } => (DamageKind::Truncated, *offset),
                    EventError::Corrupt { offset, .. } => (DamageKind::Corrupt, *offset),
                    _ => return Err(e),
                };
                if self.strict {
                    return Err(e);
                }
                self.damage = Some(Damage {
                    kind,
                    offset,
                    events_before: self.events,
                    message: e.to_string(),
                });
                return Ok(None);
            }
        };
        if batch.is_empty() {
            return Ok(Some(batch));
        }
        if let Some(i) = self.first_wild(&batch.t) {
            let before = if i == 0 {
                self.last_t.unwrap_or(batch.t[0])
            } else {
                batch.t[i - 1]
            };
            let offset = self.inner.batch_offset().unwrap_or(0);
            let reason = format!(
                "timestamp jumps from {:.6} s to {:.6} s, more than the {} s allowed ({})",
                before as f64 * 1e-6,
                batch.t[i] as f64 * 1e-6,
                self.max_gap as f64 * 1e-6,
                option("max_gap")
            );
            let e = EventError::Corrupt {
                path: self.path.clone(),
                format: self.inner.info().format,
                offset,
                reason: format!("{reason}, in the data read from this byte on"),
            };
            self.ended = true;
            if self.strict {
                return Err(e);
            }
            batch.truncate(i);
            self.damage = Some(Damage {
                kind: DamageKind::TimeJump,
                offset,
                events_before: self.events + i as u64,
                message: e.to_string(),
            });
            if batch.is_empty() {
                return Ok(None);
            }
        }
        self.last_t = batch.t.last().copied();
        self.events += batch.len() as u64;
        Ok(Some(batch))
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        self.inner.skipped()
    }

    fn batch_offset(&self) -> Option<u64> {
        self.inner.batch_offset()
    }

    fn damage(&self) -> Option<&Damage> {
        self.damage.as_ref()
    }
}
