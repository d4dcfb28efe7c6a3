//! Outlier correction and harmonic selection of per-harmonic ENF traces.

/// Running-median outlier correction (the authors' "TDMF"): an estimate farther than
/// `threshold` from the median of the `len` estimates centred on it is replaced by that median.
/// Near the ends the window is shortened to what exists.
pub fn median_correct(trace: &[f64], len: usize, threshold: f64) -> Vec<f64> {
    let half = len / 2;
    let mut buf = Vec::with_capacity(len);
    (0..trace.len())
        .map(|i| {
            buf.clear();
            let lo = i.saturating_sub(half);
            let hi = (i + half + 1).min(trace.len());
            buf.extend(trace[lo..hi].iter().copied().filter(|v| v.is_finite()));
            if buf.is_empty() {
                return trace[i];
            }
            buf.sort_by(|a, b| a.partial_cmp(b).unwrap());
            let m = buf.len();
            let med = if m % 2 == 1 {
                buf[m / 2]
            } else {
                (buf[m / 2 - 1] + buf[m / 2]) / 2.0
            };
            if !trace[i].is_finite() || (trace[i] - med).abs() > threshold {
                med
            } else {
                trace[i]
            }
        })
        .collect()
}

/// Picks, in each segment of `segment` estimates, the trace that is smoothest
/// (smallest Σ|f[n] − f[n−1]| inside the segment). `traces` are on a common scale (the ENF).
/// Returns the combined trace and the index of the trace chosen for each segment.
pub fn select_smoothest(traces: &[Vec<f64>], segment: usize) -> (Vec<f64>, Vec<usize>) {
    let n = traces.iter().map(|t| t.len()).min().unwrap_or(0);
    let segment = segment.max(1);
    let mut out = Vec::with_capacity(n);
    let mut chosen = Vec::with_capacity(n.div_ceil(segment));
    for start in (0..n).step_by(segment) {
        let end = (start + segment).min(n);
        let roughness = |t: &Vec<f64>| -> f64 {
            let r: f64 = t[start..end].windows(2).map(|w| (w[1] - w[0]).abs()).sum();
            if r.is_finite() {
                r
            } else {
                f64::INFINITY
            }
        };
        let best = (0..traces.len())
            .min_by(|&a, &b| roughness(&traces[a]).total_cmp(&roughness(&traces[b])))
            .unwrap_or(0);
        chosen.push(best);
        out.extend_from_slice(&traces[best][start..end]);
    }
    (out, chosen)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_replaces_spikes_only() {
        let mut t: Vec<f64> = (0..50).map(|i| 100.0 + 0.001 * i as f64).collect();
        t[25] += 0.5;
        let c = median_correct(&t, 21, 0.02);
        // the spike sorts to the top of its window, so the median is the 11th of the rest
        assert!((c[25] - 100.026).abs() < 1e-9, "{}", c[25]);
        for i in (0..50).filter(|&i| i != 25) {
            assert_eq!(c[i], t[i]);
        }
    }

    #[test]
    fn the_smoothest_trace_wins_per_segment() {
        let smooth: Vec<f64> = (0..20).map(|i| 50.0 + 1e-4 * i as f64).collect();
        let mut noisy = smooth.clone();
        for (i, v) in noisy.iter_mut().enumerate().take(10) {
            *v += if i % 2 == 0 { 0.01 } else { -0.01 };
        }
        let mut rough_late = smooth.clone();
        for (i, v) in rough_late.iter_mut().enumerate().skip(10) {
            *v += if i % 2 == 0 { 0.02 } else { -0.02 };
        }
        let (out, chosen) = select_smoothest(&[noisy, rough_late.clone()], 10);
        assert_eq!(chosen, vec![1, 0]);
        assert_eq!(out[..10], rough_late[..10]);
    }
}
