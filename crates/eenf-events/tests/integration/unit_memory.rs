//! Tests of eenf-events's `memory` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_events::memory::*;
use eenf_events::{EventBatch, OpenOptions};
use std::path::Path;
use std::sync::Arc;

fn batch(t: &[i64]) -> EventBatch {
    let mut b = EventBatch::default();
    for (i, &t) in t.iter().enumerate() {
        b.push(t, (i % 7) as u16, (i % 5) as u16, i % 2 == 0);
    }
    b
}

#[test]
fn hands_out_every_event_in_order_in_batches() {
    let t: Vec<i64> = (0..(2 * BATCH as i64 + 17)).map(|i| i * 3).collect();
    let whole = Arc::new(batch(&t));
    let mut r = open_events(whole.clone(), 7, 5, Path::new("a"), &OpenOptions::default()).unwrap();
    let mut got = EventBatch::default();
    let mut batches = 0;
    while let Some(b) = r.next_batch().unwrap() {
        got.extend_from(&b);
        batches += 1;
    }
    assert_eq!(batches, 3);
    assert_eq!(&got, whole.as_ref());
    assert_eq!(r.info().event_count, Some(t.len() as u64));
}

#[test]
fn refuses_disorder_and_addresses_off_the_sensor() {
    let o = OpenOptions::default();
    let e = open_events(Arc::new(batch(&[0, 5, 4])), 7, 5, Path::new("a"), &o);
    let msg = e.err().unwrap().to_string();
    assert!(msg.contains("t[2] = 4 after t[1] = 5"), "{msg}");
    let e = open_events(Arc::new(batch(&[0, 1, 2])), 7, 2, Path::new("a"), &o);
    assert!(e.err().unwrap().to_string().contains("y[2] = 2"));
    let cam = OpenOptions {
        camera: Some(1),
        ..o
    };
    assert!(open_events(Arc::new(batch(&[0])), 7, 5, Path::new("a"), &cam).is_err());
}

#[test]
fn a_wild_timestamp_ends_the_stream_as_in_a_file() {
    let mut t: Vec<i64> = (0..100).collect();
    t.extend((0..100).map(|i| 10_000_000_000 + i));
    let mut r = open_events(
        Arc::new(batch(&t)),
        7,
        5,
        Path::new("a"),
        &OpenOptions::default(),
    )
    .unwrap();
    let mut n = 0;
    while let Some(b) = r.next_batch().unwrap() {
        n += b.len();
    }
    assert_eq!(n, 100);
    assert!(r.damage().is_some());
}
