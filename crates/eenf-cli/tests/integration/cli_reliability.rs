//! Outputs are never clobbered or left half-written, damaged inputs are salvaged, pipes work:
//! the cases of the reliability issue, each run as a user runs them. Links and files are made
//! inside a temporary folder only (never a real `/dev` path).

use crate::cli;

use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use cli::{eenf, fails, ok, simulate};

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn a_symlink_target_keeps_the_link_and_replaces_its_file() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    simulate(d, "s.aedat4", "20", &[]);
    std::fs::write(d.join("real.csv"), "old").unwrap();
    std::os::unix::fs::symlink("real.csv", d.join("link.csv")).unwrap();
    ok(&["-q", "extract", "s.aedat4", "-o", "link.csv"], d);
    let meta = std::fs::symlink_metadata(d.join("link.csv")).unwrap();
    assert!(meta.file_type().is_symlink(), "the link was replaced");
    let text = std::fs::read_to_string(d.join("real.csv")).unwrap();
    assert!(text.starts_with("time_s,enf_hz"), "{text}");

    // a link to this process's stdout (in the temporary folder): the output reaches stdout's
    // file, and the link stays a link
    std::os::unix::fs::symlink("/proc/self/fd/1", d.join("out")).unwrap();
    let o_txt = std::fs::File::create(d.join("o.txt")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_eenf"))
        .args(["-q", "convert", "s.aedat4", "out", "--format", "text"])
        .current_dir(d)
        .stdout(o_txt)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let meta = std::fs::symlink_metadata(d.join("out")).unwrap();
    assert!(meta.file_type().is_symlink(), "the link was replaced");
    let text = std::fs::read_to_string(d.join("o.txt")).unwrap();
    assert!(
        text.lines().count() > 1000,
        "{} lines",
        text.lines().count()
    );
    // and through a pipe: the link names the pipe, which is written into
    let out = Command::new(env!("CARGO_BIN_EXE_eenf"))
        .args(["-q", "convert", "s.aedat4", "out", "--format", "text"])
        .current_dir(d)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(String::from_utf8_lossy(&out.stdout), text);
}

#[test]
fn a_folder_as_output_is_refused_and_missing_parents_are_made() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    simulate(d, "s.aedat4", "20", &[]);
    std::fs::create_dir(d.join("folder")).unwrap();
    let before = names(d);
    for args in [
        vec!["extract", "s.aedat4", "-o", "folder"],
        vec!["convert", "s.aedat4", "folder", "--format", "evt3"],
    ] {
        let err = fails(&args, d);
        assert!(err.contains("folder: is a folder, not a file"), "{err}");
        assert_eq!(names(d), before, "{args:?} left something");
        assert!(names(&d.join("folder")).is_empty(), "{args:?}");
    }
    ok(&["-q", "extract", "s.aedat4", "-o", "new/sub/t.csv"], d);
    ok(&["-q", "convert", "s.aedat4", "new2/x.raw"], d);
    assert!(d.join("new/sub/t.csv").is_file() && d.join("new2/x.raw").is_file());
}

/// Waits until a temporary file of `target` exists in `dir` and is being written.
fn wait_for_temp(dir: &Path, target: &str, child: &mut std::process::Child) {
    let prefix = format!(".{target}.");
    let start = Instant::now();
    loop {
        let busy = names(dir).iter().any(|n| {
            n.starts_with(&prefix) && std::fs::metadata(dir.join(n)).is_ok_and(|m| m.len() > 0)
        });
        if busy {
            return;
        }
        assert!(
            child.try_wait().unwrap().is_none(),
            "finished before it was interrupted"
        );
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no temporary file"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn kill(child: &std::process::Child, signal: &str) {
    let status = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
}

#[test]
fn an_interrupted_write_leaves_the_target_as_it_was_and_no_temporary_file() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    for (signal, code) in [("-TERM", 143), ("-INT", 130)] {
        std::fs::write(d.join("big.aedat4"), "old").unwrap();
        let mut child = Command::new(env!("CARGO_BIN_EXE_eenf"))
            .args([
                "-q",
                "simulate",
                "--duration",
                "3000",
                "--resolution",
                "64x48",
                "-o",
                "big.aedat4",
            ])
            .current_dir(d)
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        wait_for_temp(d, "big.aedat4", &mut child);
        kill(&child, signal);
        let out = child.wait_with_output().unwrap();
        assert_eq!(out.status.code(), Some(code), "{signal}: {}", stderr(&out));
        assert_eq!(
            std::fs::read_to_string(d.join("big.aedat4")).unwrap(),
            "old"
        );
        assert_eq!(names(d), vec!["big.aedat4"], "{signal}");
    }
}

