//! Bad input never panics: each case exits non-zero with one line naming the file and cause.

use std::path::{Path, PathBuf};
use std::process::Command;

use eenf_events::{Aedat4Writer, Compression};

use crate::cli;

fn eenf(args: &[&str], dir: &Path) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_eenf"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Runs a command that must fail, and checks the one-line message.
fn fails(args: &[&str], dir: &Path, file: &str, cause: &str) {
    let (ok, _, err) = eenf(args, dir);
    assert!(!ok, "{args:?} succeeded");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{args:?}: expected one line, got {err:?}");
    assert!(lines[0].starts_with("eenf: error: "), "{err}");
    assert!(
        lines[0].contains(file),
        "{args:?}: {err} does not name {file}"
    );
    assert!(
        lines[0].to_lowercase().contains(&cause.to_lowercase()),
        "{args:?}: {err} does not say {cause:?}"
    );
}

fn simulate(dir: &Path, name: &str, seconds: &str) -> PathBuf {
    cli::simulate(dir, name, seconds, &[])
}

#[test]
fn bad_inputs_give_one_line_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();

    fails(
        &["extract", "nope.aedat4"],
        d,
        "nope.aedat4",
        "no such file",
    );
    fails(&["info", "nope.aedat4"], d, "nope.aedat4", "no such file");
    // the OS's words once, without its error number
    for cmd in ["video", "audio", "compare", "info"] {
        let args: Vec<&str> = match cmd {
            "compare" => vec![cmd, "nope.csv", "nope.csv"],
            _ => vec![cmd, "nope.csv"],
        };
        let (_, _, err) = eenf(&args, d);
        assert_eq!(err.matches("No such file").count(), 1, "{err}");
        assert!(!err.contains("os error"), "{err}");
    }
    std::fs::create_dir(d.join("folder")).unwrap();
    fails(&["audio", "folder"], d, "folder", "is a folder");

    std::fs::write(d.join("notes.txt"), "hello world\nthis is not events\n").unwrap();
    fails(
        &["extract", "notes.txt"],
        d,
        "notes.txt",
        "not a supported event file",
    );

    let good = simulate(d, "good.aedat4", "20");
    let bytes = std::fs::read(&good).unwrap();
    // truncated in the middle of the second packet
    let hlen = u32::from_le_bytes(bytes[14..18].try_into().unwrap()) as usize;
    let p0 = 18 + hlen;
    let p1 = p0 + 8 + i32::from_le_bytes(bytes[p0 + 4..p0 + 8].try_into().unwrap()) as usize;
    std::fs::write(d.join("cut.aedat4"), &bytes[..p1 + 100]).unwrap();
    fails(&["extract", "cut.aedat4"], d, "cut.aedat4", "truncated");
    // a corrupt compressed packet
    let mut bad = bytes.clone();
    for b in &mut bad[p1 + 30..p1 + 90] {
        *b ^= 0xa5;
    }
    std::fs::write(d.join("corrupt.aedat4"), &bad).unwrap();
    fails(
        &["extract", "corrupt.aedat4"],
        d,
        "corrupt.aedat4",
        "corrupt",
    );

    // an event stream with no events
    Aedat4Writer::create(&d.join("empty.aedat4"), Compression::Lz4, 64, 48)
        .unwrap()
        .finish()
        .unwrap();
    fails(&["extract", "empty.aedat4"], d, "empty.aedat4", "empty");

    // shorter than the shortest window (2 s; longer recordings get a window that fits)
    simulate(d, "short.aedat4", "1.5");
    fails(
        &["extract", "short.aedat4"],
        d,
        "short.aedat4",
        "shorter than one",
    );

    // WAVs: noise without a mains tone, and a rate too low to carry one
    let mut state = 0x9e3779b97f4a7c15u64;
    let noise: Vec<f64> = (0..400 * 30)
        .map(|_| {
            // xorshift64*: white noise with no spectral lines
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            (state.wrapping_mul(0x2545f4914f6cdd1d) >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect();
    eenf::wav::write_wav(&d.join("noise.wav"), 400, &noise).unwrap();
    fails(&["reference", "noise.wav"], d, "noise.wav", "no mains line");
    fails(
        &["reference", "--nominal", "50", "noise.wav"],
        d,
        "noise.wav",
        "no mains line at any harmonic of 50 Hz",
    );
    eenf::wav::write_wav(&d.join("slow.wav"), 80, &noise[..2400]).unwrap();
    fails(&["reference", "slow.wav"], d, "slow.wav", "too low");
    std::fs::write(d.join("fake.wav"), b"RIFF\x10\x00\x00\x00WAVEjunk").unwrap();
    fails(&["reference", "fake.wav"], d, "fake.wav", "wav");

    // traces
    std::fs::write(d.join("bad.csv"), "x,y\n1,2\n").unwrap();
    fails(
        &["compare", "bad.csv", "bad.csv"],
        d,
        "bad.csv",
        "not a trace file",
    );
    std::fs::write(d.join("a.csv"), "time_s,enf_hz\n0,50\n1,50.01\n").unwrap();
    fails(
        &["compare", "a.csv", "a.csv", "--offset-s", "100"],
        d,
        "a.csv",
        "fewer than two",
    );
    fails(
        &["compare", "a.csv", "."],
        d,
        "a.csv",
        "cannot tell when the recording started",
    );
}

#[test]
fn outputs_are_all_or_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    simulate(d, "short.aedat4", "1.5");
    let (ok, _, _) = eenf(&["extract", "short.aedat4", "-o", "trace.csv"], d);
    assert!(!ok);
    // no partial or temporary file left behind
    let names: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        !names
            .iter()
            .any(|n| n.contains("trace") || n.contains(".tmp")),
        "{names:?}"
    );
}

