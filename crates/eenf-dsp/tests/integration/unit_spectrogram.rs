//! Tests of eenf-dsp's `spectrogram` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_dsp::spectrogram::*;

#[test]
fn a_chirp_shows_its_frequency_in_each_window() {
    // 100 Hz rising by 0.01 Hz/s, sampled at 1 kHz for 60 s
    let fs = 1000.0;
    let x: Vec<f64> = (0..60_000)
        .map(|i| {
            let t = i as f64 / fs;
            (std::f64::consts::TAU * (100.0 * t + 0.005 * t * t)).cos()
        })
        .collect();
    let s = spectrogram(&x, fs, 8.0, 1.0, (98.0, 102.0));
    assert_eq!(s.time_s.len(), 61);
    let nf = s.freq_hz.len();
    for i in [10usize, 30, 50] {
        let row = &s.power_db[i * nf..(i + 1) * nf];
        let k = (0..nf).max_by(|&a, &b| row[a].total_cmp(&row[b])).unwrap();
        let want = 100.0 + 0.01 * s.time_s[i];
        assert!(
            (s.freq_hz[k] - want).abs() < 0.05,
            "t {}: peak {} Hz, want {want}",
            s.time_s[i],
            s.freq_hz[k]
        );
    }
    assert!(s.power_db.iter().all(|p| *p <= 0.0));
}