#[test]
fn a_killed_dataset_build_is_removed_or_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let build = |out: &str| {
        Command::new(env!("CARGO_BIN_EXE_eenf"))
            .args([
                "-q",
                "simulate-dataset",
                out,
                "--preset",
                "small",
                "--duration",
                "60",
                "--resolution",
                "64x48",
            ])
            .current_dir(d)
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let wait_for_recordings = |out: &str, child: &mut std::process::Child| {
        let start = Instant::now();
        while !d.join(out).join("static").is_dir() {
            assert!(child.try_wait().unwrap().is_none(), "finished too soon");
            assert!(start.elapsed() < Duration::from_secs(120));
            std::thread::sleep(Duration::from_millis(20));
        }
    };
    // a folder it made: removed on SIGTERM
    let mut child = build("ds");
    wait_for_recordings("ds", &mut child);
    kill(&child, "-TERM");
    assert_eq!(child.wait().unwrap().code(), Some(143));
    assert!(!d.join("ds").exists(), "half-built folder left");
    // SIGKILL cannot be caught: the folder keeps its marker and bench refuses it
    let mut child = build("ds");
    wait_for_recordings("ds", &mut child);
    kill(&child, "-KILL");
    child.wait().unwrap();
    for target in ["ds", "ds/manifest.csv"] {
        let err = fails(&["bench", target], d);
        assert!(err.contains("did not finish building"), "{err}");
    }
}

/// Runs `eenf ARGS` in `dir` with `input` piped into its stdin.
fn with_stdin(args: &[&str], dir: &Path, input: Vec<u8>) -> std::process::Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_eenf"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let feeder = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let out = child.wait_with_output().unwrap();
    feeder.join().unwrap();
    out
}

#[test]
fn stdin_is_read_for_every_format() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    simulate(d, "s.aedat4", "20", &[]);
    ok(
        &["-q", "convert", "s.aedat4", "s.raw", "--format", "evt3"],
        d,
    );
    ok(
        &["-q", "convert", "s.aedat4", "s.txt", "--format", "text"],
        d,
    );
    for name in ["s.aedat4", "s.raw", "s.txt"] {
        let from_file = ok(&["info", name], d);
        let out = with_stdin(&["info", "-"], d, std::fs::read(d.join(name)).unwrap());
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        let from_pipe = String::from_utf8_lossy(&out.stdout);
        // the same but for the name
        let body = |s: &str| s.lines().skip(1).collect::<Vec<_>>().join("\n");
        assert_eq!(body(&from_pipe), body(&from_file), "{name}");
        // a command that reads the recording several times (map, then trace) works too
        let traced = ok(&["-q", "extract", name], d);
        let out = with_stdin(
            &["-q", "extract", "-"],
            d,
            std::fs::read(d.join(name)).unwrap(),
        );
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        assert_eq!(String::from_utf8_lossy(&out.stdout), traced, "{name}");
    }
    // `-` as the output is stdout, for event files and traces
    let out = eenf(&["-q", "convert", "s.aedat4", "-", "--format", "evt3"], d);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(out.stdout, std::fs::read(d.join("s.raw")).unwrap());
    assert!(!d.join("-").exists());
    let traced = ok(&["-q", "extract", "s.aedat4", "-o", "-"], d);
    assert!(traced.starts_with("time_s,enf_hz"), "{traced}");
}

