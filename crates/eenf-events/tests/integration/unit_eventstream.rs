//! Tests of eenf-events's `eventstream` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_events::eventstream::*;
use eenf_events::{EventBatch, Result, StreamInfo};
use std::path::Path;

fn file(events: &[u8]) -> Vec<u8> {
    let mut v = MAGIC.to_vec();
    v.extend_from_slice(&[2, 0, 0, 1, 0x40, 0x01, 0xF0, 0x00]);
    v.extend_from_slice(events);
    v
}

fn read(bytes: Vec<u8>) -> Result<(StreamInfo, EventBatch)> {
    let mut r = reader(Box::new(std::io::Cursor::new(bytes)), Path::new("t.es"))?;
    let mut all = EventBatch::default();
    while let Some(b) = r.next_batch()? {
        all.extend_from(&b);
    }
    Ok((r.info().clone(), all))
}

#[test]
fn dvs_events_overflows_and_resets() {
    // t 0: ON at (0, 239); five resets; two overflows then +3 µs: OFF at (319, 1)
    let mut ev = vec![0x01, 0, 0, 0xEF, 0];
    ev.extend_from_slice(&[0xFE; 5]);
    ev.extend_from_slice(&[0xFF, 0xFF, 3 << 1, 0x3F, 0x01, 0x01, 0x00]);
    // a reset value inside an event is data, not a reset
    ev.extend_from_slice(&[1 << 1 | 1, 0xFE, 0x00, 0xFE, 0x00]);
    let (info, b) = read(file(&ev)).unwrap();
    assert_eq!((info.width, info.height), (Some(320), Some(240)));
    assert_eq!(b.t, vec![0, 257, 258]);
    assert_eq!(b.x, vec![0, 319, 254]);
    assert_eq!(b.y, vec![239, 1, 254]);
    assert_eq!(b.p, vec![true, false, true]);
    // cut inside an event: the events before it, then the truncation
    let mut cut = file(&ev);
    cut.truncate(cut.len() - 2);
    let mut r = reader(Box::new(std::io::Cursor::new(cut)), Path::new("t.es")).unwrap();
    assert_eq!(r.next_batch().unwrap().unwrap().len(), 2);
    let e = r.next_batch().unwrap_err().to_string();
    assert!(
        e.contains("truncated") && e.contains("3 of its 5 bytes"),
        "{e}"
    );
    assert!(r.next_batch().unwrap().is_none());
}

#[test]
fn other_types_and_versions_are_refused_by_name() {
    let mut atis = file(&[]);
    atis[15] = 2;
    let e = read(atis).unwrap_err().to_string();
    assert!(e.contains("ATIS") && e.contains("t.es"), "{e}");
    let mut v1 = file(&[]);
    v1[12] = 1;
    let e = read(v1).unwrap_err().to_string();
    assert!(e.contains("version 1"), "{e}");
    let e = read(MAGIC.to_vec()).unwrap_err().to_string();
    assert!(e.contains("cut short"), "{e}");
}
