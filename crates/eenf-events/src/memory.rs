//! Events already in memory (arrays handed over by another library, such as the Python
//! package's numpy arrays) read as a stream, so that they take the same path as a file's
//! events: the same batches, the same guard against wild timestamps.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::{guard, EventBatch, EventError, EventReader, OpenOptions, Result, StreamInfo};

/// Events per batch handed out (about what one AEDAT4 packet of a busy scene holds).
pub const BATCH: usize = 1 << 16;

/// What `info().format` says of events from memory.
pub const FORMAT: &str = "events in memory";

/// A reader over events in memory.
struct MemoryReader {
    info: StreamInfo,
    events: Arc<EventBatch>,
    at: usize,
    /// Where the last batch handed out starts.
    start: usize,
}

impl EventReader for MemoryReader {
    fn info(&self) -> &StreamInfo {
        &self.info
    }

    fn next_batch(&mut self) -> Result<Option<EventBatch>> {
        let e = &self.events;
        if self.at >= e.len() {
            return Ok(None);
        }
        let r = self.at..(self.at + BATCH).min(e.len());
        self.start = r.start;
        self.at = r.end;
        Ok(Some(EventBatch {
            t: e.t[r.clone()].to_vec(),
            x: e.x[r.clone()].to_vec(),
            y: e.y[r.clone()].to_vec(),
            p: e.p[r].to_vec(),
        }))
    }

    fn batch_offset(&self) -> Option<u64> {
        // the index of the batch's first event stands for its place
        Some(self.start as u64)
    }
}

/// Checks events for a sensor of `width` × `height` pixels: columns of one length, every
/// address inside the sensor, timestamps that never decrease. `name` names them in errors.
pub fn check_events(events: &EventBatch, width: u16, height: u16, name: &Path) -> Result<()> {
    let bad = |reason: String| EventError::Unfit {
        path: name.to_path_buf(),
        reason,
    };
    let n = events.t.len();
    if events.x.len() != n || events.y.len() != n || events.p.len() != n {
        return Err(bad(format!(
            "the columns differ in length: t {n}, x {}, y {}, p {}",
            events.x.len(),
            events.y.len(),
            events.p.len()
        )));
    }
    if let Some(i) = events.t.windows(2).position(|w| w[1] < w[0]) {
        return Err(bad(format!(
            "timestamps must not decrease: t[{}] = {} after t[{i}] = {}",
            i + 1,
            events.t[i + 1],
            events.t[i]
        )));
    }
    if let Some(i) = events.x.iter().position(|&x| x >= width) {
        return Err(bad(format!(
            "x[{i}] = {} lies outside the {width} pixels wide sensor",
            events.x[i]
        )));
    }
    if let Some(i) = events.y.iter().position(|&y| y >= height) {
        return Err(bad(format!(
            "y[{i}] = {} lies outside the {height} pixels high sensor",
            events.y[i]
        )));
    }
    Ok(())
}

/// Opens events in memory (checked with [`check_events`]) as a stream from a sensor of
/// `width` × `height` pixels, read as `opts` says (one camera: only camera 0 can be asked for).
pub fn open_events(
    events: Arc<EventBatch>,
    width: u16,
    height: u16,
    name: &Path,
    opts: &OpenOptions,
) -> Result<Box<dyn EventReader>> {
    let unfit = |reason: &str| EventError::Unfit {
        path: PathBuf::from(name),
        reason: reason.to_string(),
    };
    if opts.chip.is_some() {
        return Err(unfit("a chip can be named only for jAER AEDAT 2.0 files"));
    }
    if opts.camera.is_some_and(|c| c > 0) {
        return Err(unfit("events in memory come from one camera (camera 0)"));
    }
    check_events(&events, width, height, name)?;
    let info = StreamInfo {
        format: FORMAT,
        width: Some(width),
        height: Some(height),
        event_count: Some(events.len() as u64),
        first_t: events.t.first().copied(),
        last_t: events.t.last().copied(),
        ..StreamInfo::default()
    };
    let reader = MemoryReader {
        info,
        events,
        at: 0,
        start: 0,
    };
    Ok(Box::new(guard::Guarded::new(
        Box::new(reader),
        name,
        opts.strict,
        opts.max_gap_us.unwrap_or(guard::DEFAULT_MAX_GAP_US),
    )))
}
