//! ENF from any recording's sound: synthetic hum with a known ENF, decoded, decimated and
//! tracked; hum at f0 alone, or only at 2f0 or 3f0; other formats through Symphonia and
//! ffmpeg (those need the `ffmpeg` program and run with the ignored tests in `.ci/run`).

use crate::cli;

use std::f64::consts::PI;
use std::path::Path;
use std::process::Command;

use cli::{fails, json, ok};
use eenf_dsp::{agreement, reference_enf, EnfParams};

/// The ENF of the synthetic grid at second `t` (a slow swing and a wander).
fn enf_at(t: f64) -> f64 {
    50.0 + 0.02 * (2.0 * PI * t / 97.0).sin() + 0.006 * (2.0 * PI * t / 23.0 + 1.0).sin()
}

/// `seconds` of hum at `fs` with lines at m·f0 of the given amplitudes, in broadband noise,
/// `channels` channels (the hum on channel 0, noise alone on the others); returns the mono
/// hum channel as written.
fn write_hum(path: &Path, fs: u32, seconds: f64, lines: &[(f64, f64)], channels: u16) -> Vec<f64> {
    let spec = hound::WavSpec {
        channels,
        sample_rate: fs,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut w = hound::WavWriter::create(path, spec).unwrap();
    let n = (seconds * fs as f64) as usize;
    let (mut phase, mut seed) = (0.0f64, 0x2545_f491_4f6c_dd1du64);
    let mut noise = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut hum_channel = Vec::with_capacity(n);
    for i in 0..n {
        phase += 2.0 * PI * enf_at(i as f64 / fs as f64) / fs as f64;
        let hum: f64 = lines
            .iter()
            .map(|&(m, a)| a * (m * phase + 0.3 * m).sin())
            .sum();
        let v = hum + 0.2 * noise();
        let q = (v * 32767.0).round().clamp(-32768.0, 32767.0) as i16;
        w.write_sample(q).unwrap();
        hum_channel.push(q as f64 / 32768.0);
        for _ in 1..channels {
            w.write_sample((0.2 * noise() * 32767.0) as i16).unwrap();
        }
    }
    w.finalize().unwrap();
    hum_channel
}

/// The truth as the tracker sees it: the mean ENF over each estimate's 16 s window.
fn truth(estimates: usize) -> Vec<f64> {
    (0..estimates)
        .map(|i| {
            let (a, b) = ((i as f64 - 8.0).max(0.0), i as f64 + 8.0);
            let k = 200;
            (0..k)
                .map(|j| enf_at(a + (b - a) * (j as f64 + 0.5) / k as f64))
                .sum::<f64>()
                / k as f64
        })
        .collect()
}

fn trace_of(csv: &str) -> Vec<f64> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect()
}

#[test]
fn hum_at_44_1_khz_is_traced_decimated_as_well_as_at_its_own_rate() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let wav = d.join("hum.wav");
    let x = write_hum(&wav, 44_100, 120.0, &[(1.0, 0.02), (2.0, 0.01)], 2);
    ok(
        &["-q", "audio", "hum.wav", "--channel", "0", "-o", "a.csv"],
        d,
    );
    let est = trace_of(&std::fs::read_to_string(d.join("a.csv")).unwrap());
    // today's tracker on the full-rate signal
    let p = EnfParams {
        nominal_hz: 50.0,
        ..EnfParams::default()
    };
    let full = reference_enf(&x, 44_100.0, &p).unwrap();
    let t = truth(est.len().min(full.len()));
    let new = agreement(&est[..t.len()], &t).unwrap();
    let old = agreement(&full[..t.len()], &t).unwrap();
    assert!(new.cc > 0.99 && new.mae_hz < 1e-3, "decimated: {new:?}");
    assert!(
        new.mae_hz <= old.mae_hz + 1e-4 && new.cc >= old.cc - 0.002,
        "decimated {new:?} against full rate {old:?}"
    );
    // the JSON says how the sound was read
    let j = json(&ok(
        &[
            "-q",
            "audio",
            "hum.wav",
            "--channel",
            "0",
            "--json",
            "-o",
            "a.json",
        ],
        d,
    ));
    assert_eq!(j["audio"]["decoder"], "symphonia");
    assert_eq!(j["audio"]["channels"], 2);
    assert_eq!(j["audio"]["source_rate_hz"], 44_100.0);
    assert!(j["audio"]["rate_hz"].as_f64().unwrap() < 1000.0);
    // a channel the file does not have
    let err = fails(&["audio", "hum.wav", "--channel", "2"], d);
    assert!(
        err.contains("hum.wav") && err.contains("channel 2"),
        "{err}"
    );
}

