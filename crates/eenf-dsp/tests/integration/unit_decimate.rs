//! Tests of eenf-dsp's `decimate` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_dsp::butter_lowpass;
use eenf_dsp::decimate::*;

#[test]
#[allow(clippy::excessive_precision)] // scipy's printed digits, as they are
fn lowpass_matches_scipy() {
    // scipy.signal.butter(8, 700, btype="low", fs=10000, output="sos") (scipy 1.14)
    let scipy: [[f64; 6]; 4] = [
        [
            1.9947506440331322e-06,
            3.9895012880662643e-06,
            1.9947506440331322e-06,
            1.0,
            -1.2765636139118355e+00,
            4.1083714333328519e-01,
        ],
        [
            1.0,
            2.0,
            1.0,
            1.0,
            -1.3365021985616892e+00,
            4.7708028282220388e-01,
        ],
        [
            1.0,
            2.0,
            1.0,
            1.0,
            -1.4634698682260141e+00,
            6.1740286636818276e-01,
        ],
        [
            1.0,
            2.0,
            1.0,
            1.0,
            -1.6708631565737775e+00,
            8.4661052299442185e-01,
        ],
    ];
    let sos = butter_lowpass(8, 700.0, 10_000.0);
    assert_eq!(sos.len(), 4);
    for (a, b) in sos.iter().zip(&scipy) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-12 * y.abs().max(1.0), "{a:?} vs {b:?}");
        }
    }
}

fn tone(f: f64, fs: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| (2.0 * std::f64::consts::PI * f * i as f64 / fs).sin())
        .collect()
}

fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

#[test]
fn a_stream_in_pieces_is_decimated_as_a_whole_and_keeps_its_tone() {
    let fs = 44_100.0;
    let x = tone(150.0, fs, 441_000);
    let mut whole = StreamDecimator::new(fs, 182.0);
    assert!(
        whole.factor() > 40 && whole.fs_out() >= 700.0,
        "{}",
        whole.fs_out()
    );
    let mut a = Vec::new();
    whole.push(&x, &mut a);
    let mut parts = StreamDecimator::new(fs, 182.0);
    let mut b = Vec::new();
    for chunk in x.chunks(997) {
        parts.push(chunk, &mut b);
    }
    assert_eq!(a, b);
    assert_eq!(a.len(), x.len().div_ceil(whole.factor()));
    // the 150 Hz tone passes at full height once the filter has settled
    let settled = &a[a.len() / 2..];
    assert!(
        (rms(settled) / 0.5f64.sqrt() - 1.0).abs() < 2e-3,
        "{}",
        rms(settled)
    );
    // what would fold onto 150 Hz at either stage is gone (> 100 dB down)
    let fs_out = whole.fs_out();
    for f in [fs_out - 150.0, fs_out * 4.0 - 150.0, 2.0 * fs_out + 150.0] {
        let mut d = StreamDecimator::new(fs, 182.0);
        let mut y = Vec::new();
        d.push(&tone(f, fs, 441_000), &mut y);
        let settled = &y[y.len() / 2..];
        assert!(
            rms(settled) < 1e-5 * 0.5f64.sqrt(),
            "{f} Hz: {}",
            rms(settled)
        );
    }
    // and a 400 Hz mains WAV's rate passes untouched
    let mut none = StreamDecimator::new(400.0, 62.0);
    let mut c = Vec::new();
    none.push(&x[..1000], &mut c);
    assert_eq!((none.factor(), &c[..]), (1, &x[..1000]));
}

#[test]
fn bands_pass_and_what_would_fold_onto_them_is_gone() {
    let fs = 10_000.0;
    let (factor, cutoff) = decimation_for(fs, 482.0);
    assert_eq!(factor, 4);
    let n = 50_000;
    // the 4th band of a 60 Hz grid passes whole (middle half, away from the edges)
    let y = decimate(&tone(480.0, fs, n), fs, factor, cutoff);
    let mid = &y[y.len() / 4..3 * y.len() / 4];
    assert!(
        (rms(mid) / 0.5f64.sqrt() - 1.0).abs() < 1e-3,
        "{}",
        rms(mid)
    );
    // what would fold onto the bands at 2.5 kHz (onto 482, 200 and 100 Hz) is suppressed
    // by more than 100 dB
    for f in [2018.0, 2300.0, 2400.0] {
        let y = decimate(&tone(f, fs, n), fs, factor, cutoff);
        let mid = &y[y.len() / 4..3 * y.len() / 4];
        assert!(rms(mid) < 1e-5 * 0.5f64.sqrt(), "{f} Hz: {}", rms(mid));
    }
}
