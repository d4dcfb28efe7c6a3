//! Progress, reported to whoever called: the library draws nothing itself. The command line
//! hands in a sink that draws bars on a terminal; the Python package and tests use
//! [`Progress::hidden`].

use std::sync::Arc;

/// What a piece of work counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    /// Events read (the total is the header's count, when it has one).
    Events,
    /// Steps of known number: frames, files, recordings.
    Steps,
    /// Work of unknown length: nothing is counted, only time passes.
    Spinner,
}

/// Receives the progress of the library's work: one [`Task`] per piece of work started.
pub trait ProgressSink: Send + Sync {
    /// A piece of work named `what` starts, counting `unit`s up to `total` when known.
    fn start(&self, unit: Unit, total: Option<u64>, what: &str) -> Box<dyn Task>;
}

/// One piece of work in progress, as the sink shows it.
pub trait Task: Send + Sync {
    /// `n` more units are done.
    fn inc(&self, n: u64);
    /// `n` units are done in all.
    fn set_position(&self, n: u64);
    /// The work is over (finished or abandoned): its display goes away.
    fn finish(&self);
}

/// Where the library reports progress: a sink the caller supplies, or nowhere.
#[derive(Clone, Default)]
pub struct Progress {
    sink: Option<Arc<dyn ProgressSink>>,
}

impl std::fmt::Debug for Progress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Progress")
            .field("reported", &self.sink.is_some())
            .finish()
    }
}

impl Progress {
    /// Progress that goes nowhere.
    pub fn hidden() -> Self {
        Progress { sink: None }
    }

    /// Progress reported to `sink`.
    pub fn to(sink: Arc<dyn ProgressSink>) -> Self {
        Progress { sink: Some(sink) }
    }

    fn start(&self, unit: Unit, total: Option<u64>, what: &str) -> Bar {
        Bar(self.sink.as_ref().map(|s| s.start(unit, total, what)))
    }

    /// Work over events (`total` from the header, when it says).
    pub fn events(&self, total: Option<u64>, what: &str) -> Bar {
        self.start(Unit::Events, total, what)
    }

    /// Work over a number of steps (0: not known yet).
    pub fn steps(&self, total: u64, what: &str) -> Bar {
        self.start(Unit::Steps, Some(total), what)
    }

    /// Work of unknown length.
    pub fn spinner(&self, what: &str) -> Bar {
        self.start(Unit::Spinner, None, what)
    }
}

/// A piece of work in progress; reporting on a hidden one costs nothing.
pub struct Bar(Option<Box<dyn Task>>);

impl Bar {
    /// `n` more units are done.
    pub fn inc(&self, n: u64) {
        if let Some(t) = &self.0 {
            t.inc(n);
        }
    }

    /// `n` units are done in all.
    pub fn set_position(&self, n: u64) {
        if let Some(t) = &self.0 {
            t.set_position(n);
        }
    }

    /// The work is over: its display goes away.
    pub fn finish_and_clear(&self) {
        if let Some(t) = &self.0 {
            t.finish();
        }
    }
}
