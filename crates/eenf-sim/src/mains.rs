//! The mains voltage's phase over time, from which lamps flicker and the ground truth is made.

use std::f64::consts::PI;

use eenf_dsp::{butter_bandpass, sosfiltfilt, EnfParams, PeakMethod, StftTracker};
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rustfft::{num_complex::Complex64, FftPlanner};

/// Unwrapped phase φ(t) of the mains voltage v(t) = cos φ(t), sampled at `fs` from t = 0.
#[derive(Debug, Clone)]
pub struct MainsPhase {
    /// Sampling rate of `phase`, Hz.
    pub fs: f64,
    /// φ at t = i / fs, radians.
    pub phase: Vec<f64>,
    /// Nominal frequency, Hz.
    pub nominal_hz: f64,
}

/// Why the mains phase could not be made.
#[derive(Debug, Clone, thiserror::Error)]
pub enum MainsError {
    /// The requested span is not inside the recording.
    #[error(
        "the mains recording lasts {available_s:.1} s; {start_s} s + {duration_s} s does not fit"
    )]
    OutOfRange {
        /// Length of the recording, s.
        available_s: f64,
        /// Requested start, s.
        start_s: f64,
        /// Requested duration, s.
        duration_s: f64,
    },
    /// The sampling rate cannot carry the mains tone.
    #[error("a sampling rate of {fs} Hz cannot carry a {nominal} Hz mains tone")]
    RateTooLow {
        /// Sampling rate, Hz.
        fs: f64,
        /// Nominal frequency, Hz.
        nominal: f64,
    },
}

/// The synthetic ENF process: a slow Ornstein–Uhlenbeck wander, "swings" (ramps whose rate is
/// itself a random process, pulled back towards the slow level) and per-second jitter.
/// Defaults are fitted to the shared Wuhan references as the reference tracker sees them:
/// std ≈ 20 mHz, 60 s ranges with median ≈ 20 mHz, 1 s steps with std ≈ 1 mHz that are only
/// weakly correlated.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct SyntheticEnf {
    /// Standard deviation of the slow wander, Hz.
    pub slow_std_hz: f64,
    /// Correlation time of the slow wander, s.
    pub slow_tau_s: f64,
    /// Standard deviation of the swing rate, Hz per second.
    pub rate_std_hz: f64,
    /// Correlation time of the swing rate, s.
    pub rate_tau_s: f64,
    /// Time constant pulling a swing back, s.
    pub restore_tau_s: f64,
    /// Per-second jitter, Hz.
    pub jitter_std_hz: f64,
}

impl Default for SyntheticEnf {
    fn default() -> Self {
        SyntheticEnf {
            slow_std_hz: 0.015,
            slow_tau_s: 1800.0,
            rate_std_hz: 0.0007,
            rate_tau_s: 15.0,
            restore_tau_s: 60.0,
            jitter_std_hz: 0.011,
        }
    }
}

impl SyntheticEnf {
    /// `seconds` values of the ENF at 1 s steps around `nominal_hz`.
    pub fn per_second(&self, nominal_hz: f64, seconds: usize, seed: u64) -> Vec<f64> {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let mut g = || rng.sample::<f64, _>(StandardNormal);
        let a = (-1.0 / self.slow_tau_s).exp();
        let av = (-1.0 / self.rate_tau_s).exp();
        let mut slow = self.slow_std_hz * g();
        let mut rate = self.rate_std_hz * g();
        let mut swing = 0.0;
        let warmup = (5.0 * self.restore_tau_s) as usize;
        let mut out = Vec::with_capacity(seconds);
        for i in 0..warmup + seconds {
            slow = a * slow + self.slow_std_hz * (1.0 - a * a).sqrt() * g();
            rate = av * rate + self.rate_std_hz * (1.0 - av * av).sqrt() * g();
            swing = swing * (1.0 - 1.0 / self.restore_tau_s) + rate;
            let jitter = self.jitter_std_hz * g();
            if i >= warmup {
                out.push(nominal_hz + slow + swing + jitter);
            }
        }
        out
    }
}

const PHASE_FS: f64 = 1000.0;

