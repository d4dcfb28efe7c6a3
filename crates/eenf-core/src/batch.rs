//! The event model: batches of events stored as struct-of-arrays.

/// A batch of events in time order, stored column-wise so hot loops stream over one array.
///
/// `t` is in microseconds (absolute where the format has absolute time), `x`/`y` are pixel
/// coordinates with the origin at the top-left, `p` is the polarity (`true` = ON, brighter).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct EventBatch {
    /// Timestamps in microseconds.
    pub t: Vec<i64>,
    /// Pixel columns.
    pub x: Vec<u16>,
    /// Pixel rows.
    pub y: Vec<u16>,
    /// Polarities: `true` for ON (increase), `false` for OFF.
    pub p: Vec<bool>,
}

impl EventBatch {
    /// An empty batch with room for `n` events.
    pub fn with_capacity(n: usize) -> Self {
        EventBatch {
            t: Vec::with_capacity(n),
            x: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
            p: Vec::with_capacity(n),
        }
    }

    /// Number of events.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// True when the batch holds no event.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Appends one event.
    #[inline]
    pub fn push(&mut self, t: i64, x: u16, y: u16, p: bool) {
        self.t.push(t);
        self.x.push(x);
        self.y.push(y);
        self.p.push(p);
    }

    /// Keeps the first `n` events.
    pub fn truncate(&mut self, n: usize) {
        self.t.truncate(n);
        self.x.truncate(n);
        self.y.truncate(n);
        self.p.truncate(n);
    }

    /// Removes all events, keeping the allocations.
    pub fn clear(&mut self) {
        self.t.clear();
        self.x.clear();
        self.y.clear();
        self.p.clear();
    }

    /// Appends all events of `other`.
    pub fn extend_from(&mut self, other: &EventBatch) {
        self.t.extend_from_slice(&other.t);
        self.x.extend_from_slice(&other.x);
        self.y.extend_from_slice(&other.y);
        self.p.extend_from_slice(&other.p);
    }
}
