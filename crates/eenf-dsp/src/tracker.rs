//! The centred STFT peak tracker: rectangular windows of `window_s`, a step of `step_s`, the
//! signal zero-padded by half a window at both ends (a recording of D s gives ≈ D + 1 estimates).

use std::f64::consts::PI;
use std::sync::Arc;

use rayon::prelude::*;
use realfft::num_complex::Complex64;
use realfft::{RealFftPlanner, RealToComplex};

/// A line weaker than this over its band's median power (dB, as
/// [`StftTracker::track_with_snr`] measures it) stands at the noise level: noise alone puts a
/// band's peak (the DTFT's maximum, a little above its largest bin) about 9 dB over the
/// median of its bins, past 12 dB in about one window in a hundred (white noise, 16 s windows,
/// ±2 Hz: 65 bins; in 3000 windows the median was 8.9 dB, the 99th percentile 12.1 dB). Such
/// an estimate may be noise's, not the grid's.
pub const NOISE_LEVEL_DB: f64 = 12.0;

/// How the peak frequency of each window is refined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PeakMethod {
    /// Maximise the window's DTFT magnitude (unbiased; a coarse FFT then Newton steps).
    Exact,
    /// The paper: FFT zero-padded to 0.005 Hz bins and complex quadratic interpolation
    /// (biased by up to ±1.9 mHz between bins, see `docs/method.md`).
    Paper,
}

impl PeakMethod {
    /// Every variant, by its command-line name.
    pub const NAMES: [&'static str; 2] = ["exact", "paper"];
}

impl std::fmt::Display for PeakMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(Self::NAMES[*self as usize])
    }
}

impl std::str::FromStr for PeakMethod {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "exact" => Ok(PeakMethod::Exact),
            "paper" => Ok(PeakMethod::Paper),
            _ => Err(format!("{s:?}: expected exact or paper")),
        }
    }
}

/// Tracks the strongest frequency in a band over sliding windows.
#[derive(Debug, Clone, Copy)]
pub struct StftTracker {
    /// Sampling rate of the input, Hz.
    pub fs: f64,
    /// Window length, s (16 in the paper).
    pub window_s: f64,
    /// Step between windows, s (1 in the paper).
    pub step_s: f64,
    /// Peak refinement.
    pub peak: PeakMethod,
    /// FFT bin width of the `paper` refinement, Hz (0.005: NFFT = 200·fs).
    pub paper_bin_hz: f64,
}

impl StftTracker {
    /// The paper's tracker (16 s, 1 s) at `fs` with the given refinement.
    pub fn new(fs: f64, peak: PeakMethod) -> Self {
        StftTracker {
            fs,
            window_s: 16.0,
            step_s: 1.0,
            peak,
            paper_bin_hz: 0.005,
        }
    }

    fn window_len(&self) -> usize {
        (self.window_s * self.fs).round().max(1.0) as usize
    }

    /// Samples between windows.
    pub fn step_len(&self) -> usize {
        (self.step_s * self.fs).round().max(1.0) as usize
    }

    /// Number of estimates for an input of `len` samples.
    pub fn frame_count(&self, len: usize) -> usize {
        let n = self.window_len();
        let padded = len + 2 * (n / 2);
        if len == 0 || padded < n {
            0
        } else {
            (padded - n) / self.step_len() + 1
        }
    }

    /// The peak frequency (Hz) in `band` of every window of `x`. A window whose band holds no
    /// energy gives NaN.
    pub fn track(&self, x: &[f64], band: (f64, f64)) -> Vec<f64> {
        self.track_with_snr(x, band)
            .into_iter()
            .map(|(f, _)| f)
            .collect()
    }

    /// [`StftTracker::track`], with each window's line strength: the peak's power over the
    /// median power of the band, in dB (noise alone gives about 8 dB; NaN without energy).
    pub fn track_with_snr(&self, x: &[f64], band: (f64, f64)) -> Vec<(f64, f64)> {
        self.track_frames(x, 0, x.len(), 0..self.frame_count(x.len()), band)
    }

    /// The samples (of a signal of `len`) that frames `frames` read: what a block must hold
    /// for [`StftTracker::track_frames`].
    pub fn frames_span(
        &self,
        frames: std::ops::Range<usize>,
        len: usize,
    ) -> std::ops::Range<usize> {
        let (n, step) = (self.window_len(), self.step_len());
        let lo = (frames.start * step).saturating_sub(n / 2).min(len);
        let hi = (frames.end.saturating_sub(1) * step + n)
            .saturating_sub(n / 2)
            .min(len);
        lo..hi.max(lo)
    }

