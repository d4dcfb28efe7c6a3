//! How often the phase test fires on recordings nobody edited: the null model that sets its
//! threshold and gives each finding its false-alarm rate and p-value.
//!
//! With no edit, the jump a test measures at a boundary is Δ = s + e. The noise e is the
//! recording's own (Gaussian, its variance measured from the fits' residuals); alone it makes
//! a χ² field with one degree of freedom per line, whose upcrossings of t come
//! t^((K−1)/2)·e^(−t/2) times per correlation length (Adler 1981; Worsley 1994). The stray s is
//! the grid's: an outlet's phase is not smooth (the ENF ramps faster than a cubic follows over
//! long sides, local load switching turns the phase by a degree or two), and its tail is far
//! heavier than a normal one. It is measured, not modelled: on 24 continuous hours of real
//! 50 Hz mains (`../shared/enf-reference` and `../shared/mains-day`, one day in Wuhan), its
//! spread is that of a normal bulk, and the rate per hour at which |Δ| passes x degrees falls
//! as A·e^(−x/b) ([`STRAY_TAILS`], per side length; re-measured by
//! `crates/eenf/tests/integration/shared_edits_null.rs`). The rate at a boundary is the field's, its noise
//! widened by the stray's bulk, plus the stray's tail at its jump (the exponential convolved
//! with the boundary's normal noise).

use std::f64::consts::{PI, SQRT_2};

/// The grid's stray at one side length: the rate per hour at which the jump measured at the
/// boundaries of a continuous recording passes x degrees of the fundamental (peaks closer
/// than two sides counted once) is `rate_per_hour`·e^(−x / `scale_deg`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrayTail {
    /// The side length, s.
    pub side_s: f64,
    /// A: the tail's rate extrapolated to 0°, per hour.
    pub rate_per_hour: f64,
    /// b: the tail's scale, degrees of the fundamental.
    pub scale_deg: f64,
    /// The stray's robust spread on the calibration hours (their median), degrees: a
    /// recording whose own stray is wider has its tail widened in proportion.
    pub spread_deg: f64,
    /// Upcrossings per side length of the noise field at t^((K−1)/2)·e^(−t/2) = 1 (the
    /// statistic taken to its normal equivalent, [`NullModel::widened`]): 2 bounds what 20
    /// hours of smooth mains phase in white noise gave (`shared_edits.rs`: 0.4–0.7, 1.5–1.9 in
    /// the far tail). On the real hours in a phone's noise (`shared_edits_real.rs`, 15 hours
    /// tested at 10 s) the rate at 10 s sides came 2.2–4 times that: 5 there, and 3.5 at 5 s
    /// (between the two; too few hours chose 5 s to measure it).
    pub noise_scale: f64,
}

/// The stray's tails measured on the 24 real hours, by side. The exponential is fitted to the
/// rates between 0.1 and 10 per hour and raised until it lies on or above every measured rate
/// that rests on two peaks or more (A then rounded up), so that it bounds what was seen.
pub const STRAY_TAILS: [StrayTail; 4] = [
    StrayTail {
        side_s: 2.0,
        noise_scale: 2.0,
        rate_per_hour: 3.7e3,
        scale_deg: 0.262,
        spread_deg: 0.14,
    },
    StrayTail {
        side_s: 3.0,
        noise_scale: 2.0,
        rate_per_hour: 2.8e4,
        scale_deg: 0.314,
        spread_deg: 0.39,
    },
    StrayTail {
        side_s: 5.0,
        noise_scale: 3.5,
        rate_per_hour: 4.5e2,
        scale_deg: 1.661,
        spread_deg: 1.08,
    },
    StrayTail {
        side_s: 10.0,
        noise_scale: 5.0,
        rate_per_hour: 3.0e2,
        scale_deg: 2.139,
        spread_deg: 1.14,
    },
];

/// The null model of one recording's test: its lines, its side and its grid's stray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NullModel {
    /// Lines tested (degrees of freedom of the noise field).
    pub lines: usize,
    /// The side length, s.
    pub side_s: f64,
    /// The stray's tail: A per hour.
    pub stray_rate_per_hour: f64,
    /// The stray's tail: b, radians of the fundamental.
    pub stray_scale_rad: f64,
    /// The stray's bulk: its standard deviation, radians of the fundamental.
    pub stray_spread_rad: f64,
    /// The noise field's upcrossings per side length at t^((K−1)/2)·e^(−t/2) = 1.
    pub noise_scale: f64,
    /// Degrees of freedom of the noise variance each side measures from its own residuals.
    pub noise_dof: f64,
}