/// A WAV whose header claims 4 GB of samples, and a streamed one (length 0xFFFFFFFF).
fn wav_claiming(path: &Path, riff: u32, data: u32) {
    let fs = 400u32;
    let mut bytes = Vec::new();
    bytes.extend_from_slice(b"RIFF");
    bytes.extend_from_slice(&riff.to_le_bytes());
    bytes.extend_from_slice(b"WAVEfmt ");
    for v in [16u32, 1 | 1 << 16, fs, fs * 2, 2 | 16 << 16] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes.extend_from_slice(b"data");
    bytes.extend_from_slice(&data.to_le_bytes());
    for i in 0..fs * 60 {
        let t = i as f64 / fs as f64;
        // a tone at 50 + 0.02 sin(t / 10) Hz
        let v = (2.0 * std::f64::consts::PI * (50.0 * t - 0.2 * (t / 10.0).cos())).sin();
        bytes.extend_from_slice(&((v * 16000.0) as i16).to_le_bytes());
    }
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn a_wav_claiming_4_gb_is_read_to_its_real_end_in_bounded_memory() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    wav_claiming(&d.join("lying.wav"), 0xFFFF_FFF0, 0xFFFF_FFF0 - 36);
    wav_claiming(&d.join("streamed.wav"), 0xFFFF_FFFF, 0xFFFF_FFFF);
    for name in ["lying.wav", "streamed.wav"] {
        // 2 GB of address space: an allocation sized by the header would abort
        let out = Command::new("sh")
            .args([
                "-c",
                &format!(
                    "ulimit -v 2000000 && exec {} -q reference {name}",
                    env!("CARGO_BIN_EXE_eenf")
                ),
            ])
            .current_dir(d)
            .output()
            .unwrap();
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        let rows = String::from_utf8_lossy(&out.stdout).lines().count() - 1;
        // 60 s at one estimate a second: the samples there are, not what the header claims
        assert!((55..=62).contains(&rows), "{name}: {rows} estimates");
    }
}

#[test]
fn a_48_hour_timestamp_jump_ends_the_stream_with_a_warning() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    simulate(d, "s.aedat4", "20", &[]);
    ok(
        &["-q", "convert", "s.aedat4", "s.txt", "--format", "text"],
        d,
    );
    let good = std::fs::read_to_string(d.join("s.txt")).unwrap();
    let last: i64 = good
        .lines()
        .last()
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let mut text = good.clone();
    text += &format!("{} 3 4 1\n", last + 48 * 3600 * 1_000_000);
    text += &format!("{} 3 4 0\n", last + 10);
    std::fs::write(d.join("jump.txt"), text).unwrap();
    let started = Instant::now();
    let out = Command::new("sh")
        .args([
            "-c",
            &format!(
                "ulimit -v 2000000 && exec {} -q extract jump.txt",
                env!("CARGO_BIN_EXE_eenf")
            ),
        ])
        .current_dir(d)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(started.elapsed() < Duration::from_secs(20));
    let err = stderr(&out);
    assert!(
        err.contains("warning: ") && err.contains("timestamp jumps"),
        "{err}"
    );
    // the trace is the 20 s before the jump, the same as the intact file's
    let traced = String::from_utf8_lossy(&out.stdout).into_owned();
    assert_eq!(traced, ok(&["-q", "extract", "s.txt"], d));
    let err = fails(&["extract", "jump.txt", "--strict"], d);
    assert!(err.contains("timestamp jumps"), "{err}");
    // a wider limit reads on to the end
    let info = ok(&["info", "jump.txt", "--max-gap", "200000"], d);
    let rows = good
        .lines()
        .filter(|l| l.starts_with(|c: char| c.is_ascii_digit()));
    let events = format!("events      {} ", rows.count() + 2);
    assert!(info.contains(&events), "{info}");
    assert!(!info.contains("damage"), "{info}");
}

