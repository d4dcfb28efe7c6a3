//! Placing an ENF trace in time: normalised cross-correlation against a long reference at every
//! offset, with a significance that accounts for the trace's length and autocorrelation.

use std::sync::Arc;

use rayon::prelude::*;

use crate::metrics::Agreement;
use realfft::num_complex::Complex64;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};

/// How matching is done.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct MatchOptions {
    /// Candidates to report.
    pub top: usize,
    /// Offsets closer than this (in steps) to a better candidate are not reported.
    pub exclusion: usize,
    /// Least share of the trace that must overlap valid reference values.
    pub min_overlap: f64,
    /// What ranks offsets and sets the significance.
    pub score: Score,
    /// An offset to check (a claimed time), scored and ranked among all offsets.
    pub verify: Option<usize>,
}

/// How a claimed offset scores.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Verification {
    /// The offset checked.
    pub offset: usize,
    /// CC, MAE, RMSE, max error and values compared there.
    pub agreement: Agreement,
    /// 1 + the number of offsets (farther than the exclusion zone) that score better.
    pub rank: usize,
    /// Significance of its score, as for candidates.
    pub p_value: f64,
}

/// The statistic that ranks offsets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Score {
    /// atanh(CC) − ln(RMSE): shape and level together. A clip from another time often has some
    /// window of similar shape (CC ≈ 0.99) but rarely one at the same frequency level too.
    Combined,
    /// Normalised cross-correlation alone (shape only; robust to a constant bias).
    Cc,
}

impl Score {
    /// Every score, by its command-line name.
    pub const NAMES: [&'static str; 2] = ["combined", "cc"];
}

impl std::fmt::Display for Score {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(Self::NAMES[*self as usize])
    }
}

impl std::str::FromStr for Score {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "combined" => Ok(Score::Combined),
            "cc" => Ok(Score::Cc),
            _ => Err(format!("{s:?}: expected combined or cc")),
        }
    }
}

impl Default for MatchOptions {
    fn default() -> Self {
        MatchOptions {
            top: 5,
            exclusion: 60,
            min_overlap: 0.8,
            score: Score::Combined,
            verify: None,
        }
    }
}

/// One place where the trace fits.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Candidate {
    /// Offset of the trace's first value in the reference, in steps (fractional after
    /// refinement of the correlation peak).
    pub offset: f64,
    /// CC, MAE, RMSE, max error and values compared at the integer offset.
    pub agreement: Agreement,
    /// Probability that the best of all offsets of unrelated data scores this well.
    pub p_value: f64,
}

/// The outcome of a search.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MatchResult {
    /// Best candidates, best first.
    pub candidates: Vec<Candidate>,
    /// Offsets scored.
    pub offsets: usize,
    /// Offsets over which scores stay correlated (from their autocorrelation).
    pub score_corr_len: f64,
    /// Blocks whose maxima calibrate the significance, and their length in offsets.
    pub null_blocks: usize,
    /// See `null_blocks`.
    pub block_len: usize,
    /// The tail of the null: the k-th largest block maximum `tail_u` and the mean excess over
    /// it `tail_beta` of the k − 1 above it (an exponential tail).
    pub tail_u: f64,
    /// See `tail_u`.
    pub tail_beta: f64,
    /// See `tail_u`.
    pub tail_k: usize,
    /// The claimed offset, when one was given.
    pub verification: Option<Verification>,
}

/// The significance threshold that `eenf match` calls a match.
pub const DEFAULT_ALPHA: f64 = 1e-3;

/// Why matching could not be done.
#[derive(Debug, Clone, thiserror::Error)]
pub enum MatchError {
    /// The trace is too short or too empty.
    #[error("the trace has {0} usable values; at least 10 are needed")]
    TooShort(usize),
    /// The reference is shorter than the trace.
    #[error("the reference ({reference} values) is shorter than the trace ({trace})")]
    ReferenceTooShort {
        /// Reference length.
        reference: usize,
        /// Trace length.
        trace: usize,
    },
    /// The trace does not vary at all.
    #[error("the trace is constant: it cannot be placed in time")]
    Flat,
}

