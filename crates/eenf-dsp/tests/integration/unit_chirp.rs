//! Tests of eenf-dsp's `chirp` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_dsp::chirp::*;
use std::f64::consts::PI;

/// A line sweeping 8 mHz/s (a 4 f0 line on a grid swinging 2 mHz/s) spreads over eight
/// bins of a 32 s window; followed, each estimate is the frequency at its window's centre.
#[test]
fn a_sweeping_line_is_read_at_the_window_centre() {
    let fs = 1000.0;
    let (f_start, rate) = (200.05, 0.008);
    let n = (120.0 * fs) as usize;
    let y: Vec<f64> = (0..n)
        .map(|i| {
            let t = i as f64 / fs;
            (2.0 * PI * (f_start * t + 0.5 * rate * t * t)).cos()
        })
        .collect();
    let truth: Vec<f64> = (0..=120).map(|s| f_start + rate * s as f64).collect();
    // a first pass that is off by a few bins here and there
    let first: Vec<f64> = truth
        .iter()
        .enumerate()
        .map(|(i, f)| f + if i % 7 == 0 { 0.03 } else { 0.0 })
        .collect();
    let followed = follow_chirps(&y, fs, 200.0, &first, 32.0, 1.0, 0.1, 1);
    for i in 16..=104 {
        assert!(
            (followed[i] - truth[i]).abs() < 2e-4,
            "{i} s: {} against {}",
            followed[i],
            truth[i]
        );
    }
}

#[test]
fn estimates_without_neighbours_are_kept() {
    let y = vec![0.0; 10_000];
    let first = vec![f64::NAN, 200.0, f64::NAN, f64::NAN];
    let followed = follow_chirps(&y, 1000.0, 200.0, &first, 32.0, 1.0, 0.1, 1);
    assert!(followed[0].is_nan());
    assert_eq!(followed[1], 200.0);
}