#[test]
fn hum_only_at_a_harmonic_is_traced_and_the_harmonic_named() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    for m in [2.0, 3.0] {
        write_hum(&d.join("h.wav"), 8000, 90.0, &[(m, 0.03)], 1);
        let out = cli::eenf(
            &[
                "audio", "h.wav", "--json", "-o", "h.json", "--plot", "h.svg",
            ],
            d,
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(&format!("{m} x f0")), "{err}");
        // every written file is announced alike; the figure names the band by its k·f0
        assert!(
            err.contains("trace written to h.json") && err.contains("plot written to h.svg"),
            "{err}"
        );
        let svg = std::fs::read_to_string(d.join("h.svg")).unwrap();
        assert!(
            svg.contains(&format!("(÷{m})")) && svg.contains("k·f0"),
            "{m}"
        );
        let j = json(&String::from_utf8_lossy(&out.stdout));
        assert_eq!(j["nominal_hz"], 50.0);
        let picked: Vec<u64> = j["selected"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s["harmonic"].as_u64().unwrap())
            .collect();
        assert!(picked.iter().all(|&h| h == m as u64), "{picked:?}");
        let est: Vec<f64> = j["enf_hz"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let a = agreement(&est, &truth(est.len())).unwrap();
        assert!(a.cc > 0.98 && a.mae_hz < 2e-3, "{m} x f0: {a:?}");
    }
}

