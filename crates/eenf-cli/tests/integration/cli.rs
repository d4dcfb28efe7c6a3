//! Running the `eenf` binary from the CLI tests, as a user does.
#![allow(dead_code)] // each test target uses some of these

use std::path::Path;
use std::process::{Command, Output};

/// Runs `eenf ARGS` in `dir`.
pub fn eenf(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_eenf"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

/// Runs `eenf ARGS`, which must succeed; its stdout.
pub fn ok(args: &[&str], dir: &Path) -> String {
    let out = eenf(args, dir);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Runs `eenf ARGS`, which must succeed: its stdout and stderr.
pub fn ok_out_err(args: &[&str], dir: &Path) -> (String, String) {
    let out = eenf(args, dir);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "eenf {args:?}: {err}");
    (String::from_utf8_lossy(&out.stdout).into_owned(), err)
}

/// Runs `eenf ARGS`, which must fail in one line without a panic; that line.
pub fn refused(args: &[&str], dir: &Path) -> String {
    let out = eenf(args, dir);
    let err = String::from_utf8_lossy(&out.stderr).trim().to_string();
    assert!(!out.status.success(), "eenf {args:?} succeeded: {err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// A mains frequency that is a known function of the UTC time: what the archives and the
/// operators' answers the tests write hold.
pub fn truth_hz(unix_s: f64) -> f64 {
    50.0 + 0.03 * (unix_s / 700.0).sin() + 0.01 * (unix_s / 97.0).cos()
}

/// Runs `eenf ARGS`, which must fail without a panic; its stderr.
pub fn fails(args: &[&str], dir: &Path) -> String {
    let out = eenf(args, dir);
    assert!(!out.status.success(), "{args:?} should fail");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    err
}

/// Parses JSON output.
pub fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text).unwrap()
}

/// Simulates `seconds` of a small (24x18) flickering scene into `dir/name`, with `extra` flags.
pub fn simulate(dir: &Path, name: &str, seconds: &str, extra: &[&str]) -> std::path::PathBuf {
    let mut args = vec![
        "-q",
        "simulate",
        "--duration",
        seconds,
        "--resolution",
        "24x18",
        "-o",
        name,
    ];
    args.extend_from_slice(extra);
    ok(&args, dir);
    dir.join(name)
}
