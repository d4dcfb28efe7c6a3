//! The commands chained as a user would: simulate → extract → compare, and the alignment of a
//! dataset-named recording with a folder of hourly references, across an hour boundary.

use std::path::Path;
use std::process::Command;

use eenf_events::{Aedat4Writer, Compression};
use eenf_sim::{simulate, MainsPhase, SimConfig, SyntheticEnf};

fn eenf(args: &[&str], dir: &Path) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_eenf"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{args:?}: {stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text).unwrap()
}

#[test]
fn simulate_extract_compare_meets_the_papers_accuracy() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    eenf(
        &[
            "-q",
            "simulate",
            "--duration",
            "45",
            "--resolution",
            "40x30",
            "--seed",
            "3",
            "-o",
            "s.aedat4",
        ],
        d,
    );
    let info = json(&eenf(&["info", "--json", "s.aedat4"], d));
    assert_eq!(info["format"], "AEDAT 4.0");
    assert_eq!(
        (info["width"].as_u64(), info["height"].as_u64()),
        (Some(40), Some(30))
    );
    assert!(info["events"].as_u64().unwrap() > 100_000);
    let x = json(&eenf(
        &[
            "extract",
            "s.aedat4",
            "--json",
            "-o",
            "s.enf.csv",
            "--plot",
            "s.svg",
        ],
        d,
    ));
    assert_eq!(x["nominal_hz"], 50.0);
    // one estimate per second of the sequence (from the first event to the last, ~45 s)
    let span = x["duration_s"].as_f64().unwrap();
    assert!((44.9..=45.0).contains(&span), "{span}");
    assert_eq!(
        x["enf_hz"].as_array().unwrap().len(),
        span.floor() as usize + 1
    );
    assert!(d.join("s.svg").metadata().unwrap().len() > 1000);
    let csv = std::fs::read_to_string(d.join("s.enf.csv")).unwrap();
    let first: Vec<&str> = csv.lines().nth(1).unwrap().split(',').collect();
    // the first two columns stay `time_s,enf_hz`; E-ENF adds each estimate's line strength
    assert_eq!(csv.lines().next(), Some("time_s,enf_hz,snr_db"));
    assert!(first[2].parse::<f64>().unwrap() > 12.0, "{first:?}");
    assert_eq!(first[0], "0");
    assert!(
        (first[1].parse::<f64>().unwrap() - 50.0).abs() < 0.2,
        "{first:?}"
    );
    let c = json(&eenf(
        &[
            "compare",
            "s.enf.csv",
            "s.truth.csv",
            "--json",
            "--plot",
            "c.png",
        ],
        d,
    ));
    let (cc, mae) = (c["cc"].as_f64().unwrap(), c["mae_hz"].as_f64().unwrap());
    assert!(cc >= 0.95 && mae <= 0.002, "CC {cc} MAE {mae}");
    assert_eq!(c["seconds"].as_u64(), Some(span.floor() as u64 + 1));
    assert!(d.join("c.png").metadata().unwrap().len() > 1000);
}

#[test]
fn hourly_references_align_by_name_across_the_hour() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    // two hours of mains at 200 Hz, 16:00 and 17:00, one continuous signal split in two files
    let mains = MainsPhase::synthetic(50.0, 7200.0, SyntheticEnf::default(), 42);
    let fs = 200.0;
    let volts: Vec<f64> = (0..(7200.0 * fs) as usize)
        .map(|i| 0.6 * mains.phase_at(i as f64 / fs).cos())
        .collect();
    let refs = d.join("ENF_Reference");
    std::fs::create_dir(&refs).unwrap();
    let hour = (3600.0 * fs) as usize;
    eenf::wav::write_wav(
        &refs.join("2022_08_17_Wed_16_00_00.wav"),
        200,
        &volts[..hour],
    )
    .unwrap();
    eenf::wav::write_wav(
        &refs.join("2022_08_17_Wed_17_00_00.wav"),
        200,
        &volts[hour..],
    )
    .unwrap();
    // a 60 s recording from 16:59:30, driven by the same mains
    let start = 59.0 * 60.0 + 30.0;
    let phase = MainsPhase::from_recording(&volts, fs, 50.0, start, 60.0).unwrap();
    let config = SimConfig {
        width: 40,
        height: 30,
        duration_s: 60.0,
        seed: 5,
        ..SimConfig::default()
    };
    let rec = d.join("dvSave-2022_08_17_16_59_30.aedat4");
    let mut w = Aedat4Writer::create(&rec, Compression::Zstd, 40, 30).unwrap();
    simulate(&config, &phase, |b| w.write(b)).unwrap();
    w.finish().unwrap();

    eenf(
        &["-q", "extract", rec.to_str().unwrap(), "-o", "trace.json"],
        d,
    );
    let c = json(&eenf(
        &["compare", "trace.json", "ENF_Reference", "--json"],
        d,
    ));
    let (cc, mae) = (c["cc"].as_f64().unwrap(), c["mae_hz"].as_f64().unwrap());
    let est = json(&std::fs::read_to_string(d.join("trace.json")).unwrap());
    let n = est["enf_hz"].as_array().unwrap().len();
    assert!(n >= 60, "{n} estimates");
    assert_eq!(
        c["seconds"], n,
        "all seconds, including those after 17:00, are compared"
    );
    assert!(cc >= 0.95 && mae <= 0.002, "CC {cc} MAE {mae}");
    // a wrong offset is visibly worse: the alignment really comes from the name
    let off = json(&eenf(
        &[
            "compare",
            "trace.json",
            "ENF_Reference",
            "--json",
            "--offset-s",
            "-40",
        ],
        d,
    ));
    assert!(off["mae_hz"].as_f64().unwrap() > 2.0 * mae, "{off}");
}

