//! Tests of eenf-events's `atis` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_events::atis::*;
use std::path::Path;

fn word(x: u8, y: u8, p: bool, t: u32) -> [u8; 5] {
    [
        x,
        y,
        ((t >> 16) as u8 & 0x7F) | if p { 0x80 } else { 0 },
        (t >> 8) as u8,
        t as u8,
    ]
}

#[test]
fn words_and_overflow_marks() {
    let mut bytes = Vec::new();
    for w in [
        word(7, 15, true, 654),
        word(33, 0, false, 8191),
        word(0, OVERFLOW_Y, false, 0),
        word(1, 2, true, 5),
    ] {
        bytes.extend_from_slice(&w);
    }
    for k in 0..40 {
        bytes.extend_from_slice(&word(3, 4, false, 10 + k));
    }
    assert!(looks_like(&bytes, bytes.len() as u64));
    assert!(!looks_like(&bytes[..19], 19));
    assert!(!looks_like(&bytes[..20], 20), "too few words to tell");
    assert!(!looks_like(&[b'#'; 200], 200), "text is not ATIS");
    let mut r = reader(Box::new(std::io::Cursor::new(bytes)), Path::new("a.bin")).unwrap();
    let b = r.next_batch().unwrap().unwrap();
    assert_eq!(b.len(), 43);
    assert_eq!(b.t[..4], [654, 8191, 8192 + 5, 8192 + 10]);
    assert_eq!((b.x[1], b.y[1], b.p[1]), (33, 0, false));
    assert_eq!((b.x[2], b.y[2], b.p[2]), (1, 2, true));
    assert!(r.next_batch().unwrap().is_none());
    // times that go back are not this format
    let mut back = word(1, 1, true, 500).to_vec();
    back.extend_from_slice(&word(1, 1, true, 100));
    assert!(!looks_like(&back, 10));
}
