//! Tests of eenf's `trace` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf::trace::*;
use eenf_dsp::EnfParams;
use std::path::Path;

#[test]
fn trace_csv_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("t.csv");
    let mut buf = Vec::new();
    Trace::new(1.0, vec![50.01, f64::NAN])
        .write_csv(&mut buf)
        .unwrap();
    std::fs::write(&p, &buf).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    assert_eq!(text, "time_s,enf_hz\n0,50.01\n1,\n");
    let t = Trace::read(&p, None).unwrap();
    assert_eq!(t.time_s, vec![0.0, 1.0]);
    assert_eq!(t.enf_hz[0], 50.01);
    assert!(t.enf_hz[1].is_nan());
    std::fs::write(&p, "a,b\n1,2\n").unwrap();
    assert!(Trace::read(&p, None).is_err());
}

#[test]
fn json_round_trip_keeps_provenance() {
    let params = EnfParams::default();
    let t = Trace::from_mains(
        Path::new("m.wav"),
        eenf_core::Grid::Hz50,
        &params,
        vec![50.01, f64::NAN],
    );
    let mut buf = Vec::new();
    t.write_json(&mut buf).unwrap();
    let back = Trace::parse(std::str::from_utf8(&buf).unwrap(), Path::new("x"), None).unwrap();
    assert_eq!(back.provenance, t.provenance);
    assert_eq!(back.peak(), Some(params.peak));
    assert!(back.enf_hz[1].is_nan());
}
