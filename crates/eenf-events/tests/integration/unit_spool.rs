//! Tests of eenf-events's `spool` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_events::spool::*;
use std::io::Read;

#[test]
fn a_copy_past_its_stated_size_is_refused_and_removed() {
    let (copy, mut f) = spool(b"ab", &mut &b"cdef"[..], Some(6)).unwrap();
    let mut text = String::new();
    f.read_to_string(&mut text).unwrap();
    assert_eq!(text, "abcdef");
    let path = copy.path().to_path_buf();
    drop(copy);
    assert!(!path.exists());
    let mut zeros = std::io::repeat(0).take(10 << 20);
    let Err(e) = spool(b"", &mut zeros, Some(1 << 20)) else {
        panic!("ten MiB copied where one was stated");
    };
    assert!(e.to_string().contains("the size its header states"), "{e}");
}

#[test]
fn bounded_reads_end_past_their_limit() {
    let mut r = Bounded::new(std::io::repeat(1).take(100), 64, "a test");
    let mut out = Vec::new();
    let e = r.read_to_end(&mut out).unwrap_err();
    assert!(e.to_string().contains("past 64 bytes (a test)"), "{e}");
    assert!(out.len() <= 64);
    assert_eq!(expansion_bound(1 << 20), (100 << 20) + EXPANSION_SLACK);
}