#[cfg(unix)]
#[test]
fn writing_to_a_fifo_writes_into_it_instead_of_replacing_it() {
    // a FIFO stands in for devices like /dev/null: it must be written into, not renamed over
    use std::os::unix::fs::FileTypeExt;
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    simulate(d, "s.aedat4", "20");
    let fifo = d.join("out.fifo");
    let made = Command::new("mkfifo").arg(&fifo).status();
    if !made.map(|s| s.success()).unwrap_or(false) {
        panic!("mkfifo is needed for this test");
    }
    for (args, starts) in [
        (
            vec!["-q", "convert", "s.aedat4", "out.fifo", "--format", "evt3"],
            &b"% evt 3.0"[..],
        ),
        (
            vec![
                "-q", "convert", "s.aedat4", "out.fifo", "--format", "aedat4",
            ],
            &b"#!AER-DAT4.0"[..],
        ),
        (
            vec!["-q", "extract", "s.aedat4", "-o", "out.fifo"],
            &b"time_s,enf_hz"[..],
        ),
    ] {
        let path = fifo.clone();
        let reader = std::thread::spawn(move || std::fs::read(path).unwrap());
        let (ok, _, err) = eenf(&args, d);
        assert!(ok, "{args:?}: {err}");
        let bytes = reader.join().unwrap();
        assert!(bytes.starts_with(starts), "{args:?}");
        assert!(
            std::fs::metadata(&fifo).unwrap().file_type().is_fifo(),
            "{args:?} replaced the FIFO"
        );
    }
}

#[test]
fn a_recording_shorter_than_the_window_is_traced_with_one_that_fits() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    simulate(d, "three.aedat4", "3");
    let (ok, out, err) = eenf(&["extract", "three.aedat4"], d);
    assert!(ok, "{err}");
    assert!(
        err.contains("shorter than the 16 s window: traced with a 3 s window"),
        "{err}"
    );
    assert!(err.contains("frequency resolution 0.333 Hz"), "{err}");
    let rows: Vec<&str> = out.lines().skip(1).collect();
    assert!(!rows.is_empty());
    let f: f64 = rows[0].split(',').nth(1).unwrap().parse().unwrap();
    assert!((f - 50.0).abs() < 0.1, "{f}");
}

