//! The library's errors: each says which area refused, keeps its causes in order, and lets a
//! front end find the OS's error and the option it is about (`eenf::error`).

use std::io::Write;

use eenf::options::{apply_json, MatchSettings, OptionSet};
use eenf::trace::Trace;
use eenf::{Area, Error};

#[test]
fn a_missing_file_is_the_os_error_named_by_its_path() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("absent.csv");
    let e = Trace::read(&path, None).unwrap_err();
    assert_eq!(e.area(), Area::Os);
    assert_eq!(e.io_kind(), Some(std::io::ErrorKind::NotFound));
    let text = e.report();
    assert!(text.starts_with(&path.display().to_string()), "{text}");
    assert!(text.contains("No such file"), "{text}");
}

#[test]
fn a_cause_is_kept_after_what_was_being_done() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.csv");
    std::fs::write(&path, "time_s,enf_hz\n0,50.01\n1,fifty\n").unwrap();
    let e = Trace::read(&path, None).unwrap_err();
    assert_eq!(e.area(), Area::Input);
    assert_eq!(e.io_kind(), None);
    // the context alone, then the parser's words after it
    let top = e.to_string();
    let text = e.report();
    assert!(
        text.starts_with(&top) && text.len() > top.len(),
        "{top} / {text}"
    );
    assert!(text.contains("line 3"), "{text}");
    assert!(text.contains("invalid float literal"), "{text}");
    assert!(std::error::Error::source(&e).is_some());
}

#[test]
fn a_refused_option_names_it_by_its_library_name() {
    let mut set = MatchSettings::default();
    let e: Error = apply_json(&mut [&mut set as &mut dyn OptionSet], r#"{"top": -3}"#)
        .unwrap_err()
        .into();
    assert_eq!(e.area(), Area::Option);
    assert_eq!(e.option(), Some("top"));
    assert_eq!(e.io_kind(), None);
}

#[test]
fn a_store_refusal_is_the_stores() {
    let e = eenf::refdb::check_grid_name("../x").unwrap_err();
    assert_eq!(e.area(), Area::Store);
    assert!(e.report().contains("not a grid name"), "{}", e.report());
}

/// A reader that went away: every write fails as a closed pipe.
struct ClosedPipe;

impl Write for ClosedPipe {
    fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
        Err(std::io::ErrorKind::BrokenPipe.into())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Err(std::io::ErrorKind::BrokenPipe.into())
    }
}

#[test]
fn a_closed_pipe_is_found_through_the_csv_and_json_writers() {
    let t = Trace::new(1.0, vec![50.0; 5000]);
    let e = t.write_csv(&mut ClosedPipe).unwrap_err();
    assert_eq!(
        e.io_kind(),
        Some(std::io::ErrorKind::BrokenPipe),
        "{}",
        e.report()
    );
    let e = t.write_json(&mut ClosedPipe).unwrap_err();
    assert_eq!(
        e.io_kind(),
        Some(std::io::ErrorKind::BrokenPipe),
        "{}",
        e.report()
    );
}
