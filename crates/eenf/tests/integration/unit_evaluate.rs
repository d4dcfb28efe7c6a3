//! Tests of eenf's `evaluate` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf::evaluate::*;

#[test]
fn align_matches_times_with_offset() {
    let (t, e, r) = align(
        &[0.0, 1.0, 2.0],
        &[1.0, 2.0, 3.0],
        &[10.0, 11.0, 12.0, 13.0],
        &[5.0, 6.0, 7.0, 8.0],
        11.0,
    );
    assert_eq!(t, vec![0.0, 1.0, 2.0]);
    assert_eq!(e, vec![1.0, 2.0, 3.0]);
    assert_eq!(r, vec![6.0, 7.0, 8.0]);
}