/// Catmull-Rom interpolation of `v` at fractional index `x` (clamped at both ends).
fn spline_at(v: &[f64], x: f64) -> f64 {
    if v.len() < 2 {
        return v.first().copied().unwrap_or(0.0);
    }
    let last = v.len() - 1;
    let x = x.clamp(0.0, last as f64);
    let i = (x.floor() as usize).min(last - 1);
    let u = x - i as f64;
    let p = |k: isize| v[(i as isize + k).clamp(0, last as isize) as usize];
    let (p0, p1, p2, p3) = (p(-1), p(0), p(1), p(2));
    p1 + 0.5
        * u
        * (p2 - p0 + u * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + u * (3.0 * (p1 - p2) + p3 - p0)))
}

/// The phase (rad, modulo 2π) that the frequency series `freq_hz` (values `step_s` apart,
/// interpolated as [`MainsPhase::from_frequency`] does) accumulates from its start to `t_s`.
/// The spline is cubic between knots, so Simpson's rule per knot interval is exact; pieces of
/// one series cut at different starts then join with a continuous phase.
pub fn phase_from_start(freq_hz: &[f64], step_s: f64, t_s: f64) -> f64 {
    let x_end = (t_s / step_s).max(0.0);
    let simpson = |a: f64, b: f64| {
        (b - a) / 6.0
            * (spline_at(freq_hz, a)
                + 4.0 * spline_at(freq_hz, 0.5 * (a + b))
                + spline_at(freq_hz, b))
    };
    let whole = x_end.floor() as usize;
    let mut cycles = 0.0f64;
    for i in 0..whole {
        // whole cycles do not matter: keep the fraction so precision holds over days
        cycles = (cycles + simpson(i as f64, (i + 1) as f64) * step_s).fract();
    }
    cycles += simpson(whole as f64, x_end) * step_s;
    2.0 * PI * cycles.fract()
}

impl MainsPhase {
    /// A wandering ENF from the synthetic process, linearly interpolated between seconds and
    /// integrated into phase.
    pub fn synthetic(nominal_hz: f64, duration_s: f64, stats: SyntheticEnf, seed: u64) -> Self {
        let per_second = stats.per_second(nominal_hz, duration_s.ceil() as usize + 2, seed);
        let phase0 = (seed % 6283) as f64 * 1e-3;
        Self::from_frequency(nominal_hz, &per_second, 1.0, 0.0, duration_s, phase0)
    }

    /// Integrates a frequency trace given every `step_s` seconds, from `t0_s` seconds after its
    /// first value, for `duration_s`. Between values the frequency follows a Catmull-Rom
    /// spline, so it moves smoothly (no corners every step); the same trace and `t0_s` always
    /// give the same frequency, so a recording and an hour-long reference cut from one trace
    /// agree.
    pub fn from_frequency(
        nominal_hz: f64,
        freq_hz: &[f64],
        step_s: f64,
        t0_s: f64,
        duration_s: f64,
        phase0: f64,
    ) -> Self {
        let n = (duration_s * PHASE_FS).ceil() as usize + 2;
        let mut phase = Vec::with_capacity(n);
        let mut acc = phase0;
        let f_at = |t: f64| spline_at(freq_hz, (t0_s + t) / step_s);
        let mut f_prev = f_at(0.0);
        for i in 0..n {
            phase.push(acc);
            // trapezoid over one phase sample
            let f_next = f_at((i + 1) as f64 / PHASE_FS);
            acc += 2.0 * PI * 0.5 * (f_prev + f_next) / PHASE_FS;
            f_prev = f_next;
        }
        MainsPhase {
            fs: PHASE_FS,
            phase,
            nominal_hz,
        }
    }

    /// The mains voltage as a sound card records it through a transformer: `fs` samples per
    /// second of cos φ with a little 3rd-harmonic distortion and noise, scaled to ±0.6.
    pub fn voltage(&self, fs: f64, seed: u64) -> Vec<f64> {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let n = (self.duration_s() * fs).floor() as usize;
        (0..n)
            .map(|i| {
                let phi = self.phase_at(i as f64 / fs);
                let noise: f64 = rng.sample(StandardNormal);
                0.6 * (phi.cos() + 0.04 * (3.0 * phi + 0.3).cos()) + 0.004 * noise
            })
            .collect()
    }

