//! Anti-aliased decimation: an 8th-order Butterworth low-pass run forwards and backwards
//! (zero phase, as scipy's `sosfiltfilt`), then every `factor`-th sample.

use crate::butter::butter_lowpass;
use crate::filtfilt::sosfiltfilt;

/// Order of the anti-alias low-pass.
pub const ANTI_ALIAS_ORDER: usize = 8;

/// `x` sampled at `fs`, low-passed at `cutoff` Hz and kept every `factor`-th sample (the first
/// kept). A `factor` of 1 or less returns a copy.
///
/// Panics if `cutoff` is not inside (0, fs/2).
pub fn decimate(x: &[f64], fs: f64, factor: usize, cutoff: f64) -> Vec<f64> {
    if factor <= 1 {
        return x.to_vec();
    }
    let sos = butter_lowpass(ANTI_ALIAS_ORDER, cutoff, fs);
    let y = sosfiltfilt(&sos, x);
    y.into_iter().step_by(factor).collect()
}

/// The decimation that keeps every band up to `top_hz`: the largest factor whose output rate
/// leaves the low-pass (cut off at 1.6 × `top_hz`, flat to 0.1 % at `top_hz`) room to
/// suppress what would fold onto the bands by more than 100 dB. Returns (factor, cutoff).
pub fn decimation_for(fs: f64, top_hz: f64) -> (usize, f64) {
    let cutoff = 1.6 * top_hz;
    // what folds onto `top_hz` comes from fs_out − top_hz: keep it ≥ 2.1 × the cutoff
    let fs_out = top_hz + 2.1 * cutoff;
    let factor = (fs / fs_out).floor().max(1.0) as usize;
    (factor, cutoff)
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
