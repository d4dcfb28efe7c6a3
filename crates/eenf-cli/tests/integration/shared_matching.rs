//! Matching on real ENF: clips of the shared 50 Hz hours and 60 Hz days located in the
//! references, and clips from a day outside the reference found insignificant.
//! `#[ignore]`d (needs ../shared); `.ci/run` runs it.

use std::path::PathBuf;

use eenf::mains::reference_file;
use eenf_core::Nominal;
use eenf_dsp::matching::{match_trace, MatchOptions, DEFAULT_ALPHA};
use eenf_dsp::EnfParams;

use crate::common;

fn shared() -> PathBuf {
    common::shared("enf-traces-60hz")
}

fn day60(name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(shared().join("enf-traces-60hz").join(name)).unwrap();
    text.lines()
        .filter_map(|l| l.split(',').nth(1).and_then(|v| v.trim().parse().ok()))
        .collect()
}

fn hours50() -> Vec<f64> {
    let wavs = common::reference_wavs();
    let mut all = Vec::new();
    for w in wavs {
        let t = reference_file(
            &w,
            Nominal::Grid(eenf_core::Grid::Hz50),
            &EnfParams::default(),
        )
        .unwrap()
        .enf_hz;
        all.extend_from_slice(&t[..3600]);
    }
    all
}

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (a, b) = (self.unit().max(1e-300), self.unit());
        (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
    }
}

/// A clip with estimation error: white noise of `noise_hz` smoothed over 3 values.
fn noisy_clip(src: &[f64], at: usize, len: usize, noise_hz: f64, rng: &mut Rng) -> Vec<f64> {
    let raw: Vec<f64> = (0..len + 2).map(|_| noise_hz * rng.normal()).collect();
    (0..len)
        .map(|i| src[at + i] + (raw[i] + raw[i + 1] + raw[i + 2]) / 3.0_f64.sqrt())
        .collect()
}

/// Clips of `all` placed against `all`; clips of `outside` searched for in `held_in` (which
/// does not contain them).
fn evaluate(
    name: &str,
    step_s: f64,
    all: &[f64],
    held_in: &[f64],
    outside: &[f64],
    len: usize,
    trials: usize,
) -> (f64, f64) {
    let mut rng = Rng(0x1234_5678_9abc_def1 ^ len as u64);
    let opts = MatchOptions::default();
    let (mut hits, mut significant_outside, mut significant_hits) = (0, 0, 0);
    let mut worst_true_p: f64 = 0.0;
    let mut best_false_p: f64 = 1.0;
    for _ in 0..trials {
        let at = (rng.next() % (all.len() - len) as u64) as usize;
        let clip = noisy_clip(all, at, len, 0.0005, &mut rng);
        let res = match_trace(&clip, all, &opts).unwrap();
        let top = res.candidates[0];
        if (top.offset - at as f64).abs() * step_s <= 1.0 {
            hits += 1;
            worst_true_p = worst_true_p.max(top.p_value);
            if top.p_value < DEFAULT_ALPHA {
                significant_hits += 1;
            }
        }
        let at2 = (rng.next() % (outside.len() - len) as u64) as usize;
        let clip2 = noisy_clip(outside, at2, len, 0.0005, &mut rng);
        let res2 = match_trace(&clip2, held_in, &opts).unwrap();
        best_false_p = best_false_p.min(res2.candidates[0].p_value);
        if res2.candidates[0].p_value < DEFAULT_ALPHA {
            significant_outside += 1;
        }
    }
    let rate = hits as f64 / trials as f64;
    let fp = significant_outside as f64 / trials as f64;
    println!(
        "{name}: {len}-value clips: top candidate within ±1 s {:.1} % ({hits}/{trials}), significant (p < {DEFAULT_ALPHA}) {:.1} %, worst p of a true match {worst_true_p:.2e}; outside clips significant: {:.1} % (smallest p {best_false_p:.2e})",
        rate * 100.0,
        significant_hits as f64 / trials as f64 * 100.0,
        fp * 100.0
    );
    (rate, fp)
}

