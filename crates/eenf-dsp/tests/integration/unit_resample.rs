//! Tests of eenf-dsp's `resample` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_dsp::resample::*;

#[test]
fn finer_series_are_averaged_not_picked() {
    // 0.1 s samples of a ramp: each second is the mean of the ten samples around it
    let x: Vec<f64> = (0..50).map(|i| i as f64).collect();
    let y = resample(&x, 0.1, 1.0);
    assert_eq!(y.len(), 5);
    // second 0 holds samples 0..=4 (the half step before it is not there)
    assert!((y[0] - 2.0).abs() < 1e-12, "{y:?}");
    for (j, v) in y.iter().enumerate().skip(1).take(3) {
        assert!((v - 10.0 * j as f64 + 0.5).abs() < 1e-9, "{j}: {v}");
    }
    // a sample picker would give 10, 20, 30 here: a 1 s step of a 10 Hz alternation
    // averages to the middle instead of aliasing
    let alt: Vec<f64> = (0..100)
        .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
        .collect();
    let y = resample(&alt, 0.1, 1.0);
    assert!(y[1..9].iter().all(|v| v.abs() < 1e-12), "{y:?}");
}

#[test]
fn coarser_series_are_interpolated_and_gaps_kept() {
    assert_eq!(
        resample(&[0.0, 2.0, 4.0], 2.0, 1.0),
        vec![0.0, 1.0, 2.0, 3.0, 4.0]
    );
    let y = resample(&[0.0, f64::NAN, 4.0, 6.0], 2.0, 1.0);
    assert_eq!(y[0], 0.0);
    assert!(y[1..4].iter().all(|v| v.is_nan()), "{y:?}");
    assert_eq!(&y[4..], &[4.0, 5.0, 6.0]);
}

#[test]
fn samples_in_any_order_and_repeats_are_merged() {
    let mut a = StepAverager::new(1.0, 1000);
    for (t, v) in [
        (105.0, 5.0),
        (100.0, 1.0),
        (100.2, 3.0),
        (103.0, f64::NAN),
        (101.0, 2.0),
    ] {
        assert!(a.push(t, v));
    }
    // a time far outside the bound is refused, not allocated
    assert!(!a.push(1e12, 1.0));
    assert!(!a.push(-1e12, 1.0));
    assert_eq!(a.samples(), 4);
    let s = a.finish(0.0);
    assert_eq!(s.start, 100.0);
    assert_eq!(s.values.len(), 6);
    assert_eq!((s.values[0], s.values[1]), (2.0, 2.0));
    assert!(s.values[2].is_nan() && s.values[3].is_nan() && s.values[4].is_nan());
    assert_eq!(s.values[5], 5.0);
}