/// Values of a reference series, read where needed (a year of them need not be copied).
pub trait ReferenceValues: Sync {
    /// Number of values.
    fn len(&self) -> usize;
    /// Value `i` in Hz, NaN for a gap.
    fn get(&self, i: usize) -> f64;
    /// True when there is no value.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl ReferenceValues for [f64] {
    fn len(&self) -> usize {
        <[f64]>::len(self)
    }
    #[inline]
    fn get(&self, i: usize) -> f64 {
        self[i]
    }
}

/// A series stored as integers: `offset_hz + value · scale_hz`, with `gap` marking none.
pub struct ScaledSeries<'a> {
    /// Stored values.
    pub values: &'a [i32],
    /// Value of 0, Hz.
    pub offset_hz: f64,
    /// Hz per unit.
    pub scale_hz: f64,
    /// The value that marks a gap.
    pub gap: i32,
}

impl ReferenceValues for ScaledSeries<'_> {
    fn len(&self) -> usize {
        self.values.len()
    }
    #[inline]
    fn get(&self, i: usize) -> f64 {
        let v = self.values[i];
        if v == self.gap {
            f64::NAN
        } else {
            self.offset_hz + v as f64 * self.scale_hz
        }
    }
}

/// Fills NaN gaps of a trace by linear interpolation (ends by the nearest value).
pub fn fill_gaps(x: &[f64]) -> Vec<f64> {
    let mut out = x.to_vec();
    let valid: Vec<usize> = (0..x.len()).filter(|&i| x[i].is_finite()).collect();
    if valid.is_empty() {
        return out;
    }
    for i in 0..x.len() {
        if x[i].is_finite() {
            continue;
        }
        let next = valid.partition_point(|&v| v < i);
        out[i] = match (next.checked_sub(1).map(|p| valid[p]), valid.get(next)) {
            (Some(a), Some(&b)) => x[a] + (x[b] - x[a]) * (i - a) as f64 / (b - a) as f64,
            (Some(a), None) => x[a],
            (None, Some(&b)) => x[b],
            (None, None) => f64::NAN,
        };
    }
    out
}

/// Pearson CC, MAE and RMSE of `q` against `r[k..k + q.len()]` over the values valid in both.
fn score_at<R: ReferenceValues + ?Sized>(q: &[f64], r: &R, k: usize) -> Agreement {
    // one pass of running sums (this runs per candidate over long references); the two-pass
    // [`crate::agreement`] is kept for comparisons, whose numbers it defines
    let (mut n, mut sq, mut sr, mut sqq, mut srr, mut sqr, mut abs, mut sq_err, mut max) =
        (0usize, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0f64);
    for (i, a) in q.iter().enumerate() {
        let b = &r.get(k + i);
        if a.is_finite() && b.is_finite() {
            n += 1;
            sq += a;
            sr += b;
            sqq += a * a;
            srr += b * b;
            sqr += a * b;
            abs += (a - b).abs();
            sq_err += (a - b) * (a - b);
            max = max.max((a - b).abs());
        }
    }
    if n < 3 {
        return Agreement {
            cc: f64::NAN,
            mae_hz: f64::NAN,
            rmse_hz: f64::NAN,
            max_err_hz: f64::NAN,
            n,
        };
    }
    let nf = n as f64;
    let cov = sqr - sq * sr / nf;
    let den = ((sqq - sq * sq / nf) * (srr - sr * sr / nf)).sqrt();
    Agreement {
        cc: if den > 0.0 { cov / den } else { f64::NAN },
        mae_hz: abs / nf,
        rmse_hz: (sq_err / nf).sqrt(),
        max_err_hz: max,
        n,
    }
}

