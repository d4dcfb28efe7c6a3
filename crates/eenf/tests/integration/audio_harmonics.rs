//! Hum at whichever harmonic it stands, in clips of any length: synthetic sound whose only
//! mains line sits at 3, 4 or 5 f0, in white noise, at the rates recorders use. The truth is
//! the simulator's ENF (fitted to real references), seen through the same window: the clean
//! mains tone of the same phase traced by the reference tracker.

use std::path::Path;

use eenf::audio::{AudioOptions, Sound};
use eenf::mains::{sound_trace, HumOptions, MainsLines};
use eenf::trace::{Provenance, Trace};
use eenf_core::Nominal;
use eenf_dsp::EnfParams;
use eenf_sim::{MainsPhase, SyntheticEnf};
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;

/// White noise of std 0.05 and a hum at `k`·f0 alone whose line stands `db` above the noise
/// in a 16 s window (periodogram peak over the mean noise power of a bin), and the clean
/// mains tone of the same phase.
fn hum(phase: &MainsPhase, fs: f64, k: f64, db: f64, seed: u64) -> (Vec<f32>, Vec<f32>) {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let sigma = 0.05;
    let amp = sigma * (4.0 * 10f64.powf(db / 10.0) / (16.0 * fs)).sqrt();
    let n = (phase.duration_s() * fs).floor() as usize;
    let mut noisy = Vec::with_capacity(n);
    let mut clean = Vec::with_capacity(n);
    for i in 0..n {
        let phi = phase.phase_at(i as f64 / fs);
        let g: f64 = rng.sample(StandardNormal);
        noisy.push((sigma * g + amp * (k * phi + 0.7).cos()) as f32);
        clean.push((0.5 * phi.cos()) as f32);
    }
    (noisy, clean)
}

fn trace(samples: &[f32], fs: f64, hum: HumOptions) -> eenf::Result<Trace> {
    let sound = Sound::Samples {
        name: Path::new("hum"),
        interleaved: samples,
        channels: 1,
        fs,
    };
    sound_trace(
        &sound,
        &AudioOptions::default(),
        &hum,
        Nominal::Auto,
        &EnfParams::default(),
    )
}

/// The window the trace was made with, and the harmonics it tracked.
fn how(t: &Trace) -> (f64, Vec<usize>) {
    match &t.provenance {
        Some(Provenance::Mains(m)) => (
            m.window_s,
            m.hum
                .as_ref()
                .map(|h| h.carriers.clone())
                .unwrap_or_default(),
        ),
        _ => panic!("not a mains trace"),
    }
}

/// MAE (Hz) of `t` against the clean tone traced with the same window.
fn mae_against_truth(t: &Trace, clean: &[f32], fs: f64) -> f64 {
    let (window, _) = how(t);
    let truth = trace(
        clean,
        fs,
        HumOptions {
            lines: MainsLines::UpTo(1),
            window_s: Some(window),
        },
    )
    .unwrap();
    let pairs: Vec<f64> = t
        .enf_hz
        .iter()
        .zip(&truth.enf_hz)
        .map(|(a, b)| (a - b).abs())
        .collect();
    assert!(pairs.iter().all(|d| d.is_finite()), "gaps in the trace");
    pairs.iter().sum::<f64>() / pairs.len() as f64
}

/// The real grid's fine structure: the simulator's per-second jitter (11 mHz, fitted to the
/// references as 16 s windows see them) makes one-second mean frequencies step by 16 mHz, six
/// times what the Wuhan mains recordings show at their own phase (std 2.5 mHz, measured with
/// the analytic signal of the 400 Hz WAVs; that includes their noise). At 4 f0 the difference
/// matters: the line spreads with it.
fn real_grid() -> SyntheticEnf {
    SyntheticEnf {
        jitter_std_hz: 0.0017,
        ..SyntheticEnf::default()
    }
}