#[test]
fn a_truncated_recording_yields_the_events_before_the_cut() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    simulate(d, "s.aedat4", "20", &[]);
    let bytes = std::fs::read(d.join("s.aedat4")).unwrap();
    let cut_at = bytes.len() * 3 / 5;
    std::fs::write(d.join("cut.aedat4"), &bytes[..cut_at]).unwrap();
    ok(&["-q", "convert", "s.aedat4", "full.txt"], d);
    let out = eenf(&["-q", "convert", "cut.aedat4", "cut.txt"], d);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("warning: cut.aedat4: truncated AEDAT 4.0 file at byte"),
        "{err}"
    );
    let full = std::fs::read_to_string(d.join("full.txt")).unwrap();
    let cut = std::fs::read_to_string(d.join("cut.txt")).unwrap();
    let (full, cut): (Vec<&str>, Vec<&str>) = (full.lines().collect(), cut.lines().collect());
    assert!(
        cut.len() > full.len() / 2,
        "{} of {}",
        cut.len(),
        full.len()
    );
    assert!(cut.len() < full.len());
    assert_eq!(cut[..], full[..cut.len()], "not a prefix");
    let info = ok(&["info", "cut.aedat4"], d);
    assert!(info.contains("truncated at byte"), "{info}");
    let err = fails(&["convert", "cut.aedat4", "x.txt", "--strict"], d);
    assert!(err.contains("truncated"), "{err}");
    assert!(!d.join("x.txt").exists());
}

#[test]
fn compare_places_a_recording_in_one_hourly_wav_and_reads_index_csvs() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    simulate(
        d,
        "dvSave-2022_08_17_16_10_00.aedat4",
        "40",
        &[
            "--start",
            "2022-08-17T16:10:00+08:00",
            "--reference-dir",
            "refs",
        ],
    );
    ok(
        &[
            "-q",
            "extract",
            "dvSave-2022_08_17_16_10_00.aedat4",
            "-o",
            "t.json",
        ],
        d,
    );
    let hour = "refs/2022_08_17_Wed_16_00_00.wav";
    let metric = |out: &str, name: &str| -> f64 {
        out.lines()
            .find_map(|l| l.strip_prefix(name))
            .unwrap()
            .trim()
            .trim_end_matches(" mHz")
            .parse()
            .unwrap()
    };
    let (cc, mae) = (|o: &str| metric(o, "CC"), |o: &str| metric(o, "MAE"));
    // placed at 10 min into the hour by the recording's name: as with the folder (40 s of a
    // traced reference agree to a millihertz; the CC of so short a stretch is not telling)
    let one = ok(&["compare", "t.json", hour], d);
    let folder = ok(&["compare", "t.json", "refs"], d);
    assert!(mae(&one) < 2.0, "{one}");
    assert_eq!(
        one.lines().skip(1).collect::<Vec<_>>()[1..],
        folder.lines().skip(1).collect::<Vec<_>>()[1..]
    );
    // an explicit offset is still obeyed (and here wrong)
    let off = ok(&["compare", "t.json", hour, "--offset-s", "1200"], d);
    assert!(mae(&off) > 2.0 * mae(&one), "{off}");
    // the truth as an `index,value` CSV with a value every 2 s
    let truth = std::fs::read_to_string(d.join("dvSave-2022_08_17_16_10_00.truth.csv")).unwrap();
    let mut index = String::new();
    for (i, l) in truth.lines().skip(1).step_by(2).enumerate() {
        let v = l.split(',').nth(1).unwrap();
        index += &format!("{i},{v}\n");
    }
    std::fs::write(d.join("idx.csv"), index).unwrap();
    let by_index = ok(&["compare", "t.json", "idx.csv"], d);
    assert!(cc(&by_index) > 0.9, "{by_index}");
}
