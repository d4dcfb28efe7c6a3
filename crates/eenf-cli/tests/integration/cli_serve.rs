//! `eenf serve` as a user starts and stops it: the URL first, SIGTERM ends it with nothing
//! left behind, a missing store or a taken port is one line.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Command, Stdio};

use crate::cli::fails;

#[test]
fn serve_prints_its_url_first_and_stops_cleanly_on_sigterm() {
    let dir = tempfile::tempdir().unwrap();
    let uploads = dir.path().join("tmp");
    std::fs::create_dir(&uploads).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_eenf"))
        .args(["serve", "--port", "0"])
        .env("TMPDIR", &uploads)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let url = line.trim();
    assert!(
        url.starts_with("http://127.0.0.1:") && url.contains("/?token="),
        "{url}"
    );
    // the page answers with its token, and only with it
    let rest = url.strip_prefix("http://").unwrap();
    let (host, path) = rest.split_at(rest.find('/').unwrap());
    for (p, want) in [(path, "200"), ("/", "401")] {
        let mut s = std::net::TcpStream::connect(host).unwrap();
        write!(
            s,
            "GET {p} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n"
        )
        .unwrap();
        let mut got = String::new();
        s.read_to_string(&mut got).unwrap();
        assert!(got.starts_with(&format!("HTTP/1.1 {want}")), "{p}: {got}");
    }
    assert_eq!(
        std::fs::read_dir(&uploads).unwrap().count(),
        1,
        "its upload folder"
    );
    let killed = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let status = child.wait().unwrap();
    assert!(status.success(), "{status:?}");
    assert_eq!(
        std::fs::read_dir(&uploads).unwrap().count(),
        0,
        "the upload folder is removed"
    );
}

#[test]
fn serve_refuses_a_missing_store_and_a_taken_port_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let err = fails(
        &["serve", "--port", "0", "--store", "no-such-store"],
        dir.path(),
    );
    assert!(
        err.contains("no-such-store") && err.lines().count() == 1,
        "{err}"
    );
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let err = fails(&["serve", "--port", &port], dir.path());
    assert!(err.contains(&port) && err.lines().count() == 1, "{err}");
}