/// A monotone stand-in for [`statistic`] that needs no logarithm, kept for every offset:
/// CC itself, or (1 + CC) / ((1 − CC)·RMSE²), whose half logarithm is the combined score.
#[inline]
fn rank_key(score: Score, cc: f64, rmse: f64) -> f64 {
    let c = cc.clamp(-0.999_999, 0.999_999);
    match score {
        Score::Cc => c,
        Score::Combined => {
            let e = rmse.max(1e-6);
            (1.0 + c) / ((1.0 - c) * e * e)
        }
    }
}

/// The score from its key.
pub fn key_to_statistic(score: Score, key: f64) -> f64 {
    match score {
        Score::Cc => key.atanh(),
        Score::Combined => 0.5 * key.ln(),
    }
}

/// The score of `q` (no gaps, zero mean; `q_mean` is its mean relative to `r_mean`) against
/// every window of `reference` (NaN = gap; `r_mean` is subtracted on the fly to keep the running
/// sums well conditioned), by overlap-save FFT blocks and running sums; windows with gaps are
/// scored directly.
pub fn scores_all<R: ReferenceValues + ?Sized>(
    q: &[f64],
    q_mean: f64,
    reference: &R,
    r_mean: f64,
    min_valid: usize,
    score: Score,
) -> Vec<f32> {
    let r = reference;
    let m = q.len();
    let n_off = r.len() - m + 1;
    let block = (4 * m).next_power_of_two().max(1 << 15);
    let hop = block - m + 1;
    let mut planner = RealFftPlanner::<f64>::new();
    let fwd: Arc<dyn RealToComplex<f64>> = planner.plan_fft_forward(block);
    let inv: Arc<dyn ComplexToReal<f64>> = planner.plan_fft_inverse(block);
    let mut qbuf = vec![0.0; block];
    qbuf[..m].copy_from_slice(q);
    let mut qspec = fwd.make_output_vec();
    fwd.process(&mut qbuf, &mut qspec).expect("sized by plan");
    let qspec: Vec<Complex64> = qspec.iter().map(|c| c.conj() / block as f64).collect();
    let q_norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    // Σ (q + q_mean)² for the RMSE
    let q_abs_sq = q.iter().map(|v| (v + q_mean) * (v + q_mean)).sum::<f64>();
    let mut out = vec![f32::NAN; n_off];
    // the trace in the reference's own units, for windows with gaps
    let q_raw: Vec<f64> = q.iter().map(|v| v + q_mean + r_mean).collect();
    out.par_chunks_mut(hop).enumerate().for_each_init(
        || {
            (
                vec![f64::NAN; block],
                fwd.make_input_vec(),
                fwd.make_output_vec(),
                fwd.make_scratch_vec(),
                inv.make_scratch_vec(),
            )
        },
        |(seg, buf, spec, s1, s2), (bi, dst)| {
            let start = bi * hop;
            let seg_len = (start + block).min(r.len()) - start;
            // the block's values relative to the reference mean, NaN for gaps and past the end
            for (j, d) in seg.iter_mut().enumerate() {
                *d = if j < seg_len {
                    r.get(start + j) - r_mean
                } else {
                    f64::NAN
                };
            }
            // gaps count as zero in the FFT; their windows are redone below
            for (d, &v) in buf.iter_mut().zip(seg.iter()) {
                *d = if v.is_finite() { v } else { 0.0 };
            }
            fwd.process_with_scratch(buf, spec, s1)
                .expect("sized by plan");
            for (a, b) in spec.iter_mut().zip(&qspec) {
                *a *= b;
            }
            inv.process_with_scratch(spec, buf, s2)
                .expect("sized by plan");
            // running window sums of r, r² and the gap count
            let (mut s, mut ss, mut gaps) = (0.0f64, 0.0f64, 0usize);
            for &v in &seg[..m] {
                if v.is_finite() {
                    s += v;
                    ss += v * v;
                } else {
                    gaps += 1;
                }
            }
            let inv_m = 1.0 / m as f64;
            for (k, o) in dst.iter_mut().enumerate() {
                if k > 0 {
                    let (old, new) = (seg[k - 1], seg[k + m - 1]);
                    if old.is_finite() {
                        s -= old;
                        ss -= old * old;
                    } else {
                        gaps -= 1;
                    }
                    if new.is_finite() {
                        s += new;
                        ss += new * new;
                    } else {
                        gaps += 1;
                    }
                }
                let (cc, e) = if gaps == 0 {
                    let var = ss - s * s * inv_m;
                    let cc = buf[k] / (q_norm * var.sqrt());
                    // Σ(q − r)² = Σq² − 2Σq·r + Σr², with Σq·r = Σ(q − q̄)·r + q̄·Σr
                    let sse = q_abs_sq - 2.0 * (buf[k] + q_mean * s) + ss;
                    (cc, (sse.max(0.0) * inv_m).sqrt())
                } else if m - gaps >= min_valid {
                    let a = score_at(&q_raw, r, start + k);
                    (a.cc, a.rmse_hz)
                } else {
                    (f64::NAN, f64::NAN)
                };
                // a flat window (var = 0) gives a non-finite CC and no score
                *o = if cc.is_finite() && e.is_finite() {
                    rank_key(score, cc, e) as f32
                } else {
                    f32::NAN
                };
            }
        },
    );
    out
}

