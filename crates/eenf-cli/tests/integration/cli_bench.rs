//! `eenf bench` as a user runs it: Table 2 on a simulated dataset with videos, numbers that
//! equal `eenf compare` on the same traces, a manifest with a recording across an hour and a
//! corrupt file, sweeps, and clear errors (also for `eenf video`).

use crate::cli;
use cli::{eenf, fails, ok};

/// Rows of a CSV with a header, as maps.
fn csv_maps(text: &str) -> Vec<std::collections::HashMap<String, String>> {
    let mut r = csv::Reader::from_reader(text.as_bytes());
    let headers = r.headers().unwrap().clone();
    r.records()
        .map(|row| {
            let row = row.unwrap();
            headers
                .iter()
                .zip(row.iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

fn num(row: &std::collections::HashMap<String, String>, key: &str) -> f64 {
    row[key].parse().unwrap_or(f64::NAN)
}

#[test]
#[ignore = "long (30 s): run by .ci/run with the real-data checks"]
fn bench_gives_table_2_and_the_numbers_of_compare_on_the_same_traces() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    ok(
        &[
            "-q",
            "simulate-dataset",
            "ds",
            "--preset",
            "small",
            "--duration",
            "30",
            "--resolution",
            "16x12",
            "--seed",
            "8",
            "--video",
            "lr,hr",
            "--video-scale",
            "0.1",
        ],
        d,
    );
    // the manifest lists the videos written beside each recording
    let manifest = std::fs::read_to_string(d.join("ds/manifest.csv")).unwrap();
    let rows = csv_maps(&manifest);
    assert_eq!(rows.len(), 9);
    for r in &rows {
        let videos: Vec<&str> = r["videos"].split(';').collect();
        assert_eq!(videos.len(), 2, "{r:?}");
        for v in videos {
            assert!(d.join("ds").join(v).is_file(), "{v}");
        }
    }
    let table = ok(
        &[
            "-q", "bench", "ds", "--csv", "b.csv", "-o", "b.json", "--report", "r.md", "--traces",
            "tr", "--plots", "pl",
        ],
        d,
    );
    assert!(table.contains("| data, method | static CC | static MAE (mHz) | dynamic CC"));
    let report = std::fs::read_to_string(d.join("r.md")).unwrap();
    for want in [
        "Events, E-ENF (eenf)",
        "Video-LR, V-ENF (eenf)",
        "Video-HR, V-ENF (eenf)",
        "*0.9862*",
        "## Parameters",
    ] {
        assert!(report.contains(want), "report lacks {want}");
    }
    let rows = csv_maps(&std::fs::read_to_string(d.join("b.csv")).unwrap());
    let per_recording: Vec<_> = rows
        .iter()
        .filter(|r| !r["recording"].starts_with("mean:"))
        .collect();
    assert_eq!(per_recording.len(), 27, "9 recordings x 3 methods");
    // E-ENF works on every recording
    for r in per_recording.iter().filter(|r| r["method"] == "e-enf") {
        assert_eq!(r["status"], "ok", "{r:?}");
    }
    // every scored trace: `eenf compare` on the saved trace gives the same numbers
    let mut checked = 0;
    for r in per_recording.iter().filter(|r| r["status"] == "ok") {
        let (class, stem) = r["recording"].split_once('/').unwrap();
        let trace = format!("tr/{class}/{stem}.{}.json", r["method"]);
        let c: serde_json::Value =
            serde_json::from_str(&ok(&["compare", &trace, "ds/ENF_Reference", "--json"], d))
                .unwrap();
        for (key, col) in [
            ("cc", "cc"),
            ("mae_hz", "mae_hz"),
            ("rmse_hz", "rmse_hz"),
            ("max_err_hz", "max_err_hz"),
            ("seconds", "seconds"),
        ] {
            let by_hand = c[key].as_f64().unwrap();
            let bench = num(r, col);
            assert!(
                (by_hand - bench).abs() <= 1e-12 * by_hand.abs().max(1.0),
                "{trace} {key}: compare {by_hand}, bench {bench}"
            );
        }
        checked += 1;
    }
    assert!(checked >= 9, "only {checked} traces compared");
    // the means in CSV, JSON and Markdown are those of the rows
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("b.json")).unwrap()).unwrap();
    for class in ["static", "dynamic", "extreme"] {
        let ccs: Vec<f64> = per_recording
            .iter()
            .filter(|r| r["class"] == class && r["method"] == "e-enf")
            .map(|r| num(r, "cc"))
            .collect();
        let mean = ccs.iter().sum::<f64>() / ccs.len() as f64;
        let mean_row = rows
            .iter()
            .find(|r| r["recording"] == format!("mean:{class}") && r["method"] == "e-enf")
            .unwrap();
        assert!((num(mean_row, "cc") - mean).abs() < 1e-12);
        let summary = json["runs"][0]["summary"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["class"] == class && s["method"] == "e-enf")
            .unwrap();
        assert!((summary["cc"].as_f64().unwrap() - mean).abs() < 1e-12);
        assert!(
            table.contains(&format!("{mean:.4}")),
            "table lacks {mean:.4}"
        );
    }
    // figures: per recording and the summary, PNG and SVG
    for f in ["pl/summary.png", "pl/summary.svg"] {
        assert!(std::fs::metadata(d.join(f)).unwrap().len() > 1000, "{f}");
    }
    let stem = rows[0]["recording"].split_once('/').unwrap().1.to_string();
    for kind in ["methods", "harmonics", "spectrogram"] {
        for ext in ["png", "svg"] {
            let f = d.join(format!("pl/static/{stem}.{kind}.{ext}"));
            assert!(f.is_file(), "{}", f.display());
        }
    }
}

#[test]
fn a_manifest_places_a_recording_across_an_hour_and_reports_a_corrupt_file() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    // 40 s from 16:59:45: the last 25 s are in the 17:00 reference
    ok(
        &[
            "-q",
            "simulate",
            "--start",
            "2022-08-17T16:59:45+08:00",
            "--duration",
            "40",
            "--resolution",
            "16x12",
            "--reference-dir",
            "ENF1",
            "-o",
            "cross.aedat4",
        ],
        d,
    );
    ok(
        &[
            "-q",
            "simulate",
            "--start",
            "2022-08-17T16:20:00+08:00",
            "--duration",
            "30",
            "--resolution",
            "16x12",
            "--seed",
            "3",
            "--reference-dir",
            "ENF2",
            "-o",
            "plain.aedat4",
        ],
        d,
    );
    let mut bad = b"#!AER-DAT4.0\r\n".to_vec();
    bad.extend((0..5000u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8));
    std::fs::write(d.join("bad.aedat4"), bad).unwrap();
    std::fs::write(
        d.join("m.csv"),
        "recording,class,reference,offset_s,videos\n\
         cross.aedat4,static,ENF1/2022_08_17_Wed_16_00_00.wav,3585,\n\
         bad.aedat4,static,ENF1/2022_08_17_Wed_16_00_00.wav,0,\n\
         plain.aedat4,dynamic,ENF2/2022_08_17_Wed_16_00_00.wav,1200,\n",
    )
    .unwrap();
    let out = eenf(
        &[
            "-q",
            "bench",
            "m.csv",
            "--methods",
            "e-enf",
            "--csv",
            "b.csv",
            "--traces",
            "tr",
        ],
        d,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.aedat4"), "{err}");
    let rows = csv_maps(&std::fs::read_to_string(d.join("b.csv")).unwrap());
    let row = |name: &str| {
        rows.iter()
            .find(|r| r["recording"].ends_with(name))
            .unwrap_or_else(|| panic!("no row for {name}"))
    };
    let bad = row("/bad");
    assert_eq!(bad["status"], "failed");
    assert!(bad["error"].contains("bad.aedat4"), "{bad:?}");
    // across the hour: every second compared (the 17:00 file continues the 16:00 one), and the
    // trace agrees with the reference there, as it does with its own truth
    let cross = row("/cross");
    assert_eq!(cross["status"], "ok");
    assert!(num(cross, "seconds") >= 40.0, "{cross:?}");
    let truth: serde_json::Value = serde_json::from_str(&ok(
        &[
            "compare",
            "tr/static/cross.e-enf.json",
            "cross.truth.csv",
            "--json",
        ],
        d,
    ))
    .unwrap();
    println!(
        "across the hour: CC {} MAE {} mHz against the references; CC {} against the truth",
        cross["cc"],
        num(cross, "mae_hz") * 1e3,
        truth["cc"]
    );
    assert!(num(cross, "cc") > 0.9, "{cross:?}");
    assert!(num(cross, "mae_hz") < 0.002, "{cross:?}");
    // a wrong offset (the recording placed 30 s later) does not fit
    std::fs::write(
        d.join("m2.csv"),
        "recording,class,reference,offset_s\ncross.aedat4,static,ENF1/2022_08_17_Wed_16_00_00.wav,3615\n",
    )
    .unwrap();
    ok(
        &[
            "-q",
            "bench",
            "m2.csv",
            "--methods",
            "e-enf",
            "--csv",
            "c.csv",
        ],
        d,
    );
    let shifted = csv_maps(&std::fs::read_to_string(d.join("c.csv")).unwrap());
    assert!(num(&shifted[0], "mae_hz") > 2.0 * num(cross, "mae_hz"));
    let plain = row("/plain");
    assert_eq!(plain["status"], "ok");
    assert!(num(plain, "mae_hz") < 0.003, "{plain:?}");
    // without --methods, the methods with no input (no videos here) are named once, not run;
    // --json prints the numbers instead of the tables
    let out = eenf(&["-q", "bench", "m2.csv", "--json"], d);
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.matches("not run").count(), 1, "{err}");
    assert!(err.contains("v-enf-lr, v-enf-hr not run"), "{err}");
    assert!(!err.contains("failed"), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["methods"], serde_json::json!(["e-enf"]));
    let mae = v["runs"][0]["recordings"][0]["scores"]["mae_hz"].as_f64();
    assert!(
        mae.is_some_and(|m| (m - num(&shifted[0], "mae_hz")).abs() < 1e-9),
        "{v}"
    );
}

