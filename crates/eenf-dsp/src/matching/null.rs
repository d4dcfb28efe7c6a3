//! The null of a search: how the best score of unrelated data is distributed, from the block
//! maxima of the reference's own scores.

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
    for lag in 1..=max_lag {
        let c = s[..n - lag]
            .iter()
            .zip(&s[lag..])
            .map(|(a, b)| (a - mean) * (b - mean))
            .sum::<f64>()
            / ((n - lag) as f64 * var);
        if c < (-1.0f64).exp() {
            return lag as f64;
        }
    }
    max_lag as f64
}