#[test]
fn refdb_and_match_locate_a_clip() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let mains = MainsPhase::synthetic(50.0, 7200.0, SyntheticEnf::default(), 8);
    let fs = 200.0;
    let volts: Vec<f64> = (0..(7200.0 * fs) as usize)
        .map(|i| 0.6 * mains.phase_at(i as f64 / fs).cos())
        .collect();
    let hour = (3600.0 * fs) as usize;
    eenf::wav::write_wav(&d.join("2022_08_17_Wed_16_00_00.wav"), 200, &volts[..hour]).unwrap();
    eenf::wav::write_wav(&d.join("2022_08_17_Wed_17_00_00.wav"), 200, &volts[hour..]).unwrap();
    eenf(
        &[
            "-q",
            "refdb",
            "build",
            "store",
            "2022_08_17_Wed_16_00_00.wav",
            "2022_08_17_Wed_17_00_00.wav",
            "--tz",
            "+08:00",
        ],
        d,
    );
    let info = eenf(&["refdb", "info", "store"], d);
    assert!(info.contains("from        2022-08-17T08:00:00Z"), "{info}");
    assert!(info.contains("100.0 % covered"), "{info}");
    // the folder of hourly WAVs as one input gives the same store, values and checksum alike
    std::fs::create_dir(d.join("hours")).unwrap();
    for h in ["16", "17"] {
        let name = format!("2022_08_17_Wed_{h}_00_00.wav");
        std::fs::copy(d.join(&name), d.join("hours").join(&name)).unwrap();
    }
    eenf(
        &["-q", "refdb", "build", "again", "hours", "--tz", "+08:00"],
        d,
    );
    assert_eq!(eenf(&["refdb", "info", "again"], d), info);
    // a store is searched by match, not taken by compare or added to another store
    std::fs::write(
        d.join("est.csv"),
        "time_s,enf_hz\n0,50.01\n1,50.02\n2,50.01\n",
    )
    .unwrap();
    for args in [
        &["compare", "est.csv", "store"][..],
        &["refdb", "build", "third", "store"][..],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_eenf"))
            .args(args)
            .current_dir(d)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains("a reference store"),
            "{args:?}: {err}"
        );
    }
    assert!(
        !d.join("third").exists(),
        "a refused build leaves no store behind"
    );
    // a 5-minute clip of the 17:xx reference with a little estimation noise
    eenf(
        &[
            "-q",
            "reference",
            "2022_08_17_Wed_17_00_00.wav",
            "-o",
            "r17.csv",
        ],
        d,
    );
    let text = std::fs::read_to_string(d.join("r17.csv")).unwrap();
    let vals: Vec<f64> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    let at = 1234;
    let mut clip = String::from("time_s,enf_hz\n");
    for (i, v) in vals[at..at + 300].iter().enumerate() {
        clip.push_str(&format!(
            "{i},{}\n",
            v + 0.0002 * ((i * 7919 % 13) as f64 - 6.0) / 6.0
        ));
    }
    std::fs::write(d.join("clip.csv"), clip).unwrap();
    let m = json(&eenf(
        &[
            "match",
            "clip.csv",
            "store",
            "--json",
            "--verify",
            "2022-08-17T17:20:34+08:00",
        ],
        d,
    ));
    let top = &m["candidates"][0];
    // 17:00 + 1234 s local (+08:00) = 2022-08-17T09:20:34Z
    let want = 1_660_728_034.0;
    assert!((top["start_s"].as_f64().unwrap() - want).abs() < 0.5, "{m}");
    assert_eq!(top["match"], true, "{m}");
    assert_eq!(m["verify"]["rank"], 1, "{m}");
    // a wrong claim ranks far down
    let w = json(&eenf(
        &[
            "match",
            "clip.csv",
            "store",
            "--json",
            "--verify",
            "2022-08-17T16:30:00+08:00",
        ],
        d,
    ));
    assert!(w["verify"]["rank"].as_u64().unwrap() > 1, "{w}");
    // the text ends with a verdict, in UTC and in the zone asked for
    let text = eenf(&["match", "clip.csv", "store", "--tz", "Asia/Shanghai"], d);
    let verdict = text.lines().find(|l| l.starts_with("verdict:")).unwrap();
    assert!(
        verdict.contains("recorded at 2022-08-17T09:20:34"),
        "{text}"
    );
    assert!(verdict.contains("17:20:34"), "{text}");
    // 12 values of a grid's wander fit many places: no verdict of a time
    let short: String = std::fs::read_to_string(d.join("clip.csv"))
        .unwrap()
        .lines()
        .take(13)
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(d.join("short.csv"), short).unwrap();
    let text = eenf(&["match", "short.csv", "store"], d);
    assert!(text.contains("verdict: no significant match"), "{text}");
    // 60 Hz traces never match a 50 Hz grid
    let sixty: String = std::iter::once("time_s,enf_hz\n".to_string())
        .chain((0..300).map(|i| format!("{i},{}\n", 60.0 + 0.01 * (i as f64 / 30.0).sin())))
        .collect();
    std::fs::write(d.join("sixty.csv"), sixty).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_eenf"))
        .args(["match", "sixty.csv", "store"])
        .current_dir(d)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no 60 Hz grid"));
}