/// Finds where `trace` (step-aligned with `reference`, NaN = missing) best fits in
/// `reference` (NaN = gap).
pub fn match_trace<R: ReferenceValues + ?Sized>(
    trace: &[f64],
    reference: &R,
    opts: &MatchOptions,
) -> Result<MatchResult, MatchError> {
    let usable = trace.iter().filter(|v| v.is_finite()).count();
    if usable < 10 {
        return Err(MatchError::TooShort(usable));
    }
    if reference.len() < trace.len() {
        return Err(MatchError::ReferenceTooShort {
            reference: reference.len(),
            trace: trace.len(),
        });
    }
    let filled = fill_gaps(trace);
    let mean = filled.iter().sum::<f64>() / filled.len() as f64;
    let q: Vec<f64> = filled.iter().map(|v| v - mean).collect();
    if q.iter().all(|v| v.abs() < 1e-12) {
        return Err(MatchError::Flat);
    }
    let min_valid = ((opts.min_overlap * trace.len() as f64).ceil() as usize).max(3);
    // deviations from the reference's own mean keep the running sums well conditioned
    let r_mean = {
        let (s, n) = (0..reference.len())
            .into_par_iter()
            .map(|i| reference.get(i))
            .filter(|v| v.is_finite())
            .fold(|| (0.0, 0usize), |(s, n), v| (s + v, n + 1))
            .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        if n > 0 {
            s / n as f64
        } else {
            0.0
        }
    };
    let cc = scores_all(&q, mean - r_mean, reference, r_mean, min_valid, opts.score);

    // How far scores stay correlated, then the null from block maxima: the best score in a
    // stretch of reference unrelated to the trace follows a Gumbel law.
    let stat = |key: f32| key_to_statistic(opts.score, key as f64);
    let sample: Vec<f32> = cc[..cc.len().min(1 << 18)]
        .iter()
        .map(|&k| {
            if k.is_finite() {
                stat(k) as f32
            } else {
                f32::NAN
            }
        })
        .collect();
    let corr_len = score_correlation_length(&sample, trace.len());
    let nz = cc.par_iter().filter(|c| c.is_finite()).count();
    let block_len = ((4.0 * corr_len).ceil() as usize)
        .max(trace.len() / 2)
        .max(10);
    let picked = best_offsets(&cc, opts.top, opts.exclusion);
    let best_at = picked.first().copied().unwrap_or(0);
    let maxima: Vec<f64> = cc
        .par_chunks(block_len)
        .enumerate()
        // leave out the blocks near the best offset: they may hold the real match
        .filter(|(i, _)| {
            let (lo, hi) = (i * block_len, (i + 1) * block_len);
            hi + trace.len() <= best_at || lo > best_at + trace.len()
        })
        .filter_map(|(_, c)| {
            c.iter()
                .copied()
                .filter(|v| v.is_finite())
                .max_by(f32::total_cmp)
        })
        .map(stat)
        .collect();
    let tail = TailFit::new(maxima.clone());

    let candidates = picked
        .into_iter()
        .map(|k| {
            let agreement = score_at(&filled, reference, k);
            // sub-step offset from a parabola through the neighbouring scores
            let at = |i: Option<usize>| {
                i.and_then(|i| cc.get(i))
                    .filter(|v| v.is_finite())
                    .map(|v| stat(*v))
            };
            let frac = match (at(k.checked_sub(1)), at(Some(k + 1))) {
                (Some(a), Some(b)) => {
                    let c0 = stat(cc[k]);
                    let den = a - 2.0 * c0 + b;
                    if den < 0.0 {
                        (0.5 * (a - b) / den).clamp(-0.5, 0.5)
                    } else {
                        0.0
                    }
                }
                _ => 0.0,
            };
            Candidate {
                offset: k as f64 + frac,
                agreement,
                p_value: tail.p_value(stat(cc[k])),
            }
        })
        .collect();
    let verification = opts.verify.and_then(|k| {
        let agreement = score_offset(trace, reference, k)?;
        let key = cc.get(k).copied().filter(|v| v.is_finite())?;
        let sk = stat(key);
        let better = cc
            .par_iter()
            .enumerate()
            .filter(|(i, v)| v.is_finite() && **v > key && i.abs_diff(k) >= opts.exclusion)
            .count();
        Some(Verification {
            offset: k,
            agreement,
            rank: better + 1,
            p_value: tail.p_value(sk),
        })
    });
    Ok(MatchResult {
        verification,
        candidates,
        offsets: nz,
        score_corr_len: corr_len,
        null_blocks: maxima.len(),
        block_len,
        tail_u: tail.u,
        tail_beta: tail.beta,
        tail_k: tail.k,
    })
}

