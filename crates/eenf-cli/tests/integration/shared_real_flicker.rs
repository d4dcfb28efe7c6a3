//! Real recordings that see mains flicker (`shared/fixtures/real-flicker`): old jAER DVS128
//! files without an `# AEChip:` line, one of them a stereo pair on two clocks. No ENF ground
//! truth exists; the independent spectral analysis in `shared/fixtures/README.md` gives each
//! file's flicker line. `#[ignore]`d (needs the shared data); `.ci/run` runs it.

use crate::cli;
use crate::common;

use std::path::PathBuf;

fn real(name: &str) -> PathBuf {
    common::shared("fixtures/real-flicker")
        .join("fixtures/real-flicker")
        .join(name)
}

/// Traces `file` with the defaults (plus `extra`) and returns the trace's JSON.
fn extract(file: &std::path::Path, extra: &[&str]) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let mut args = vec!["-q", "extract", file.to_str().unwrap(), "--json"];
    args.extend_from_slice(extra);
    let out = cli::ok(&args, dir.path());
    serde_json::from_str(&out).unwrap()
}

fn mean(v: &serde_json::Value) -> f64 {
    let x: Vec<f64> = v["enf_hz"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|x| x.as_f64())
        .collect();
    x.iter().sum::<f64>() / x.len() as f64
}

#[test]
#[ignore = "needs ../shared"]
fn real_dvs128_recordings_are_traced_with_the_defaults() {
    // (file, camera, the independent analysis' ENF: flicker line / 2)
    let cases: [(&str, Option<&str>, f64); 3] = [
        ("jaer_MovingDarkBox.aedat", None, 99.980 / 2.0),
        (
            "fhaust_Tmpdiff128StereoPair-vertical-arm.aedat",
            Some("0"),
            100.028 / 2.0,
        ),
        (
            "fhaust_Tmpdiff128StereoPair-vertical-arm.aedat",
            Some("1"),
            99.937 / 2.0,
        ),
    ];
    for (name, camera, want) in cases {
        let file = real(name);
        let extra: Vec<&str> = camera.map(|c| vec!["--camera", c]).unwrap_or_default();
        let v = extract(&file, &extra);
        let got = mean(&v);
        eprintln!("{name} camera {camera:?}: mean {got:.4} Hz, independent {want:.4} Hz");
        assert_eq!(v["nominal_hz"], 50.0, "{name}: the grid");
        assert!(
            (got - want).abs() <= 0.010,
            "{name} {camera:?}: {got} vs {want}"
        );
        // per-event timestamps: every event of a bin votes
        assert_eq!(v["sampling"], "block", "{name}");
        assert!(v["enf_hz"].as_array().unwrap().len() >= 30);
    }
    // the stereo pair without --camera: one camera, never a mix of both clocks
    let v = extract(&real("fhaust_Tmpdiff128StereoPair-vertical-arm.aedat"), &[]);
    let camera = v["camera"].as_u64().expect("a camera is picked");
    let want = [100.028 / 2.0, 99.937 / 2.0][camera as usize];
    assert!((mean(&v) - want).abs() <= 0.010, "{} vs {want}", mean(&v));
}

#[test]
#[ignore = "needs ../shared"]
fn info_reports_the_chip_the_cameras_and_each_flicker_line() {
    let dir = tempfile::tempdir().unwrap();
    let f = real("fhaust_Tmpdiff128StereoPair-vertical-arm.aedat");
    let out = cli::ok(&["info", f.to_str().unwrap()], dir.path());
    assert!(
        out.contains("chip inferred from the addresses as DVS128"),
        "{out}"
    );
    // one measure, the ON − OFF sums of the independent analysis (100.028 and 99.937 Hz)
    assert!(out.contains("camera 0: 100.028 Hz"), "{out}");
    assert!(out.contains("camera 1: 99.937 Hz"), "{out}");
    let f = real("jaer_MovingDarkBox.aedat");
    let out = cli::ok(&["info", f.to_str().unwrap(), "--json"], dir.path());
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!((v["flicker"][0]["line"]["hz"].as_f64().unwrap() - 99.980).abs() < 0.003);
    let line = &v["flicker"][0]["sum_line"];
    // the independent analysis: 99.980 Hz, prominence 19.8
    assert!(
        (line["hz"].as_f64().unwrap() - 99.980).abs() < 0.002,
        "{line}"
    );
    assert!(
        (line["prominence"].as_f64().unwrap() - 19.8).abs() < 1.0,
        "{line}"
    );
    assert_eq!(v["width"], 128);
}

/// `info` and `extract` report one line, measured one way, for every real-flicker recording.
#[test]
#[ignore = "needs ../shared"]
fn info_and_extract_report_the_same_line() {
    let dir = tempfile::tempdir().unwrap();
    for (name, camera) in [
        ("jaer_MovingDarkBox.aedat", 0),
        ("fhaust_Tmpdiff128StereoPair-vertical-arm.aedat", 1),
    ] {
        let f = real(name);
        let info = cli::ok(&["info", f.to_str().unwrap(), "--json"], dir.path());
        let info: serde_json::Value = serde_json::from_str(&info).unwrap();
        let flicker = info["flicker"].as_array().unwrap();
        let line = &flicker[camera.min(flicker.len() - 1)]["line"];
        let out = dir.path().join("t.json");
        cli::ok(
            &["extract", f.to_str().unwrap(), "-o", out.to_str().unwrap()],
            dir.path(),
        );
        let trace: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        let got = &trace["flicker"];
        assert_eq!(got["hz"], line["hz"], "{name}: {got} vs {line}");
        assert_eq!(
            got["prominence"], line["prominence"],
            "{name}: {got} vs {line}"
        );
    }
}

#[test]
#[ignore = "needs ../shared"]
fn the_flicker_map_finds_the_lit_patch() {
    let dir = tempfile::tempdir().unwrap();
    let f = real("jaer_MovingDarkBox.aedat");
    let out = cli::ok(
        &[
            "-q",
            "flicker-map",
            f.to_str().unwrap(),
            "-o",
            "map.png",
            "--json",
        ],
        dir.path(),
    );
    assert!(dir.path().join("map.png").metadata().unwrap().len() > 10_000);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let cols = v["cols"].as_u64().unwrap() as usize;
    let strength: Vec<f64> = v["strength"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_f64().unwrap_or(0.0))
        .collect();
    let lit: Vec<usize> = (0..strength.len())
        .filter(|&k| strength[k] >= 3.5)
        .collect();
    // a patch, not the whole view: a few percent of the tiles, most of them in its rows
    assert!((5..=100).contains(&lit.len()), "{}", lit.len());
    let tile = v["tile"].as_u64().unwrap() as usize;
    let low = lit.iter().filter(|&&k| (k / cols) * tile >= 84).count();
    assert!(low * 2 > lit.len(), "{low} of {} below row 84", lit.len());
}
