//! Tests of eenf-dsp's `postprocess` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_dsp::postprocess::*;

#[test]
fn median_replaces_spikes_only() {
    let mut t: Vec<f64> = (0..50).map(|i| 100.0 + 0.001 * i as f64).collect();
    t[25] += 0.5;
    let c = median_correct(&t, 21, 0.02);
    // the spike sorts to the top of its window, so the median is the 11th of the rest
    assert!((c[25] - 100.026).abs() < 1e-9, "{}", c[25]);
    for i in (0..50).filter(|&i| i != 25) {
        assert_eq!(c[i], t[i]);
    }
}

#[test]
fn the_smoothest_trace_wins_per_segment() {
    let smooth: Vec<f64> = (0..20).map(|i| 50.0 + 1e-4 * i as f64).collect();
    let mut noisy = smooth.clone();
    for (i, v) in noisy.iter_mut().enumerate().take(10) {
        *v += if i % 2 == 0 { 0.01 } else { -0.01 };
    }
    let mut rough_late = smooth.clone();
    for (i, v) in rough_late.iter_mut().enumerate().skip(10) {
        *v += if i % 2 == 0 { 0.02 } else { -0.02 };
    }
    let (out, chosen) = select_harmonics(
        &[noisy, rough_late.clone()],
        10,
        HarmonicSelection::Smoothest,
    );
    assert_eq!(chosen, vec![1, 0]);
    assert_eq!(out[..10], rough_late[..10]);
}

#[test]
fn consensus_ignores_a_flat_trace_that_agrees_with_nothing() {
    let truth: Vec<f64> = (0..10).map(|i| 50.0 + 1e-3 * (i as f64).sin()).collect();
    let a: Vec<f64> = truth.iter().map(|v| v + 2e-4).collect();
    let b: Vec<f64> = truth.iter().map(|v| v - 3e-4).collect();
    let locked = vec![50.15; 10]; // a band stuck on a spurious line: perfectly flat
    let traces = [a, b, locked];
    let (_, paper) = select_harmonics(&traces, 10, HarmonicSelection::Smoothest);
    assert_eq!(
        paper,
        vec![2],
        "the paper's rule takes the flat wrong trace"
    );
    let (_, robust) = select_harmonics(&traces, 10, HarmonicSelection::Consensus(0.005));
    assert!(robust[0] < 2, "{robust:?}");
    // a single trace is taken as it is
    let (out, c) = select_harmonics(&traces[2..], 10, HarmonicSelection::Consensus(0.005));
    assert_eq!((out[0], c[0]), (50.15, 0));
}

#[test]
fn a_flat_band_locked_on_noise_is_not_taken_where_another_is_heard() {
    // band 0 follows the ENF; band 1 locked onto noise is flat (the smoothest); band 2 wanders
    let real: Vec<f64> = (0..20).map(|i| 50.0 + 0.002 * i as f64).collect();
    let flat = vec![49.9; 20];
    let wild: Vec<f64> = (0..20).map(|i| 50.1 + 0.05 * (i % 3) as f64).collect();
    let traces = [real.clone(), flat.clone(), wild];
    let (_, picked) = select_harmonics(&traces, 10, HarmonicSelection::Smoothest);
    assert_eq!(picked, vec![1, 1], "the paper's rule takes the flat band");
    let heard = [vec![true, true], vec![false, false], vec![false, true]];
    for rule in [
        HarmonicSelection::Smoothest,
        HarmonicSelection::Consensus(0.005),
    ] {
        let (out, picked) = select_audible_harmonics(&traces, &heard, 10, rule);
        assert_eq!(picked, vec![0, 0], "{rule:?}");
        assert_eq!(out, real);
    }
    // where nothing is heard, the rule decides as before
    let none = [vec![false; 2], vec![false; 2], vec![false; 2]];
    let (_, picked) = select_audible_harmonics(&traces, &none, 10, HarmonicSelection::Smoothest);
    assert_eq!(picked, vec![1, 1]);
}
