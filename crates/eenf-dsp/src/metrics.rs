//! Agreement between an estimated ENF trace and a reference.

/// Metrics over the seconds both traces cover.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Agreement {
    /// Pearson correlation coefficient.
    pub cc: f64,
    /// Mean absolute error, Hz.
    pub mae_hz: f64,
    /// Root-mean-square error, Hz.
    pub rmse_hz: f64,
    /// Largest absolute error, Hz.
    pub max_err_hz: f64,
    /// Number of estimates compared (seconds at the usual 1 s step; `seconds` in JSON).
    #[serde(rename = "seconds")]
    pub n: usize,
}

/// Pearson CC, MAE, RMSE and max error of `est` against `reference` (pairs with a non-finite
/// value are left out). `None` when fewer than two pairs remain.
pub fn agreement(est: &[f64], reference: &[f64]) -> Option<Agreement> {
    let pairs: Vec<(f64, f64)> = est
        .iter()
        .zip(reference)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(a, b)| (*a, *b))
        .collect();
    let n = pairs.len();
    if n < 2 {
        return None;
    }
    let nf = n as f64;
    let (ma, mb) = pairs
        .iter()
        .fold((0.0, 0.0), |s, p| (s.0 + p.0 / nf, s.1 + p.1 / nf));
    let (mut sab, mut saa, mut sbb, mut abs, mut sq, mut max) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0f64);
    for &(a, b) in &pairs {
        let (da, db) = (a - ma, b - mb);
        sab += da * db;
        saa += da * da;
        sbb += db * db;
        let e = (a - b).abs();
        abs += e;
        sq += e * e;
        max = max.max(e);
    }
    let den = (saa * sbb).sqrt();
    Some(Agreement {
        cc: if den > 0.0 { sab / den } else { f64::NAN },
        mae_hz: abs / nf,
        rmse_hz: (sq / nf).sqrt(),
        max_err_hz: max,
        n,
    })
}

/// 1.4826 × the median absolute deviation of the finite values of `v`: the standard deviation
/// of the bulk, unmoved by a few values that stand out (NaN when there are none).
pub fn robust_spread(v: &[f64]) -> f64 {
    let mut v: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    let mid = v.len() / 2;
    let centre = *v.select_nth_unstable_by(mid, f64::total_cmp).1;
    let mut dev: Vec<f64> = v.iter().map(|x| (x - centre).abs()).collect();
    1.4826 * *dev.select_nth_unstable_by(mid, f64::total_cmp).1
}