    /// The phase of a recorded mains signal `x` (sampled at `fs`) from `start_s` for
    /// `duration_s`: a narrow zero-phase band-pass around the nominal frequency, then the
    /// analytic signal's unwrapped phase.
    pub fn from_recording(
        x: &[f64],
        fs: f64,
        nominal_hz: f64,
        start_s: f64,
        duration_s: f64,
    ) -> Result<Self, MainsError> {
        if nominal_hz + 1.0 >= fs / 2.0 {
            return Err(MainsError::RateTooLow {
                fs,
                nominal: nominal_hz,
            });
        }
        let available_s = x.len() as f64 / fs;
        if start_s < 0.0 || start_s + duration_s > available_s {
            return Err(MainsError::OutOfRange {
                available_s,
                start_s,
                duration_s,
            });
        }
        // margins keep filter and Hilbert edge effects out of the span
        let margin = (20.0 * fs) as usize;
        let a = ((start_s * fs) as usize).saturating_sub(margin);
        let b = (((start_s + duration_s) * fs).ceil() as usize + margin + 2).min(x.len());
        let sos = butter_bandpass(2, nominal_hz - 1.0, nominal_hz + 1.0, fs);
        let y = sosfiltfilt(&sos, &x[a..b]);
        let n = y.len();
        let mut buf: Vec<Complex64> = y.iter().map(|&v| Complex64::new(v, 0.0)).collect();
        let mut planner = FftPlanner::new();
        planner.plan_fft_forward(n).process(&mut buf);
        for (k, c) in buf.iter_mut().enumerate() {
            let gain = if k == 0 || (n.is_multiple_of(2) && k == n / 2) {
                1.0
            } else if k < n.div_ceil(2) {
                2.0
            } else {
                0.0
            };
            *c *= gain / n as f64;
        }
        planner.plan_fft_inverse(n).process(&mut buf);
        let mut phase = Vec::with_capacity(n);
        let mut prev = 0.0;
        let mut unwrap = 0.0;
        for c in &buf {
            let p = c.arg();
            if !phase.is_empty() {
                let d = p - prev;
                if d < -PI {
                    unwrap += 2.0 * PI;
                } else if d > PI {
                    unwrap -= 2.0 * PI;
                }
            }
            prev = p;
            phase.push(p + unwrap);
        }
        let skip = (start_s * fs) as usize - a;
        let frac = start_s * fs - (start_s * fs).floor();
        // resample to PHASE_FS from t = start_s
        let len = (duration_s * PHASE_FS).ceil() as usize + 2;
        let src = |t: f64| {
            let x = t * fs + skip as f64 + frac;
            let i = (x.floor() as usize).min(phase.len() - 2);
            let w = x - i as f64;
            phase[i] * (1.0 - w) + phase[i + 1] * w
        };
        Ok(MainsPhase {
            fs: PHASE_FS,
            phase: (0..len).map(|i| src(i as f64 / PHASE_FS)).collect(),
            nominal_hz,
        })
    }

    /// φ(t), linearly interpolated (t in seconds from the start; before the start the phase
    /// runs on at the nominal frequency).
    #[inline]
    pub fn phase_at(&self, t: f64) -> f64 {
        if t < 0.0 {
            return self.phase[0] + 2.0 * PI * self.nominal_hz * t;
        }
        let x = t * self.fs;
        let i = (x as usize).min(self.phase.len() - 2);
        let w = x - i as f64;
        self.phase[i] + (self.phase[i + 1] - self.phase[i]) * w
    }

    /// Seconds covered.
    pub fn duration_s(&self) -> f64 {
        (self.phase.len() - 2) as f64 / self.fs
    }

    /// The ground-truth ENF of the first `duration_s` seconds: the reference tracker (same
    /// windows, centring and step as `eenf reference`, exact peak) on the clean voltage cos φ
    /// sampled at 400 Hz, so that a perfect estimator scores MAE ≈ 0.
    pub fn truth(&self, duration_s: f64) -> Vec<f64> {
        let fs = 400.0;
        let n = (duration_s * fs).round() as usize;
        let v: Vec<f64> = (0..n).map(|i| self.phase_at(i as f64 / fs).cos()).collect();
        let p = EnfParams {
            nominal_hz: self.nominal_hz,
            ..EnfParams::default()
        };
        let band = (p.nominal_hz - p.half_band_hz, p.nominal_hz + p.half_band_hz);
        StftTracker::new(fs, PeakMethod::Exact).track(&v, band)
    }
}
