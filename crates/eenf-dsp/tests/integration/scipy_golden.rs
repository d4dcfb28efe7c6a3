//! Agreement with scipy 1.17 (`../shared/golden/dsp-golden.json`). Needs the shared data, so
//! `#[ignore]`d here and run by `.ci/run` with `--ignored`, where a missing file fails.

use eenf_dsp::{butter_bandpass, sos_to_ba, sosfiltfilt, PeakMethod, StftTracker};
use serde_json::Value;
use std::path::PathBuf;

fn golden() -> Value {
    let dir = std::env::var_os("EENF_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared"));
    let path = dir.join("golden/dsp-golden.json");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (set EENF_SHARED)", path.display()));
    serde_json::from_str(&text).unwrap()
}

fn vec_of(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
#[ignore = "needs ../shared"]
fn butterworth_designs_match_scipy() {
    let g = golden();
    let designs = g["butterworth_designs"].as_array().unwrap();
    assert_eq!(designs.len(), 8);
    for d in designs {
        let (lo, hi, fs) = (
            d["low_hz"].as_f64().unwrap(),
            d["high_hz"].as_f64().unwrap(),
            d["fs"].as_f64().unwrap(),
        );
        let order = d["order"].as_u64().unwrap() as usize;
        let sos = butter_bandpass(order, lo, hi, fs);
        let want: Vec<Vec<f64>> = d["sos"].as_array().unwrap().iter().map(vec_of).collect();
        assert_eq!(sos.len(), want.len());
        for (s, w) in sos.iter().zip(&want) {
            for (a, b) in s.iter().zip(w) {
                // b0..b2 of section 0 carry the ~1e-8 gain: compare relative to the row scale
                let scale = w.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
                assert!(
                    (a - b).abs() <= 1e-9 * scale,
                    "{lo}-{hi} Hz: sos {s:?} vs {w:?}"
                );
            }
        }
        let (b, a) = sos_to_ba(&sos);
        let (wb, wa) = (vec_of(&d["b"]), vec_of(&d["a"]));
        let bscale = wb.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (x, y) in b.iter().zip(&wb) {
            assert!((x - y).abs() <= 1e-9 * bscale, "b {b:?} vs {wb:?}");
        }
        for (x, y) in a.iter().zip(&wa) {
            assert!((x - y).abs() <= 1e-8, "a {a:?} vs {wa:?}");
        }
    }
}

#[test]
#[ignore = "needs ../shared"]
fn zero_phase_filter_matches_filtfilt_and_sosfiltfilt() {
    let g = golden();
    let c = &g["filtfilt_case"];
    let x = vec_of(&c["input"]);
    let sos = butter_bandpass(4, 98.0, 102.0, c["fs"].as_f64().unwrap());
    let y = sosfiltfilt(&sos, &x);
    for key in ["sosfiltfilt_output", "filtfilt_ba_output"] {
        let want = vec_of(&c[key]);
        assert_eq!(y.len(), want.len());
        let max = y
            .iter()
            .zip(&want)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!("{key}: max abs difference {max:.3e}");
        assert!(max <= 1e-6, "{key}: max abs difference {max}");
    }
}

#[test]
#[ignore = "needs ../shared"]
fn paper_tracker_matches_scipy_definition() {
    let g = golden();
    let c = &g["stft_tracker_case"];
    let x = vec_of(&c["input"]);
    let fs = c["fs"].as_f64().unwrap();
    let want = vec_of(&c["expected_hz"]);
    let mut t = StftTracker::new(fs, PeakMethod::Paper);
    t.paper_bin_hz = fs / c["nfft"].as_f64().unwrap();
    let got = t.track(&x, (48.0, 52.0));
    assert_eq!(got.len(), want.len());
    let max = got
        .iter()
        .zip(&want)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!(
        "paper tracker: max abs difference {max:.3e} Hz over {}",
        got.len()
    );
    assert!(max <= 1e-5, "max difference {max} Hz");
}
