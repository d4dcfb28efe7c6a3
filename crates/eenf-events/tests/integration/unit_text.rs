//! Tests of eenf-events's `text` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_events::text::*;
use eenf_events::EventReader;
use std::path::Path;

#[test]
fn parses_the_accepted_spellings() {
    assert_eq!(
        parse_line("0.000001500000 3 4 1", TimeUnit::Seconds).unwrap(),
        Some((2, 3, 4, true))
    );
    assert_eq!(
        parse_line("12, 3, 4, -1", TimeUnit::Micros).unwrap(),
        Some((12, 3, 4, false))
    );
    assert_eq!(parse_line("# comment", TimeUnit::Micros).unwrap(), None);
    assert!(parse_line("1 2 3", TimeUnit::Micros).is_err());
    assert!(parse_line("1 2 x 3", TimeUnit::Micros).is_err());
    // 0.0000015 s is 1.5 us: rounds (not truncates) to 2
    assert_eq!(
        parse_line("1.5e-6 0 0 0", TimeUnit::Seconds).unwrap(),
        Some((2, 0, 0, false))
    );
}

#[test]
fn non_finite_and_absurd_values_are_refused_where_they_are() {
    for (line, unit) in [
        ("nan 1 2 1", TimeUnit::Seconds),
        ("inf 1 2 1", TimeUnit::Micros),
        ("-inf 1 2 1", TimeUnit::Seconds),
        ("12345678901234567890123456 1 2 1", TimeUnit::Micros),
        ("1e12 1 2 1", TimeUnit::Seconds),
        ("5 1 2 nan", TimeUnit::Micros),
    ] {
        assert!(parse_line(line, unit).is_err(), "{line}");
    }
    // the error names the line and the byte where it starts
    let text = "t x y p\n10 1 2 1\n20 1 2 0\nnan 1 2 1\n";
    let mut r = TextReader::new(
        Box::new(std::io::Cursor::new(text.as_bytes().to_vec())),
        Path::new("e.txt"),
    )
    .unwrap();
    // the events before the bad line come first, then the error
    assert_eq!(r.next_batch().unwrap().unwrap().t, vec![10, 20]);
    let e = r.next_batch().unwrap_err().to_string();
    assert!(e.contains("at byte 26") && e.contains("line 4"), "{e}");
    // a line without an end is held to a few KiB, never read whole
    let mut long = b"10 1 2 1\n".to_vec();
    long.resize(1 << 20, b'7');
    let mut r = TextReader::new(Box::new(std::io::Cursor::new(long)), Path::new("e.txt")).unwrap();
    assert_eq!(r.next_batch().unwrap().unwrap().len(), 1);
    let e = r.next_batch().unwrap_err().to_string();
    assert!(e.contains("longer than 4096 bytes"), "{e}");
}
