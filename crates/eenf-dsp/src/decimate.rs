//! Anti-aliased decimation: an 8th-order Butterworth low-pass run forwards and backwards
//! (zero phase, as scipy's `sosfiltfilt`), then every `factor`-th sample.

use crate::butter::{butter_lowpass, Section};
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

/// Decimation of a stream as it arrives: the same low-pass as [`decimate`], run forward only
/// (a causal filter; its group delay near the mains bands, a few ms and flat, shifts a trace by
/// nothing that its 1 s steps could see), so that an hour of audio never sits in memory at its
/// own rate.
pub struct StreamDecimator {
    sos: Vec<Section>,
    /// Direct form II transposed state of each section.
    state: Vec<[f64; 2]>,
    factor: usize,
    /// Samples since the last one kept.
    phase: usize,
    fs_out: f64,
}

impl StreamDecimator {
    /// A decimator from `fs` that keeps every band up to `top_hz` (see [`decimation_for`]);
    /// it passes samples through untouched when no decimation is possible.
    pub fn new(fs: f64, top_hz: f64) -> Self {
        let (factor, cutoff) = decimation_for(fs, top_hz);
        let sos = if factor > 1 {
            butter_lowpass(ANTI_ALIAS_ORDER, cutoff, fs)
        } else {
            Vec::new()
        };
        StreamDecimator {
            state: vec![[0.0; 2]; sos.len()],
            sos,
            factor,
            phase: 0,
            fs_out: fs / factor as f64,
        }
    }

    /// The output rate, Hz.
    pub fn fs_out(&self) -> f64 {
        self.fs_out
    }

    /// The decimation factor (1: samples pass through).
    pub fn factor(&self) -> usize {
        self.factor
    }

    /// Filters `x` and appends every `factor`-th output to `out`.
    pub fn push(&mut self, x: &[f64], out: &mut Vec<f64>) {
        if self.factor <= 1 {
            out.extend_from_slice(x);
            return;
        }
        for &v in x {
            let mut y = v;
            for (s, z) in self.sos.iter().zip(self.state.iter_mut()) {
                // direct form II transposed
                let o = s[0] * y + z[0];
                z[0] = s[1] * y - s[4] * o + z[1];
                z[1] = s[2] * y - s[5] * o;
                y = o;
            }
            if self.phase == 0 {
                out.push(y);
            }
            self.phase += 1;
            if self.phase == self.factor {
                self.phase = 0;
            }
        }
    }
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
    fn a_stream_in_pieces_is_decimated_as_a_whole_and_keeps_its_tone() {
        let fs = 44_100.0;
        let x = tone(150.0, fs, 441_000);
        let mut whole = StreamDecimator::new(fs, 182.0);
        assert!(whole.factor() > 40 && whole.fs_out() >= 700.0, "{}", whole.fs_out());
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
        assert!((rms(settled) / 0.5f64.sqrt() - 1.0).abs() < 2e-3, "{}", rms(settled));
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
}