/// MP3, FLAC, M4A and OGG made by ffmpeg give the WAV's trace within 0.5 mHz; an AVI's
/// soundtrack goes through ffmpeg.
#[test]
#[ignore = "needs the ffmpeg program (run by .ci/run)"]
fn other_formats_give_the_wavs_trace() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    write_hum(&d.join("hum.wav"), 44_100, 120.0, &[(1.0, 0.02)], 1);
    let wav = trace_of(&ok(&["-q", "audio", "hum.wav"], d));
    let convert = |args: &[&str]| {
        let out = std::process::Command::new("ffmpeg")
            .args(["-v", "error", "-y"])
            .args(args)
            .current_dir(d)
            .output()
            .expect("ffmpeg is installed");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    for f in ["hum.mp3", "hum.flac", "hum.m4a", "hum.ogg"] {
        convert(&["-i", "hum.wav", f]);
        let t = trace_of(&ok(&["-q", "audio", f], d));
        // an encoder's padding may add a fraction of a second, so one more estimate
        assert!(
            t.len().abs_diff(wav.len()) <= 1,
            "{f}: {} vs {}",
            t.len(),
            wav.len()
        );
        let n = t.len().min(wav.len());
        let a = agreement(&t[..n], &wav[..n]).unwrap();
        assert!(a.mae_hz < 5e-4, "{f}: {a:?}");
    }
    convert(&[
        "-f",
        "lavfi",
        "-i",
        "testsrc=size=64x48:rate=5",
        "-i",
        "hum.wav",
        "-shortest",
        "-c:v",
        "mpeg4",
        "-c:a",
        "libmp3lame",
        "vid.avi",
    ]);
    let j = json(&ok(
        &["-q", "audio", "vid.avi", "--json", "-o", "v.json"],
        d,
    ));
    assert_eq!(j["audio"]["decoder"], "ffmpeg");
    let t: Vec<f64> = j["enf_hz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let n = t.len().min(wav.len());
    assert!(agreement(&t[..n], &wav[..n]).unwrap().mae_hz < 5e-4);
}

/// No trace without a line: sound that holds no mains hum is refused, not traced at the edges
/// of the search bands. Noise, a 7 Hz square wave (its odd harmonics at 49 and 63 Hz), a steady
/// tone 0.7 Hz below 50 Hz and one 1.2 Hz above 60 Hz, at telephone and mains-logger rates.
#[test]
fn sound_without_mains_hum_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, fs: u32, f: &dyn Fn(f64, u32) -> f64| {
        let path = dir.path().join(name);
        let spec = hound::WavSpec {
            channels: 1,
            sample_rate: fs,
            bits_per_sample: 16,
            sample_format: hound::SampleFormat::Int,
        };
        let mut w = hound::WavWriter::create(&path, spec).unwrap();
        let mut state = 99u64;
        for i in 0..fs * 40 {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let noise = ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.1;
            let v = f(i as f64 / fs as f64, i) + noise;
            w.write_sample((v.clamp(-1.0, 1.0) * 32000.0) as i16)
                .unwrap();
        }
        w.finalize().unwrap();
        path
    };
    let tau = std::f64::consts::TAU;
    let cases = [
        write("noise.wav", 8000, &|_, _| 0.0),
        write("square7.wav", 400, &|t, _| {
            0.5 * (tau * 7.0 * t).sin().signum()
        }),
        write("tone49_3.wav", 8000, &|t, _| 0.3 * (tau * 49.3 * t).sin()),
        write("tone61_2.wav", 8000, &|t, _| 0.3 * (tau * 61.2 * t).sin()),
    ];
    for path in cases {
        let out = Command::new(env!("CARGO_BIN_EXE_eenf"))
            .args(["-q", "audio"])
            .arg(&path)
            .args(["-o"])
            .arg(path.with_extension("csv"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{}: traced", path.display());
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!path.with_extension("csv").exists(), "{}", path.display());
    }
}

/// Every audio trace says how far each estimate's line stands over its noise (`snr_db`), and
/// the estimates where the hum has gone (noise alone, past 12 dB in about one window in a
/// hundred) are named in a warning: 120 s with hum for the first 80 s, noise alone after.
#[test]
fn audio_traces_carry_snr_and_flag_estimates_at_the_noise_level() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fs = 1000u32;
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: fs,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut w = hound::WavWriter::create(d.join("fade.wav"), spec).unwrap();
    let (mut phase, mut state) = (0.0f64, 7u64);
    for i in 0..fs * 120 {
        let t = i as f64 / fs as f64;
        phase += 2.0 * PI * enf_at(t) / fs as f64;
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let noise = ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.2;
        let hum = if t < 80.0 { 0.05 * phase.sin() } else { 0.0 };
        w.write_sample(((hum + noise) * 32000.0) as i16).unwrap();
    }
    w.finalize().unwrap();
    let out = cli::eenf(
        &[
            "-q",
            "reference",
            "fade.wav",
            "--harmonics",
            "1",
            "--nominal",
            "50",
            "-o",
            "t.csv",
        ],
        d,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let text = std::fs::read_to_string(d.join("t.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("time_s,enf_hz,snr_db"));
    let rows: Vec<(f64, Option<f64>, f64)> = lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[0].parse().unwrap(),
                f[1].parse().ok(),
                f[2].parse().unwrap_or(f64::NAN),
            )
        })
        .collect();
    // whole windows of hum (16 s) stand well clear; whole windows of noise do not
    let hum: Vec<f64> = rows.iter().filter(|r| r.0 <= 72.0).map(|r| r.2).collect();
    let noise: Vec<&(f64, Option<f64>, f64)> = rows.iter().filter(|r| r.0 >= 88.0).collect();
    assert!(hum.iter().all(|s| *s > 20.0), "{hum:?}");
    let flagged = noise
        .iter()
        .filter(|r| r.1.is_none() || r.2 < eenf_dsp::NOISE_LEVEL_DB)
        .count();
    assert!(
        flagged * 10 >= noise.len() * 9,
        "{flagged} of {}: {noise:?}",
        noise.len()
    );
    let warning = err
        .lines()
        .find(|l| l.contains("stand at the noise level"))
        .unwrap_or_else(|| panic!("no warning: {err}"));
    // the stretches it names: all after the hum ended, the last one at the end
    let spans = warning
        .split("): ")
        .nth(1)
        .unwrap()
        .split(". ")
        .next()
        .unwrap();
    let times: Vec<f64> = spans
        .split([',', '–', ' '])
        .filter_map(|w| w.parse().ok())
        .collect();
    assert!(times.iter().all(|t| *t >= 72.0), "{warning}");
    assert!(times.iter().any(|t| *t >= 110.0), "{warning}");
}
