//! Tests of eenf-dsp's `flicker` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_dsp::flicker::*;

use crate::test_noise as noise;

/// A tone in noise: the line is found to a few mHz, stands, and its prominence grows with its
/// amplitude; noise alone does not stand.
#[test]
fn finds_a_line_in_noise_and_none_in_noise_alone() {
    let fs = 1000.0;
    let n = 40_000;
    let mut draw = noise(0x1234_5678_9abc_def0);
    let noise: Vec<f64> = (0..n).map(|_| draw()).collect();
    let alone = flicker_line(&noise, fs).unwrap();
    assert!(!alone.stands, "{alone:?}");
    assert!(
        alone.floor_db.unwrap() < alone.threshold_db.unwrap(),
        "{alone:?}"
    );
    let tone = |a: f64, f: f64| -> Vec<f64> {
        noise
            .iter()
            .enumerate()
            .map(|(i, v)| v + a * (2.0 * std::f64::consts::PI * f * i as f64 / fs).sin())
            .collect()
    };
    let weak = flicker_line(&tone(0.08, 119.69), fs).unwrap();
    let strong = flicker_line(&tone(0.3, 119.69), fs).unwrap();
    for l in [weak, strong] {
        assert_eq!(l.grid_hz, 60.0);
        assert!((l.hz - 119.69).abs() < 0.005, "{l:?}");
        assert!((l.offset + 0.00258).abs() < 1e-4, "{l:?}");
    }
    assert!(weak.is_mains() && strong.prominence > 3.0 * weak.prominence);
    let fifty = flicker_line(&tone(0.1, 99.98), fs).unwrap();
    assert_eq!(fifty.grid_hz, 50.0);
    assert!((fifty.hz - 99.98).abs() < 0.005, "{fifty:?}");
    assert!(flicker_line(&noise[..500], fs).is_none());
}

#[test]
fn line_strength_is_read_where_the_line_is_and_about_one_elsewhere() {
    let fs = 500.0;
    let mut draw = noise(0x2545_f491_4f6c_dd1d);
    let x: Vec<f64> = (0..20_000)
        .map(|i| draw() + 0.3 * (2.0 * std::f64::consts::PI * 100.02 * i as f64 / fs).sin())
        .collect();
    let at = line_strength_at(&x, fs, 100.02).unwrap();
    let off = line_strength_at(&x, fs, 117.3).unwrap();
    assert!(at > 10.0, "{at}");
    assert!((0.3..3.5).contains(&off), "{off}");
}
