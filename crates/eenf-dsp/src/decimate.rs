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
/// suppress what would fold onto the bands by more than 100 dB, and, for an integer `fs`, an
/// integer output rate. Returns (factor, cutoff).
pub fn decimation_for(fs: f64, top_hz: f64) -> (usize, f64) {
    let cutoff = 1.6 * top_hz;
    // what folds onto `top_hz` comes from fs_out − top_hz: keep it ≥ 2.1 × the cutoff
    let fs_out = top_hz + 2.1 * cutoff;
    let most = (fs / fs_out).floor().max(1.0) as usize;
    // an integer rate stays an integer (44.1 kHz by 49 → 900 Hz), so that a tracker's 1 s
    // steps are whole samples and its estimates do not drift from the recording's seconds
    let factor = if fs.fract() == 0.0 && fs <= u64::MAX as f64 {
        (1..=most)
            .rev()
            .find(|f| (fs as u64).is_multiple_of(*f as u64))
            .unwrap_or(1)
    } else {
        most
    };
    (factor, cutoff)
}

/// Decimation of a stream as it arrives, so that an hour of audio never sits in memory at its
/// own rate: linear-phase FIR low-passes (a delay of half their length, well under a second,
/// taken back out) that compute only the samples they keep. A factor of 16 or more is taken in
/// two stages, the second for the last factor of about 4. Each stage passes the bands flat and
/// suppresses what would fold onto them by 100 dB.
pub struct StreamDecimator {
    stages: Vec<FirStage>,
    /// Output of the first stage, fed to the second.
    mid: Vec<f64>,
    fs_out: f64,
    delay_s: f64,
}

/// A Kaiser-windowed sinc low-pass that computes only every `factor`-th output (a recursive
/// filter must run at the full rate, one sample after another; this one is a few multiplies
/// per input sample, in vector registers).
struct FirStage {
    taps: Vec<f64>,
    factor: usize,
    /// The last `taps.len() − 1` inputs, then the new ones.
    buf: Vec<f64>,
    /// Position in `buf` of the next output's newest input.
    next: usize,
}

impl FirStage {
    /// Passes `pass` Hz, stops from `stop` Hz (100 dB), at `fs`.
    fn new(fs: f64, pass: f64, stop: f64, factor: usize) -> Self {
        let atten = 100.0;
        let beta = 0.1102 * (atten - 8.7);
        let width = 2.0 * std::f64::consts::PI * (stop - pass) / fs;
        let n = (((atten - 8.0) / (2.285 * width)).ceil() as usize) | 1;
        let fc = 0.5 * (pass + stop) / fs;
        let m = (n - 1) as f64 / 2.0;
        let i0 = |x: f64| {
            // modified Bessel function of the first kind, order 0 (series)
            let (mut sum, mut term, mut k) = (1.0, 1.0, 1.0);
            while term > 1e-16 * sum {
                term *= (x / (2.0 * k)).powi(2);
                sum += term;
                k += 1.0;
            }
            sum
        };
        let mut taps: Vec<f64> = (0..n)
            .map(|i| {
                let t = i as f64 - m;
                let sinc = if t == 0.0 {
                    2.0 * fc
                } else {
                    (2.0 * std::f64::consts::PI * fc * t).sin() / (std::f64::consts::PI * t)
                };
                let r = t / m;
                sinc * i0(beta * (1.0 - r * r).max(0.0).sqrt()) / i0(beta)
            })
            .collect();
        let dc: f64 = taps.iter().sum();
        taps.iter_mut().for_each(|t| *t /= dc);
        FirStage {
            buf: vec![0.0; n - 1],
            next: n - 1,
            taps,
            factor,
        }
    }

    fn push(&mut self, x: &[f64], out: &mut Vec<f64>) {
        let n = self.taps.len();
        self.buf.extend_from_slice(x);
        while self.next < self.buf.len() {
            let window = &self.buf[self.next + 1 - n..=self.next];
            out.push(window.iter().zip(&self.taps).map(|(a, b)| a * b).sum());
            self.next += self.factor;
        }
        // keep what the next outputs still need
        let keep_from = self.next + 1 - n;
        let keep_from = keep_from.min(self.buf.len());
        self.buf.drain(..keep_from);
        self.next -= keep_from;
    }
}

impl StreamDecimator {
    /// A decimator from `fs` that keeps every band up to `top_hz` (see [`decimation_for`]);
    /// it passes samples through untouched when no decimation is possible.
    pub fn new(fs: f64, top_hz: f64) -> Self {
        let (factor, _) = decimation_for(fs, top_hz);
        // two stages when the factor splits into two of at least 2, the second near 4
        let split = (2..=factor / 2)
            .filter(|q| factor.is_multiple_of(*q))
            .min_by_key(|q| q.abs_diff(4));
        let factors = match (factor, split) {
            (f, Some(q)) if f >= 16 => vec![f / q, q],
            (f, _) if f > 1 => vec![f],
            _ => vec![],
        };
        let (mut rate, mut delay_s) = (fs, 0.0);
        let stages = factors
            .into_iter()
            .map(|q| {
                let out = rate / q as f64;
                // what folds onto the top band comes from `out − top_hz` and above
                let stage = FirStage::new(rate, top_hz, out - top_hz, q);
                delay_s += (stage.taps.len() - 1) as f64 / 2.0 / rate;
                rate = out;
                stage
            })
            .collect();
        StreamDecimator {
            stages,
            mid: Vec::new(),
            fs_out: rate,
            delay_s,
        }
    }

    /// The output rate, Hz.
    pub fn fs_out(&self) -> f64 {
        self.fs_out
    }

    /// The decimation factor (1: samples pass through).
    pub fn factor(&self) -> usize {
        self.stages.iter().map(|s| s.factor).product()
    }

    /// Filters `x` and appends the decimated output to `out`.
    pub fn push(&mut self, x: &[f64], out: &mut Vec<f64>) {
        match self.stages.as_mut_slice() {
            [] => out.extend_from_slice(x),
            [one] => one.push(x, out),
            [first, second, ..] => {
                self.mid.clear();
                first.push(x, &mut self.mid);
                second.push(&self.mid, out);
            }
        }
    }

    /// Seconds by which the output lags the input: the FIRs' half lengths (a few ms).
    pub fn delay_s(&self) -> f64 {
        self.delay_s
    }
}
