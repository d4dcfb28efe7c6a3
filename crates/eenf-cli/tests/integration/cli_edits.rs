//! `eenf edits` as a user runs it: a 16-bit WAV of hum (lines at f0, 2f0, 3f0) whose grid
//! wanders smoothly, in white noise, whole and with a stretch cut out; the JSON layout; the
//! figure; a recording with no hum refused; a trace tested for frequency steps.

use crate::cli;

use std::f64::consts::PI;
use std::path::Path;

use cli::{fails, json, ok};

/// The grid's frequency at second `t`: a slow swing and a wander.
fn enf_at(t: f64) -> f64 {
    50.0 + 0.02 * (2.0 * PI * t / 97.0).sin() + 0.006 * (2.0 * PI * t / 23.0 + 1.0).sin()
}

/// `seconds` of hum at 8 kHz (0.01, 0.004, 0.003 at f0, 2f0, 3f0; white noise of std
/// `noise`); `cut` removes `(at, length)` seconds, the hum's phase running on through them.
fn write_hum(path: &Path, seconds: f64, noise: f64, hum: f64, cut: Option<(f64, f64)>) {
    let fs = 8000.0;
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: 8000,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut w = hound::WavWriter::create(path, spec).unwrap();
    let (mut phase, mut seed) = (0.0f64, 0x2545_f491_4f6c_dd1du64);
    let mut gauss = || {
        // a sum of twelve uniforms: close to a unit normal
        (0..12)
            .map(|_| {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                (seed >> 11) as f64 / (1u64 << 53) as f64
            })
            .sum::<f64>()
            - 6.0
    };
    let total = ((seconds + cut.map_or(0.0, |c| c.1)) * fs) as usize;
    let (from, to) = cut.map_or((usize::MAX, usize::MAX), |(a, l)| {
        ((a * fs) as usize, ((a + l) * fs) as usize)
    });
    for i in 0..total {
        phase += 2.0 * PI * enf_at(i as f64 / fs) / fs;
        if (from..to).contains(&i) {
            continue;
        }
        let v = hum
            * (0.01 * phase.cos()
                + 0.004 * (2.0 * phase + 0.4).cos()
                + 0.003 * (3.0 * phase + 1.3).cos())
            + noise * gauss();
        w.write_sample((v * 32767.0).round().clamp(-32768.0, 32767.0) as i16)
            .unwrap();
    }
    w.finalize().unwrap();
}

#[test]
fn a_cut_is_reported_at_its_place_with_its_phase_jump_and_the_whole_clip_is_not() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // 1.2345 s removed: about 61.7 cycles of 50 Hz, a jump of about −108°
    write_hum(&d.join("cut.wav"), 180.0, 0.05, 1.0, Some((83.2, 1.2345)));
    write_hum(&d.join("whole.wav"), 180.0, 0.05, 1.0, None);
    let r = json(&ok(
        &["-q", "edits", "cut.wav", "--json", "--plot", "cut.svg"],
        d,
    ));
    let edits = r["edits"].as_array().unwrap();
    assert_eq!(edits.len(), 1, "{r}");
    let e = &edits[0];
    assert!((e["time_s"].as_f64().unwrap() - 83.2).abs() <= 0.5, "{e}");
    assert!(e["kind"].as_str().unwrap().starts_with("phase_jump"), "{e}");
    // the jump the cut makes: the phase the removed stretch would have advanced
    let removed: f64 = (0..12345)
        .map(|i| enf_at(83.2 + i as f64 * 1e-4) * 1e-4)
        .sum::<f64>();
    // the phase runs on through the removed stretch: after the cut it is ahead by that much
    let truth = (removed * 360.0 + 180.0).rem_euclid(360.0) - 180.0;
    let jump = e["phase_jump_deg"].as_f64().unwrap();
    let diff = (jump - truth + 180.0).rem_euclid(360.0) - 180.0;
    assert!(diff.abs() < 20.0, "jump {jump}° vs {truth}°");
    assert_eq!(e["phase_jump_line_hz"].as_f64(), Some(50.0));
    for key in ["strength", "false_alarms_per_hour", "p_value"] {
        assert!(e[key].as_f64().is_some(), "{key} missing: {e}");
    }
    assert!(e["strength"].as_f64().unwrap() >= 1.0);
    assert!(r["verdict"].as_str().unwrap().starts_with("discontinuous"));
    assert_eq!(r["grid_hz"].as_f64(), Some(50.0));
    let svg = std::fs::read_to_string(d.join("cut.svg")).unwrap();
    assert!(svg.contains("phase deviation") && svg.contains("threshold"));
    let r = json(&ok(&["-q", "edits", "whole.wav", "--json"], d));
    assert_eq!(r["edits"].as_array().unwrap().len(), 0, "{r}");
    assert!(
        r["verdict"].as_str().unwrap().starts_with("no edit found"),
        "{r}"
    );
    // the plain text names the finding and its time
    let text = ok(&["-q", "edits", "cut.wav"], d);
    assert!(
        text.contains("phase jump") && text.contains("83."),
        "{text}"
    );
}

#[test]
fn no_hum_is_refused_not_declared_clean() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_hum(&d.join("noise.wav"), 60.0, 0.05, 0.0, None);
    let err = fails(&["-q", "edits", "noise.wav"], d);
    assert!(err.contains("noise.wav"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    let err = fails(&["-q", "edits", "missing.wav"], d);
    assert!(err.contains("missing.wav"), "{err}");
}

#[test]
fn a_trace_is_tested_for_frequency_steps() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // a smooth ENF with 20 mHz more from 300 s on (material from another time)
    let mut csv = String::from("time_s,enf_hz\n");
    for i in 0..600 {
        let t = i as f64;
        let step = if t >= 300.0 { 0.02 } else { 0.0 };
        csv += &format!("{t},{:.6}\n", enf_at(t) + step);
    }
    std::fs::write(d.join("trace.csv"), csv).unwrap();
    let r = json(&ok(&["-q", "edits", "trace.csv", "--json"], d));
    assert_eq!(r["input"], "trace");
    let edits = r["edits"].as_array().unwrap();
    assert_eq!(edits.len(), 1, "{r}");
    assert_eq!(edits[0]["kind"], "frequency_step");
    assert!(
        (edits[0]["time_s"].as_f64().unwrap() - 300.0).abs() <= 2.0,
        "{r}"
    );
    let step = edits[0]["frequency_step_mhz"].as_f64().unwrap();
    assert!((step - 20.0).abs() < 4.0, "{step}");
}
