//! Tests of eenf-sim's `mains` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_sim::*;
use std::f64::consts::PI;

#[test]
fn pieces_of_one_series_join_with_a_continuous_phase() {
    let freq: Vec<f64> = (0..400)
        .map(|i| 50.0 + 0.02 * (i as f64 * 0.05).sin() + 0.003 * (i as f64 * 0.7).cos())
        .collect();
    let (step, cut) = (2.0, 333.3);
    let first = MainsPhase::from_frequency(50.0, &freq, step, 0.0, cut + 1.0, 0.0);
    let second = MainsPhase::from_frequency(
        50.0,
        &freq,
        step,
        cut,
        10.0,
        phase_from_start(&freq, step, cut),
    );
    let wrap = |d: f64| (d + PI).rem_euclid(2.0 * PI) - PI;
    for dt in [0.0, 0.25, 0.5] {
        let d = wrap(first.phase_at(cut + dt) - second.phase_at(dt));
        assert!(d.abs() < 1e-6, "phase step {d} rad at {dt} s after the cut");
    }
}

#[test]
fn synthetic_enf_has_grid_like_statistics() {
    // statistics of the trace as a 16 s tracker sees it, compared with the real references
    let raw = SyntheticEnf::default().per_second(50.0, 6 * 3600, 7);
    let smooth: Vec<f64> = (8..raw.len() - 8)
        .map(|i| raw[i - 8..i + 8].iter().sum::<f64>() / 16.0)
        .collect();
    let sd = |v: &[f64]| {
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
    };
    let steps: Vec<f64> = smooth.windows(2).map(|w| w[1] - w[0]).collect();
    let step_sd = sd(&steps);
    assert!(step_sd > 0.0006 && step_sd < 0.002, "step sd {step_sd}");
    let total = sd(&smooth);
    assert!(total > 0.010 && total < 0.035, "std {total}");
    let mut ranges: Vec<f64> = smooth
        .chunks(60)
        .map(|w| {
            w.iter().cloned().fold(f64::MIN, f64::max) - w.iter().cloned().fold(f64::MAX, f64::min)
        })
        .collect();
    ranges.sort_by(f64::total_cmp);
    let median = ranges[ranges.len() / 2];
    assert!(
        median > 0.010 && median < 0.035,
        "median 60 s range {median}"
    );
}

#[test]
fn phase_from_a_recorded_tone_recovers_its_frequency() {
    let fs = 400.0;
    let x: Vec<f64> = (0..(120.0 * fs) as usize)
        .map(|i| (2.0 * PI * 50.013 * i as f64 / fs + 0.4).cos() * 0.8)
        .collect();
    let m = MainsPhase::from_recording(&x, fs, 50.0, 30.0, 40.0).unwrap();
    let f = (m.phase_at(40.0) - m.phase_at(0.0)) / (2.0 * PI * 40.0);
    assert!((f - 50.013).abs() < 1e-6, "{f}");
    let truth = m.truth(40.0);
    assert_eq!(truth.len(), 41);
    assert!(truth.iter().all(|v| (v - 50.013).abs() < 1e-4), "{truth:?}");
    assert!(MainsPhase::from_recording(&x, fs, 50.0, 100.0, 40.0).is_err());
}