    /// [`StftTracker::track_with_snr`]'s frames `frames` of a signal of `len` samples, of
    /// which `block` holds those from `block_start` on (at least [`StftTracker::frames_span`]):
    /// a long signal tracked a block at a time gives what it gives whole.
    pub fn track_frames(
        &self,
        block: &[f64],
        block_start: usize,
        len: usize,
        frames: std::ops::Range<usize>,
        band: (f64, f64),
    ) -> Vec<(f64, f64)> {
        let n = self.window_len();
        let half = n / 2;
        let step = self.step_len();
        let x = block;
        // segment of the block covered by frame i, and where it starts inside the frame
        let segment = move |i: usize| {
            let start = (i * step) as isize - half as isize;
            let lo = start.max(0) as usize;
            let hi = ((start + n as isize).max(0) as usize).min(len);
            let lo = lo.min(hi);
            (
                lo - block_start,
                hi - block_start,
                (lo as isize - start) as usize,
            )
        };
        let nfft = match self.peak {
            PeakMethod::Paper => (self.fs / self.paper_bin_hz).round() as usize,
            // the FFT only brackets the peak (its bins, 1/window apart at most, are narrower
            // than the main lobe); the DTFT itself is then maximised, and its power read there
            PeakMethod::Exact => n.next_power_of_two(),
        };
        let fft: Arc<dyn RealToComplex<f64>> = RealFftPlanner::new().plan_fft_forward(nfft);
        let df = self.fs / nfft as f64;
        let k_lo = ((band.0 / df).ceil() as usize).max(1);
        let k_hi = ((band.1 / df).floor() as usize).min(nfft / 2 - 1);
        let fs = self.fs;
        let peak = self.peak;
        frames
            .into_par_iter()
            .map_init(
                || {
                    (
                        fft.make_input_vec(),
                        fft.make_output_vec(),
                        fft.make_scratch_vec(),
                    )
                },
                |(input, spec, scratch), i| {
                    let (lo, hi, at) = segment(i);
                    input.iter_mut().for_each(|v| *v = 0.0);
                    input[at..at + (hi - lo)].copy_from_slice(&x[lo..hi]);
                    fft.process_with_scratch(input, spec, scratch)
                        .expect("buffers sized by the plan");
                    let (k, mag) = (k_lo..=k_hi)
                        .map(|k| (k, spec[k].norm_sqr()))
                        .fold((k_lo, -1.0), |b, c| if c.1 > b.1 { c } else { b });
                    if k_lo > k_hi || mag <= 0.0 {
                        return (f64::NAN, f64::NAN);
                    }
                    let median = {
                        let mut power: Vec<f64> =
                            (k_lo..=k_hi).map(|k| spec[k].norm_sqr()).collect();
                        let m = power.len() / 2;
                        *power.select_nth_unstable_by(m, f64::total_cmp).1
                    };
                    let snr = |peak_power: f64| {
                        if median > 0.0 {
                            10.0 * (peak_power / median).log10()
                        } else {
                            f64::INFINITY
                        }
                    };
                    let (f, snr_db) = match peak {
                        PeakMethod::Paper => {
                            let (a, b, c) = (spec[k - 1], spec[k], spec[k + 1]);
                            let delta = -((c - a) / (b * 2.0 - c - a)).re;
                            ((k as f64 + delta) * df, snr(mag))
                        }
                        PeakMethod::Exact => {
                            // start from the complex interpolation of the three bins (close
                            // at the window's own resolution: Newton needs two or three
                            // steps from there), then maximise the DTFT itself
                            let (a, b, c) = (spec[k - 1], spec[k], spec[k + 1]);
                            let p = -((c - a) / (b * 2.0 - c - a)).re;
                            let p = if p.is_finite() {
                                p.clamp(-0.5, 0.5)
                            } else {
                                0.0
                            };
                            let f0 = (k as f64 + p) * df;
                            let seg = &x[lo..hi];
                            let (f, power) =
                                dtft_peak(seg, fs, f0, ((k - 1) as f64 * df, (k + 1) as f64 * df));
                            (f, snr(power.max(mag)))
                        }
                    };
                    // a maximum on the band's first or last bin is the slope of something
                    // outside the band (or noise), not a line within it: no estimate
                    if k == k_lo || k == k_hi || !(band.0..=band.1).contains(&f) {
                        return (f64::NAN, snr_db);
                    }
                    (f, snr_db)
                },
            )
            .collect()
    }
}

/// Lanes of the DTFT sums: each lane's phasor advances by step⁴, so the four complex
/// recurrences run side by side instead of one after another.
const LANES: usize = 4;