/// A camera whose clock runs 0.26 % slow (an eDVS seen at 119.69 Hz on a 60 Hz grid): its
/// events, stamped one by one, are recognised as a 60 Hz grid's flicker, with a note, and the
/// trace is reported as measured.
#[test]
fn a_camera_clock_that_runs_off_is_recognised_and_reported_as_measured() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let mut text = String::from("# t x y p\n");
    let (mut t, mut s) = (0.0f64, 0x9e37_79b9_7f4a_7c15u64);
    let mut uniform = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    while t < 20.0 {
        // 8 k events/s at random; ON more likely while the light rises
        t += -uniform().ln() / 8000.0;
        let rising = (2.0 * std::f64::consts::PI * 119.69 * t).cos() > 0.0;
        let on = uniform() < if rising { 0.65 } else { 0.35 };
        let x = (uniform() * 128.0) as u32;
        let y = (uniform() * 128.0) as u32;
        text.push_str(&format!("{} {x} {y} {}\n", (t * 1e6) as i64, on as u8));
    }
    std::fs::write(d.join("edvs.txt"), text).unwrap();
    let (ok, out, err) = eenf(&["extract", "edvs.txt"], d);
    assert!(ok, "{err}");
    assert!(err.contains("60 Hz grid"), "{err}");
    assert!(err.contains("block sampling"), "{err}");
    assert!(err.contains("0.26 % below 120 Hz"), "{err}");
    let v: Vec<f64> = out
        .lines()
        .skip(1)
        .filter_map(|l| l.split(',').nth(1)?.parse().ok())
        .collect();
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    assert!((mean - 119.69 / 2.0).abs() < 0.002, "{mean}");
}

