//! Tests of eenf-events's `contain` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_events::contain::*;

#[test]
fn a_panic_becomes_its_message_and_values_pass_through() {
    assert_eq!(contain(|| 7), Ok(7));
    let e = contain(|| -> u8 { panic!("index {} out of range", 9) }).unwrap_err();
    assert!(e.contains("index 9 out of range"), "{e}");
    let v: Vec<u8> = Vec::new();
    #[allow(clippy::unnecessary_operation)]
    let e = contain(|| v[3]).unwrap_err();
    assert!(e.contains("index out of bounds"), "{e}");
    // nested calls and calls after a panic still work
    assert_eq!(contain(|| contain(|| 1)), Ok(Ok(1)));
}