impl NullModel {
    /// The model for `lines` lines tested with sides of `side_s`, the stray of the calibration
    /// hours widened to `own_spread_deg` (the recording's own stray, degrees) when that is wider.
    /// A side between two measured ones takes the longer one's tail (the stray grows with the
    /// side); one past the longest widens its tail as side^1.2.
    pub fn new(lines: usize, side_s: f64, own_spread_deg: Option<f64>) -> Self {
        let last = STRAY_TAILS[STRAY_TAILS.len() - 1];
        let (tail, widen) = match STRAY_TAILS.iter().find(|t| t.side_s >= side_s - 1e-9) {
            Some(t) => (*t, 1.0),
            None => (last, (side_s / last.side_s).powf(1.2)),
        };
        let own = own_spread_deg
            .filter(|s| s.is_finite())
            .map_or(1.0, |s| (s / (tail.spread_deg * widen)).max(1.0));
        NullModel {
            lines: lines.clamp(1, 16),
            side_s: side_s.max(0.1),
            stray_rate_per_hour: tail.rate_per_hour,
            stray_scale_rad: (tail.scale_deg * widen * own).to_radians(),
            stray_spread_rad: (tail.spread_deg * widen * own).to_radians(),
            noise_scale: tail.noise_scale,
            // a side of m blocks: m residuals, less its mean and its share of the cubic; both
            // sides' variances together
            noise_dof: (2.0 * side_s / super::BLOCK_S - 5.0).max(4.0),
        }
    }

    /// The noise statistic `t` of a boundary of noise precision `precision` as the field sees
    /// it. The stray's bulk is added to the noise (÷ (1 + σ²·precision)). The noise is measured
    /// from the sides' own residuals, so the statistic is a squared Student t, whose tail is far
    /// heavier than the normal's at short sides; its degrees of freedom are
    /// [`NullModel::noise_dof`], raised by Satterthwaite's rule where the known stray carries
    /// part of the variance, and Wallace's (1959) normal equivalent ν·ln(1 + t/ν)·((8ν+1)/(8ν+3))²
    /// maps it back.
    pub fn widened(&self, t: f64, precision: f64) -> f64 {
        let s = self.stray_spread_rad;
        let grow = 1.0 + s * s * precision.max(0.0);
        let nu = self.noise_dof * grow * grow;
        let c = (8.0 * nu + 1.0) / (8.0 * nu + 3.0);
        nu * (t.max(0.0) / grow / nu).ln_1p() * c * c
    }

    /// Upcrossings of `t` per hour by the noise field alone.
    pub fn noise_rate(&self, t: f64) -> f64 {
        let k = self.lines as f64;
        self.noise_scale * 3600.0 / self.side_s.max(1.0)
            * t.max(0.0).powf((k - 1.0) / 2.0)
            * (-t / 2.0).exp()
    }

    /// The rate per hour at which the grid's stray, seen through noise of variance
    /// `noise_var` (rad²), passes `jump` (rad): A·E[e^(−(|Δ|−e)/b); |Δ|−e > 0], that is
    /// A·e^(−x/b + σ²/2b²)·Φ((x − σ²/b)/σ), computed in logarithms (the two factors over- and
    /// underflow together when the noise dominates).
    pub fn stray_rate(&self, jump: f64, noise_var: f64) -> f64 {
        let x = jump.abs();
        let b = self.stray_scale_rad;
        let v = noise_var.max(0.0);
        let ln_a = self.stray_rate_per_hour.ln();
        if v <= 1e-300 {
            return (ln_a - x / b).exp();
        }
        let s = v.sqrt();
        (ln_a - x / b + v / (2.0 * b * b) + ln_normal_cdf((x - v / b) / s)).exp()
    }

    /// False alarms per hour at a boundary whose noise statistic is `t` and whose jump is
    /// `jump` (rad) with noise precision `precision` (rad⁻²).
    pub fn rate(&self, t: f64, jump: f64, precision: f64) -> f64 {
        self.noise_rate(self.widened(t, precision))
            + self.stray_rate(jump, 1.0 / precision.max(1e-300))
    }

    /// The noise statistic whose upcrossings come `rate` times per hour: the scale on which the
    /// test's statistic and threshold are given (a rate of 0.05 per hour is the same statistic
    /// whatever the side, the lines aside).
    pub fn statistic_for(&self, rate: f64) -> f64 {
        // the field's rate falls monotonically beyond t = K − 1, where the bisection starts
        let (mut lo, mut hi) = ((self.lines - 1) as f64, 5000.0f64);
        if self.noise_rate(hi) >= rate {
            return hi;
        }
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if self.noise_rate(mid) > rate {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }

    /// The smallest jump (rad) that reaches `rate` at a boundary of noise precision
    /// `precision`, or infinity when even a half-turn does not.
    pub fn min_jump(&self, precision: f64, rate: f64) -> f64 {
        let at = |x: f64| self.rate(x * x * precision, x, precision);
        if at(PI) > rate {
            return f64::INFINITY;
        }
        let (mut lo, mut hi) = (0.0, PI);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if at(mid) > rate {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }
}

/// ln Φ(z), the standard normal distribution function, accurate far into the lower tail.
pub fn ln_normal_cdf(z: f64) -> f64 {
    if z > -30.0 {
        (0.5 * libm::erfc(-z / SQRT_2)).ln()
    } else {
        // Mills' ratio: Φ(z) ≈ φ(z)/|z|·(1 − 1/z²)
        -0.5 * z * z - (-z).ln() - 0.5 * (2.0 * PI).ln() + (1.0 - 1.0 / (z * z)).ln()
    }
}
