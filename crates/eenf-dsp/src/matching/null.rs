//! The null of a search: how the best score of unrelated data is distributed, from the block
//! maxima of the reference's own scores.

use realfft::num_complex::Complex64;
use realfft::RealFftPlanner;

/// An exponential tail fitted to the largest block maxima of the null (peaks over threshold).
/// The blocks differ (parts of the reference at other frequency levels score far lower), so
/// only the top of the distribution is modelled.
pub struct TailFit {
    /// The threshold: the smallest of the `k` largest maxima.
    pub u: f64,
    /// The mean excess over `u` of the larger ones (the exponential's scale).
    pub beta: f64,
    /// How many maxima the tail holds.
    pub k: usize,
}

impl TailFit {
    /// Fits the tail to the block maxima.
    pub fn new(mut maxima: Vec<f64>) -> Self {
        maxima.sort_by(|a, b| b.total_cmp(a));
        let k = (maxima.len() / 4).clamp(3, 20).min(maxima.len());
        if k < 3 {
            return TailFit {
                u: f64::NAN,
                beta: f64::NAN,
                k,
            };
        }
        let u = maxima[k - 1];
        let beta = (maxima[..k - 1].iter().map(|m| m - u).sum::<f64>() / (k - 1) as f64).max(1e-9);
        TailFit { u, beta, k }
    }

    /// P(some null block scores ≥ s): 1 − exp(−λ), λ = expected null blocks above s.
    pub fn p_value(&self, s: f64) -> f64 {
        if !(self.u.is_finite() && self.beta.is_finite()) {
            return 1.0;
        }
        let lambda = self.k as f64 * (-(s - self.u).max(0.0) / self.beta).exp();
        -(-lambda).exp_m1()
    }
}

/// Lag (in offsets) at which the autocorrelation of the score sequence falls below 1/e,
/// measured on up to 2^18 offsets.
pub(crate) fn score_correlation_length(cc: &[f32], m: usize) -> f64 {
    let n = cc.len().min(1 << 18);
    let s: Vec<f64> = cc[..n]
        .iter()
        .map(|v| if v.is_finite() { *v as f64 } else { 0.0 })
        .collect();
    let mean = s.iter().sum::<f64>() / n as f64;
    let var = s.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64;
    if var <= 0.0 || n < 4 {
        return 1.0;
    }
    let max_lag = (2 * m).min(n / 2).max(1);
    // every lag's autocovariance at once, by FFT (a search of an hour-long trace looks up to
    // 7200 lags into 2^18 scores): zero-padded past n + max_lag, so no lag wraps around
    let len = (n + max_lag + 1).next_power_of_two();
    let mut planner = RealFftPlanner::<f64>::new();
    let (fwd, inv) = (planner.plan_fft_forward(len), planner.plan_fft_inverse(len));
    let mut x = fwd.make_input_vec();
    for (d, v) in x.iter_mut().zip(&s) {
        *d = v - mean;
    }
    let mut spec = fwd.make_output_vec();
    fwd.process(&mut x, &mut spec).expect("sized by plan");
    for c in spec.iter_mut() {
        *c = Complex64::new(c.norm_sqr(), 0.0);
    }
    inv.process(&mut spec, &mut x).expect("sized by plan");
    // x[lag] = len · Σ (s_i − mean)(s_{i+lag} − mean)
    for (lag, &cov) in x.iter().enumerate().take(max_lag + 1).skip(1) {
        let c = cov / len as f64 / ((n - lag) as f64 * var);
        if c < (-1.0f64).exp() {
            return lag as f64;
        }
    }
    max_lag as f64
}

#[cfg(test)]
mod tests {
    use super::score_correlation_length;

    /// The lag where the autocorrelation falls below 1/e, one lag at a time (the definition).
    fn by_definition(s: &[f64], max_lag: usize) -> f64 {
        let n = s.len();
        let mean = s.iter().sum::<f64>() / n as f64;
        let var = s.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64;
        for lag in 1..=max_lag {
            let c = (0..n - lag)
                .map(|i| (s[i] - mean) * (s[i + lag] - mean))
                .sum::<f64>()
                / ((n - lag) as f64 * var);
            if c < (-1.0f64).exp() {
                return lag as f64;
            }
        }
        max_lag as f64
    }

    #[test]
    fn the_correlation_length_is_that_of_an_ar1_series() {
        // x_i = φ·x_{i−1} + noise has autocorrelation φ^lag: below 1/e from lag −1/ln φ
        let (phi, n) = (0.99f64, 1 << 16);
        let mut state = 12345u64;
        let mut noise = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut x = 0.0;
        let s: Vec<f64> = (0..n)
            .map(|_| {
                x = phi * x + noise();
                x
            })
            .collect();
        let keys: Vec<f32> = s.iter().map(|&v| v as f32).collect();
        let m = 400; // looks up to 800 lags
        let got = score_correlation_length(&keys, m);
        let exact = by_definition(&keys.iter().map(|&v| v as f64).collect::<Vec<_>>(), 2 * m);
        assert_eq!(got, exact);
        let theory = -1.0 / phi.ln();
        assert!((got - theory).abs() < 0.3 * theory, "{got} vs {theory}");
    }
}