/// Weak hum (10 dB in a 16 s window; 4.5–7 dB in the detector's Welch spectrum, as the ENF's
/// swings spread the line at 4 f0) is found in most realisations and traced with a 32 s
/// window, each window dechirped by the sweep its neighbours show: MAE under 1 mHz against the
/// truth. (The Cramér-Rao bound of one 16 s window at this strength is 1.9 mHz on the f0
/// scale, of a 32 s window 0.7 mHz.) Undechirped, such traces err by 1.7 mHz in the median.
#[test]
fn weak_hum_at_four_f0_alone_is_found_and_traced_within_a_millihertz_at_1_and_8_khz() {
    for fs in [1000.0, 8000.0] {
        let mut traced = 0;
        for seed in 1..=6u64 {
            let phase = MainsPhase::synthetic(50.0, 240.0, real_grid(), seed);
            let (noisy, clean) = hum(&phase, fs, 4.0, 10.0, seed);
            // too weak to tell from noise at a false-alarm rate of 1e-3 now and then: the
            // line then stands under 6 dB in the detector's spectrum
            let Ok(t) = trace(&noisy, fs, HumOptions::default()) else {
                continue;
            };
            traced += 1;
            assert_eq!(t.nominal_hz, Some(50.0));
            assert_eq!(how(&t), (32.0, vec![4]), "{fs} Hz, seed {seed}");
            let mae = mae_against_truth(&t, &clean, fs);
            eprintln!("{fs} Hz, seed {seed}: MAE {:.2} mHz", mae * 1e3);
            assert!(
                mae <= 1e-3,
                "{fs} Hz, seed {seed}: MAE {:.2} mHz",
                mae * 1e3
            );
        }
        assert!(traced >= 5, "{fs} Hz: {traced} of 6 traced");
    }
}

/// Hum at 3 or 5 f0 alone, 16 dB in a 16 s window, at 44.1 kHz: traced to below a millihertz.
#[test]
fn hum_at_three_or_five_f0_is_traced_at_44_1_khz() {
    for (grid, k, seed) in [(60.0, 3.0, 3u64), (50.0, 5.0, 4)] {
        let phase = MainsPhase::synthetic(grid, 60.0, SyntheticEnf::default(), seed);
        let (noisy, clean) = hum(&phase, 44_100.0, k, 16.0, seed);
        let t = trace(&noisy, 44_100.0, HumOptions::default()).unwrap();
        assert_eq!(t.nominal_hz, Some(grid));
        assert_eq!(how(&t), (16.0, vec![k as usize]));
        let mae = mae_against_truth(&t, &clean, 44_100.0);
        eprintln!("{k} f0: MAE {:.2} mHz", mae * 1e3);
        assert!(mae <= 1e-3, "{k} f0: MAE {:.2} mHz", mae * 1e3);
    }
}

/// Clips shorter than the 16 s window get one that fits (the resolution it costs is stated);
/// under four seconds they are refused.
#[test]
fn clips_of_5_10_and_20_s_with_a_clear_line_are_traced_with_windows_that_fit() {
    for (secs, want_window, most_mhz) in [(5.0, 4.0, 5.0), (10.0, 8.0, 2.0), (20.0, 16.0, 2.0)] {
        let phase = MainsPhase::synthetic(50.0, secs, SyntheticEnf::default(), 5);
        let (noisy, clean) = hum(&phase, 8000.0, 4.0, 22.0, 5);
        let t = trace(&noisy, 8000.0, HumOptions::default()).unwrap();
        let (window, carriers) = how(&t);
        assert_eq!((window, carriers), (want_window, vec![4]), "{secs} s");
        let mae = mae_against_truth(&t, &clean, 8000.0);
        assert!(mae <= most_mhz * 1e-3, "{secs} s: MAE {:.2} mHz", mae * 1e3);
        if secs < 16.0 {
            let note = match &t.provenance {
                Some(Provenance::Mains(m)) => m.hum.as_ref().and_then(|h| h.window_note.clone()),
                _ => None,
            };
            assert!(note.is_some_and(|n| n.contains("resolution")));
        }
    }
    let phase = MainsPhase::synthetic(50.0, 3.0, SyntheticEnf::default(), 6);
    let (noisy, _) = hum(&phase, 8000.0, 4.0, 30.0, 6);
    let e = trace(&noisy, 8000.0, HumOptions::default()).unwrap_err();
    assert!(e.report().contains("shorter than"), "{}", e.report());
}

#[test]
fn noise_and_lone_tones_near_the_mains_are_refused() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(9);
    let fs = 8000.0;
    let noise: Vec<f32> = (0..(60.0 * fs) as usize)
        .map(|_| 0.05 * rng.sample::<f64, _>(StandardNormal) as f32)
        .collect();
    assert!(trace(&noise, fs, HumOptions::default()).is_err());
    // a steady tone 110 mHz below 7 x 50 Hz (a musical F4), alone
    let tone: Vec<f32> = noise
        .iter()
        .enumerate()
        .map(|(i, v)| v + 0.05 * (2.0 * std::f64::consts::PI * 349.23 * i as f64 / fs).sin() as f32)
        .collect();
    let e = trace(&tone, fs, HumOptions::default()).unwrap_err();
    assert!(e.report().contains("not the mains"), "{}", e.report());
}
