//! Tests of eenf-dsp's `tracker` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_dsp::tracker::*;
use std::f64::consts::PI;

fn tone(f: f64, fs: f64, secs: f64, phase: f64) -> Vec<f64> {
    (0..(secs * fs) as usize)
        .map(|i| (2.0 * PI * f * i as f64 / fs + phase).cos())
        .collect()
}

#[test]
fn frame_count_follows_the_centred_convention() {
    let t = StftTracker::new(400.0, PeakMethod::Exact);
    assert_eq!(t.frame_count(48_000), 121);
    assert_eq!(t.frame_count(1_440_000), 3601);
    assert_eq!(t.frame_count(0), 0);
}

#[test]
fn exact_finds_tones_between_bins_within_0_05_mhz() {
    // offsets across a 5 mHz paper bin, where the paper's interpolation is worst
    for (j, off) in [0.0, 0.0007, 0.001, 0.0025, 0.0031, 0.0049]
        .iter()
        .enumerate()
    {
        for base in [100.0, 200.0] {
            let f = base + off;
            let x = tone(f, 1000.0, 40.0, j as f64);
            let est =
                StftTracker::new(1000.0, PeakMethod::Exact).track(&x, (base - 2.0, base + 2.0));
            assert_eq!(est.len(), 41);
            for (i, e) in est.iter().enumerate() {
                assert!((e - f).abs() < 5e-5, "frame {i}: {e} vs {f}");
            }
        }
    }
}

#[test]
fn paper_interpolation_is_biased_between_bins() {
    // method.md: a tone at 50.0025 Hz (mid-bin) comes out ≈ +1.87 mHz off
    let x = tone(50.0025, 400.0, 40.0, 0.3);
    let est = StftTracker::new(400.0, PeakMethod::Paper).track(&x, (48.0, 52.0));
    let mid = est[20] - 50.0025;
    assert!(mid > 1.5e-3 && mid < 2.2e-3, "bias {mid}");
    let exact = StftTracker::new(400.0, PeakMethod::Exact).track(&x, (48.0, 52.0));
    assert!((exact[20] - 50.0025).abs() < 2e-5);
}

#[test]
fn silence_gives_nan() {
    let est = StftTracker::new(400.0, PeakMethod::Exact).track(&[0.0; 8000], (48.0, 52.0));
    assert!(est.iter().all(|v| v.is_nan()));
}