/// The phasors e^{-iω·k}, k = 0..LANES, from `start`, and their common step e^{-iω·LANES}.
fn lanes(start: Complex64, w: f64) -> ([Complex64; LANES], Complex64) {
    let step = Complex64::from_polar(1.0, -w);
    let mut z = [start; LANES];
    for k in 1..LANES {
        z[k] = z[k - 1] * step;
    }
    (z, Complex64::from_polar(1.0, -w * LANES as f64))
}

/// |X|², and its first and second derivatives in ω, of the DTFT of `seg` at `f` Hz, with time
/// counted from the segment's centre (better conditioned).
fn dtft_derivs(seg: &[f64], fs: f64, f: f64) -> (f64, f64, f64) {
    let w = 2.0 * PI * f / fs;
    let c = (seg.len() as f64 - 1.0) / 2.0;
    let (mut z, step) = lanes(Complex64::from_polar(1.0, w * c), w);
    let zero = Complex64::default();
    let (mut a, mut b, mut cc) = ([zero; LANES], [zero; LANES], [zero; LANES]);
    let chunks = seg.chunks_exact(LANES);
    let tail = chunks.remainder();
    for (j, v) in chunks.enumerate() {
        for k in 0..LANES {
            let n = (j * LANES + k) as f64 - c;
            let t = z[k] * v[k];
            a[k] += t;
            b[k] += t * n;
            cc[k] += t * (n * n);
            z[k] *= step;
        }
        if j % 1024 == 1023 {
            // keep the phasors on the unit circle
            z.iter_mut().for_each(|z| *z /= z.norm());
        }
    }
    let (mut a, mut b, mut cc) = (
        a.iter().sum::<Complex64>(),
        b.iter().sum::<Complex64>(),
        cc.iter().sum::<Complex64>(),
    );
    for (k, &v) in tail.iter().enumerate() {
        let n = (seg.len() - tail.len() + k) as f64 - c;
        let t = z[k] * v;
        a += t;
        b += t * n;
        cc += t * (n * n);
    }
    let p = a.norm_sqr();
    let dp = 2.0 * (a.conj() * b).im;
    let ddp = 2.0 * (b.norm_sqr() - (a.conj() * cc).re);
    (p, dp, ddp)
}

fn dtft_power(seg: &[f64], fs: f64, f: f64) -> f64 {
    let w = 2.0 * PI * f / fs;
    let (mut z, step) = lanes(Complex64::new(1.0, 0.0), w);
    let mut a = [Complex64::default(); LANES];
    let chunks = seg.chunks_exact(LANES);
    let tail = chunks.remainder();
    for (j, v) in chunks.enumerate() {
        for k in 0..LANES {
            a[k] += z[k] * v[k];
            z[k] *= step;
        }
        if j % 1024 == 1023 {
            z.iter_mut().for_each(|z| *z /= z.norm());
        }
    }
    let mut sum = a.iter().sum::<Complex64>();
    for (k, &v) in tail.iter().enumerate() {
        sum += z[k] * v;
    }
    sum.norm_sqr()
}

/// The frequency in `bracket` that maximises |DTFT(seg)|, starting from `f0`, and |DTFT|²
/// there: Newton steps on the derivative, falling back to golden-section search if they leave
/// the bracket.
fn dtft_peak(seg: &[f64], fs: f64, f0: f64, bracket: (f64, f64)) -> (f64, f64) {
    let to_f = fs / (2.0 * PI);
    let mut f = f0;
    for _ in 0..12 {
        let (p, dp, ddp) = dtft_derivs(seg, fs, f);
        if ddp >= 0.0 {
            break;
        }
        let next = f - dp / ddp * to_f;
        if !(bracket.0..=bracket.1).contains(&next) {
            break;
        }
        // quadratic convergence: after a step this small the error is far below 1e-9 Hz, and
        // the power at `f` is the peak's to second order
        let done = (next - f).abs() < 1e-7;
        f = next;
        if done {
            return (f, p);
        }
    }
    // golden-section search on the bracket
    golden_section_max(|f| dtft_power(seg, fs, f), bracket, 1e-8)
}

/// The point of (a, b) where the unimodal `g` peaks, to within `tol`, and `g` there:
/// golden-section search.
pub(crate) fn golden_section_max(
    g: impl Fn(f64) -> f64,
    (mut a, mut b): (f64, f64),
    tol: f64,
) -> (f64, f64) {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - ratio * (b - a);
    let mut d = a + ratio * (b - a);
    let (mut gc, mut gd) = (g(c), g(d));
    while b - a > tol {
        if gc > gd {
            b = d;
            d = c;
            gd = gc;
            c = b - ratio * (b - a);
            gc = g(c);
        } else {
            a = c;
            c = d;
            gc = gd;
            d = a + ratio * (b - a);
            gd = g(d);
        }
    }
    ((a + b) / 2.0, gc.max(gd))
}
