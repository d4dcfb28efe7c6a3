//! Tests of eenf's `progress` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf::progress::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// Counts what it is told.
#[derive(Default)]
struct Counter(Arc<AtomicU64>);
struct Counted(Arc<AtomicU64>);

impl ProgressSink for Counter {
    fn start(&self, _: Unit, _: Option<u64>, _: &str) -> Box<dyn Task> {
        Box::new(Counted(self.0.clone()))
    }
}
impl Task for Counted {
    fn inc(&self, n: u64) {
        self.0.fetch_add(n, Ordering::Relaxed);
    }
    fn set_position(&self, n: u64) {
        self.0.store(n, Ordering::Relaxed);
    }
    fn finish(&self) {}
}

#[test]
fn a_supplied_sink_hears_the_work_and_a_hidden_one_costs_nothing() {
    let count = Arc::new(AtomicU64::new(0));
    let p = Progress::to(Arc::new(Counter(count.clone())));
    let bar = p.events(Some(10), "reading");
    bar.inc(3);
    bar.inc(4);
    assert_eq!(count.load(Ordering::Relaxed), 7);
    bar.set_position(2);
    assert_eq!(count.load(Ordering::Relaxed), 2);
    let hidden = Progress::hidden().steps(5, "nothing");
    hidden.inc(1);
    assert_eq!(count.load(Ordering::Relaxed), 2);
}