#[test]
fn sweeps_give_one_table_per_combination_with_the_numbers_of_extract() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    ok(
        &[
            "-q",
            "simulate",
            "--start",
            "2022-08-17T16:20:00+08:00",
            "--duration",
            "30",
            "--resolution",
            "16x12",
            "--reference-dir",
            "ds/ENF_Reference",
            "-o",
            "ds/static/dvSave-2022_08_17_16_20_00.aedat4",
        ],
        d,
    );
    let table = ok(
        &[
            "-q",
            "bench",
            "ds",
            "--methods",
            "e-enf",
            "--sweep",
            "harmonics=1,2",
            "--sweep",
            "peak=exact,paper",
            "--csv",
            "b.csv",
        ],
        d,
    );
    for combo in [
        "harmonics=1, peak=exact",
        "harmonics=1, peak=paper",
        "harmonics=2, peak=exact",
        "harmonics=2, peak=paper",
    ] {
        assert!(
            table.contains(&format!("### Table 2 layout: {combo}")),
            "{combo}"
        );
    }
    let rows = csv_maps(&std::fs::read_to_string(d.join("b.csv")).unwrap());
    let row = rows
        .iter()
        .find(|r| {
            r["settings"] == "harmonics=1, peak=paper" && r["recording"].starts_with("static/")
        })
        .unwrap();
    // the same settings by hand
    ok(
        &[
            "extract",
            "ds/static/dvSave-2022_08_17_16_20_00.aedat4",
            "--harmonics",
            "1",
            "--peak",
            "paper",
            "-o",
            "h1.json",
        ],
        d,
    );
    let c: serde_json::Value = serde_json::from_str(&ok(
        &["compare", "h1.json", "ds/ENF_Reference", "--json"],
        d,
    ))
    .unwrap();
    assert!((c["cc"].as_f64().unwrap() - num(row, "cc")).abs() < 1e-12);
    assert!((c["mae_hz"].as_f64().unwrap() - num(row, "mae_hz")).abs() < 1e-12);
}