#[test]
fn the_flicker_map_of_a_lamp_lit_room_flickers_everywhere() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    eenf(
        &[
            "-q",
            "simulate",
            "--duration",
            "8",
            "--resolution",
            "32x24",
            "-o",
            "room.aedat4",
        ],
        d,
    );
    let map = json(&eenf(
        &[
            "-q",
            "flicker-map",
            "room.aedat4",
            "-o",
            "map.svg",
            "--tile",
            "8",
            "--json",
        ],
        d,
    ));
    assert_eq!(
        (map["cols"].as_u64(), map["rows"].as_u64()),
        (Some(4), Some(3))
    );
    let line = &map["whole"];
    assert!((line["hz"].as_f64().unwrap() - 100.0).abs() < 0.2, "{line}");
    // every pixel sees the lamp: every tile's line stands out
    for s in map["strength"].as_array().unwrap() {
        assert!(s.as_f64().unwrap() > 10.0, "{s}");
    }
    assert!(d.join("map.svg").metadata().unwrap().len() > 1000);
    // --json alone prints the map and draws nothing unasked
    let again = json(&eenf(
        &["-q", "flicker-map", "room.aedat4", "--tile", "8", "--json"],
        d,
    ));
    assert_eq!(again["cols"], map["cols"]);
    assert!(!d.join("flicker-map.png").exists());
}

/// A lamp's flicker that stands over two minutes but weakly in each 16 s window (a DVS128 whose
/// lamp pool is 2 % brighter than the room, in its background noise): traced with a 32 s window,
/// as `audio` traces weak hum, with a note, and far closer to the truth than with the 16 s
/// window asked for by `--window`.
#[test]
fn a_weak_flicker_line_gets_a_longer_window() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    eenf(
        &[
            "-q",
            "simulate",
            "--scene",
            "lamp-spot",
            "--readout",
            "dvs128",
            "--resolution",
            "32x24",
            "--spot-gain",
            "1.02",
            "--noise-hz",
            "20",
            "--seed",
            "1",
            "--duration",
            "120",
            "-o",
            "w.aedat4",
        ],
        d,
    );
    let score = |trace: &str| {
        let c = json(&eenf(&["compare", trace, "w.truth.csv", "--json"], d));
        (c["cc"].as_f64().unwrap(), c["mae_hz"].as_f64().unwrap())
    };
    let chosen = json(&eenf(&["extract", "w.aedat4", "--json", "-o", "c.csv"], d));
    let notes = chosen["notes"].to_string();
    assert!(
        notes.contains("is weak") && notes.contains("traced with a 32 s window"),
        "{notes}"
    );
    assert_eq!(chosen["params"]["window_s"], 32.0);
    eenf(
        &["extract", "w.aedat4", "--window", "16", "-o", "16.csv"],
        d,
    );
    let ((cc, mae), (cc16, mae16)) = (score("c.csv"), score("16.csv"));
    println!(
        "32 s: CC {cc:.3}, MAE {:.2} mHz; 16 s: CC {cc16:.3}, MAE {:.2} mHz",
        mae * 1e3,
        mae16 * 1e3
    );
    assert!(cc >= 0.9 && mae <= 0.0025, "CC {cc} MAE {mae}");
    assert!(cc > cc16 + 0.2, "{cc} vs {cc16}");
}