/// The `top` best offsets by key, each at least `exclusion` away from every better one
/// (greedy, ties to the earlier offset). Chunk maxima are found in parallel; a pick only
/// makes the chunks under its exclusion zone be scanned again.
pub fn best_offsets(keys: &[f32], top: usize, exclusion: usize) -> Vec<usize> {
    const CHUNK: usize = 4096;
    let exclusion = exclusion.max(1);
    let best_in = |c: usize, picked: &[usize]| -> Option<(usize, f32)> {
        let lo = c * CHUNK;
        let hi = (lo + CHUNK).min(keys.len());
        let mut best: Option<(usize, f32)> = None;
        for (k, &v) in (lo..hi).zip(&keys[lo..hi]) {
            // NaN fails both comparisons
            if best.map_or(v.is_finite(), |b| v > b.1)
                && picked.iter().all(|p| p.abs_diff(k) >= exclusion)
            {
                best = Some((k, v));
            }
        }
        best
    };
    let n_chunks = keys.len().div_ceil(CHUNK);
    let mut chunk_best: Vec<Option<(usize, f32)>> = (0..n_chunks)
        .into_par_iter()
        .map(|c| best_in(c, &[]))
        .collect();
    let mut picked = Vec::with_capacity(top);
    while picked.len() < top {
        let next = chunk_best
            .iter()
            .flatten()
            .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)));
        let Some(&(k, _)) = next else { break };
        picked.push(k);
        let first = k.saturating_sub(exclusion - 1) / CHUNK;
        let last = ((k + exclusion - 1) / CHUNK).min(n_chunks - 1);
        for (c, best) in chunk_best.iter_mut().enumerate().take(last + 1).skip(first) {
            *best = best_in(c, &picked);
        }
    }
    picked
}

/// CC, MAE, RMSE, max error and overlap at one offset, for checking a claimed time.
pub fn score_offset<R: ReferenceValues + ?Sized>(
    trace: &[f64],
    reference: &R,
    k: usize,
) -> Option<Agreement> {
    if k + trace.len() > reference.len() {
        return None;
    }
    Some(score_at(&fill_gaps(trace), reference, k))
}

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
fn score_correlation_length(cc: &[f32], m: usize) -> f64 {
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