#[test]
#[ignore = "needs ../shared"]
fn real_enf_clips_are_placed_and_outsiders_rejected() {
    // 60 Hz (2 s steps): clips of the three days placed among all three; outsiders are clips
    // of Aug 3 searched for in Aug 1–2
    let mut all60 = day60("August_01_2022.csv");
    all60.extend(day60("August_02_2022.csv"));
    let held60 = all60.clone();
    let out60 = day60("August_03_2022.csv");
    all60.extend_from_slice(&out60);
    let (hit, fp) = evaluate("60 Hz", 2.0, &all60, &held60, &out60, 150, 200);
    assert!(
        hit >= 0.99 && fp <= 0.01,
        "60 Hz 5 min: hits {hit}, false positives {fp}"
    );
    evaluate("60 Hz", 2.0, &all60, &held60, &out60, 30, 200);
    // 50 Hz (1 s steps): clips of the six hours among all six; outsiders are clips of
    // 20:00–21:59 searched for in 16:00–19:59
    let h = hours50();
    let (held50, out50) = h.split_at(4 * 3600);
    let (hit, fp) = evaluate("50 Hz", 1.0, &h, held50, out50, 300, 200);
    assert!(
        hit >= 0.99 && fp <= 0.01,
        "50 Hz 5 min: hits {hit}, false positives {fp}"
    );
    evaluate("50 Hz", 1.0, &h, held50, out50, 60, 200);
}

#[test]
#[ignore = "needs ../shared"]
fn an_eenf_trace_from_a_simulated_recording_is_placed_at_its_time() {
    use eenf::extract::{extract_file, ExtractOptions};
    use eenf::progress::Progress;
    use eenf_events::{Aedat4Writer, Compression};
    use eenf_sim::{simulate, MainsPhase, SimConfig};

    let wav = shared().join("enf-reference/2022_08_17_Wed_17_00_00.wav");
    let sig = eenf::audio::read_wav(&wav).unwrap();
    let config = SimConfig {
        duration_s: 300.0,
        seed: 17,
        ..SimConfig::default()
    };
    let mains = MainsPhase::from_recording(&sig.samples, sig.fs, 50.0, 1200.0, 300.0).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let rec = tmp.path().join("clip.aedat4");
    let mut w = Aedat4Writer::create(&rec, Compression::Lz4, config.width, config.height).unwrap();
    simulate(&config, &mains, |b| w.write(b)).unwrap();
    w.finish().unwrap();
    let x = extract_file(&rec, &ExtractOptions::default(), &Progress::hidden()).unwrap();
    // the six hours from 16:00; the recording starts at 17:20:00, value 3600 + 1200
    let hours = hours50();
    let res = match_trace(&x.enf_hz, &hours[..], &MatchOptions::default()).unwrap();
    let top = res.candidates[0];
    println!("E-ENF clip: {top:?}");
    assert!((top.offset - 4800.0).abs() <= 1.0, "{top:?}");
    assert!(top.p_value < DEFAULT_ALPHA, "{top:?}");
}

/// The hourly WAVs are named in local time: without `--tz`, `match` refuses to guess the zone
/// (it once reported the right moment eight hours off, labelled UTC); with it, the moment is
/// given in UTC and in that zone; a claimed time without a zone is refused.
#[test]
#[ignore = "needs ../shared"]
fn local_file_names_need_their_zone() {
    let refs = common::shared("enf-reference").join("enf-reference");
    let hour = refs.join("2022_08_17_Wed_17_00_00.wav");
    let trace = reference_file(
        &hour,
        Nominal::Grid(eenf_core::Grid::Hz50),
        &EnfParams::default(),
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let clip = dir.path().join("clip.csv");
    let mut text = String::from("time_s,enf_hz\n");
    for (i, v) in trace.enf_hz[600..900].iter().enumerate() {
        text += &format!("{i},{v}\n");
    }
    std::fs::write(&clip, text).unwrap();
    let run = |extra: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_eenf"))
            .args(["-q", "match"])
            .arg(&clip)
            .arg(&refs)
            .args(["--top", "1"])
            .args(extra)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).to_string()
            + &String::from_utf8_lossy(&out.stderr);
        (out.status.success(), text)
    };
    let (ok, text) = run(&[]);
    assert!(
        !ok && text.contains("--tz") && !text.contains("T09:"),
        "{text}"
    );
    let (ok, text) = run(&["--tz", "+08:00"]);
    assert!(ok, "{text}");
    // the clip starts at 17:10:00 local (09:10:00 UTC), to within the sub-second fit
    let (utc, local) = if text.contains("T09:09:59") {
        ("T09:09:59", "(2022-08-17 17:09:59")
    } else {
        ("T09:10:00", "(2022-08-17 17:10:00")
    };
    assert!(text.contains(utc) && text.contains(local), "{text}");
    assert!(text.contains(" +08:00)"), "{text}");
    let (ok, text) = run(&["--tz", "+08:00", "--verify", "2022-08-17T17:10:00"]);
    assert!(!ok && text.contains("no time zone"), "{text}");
}