#[test]
fn bad_benchmarks_and_videos_get_clear_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let err = fails(&["bench", "nowhere"], d);
    assert!(err.contains("nowhere"), "{err}");
    std::fs::create_dir_all(d.join("empty/static")).unwrap();
    let err = fails(&["bench", "empty"], d);
    assert!(err.contains("ENF_Reference"), "{err}");
    std::fs::write(d.join("m.csv"), "file,kind\na,b\n").unwrap();
    let err = fails(&["bench", "m.csv"], d);
    assert!(err.contains("recording, class, reference"), "{err}");
    std::fs::write(
        d.join("m2.csv"),
        "recording,class,reference\nmissing.aedat4,static,nowhere.wav\n",
    )
    .unwrap();
    let err = fails(&["bench", "m2.csv", "--methods", "e-enf"], d);
    assert!(err.contains("missing.aedat4"), "{err}");
    assert!(err.contains("no recording could be scored"), "{err}");
    let err = fails(&["bench", "m2.csv", "--methods", "x-enf"], d);
    assert!(err.contains("x-enf"), "{err}");
    let err = fails(&["bench", "m2.csv", "--sweep", "colour=red"], d);
    assert!(err.contains("colour"), "{err}");
    // eenf video: a missing file, a file that is no video
    let err = fails(&["video", "none.y4m"], d);
    assert!(err.contains("none.y4m"), "{err}");
    std::fs::write(d.join("notes.y4m"), "YUV4MPEG2 W0 H0 F30:1\n").unwrap();
    let err = fails(&["video", "notes.y4m"], d);
    assert!(err.contains("notes.y4m"), "{err}");
}