/// A DVS128 whose clock runs 0.26 % fast and whose lamp light reaches every pixel a little (as
/// in a real recording that `extract` once refused): the flicker map keeps the one tile that
/// flickers most, but its events alone do not carry a line that stands, while the whole
/// sensor's do. Every pixel is traced, with a note, and the clock is named.
#[test]
fn a_line_the_flicker_tiles_lose_is_traced_from_every_pixel() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let s = std::cell::Cell::new(0x2545_f491_4f6c_dd1du64);
    let uniform = || {
        let mut v = s.get();
        v ^= v << 13;
        v ^= v >> 7;
        v ^= v << 17;
        s.set(v);
        ((v >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let mut events: Vec<(u32, u32, u32, bool)> = Vec::new();
    // the whole sensor at 8 k events/s, a 4x4 patch at 1.5 k events/s more; ON more likely
    // while the light rises, by 2.5 and 1.5 points
    for (rate, depth, side) in [(8000.0, 0.025, 128.0), (1500.0, 0.015, 4.0)] {
        let mut t = 0.0f64;
        loop {
            t += -uniform().ln() / rate;
            if t >= 23.5 {
                break;
            }
            let rising = (2.0 * std::f64::consts::PI * 119.69 * t).cos();
            let on = uniform() < 0.5 + depth * rising;
            let x = (uniform() * side) as u32;
            let y = (uniform() * side) as u32;
            events.push(((t * 1e6) as u32, x, y, on));
        }
    }
    events.sort_by_key(|e| e.0);
    // jAER AEDAT 2.0: big-endian address (bit 0 polarity, 1-7 x, 8-14 y) and timestamp
    let mut bytes = b"#!AER-DAT2.0\r\n# AEChip: ch.unizh.ini.jaer.chip.retina.DVS128\r\n".to_vec();
    for (t, x, y, on) in events {
        bytes.extend_from_slice(&((y << 8) | (x << 1) | on as u32).to_be_bytes());
        bytes.extend_from_slice(&t.to_be_bytes());
    }
    std::fs::write(d.join("dvs128.aedat"), bytes).unwrap();
    let (ok, _, err) = eenf(&["extract", "dvs128.aedat", "-o", "t.csv"], d);
    assert!(ok, "{err}");
    assert!(
        err.contains("the flicker tiles' line does not stand")
            && err.contains("every pixel traced"),
        "{err}"
    );
    assert!(
        err.contains("60 Hz grid") && err.contains("0.26 % below 120 Hz"),
        "{err}"
    );
    // `info` reports the line `extract` traced: every pixel's
    let strength = err
        .split("(flicker ")
        .nth(1)
        .and_then(|r| r.split_once(" Hz, "))
        .and_then(|(_, r)| r.split("needed)").next())
        .unwrap();
    let (ok, out, info_err) = eenf(&["info", "dvs128.aedat"], d);
    assert!(ok, "{info_err}");
    assert!(out.contains(strength), "{strength} / {out}");
}

#[test]
fn a_recording_without_flicker_names_the_strongest_line_and_its_height() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    // daylight only: nothing flickers, the walker still makes events
    let (ok, _, err) = eenf(
        &[
            "-q",
            "simulate",
            "--scene",
            "dynamic-object",
            "--ambient",
            "0.9999",
            "--duration",
            "20",
            "--resolution",
            "24x18",
            "-o",
            "dark.aedat4",
        ],
        d,
    );
    assert!(ok, "{err}");
    let (ok, _, err) = eenf(&["extract", "dark.aedat4"], d);
    assert!(!ok);
    assert!(err.contains("dark.aedat4"), "{err}");
    assert!(
        err.contains("no mains flicker: the strongest line near 100 or 120 Hz"),
        "{err}"
    );
    // a walker's events hold lines well over their local floor, but none prominent
    assert!(err.contains("does not stand"), "{err}");
    assert!(err.contains("dB and 6 needed)"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
}

/// A reader that goes away (`| head -1`) ends eenf quietly; a full stdout (`> /dev/full`) is
/// a one-line error, never a panic.
#[test]
fn a_closed_pipe_is_quiet_and_a_full_stdout_one_line() {
    use std::io::{BufRead, BufReader};
    use std::process::{Command, Stdio};
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let rec = simulate(d, "pipe.aedat4", "20");
    // an hour of mains: 3601 lines, more than a pipe holds, so the write meets the closed end
    let (ok, _, err) = eenf(
        &[
            "-q",
            "simulate",
            "--duration",
            "20",
            "--resolution",
            "8x6",
            "-o",
            "r.aedat4",
            "--reference-dir",
            "refs",
        ],
        d,
    );
    assert!(ok, "{err}");
    let hour = std::fs::read_dir(d.join("refs"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    for args in [
        vec!["-q", "reference", hour.to_str().unwrap()],
        vec!["-q", "extract", rec.to_str().unwrap()],
        vec!["-q", "extract", rec.to_str().unwrap(), "--json"],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_eenf"))
            .args(&args)
            .current_dir(d)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut first = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut first)
            .unwrap();
        assert!(!first.is_empty(), "{args:?}");
        // the reader is gone: the rest of the output meets a closed pipe
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{args:?}: {err}");
        assert!(
            !err.contains("Broken pipe") && !err.contains("panicked"),
            "{err}"
        );
    }
    if let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") {
        let out = Command::new(env!("CARGO_BIN_EXE_eenf"))
            .args(["-q", "info", rec.to_str().unwrap()])
            .stdout(full)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains("No space left"), "{err}");
    }
}

/// Absurd numbers on the command line are one-line errors naming the flag and its range,
/// before anything is sized by them.
#[test]
fn absurd_flags_are_one_line_errors_with_the_range() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("t.csv"), "time_s,enf_hz\n0,50\n1,50.01\n").unwrap();
    for (args, flag) in [
        (
            vec!["match", "t.csv", "t.csv", "--top", "18446744073709551615"],
            "--top",
        ),
        (
            vec!["match", "t.csv", "t.csv", "--top", "1000000000"],
            "--top",
        ),
        (
            vec!["extract", "x.aedat4", "--median-len", "1000000000"],
            "--median-len",
        ),
        (vec!["extract", "x.aedat4", "--window", "nan"], "--window"),
        // a negative number is the flag's value, refused by its range, not taken for a flag
        (vec!["extract", "x.aedat4", "--window", "-3"], "--window"),
        (vec!["reference", "x.wav", "--step", "1e-300"], "--step"),
        (vec!["simulate", "--duration", "1e12"], "--duration"),
        (vec!["match", "t.csv", "t.csv", "--alpha", "7"], "--alpha"),
    ] {
        let (ok, _, err) = eenf(&args, d);
        assert!(!ok, "{args:?} succeeded");
        let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
        assert_eq!(lines.len(), 1, "{args:?}: {err}");
        assert!(
            lines[0].contains(flag) && lines[0].contains("outside"),
            "{err}"
        );
    }
}

