//! Tests of eenf-dsp's `hum` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_dsp::hum::*;

/// `n` samples of the unit tests' noise from `seed`.
fn noise(seed: u64, n: usize) -> Vec<f64> {
    let mut g = crate::test_noise(seed);
    (0..n).map(|_| g()).collect()
}

fn with_tone(x: &[f64], fs: f64, f: f64, a: f64) -> Vec<f64> {
    x.iter()
        .enumerate()
        .map(|(i, v)| v + a * (2.0 * std::f64::consts::PI * f * i as f64 / fs).sin())
        .collect()
}

#[test]
fn noise_alone_stands_nowhere_over_many_seeds() {
    // 200 recordings of noise, 10 s to 120 s at 1 kHz: FALSE_ALARM is 1e-3 per recording
    for seed in 1..=200u64 {
        let secs = [10.0, 30.0, 120.0][seed as usize % 3];
        let x = noise(seed * 7919, (secs * 1000.0) as usize);
        let s = search_hum(&x, 1000.0, 1.0, &[50.0, 60.0], MAX_HUM_HARMONIC).unwrap();
        assert!(s.verdict().is_err(), "seed {seed}: {:?}", s.strongest());
    }
}

#[test]
fn a_hum_at_four_f0_alone_is_found_and_its_grid_told() {
    let fs = 1000.0;
    // a lone line just over the noise's height (7.9 dB, noise reaches 6.6) is not enough
    let x = with_tone(&noise(3, 60_000), fs, 4.0 * 50.013, 0.05);
    let s = search_hum(&x, fs, 1.0, &[50.0, 60.0], MAX_HUM_HARMONIC).unwrap();
    let e = s.verdict().unwrap_err().to_string();
    assert!(e.contains("no other harmonic confirms"), "{e}");
    let x = with_tone(&noise(3, 60_000), fs, 4.0 * 50.013, 0.08);
    let s = search_hum(&x, fs, 1.0, &[50.0, 60.0], MAX_HUM_HARMONIC).unwrap();
    let v = s.verdict().unwrap();
    assert_eq!(v.grid_hz, 50.0);
    assert_eq!(v.carriers, vec![4]);
    assert!((v.strongest.f0_hz - 50.013).abs() < 0.005, "{v:?}");
    // the same hum at 300 Hz, shared by both grids, cannot tell them apart alone
    let x = with_tone(&noise(4, 60_000), fs, 300.0, 0.05);
    let s = search_hum(&x, fs, 1.0, &[50.0, 60.0], MAX_HUM_HARMONIC).unwrap();
    assert!(s.verdict().is_err());
}

#[test]
fn a_lone_line_far_from_nominal_is_a_tone_but_a_clock_offset_at_two_harmonics_is_believed() {
    let fs = 1000.0;
    // F4 (349.23 Hz): 110 mHz below 7 x 50 Hz, alone
    let x = with_tone(&noise(5, 40_000), fs, 349.23, 0.1);
    let s = search_hum(&x, fs, 1.0, &[50.0, 60.0], MAX_HUM_HARMONIC).unwrap();
    let e = s.verdict().unwrap_err().to_string();
    assert!(e.contains("one harmonic alone"), "{e}");
    // a recorder 0.23 % slow: 59.861 Hz at 2 and 3 f0
    let x = with_tone(&noise(6, 40_000), fs, 2.0 * 59.861, 0.1);
    let x = with_tone(&x, fs, 3.0 * 59.861, 0.1);
    let v = search_hum(&x, fs, 1.0, &[50.0, 60.0], MAX_HUM_HARMONIC)
        .unwrap()
        .verdict()
        .unwrap();
    assert_eq!((v.grid_hz, v.carriers.len()), (60.0, 2));
}

#[test]
fn thresholds_follow_the_segments_averaged() {
    // one segment: an exponential bin's 1e-3/100 tail is ln(1e5) ≈ 11.5 over the mean,
    // 16.6 over the median (12.2 dB); Wilson-Hilferty is a little above
    let one = noise_threshold_db(1.0, 100);
    assert!((12.0..13.5).contains(&one), "{one}");
    let many = noise_threshold_db(200.0, 100);
    assert!(many < 2.5 && many > 0.5, "{many}");
    assert!((normal_quantile(0.975) - 1.96).abs() < 1e-3);
}

#[test]
fn windows_fit_short_clips_and_grow_for_weak_hum() {
    assert_eq!(choose_window(15.88, 16.0, 20.0, 7.9).unwrap().0, 8.0);
    assert_eq!(choose_window(10.0, 16.0, 20.0, 5.0).unwrap().0, 8.0);
    assert_eq!(choose_window(5.0, 16.0, 20.0, 2.5).unwrap().0, 4.0);
    assert!(choose_window(3.0, 16.0, 20.0, 1.5).is_err());
    assert_eq!(
        choose_window(600.0, 16.0, 20.0, 16.0).unwrap(),
        (16.0, None)
    );
    // 4 dB in 16 s segments: 16 s windows give 4 + 1.8 = 5.8 dB, 32 s 8.8 dB (at most 2x:
    // the ENF moves within a window)
    assert_eq!(choose_window(600.0, 16.0, 4.0, 16.0).unwrap().0, 32.0);
    // a weak line in a recording shorter than three of the longer windows keeps the default
    assert_eq!(choose_window(90.0, 16.0, 4.0, 16.0).unwrap().0, 16.0);
    assert_eq!(choose_window(100.0, 16.0, 4.0, 16.0).unwrap().0, 32.0);
}

#[test]
fn a_trace_that_jumps_between_windows_holds_no_line() {
    // the false alarm of a 7 Hz square wave: 40 mHz, then 131 mHz above 60 Hz
    let jumpy: Vec<f64> = (0..40)
        .map(|i| 60.0 + if i < 21 { 0.040 } else { 0.131 } + 1e-4 * i as f64)
        .collect();
    assert!(check_holds_line(&jumpy, 1.0, 16.0).is_err());
    let grid: Vec<f64> = (0..40)
        .map(|i| 60.0 + 0.01 * (i as f64 / 20.0).sin())
        .collect();
    assert!(check_holds_line(&grid, 1.0, 16.0).is_ok());
}

#[test]
fn plausibility_flags_offsets_and_steady_tones() {
    // a steady tone 139 mHz below 60 Hz for two minutes
    let steady: Vec<f64> = (0..140).map(|i| 59.861 + 1e-5 * (i % 3) as f64).collect();
    let p = plausibility(&steady, 1.0, 60.0, 8);
    assert_eq!(p.flags.len(), 2, "{p:?}");
    // a wandering grid near nominal
    let grid: Vec<f64> = (0..140)
        .map(|i| 60.0 + 0.01 * (i as f64 / 20.0).sin())
        .collect();
    assert!(plausibility(&grid, 1.0, 60.0, 8).flags.is_empty());
}