/// Trace files that no ENF trace can be: steps of a nanosecond, values of 1e308, a binary
/// file, one endless line.
#[test]
fn impossible_traces_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let rows = |f: &dyn Fn(usize) -> String| -> String {
        let mut s = String::from("time_s,enf_hz\n");
        for i in 0..200 {
            s += &f(i);
        }
        s
    };
    let clip = rows(&|i| format!("{i},{}\n", 50.0 + 0.01 * ((i as f64) * 0.1).sin()));
    std::fs::write(d.join("clip.csv"), &clip).unwrap();
    std::fs::write(d.join("ns.csv"), rows(&|i| format!("{}e-9,50.0\n", i))).unwrap();
    std::fs::write(
        d.join("huge.csv"),
        rows(&|i| format!("{i},{}1e308\n", if i % 2 == 0 { "-" } else { "" })),
    )
    .unwrap();
    std::fs::write(
        d.join("back.csv"),
        rows(&|i| format!("{},50.0\n", (i % 7) as f64)),
    )
    .unwrap();
    std::fs::write(d.join("bin.csv"), [0u8, 159, 146, 150, 0, 1, 2]).unwrap();
    std::fs::write(d.join("long.csv"), vec![b'7'; 3 << 20]).unwrap();
    fails(&["match", "clip.csv", "ns.csv"], d, "ns.csv", "s apart");
    fails(
        &["match", "clip.csv", "huge.csv"],
        d,
        "huge.csv",
        "beyond any frequency",
    );
    fails(
        &["match", "clip.csv", "back.csv"],
        d,
        "back.csv",
        "times must rise",
    );
    fails(
        &["match", "clip.csv", "bin.csv"],
        d,
        "bin.csv",
        "not a trace file",
    );
    fails(
        &["match", "clip.csv", "long.csv"],
        d,
        "long.csv",
        "longer than",
    );
    fails(&["compare", "ns.csv", "clip.csv"], d, "ns.csv", "s apart");
}

/// A WAV whose header says 0 Hz (Symphonia panicked on it) is a one-line error.
#[test]
fn a_wav_at_zero_hertz_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let data = vec![0u8; 2000];
    let mut wav = Vec::new();
    wav.extend_from_slice(b"RIFF");
    wav.extend_from_slice(&(36 + data.len() as u32).to_le_bytes());
    wav.extend_from_slice(b"WAVEfmt ");
    wav.extend_from_slice(&16u32.to_le_bytes());
    wav.extend_from_slice(&1u16.to_le_bytes()); // PCM
    wav.extend_from_slice(&1u16.to_le_bytes()); // mono
    wav.extend_from_slice(&0u32.to_le_bytes()); // 0 Hz
    wav.extend_from_slice(&0u32.to_le_bytes());
    wav.extend_from_slice(&2u16.to_le_bytes());
    wav.extend_from_slice(&16u16.to_le_bytes());
    wav.extend_from_slice(b"data");
    wav.extend_from_slice(&(data.len() as u32).to_le_bytes());
    wav.extend_from_slice(&data);
    std::fs::write(d.join("zero.wav"), &wav).unwrap();
    fails(&["-q", "audio", "zero.wav"], d, "zero.wav", "0");
}
