//! Placing an ENF trace in time: normalised cross-correlation against a long reference at every
//! offset, with a significance that accounts for the trace's length and autocorrelation.

use std::collections::HashMap;

use rayon::prelude::*;

use crate::metrics::Agreement;

mod null;
mod scores;

use null::score_correlation_length;
pub use null::TailFit;
use scores::Scorer;

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
    /// The reference could not be read (its file and the cause).
    #[error("{0}")]
    Read(String),
}

/// Values of a reference series, read a stretch at a time where needed: a decade of them is
/// never held at once.
pub trait ReferenceValues: Sync {
    /// Number of values.
    fn len(&self) -> usize;
    /// Values `start .. start + dst.len()` in Hz, NaN for a gap (the stretch lies inside).
    fn read(&self, start: usize, dst: &mut [f64]) -> Result<(), MatchError>;
    /// [`Self::read`] for a search, which reads the series a block at a time and calls
    /// [`Self::end_pass`] once it has read every block: the first `own` values of `dst` are
    /// this block's own (every value is one block's own). A reader that checks its values
    /// (a store's checksums) may check them as they pass, once, rather than read them all
    /// before.
    fn read_in_pass(&self, start: usize, dst: &mut [f64], own: usize) -> Result<(), MatchError> {
        let _ = own;
        self.read(start, dst)
    }
    /// Called once every block has been read by [`Self::read_in_pass`], before any answer
    /// is given: fails when what was read does not check out.
    fn end_pass(&self) -> Result<(), MatchError> {
        Ok(())
    }
    /// True when there is no value.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The mean of the values that are not gaps (0 when all are), read in stretches.
    fn finite_mean(&self) -> Result<f64, MatchError> {
        const STRETCH: usize = 1 << 16;
        let sums = (0..self.len().div_ceil(STRETCH))
            .into_par_iter()
            .map_init(
                || vec![0.0; STRETCH],
                |buf, i| {
                    let lo = i * STRETCH;
                    let part = &mut buf[..STRETCH.min(self.len() - lo)];
                    self.read(lo, part)?;
                    let finite = part.iter().filter(|v| v.is_finite());
                    Ok(finite.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1)))
                },
            )
            .collect::<Result<Vec<_>, MatchError>>()?;
        let (s, n) = sums
            .iter()
            .fold((0.0, 0usize), |(s, n), (a, b)| (s + a, n + b));
        Ok(if n > 0 { s / n as f64 } else { 0.0 })
    }
    /// Values `start .. start + n`, as far as the series goes.
    fn window(&self, start: usize, n: usize) -> Result<Vec<f64>, MatchError> {
        let n = n.min(self.len().saturating_sub(start));
        let mut out = vec![f64::NAN; n];
        self.read(start, &mut out)?;
        Ok(out)
    }
}

impl ReferenceValues for [f64] {
    fn len(&self) -> usize {
        <[f64]>::len(self)
    }
    fn read(&self, start: usize, dst: &mut [f64]) -> Result<(), MatchError> {
        dst.copy_from_slice(&self[start..start + dst.len()]);
        Ok(())
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

/// Pearson CC, MAE and RMSE of `q` against `r` (as long) over the values valid in both.
fn score_at(q: &[f64], r: &[f64]) -> Agreement {
    // one pass of running sums (this runs per candidate over long references); the two-pass
    // [`crate::agreement`] is kept for comparisons, whose numbers it defines
    let (mut n, mut sq, mut sr, mut sqq, mut srr, mut sqr, mut abs, mut sq_err, mut max) =
        (0usize, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0f64);
    for (a, b) in q.iter().zip(r) {
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

/// The key of `q` (no gaps, zero mean; `q_mean` is its mean relative to `r_mean`) at every
/// offset of `reference` (NaN = gap; `r_mean` is subtracted on the fly to keep the running
/// sums well conditioned), NaN where an offset has no score. Holds one key per offset: for
/// tests and short references; [`match_trace`] keeps only what it needs of them.
pub fn scores_all<R: ReferenceValues + ?Sized>(
    q: &[f64],
    q_mean: f64,
    reference: &R,
    r_mean: f64,
    min_valid: usize,
    score: Score,
) -> Result<Vec<f32>, MatchError> {
    let scorer = Scorer::new(q, q_mean, reference, r_mean, min_valid, score);
    let mut out = vec![f32::NAN; scorer.n_off];
    out.par_chunks_mut(scorer.hop)
        .enumerate()
        .try_for_each_init(
            || (scorer.buffers(), Vec::new()),
            |(b, keys), (bi, dst)| {
                scorer.block_keys(bi, b, keys)?;
                dst.copy_from_slice(keys);
                Ok(())
            },
        )?;
    Ok(out)
}

/// What the search keeps of one block's keys.
struct BlockSummary {
    /// Its best offset and key.
    best: Option<(usize, f32)>,
    /// Offsets with a score.
    scored: usize,
    /// Offsets (outside the exclusion zone) whose key beats the claimed offset's.
    better: usize,
    /// The first null block it reaches, and its maxima over each null block it reaches.
    null_first: usize,
    null_max: Vec<f32>,
}

/// Blocks whose keys are kept once computed (the few a search looks at again).
struct KeyCache<'s, 'a, R: ?Sized> {
    scorer: &'s Scorer<'a, R>,
    blocks: HashMap<usize, Vec<f32>>,
}

impl<R: ReferenceValues + ?Sized> KeyCache<'_, '_, R> {
    fn block(&mut self, bi: usize) -> Result<&[f32], MatchError> {
        if !self.blocks.contains_key(&bi) {
            let mut keys = Vec::new();
            self.scorer
                .block_keys(bi, &mut self.scorer.buffers(), &mut keys)?;
            self.blocks.insert(bi, keys);
        }
        Ok(&self.blocks[&bi])
    }

    /// The key at offset `k` (NaN past the end or without a score).
    fn key(&mut self, k: usize) -> Result<f32, MatchError> {
        if k >= self.scorer.n_off {
            return Ok(f32::NAN);
        }
        let hop = self.scorer.hop;
        Ok(self.block(k / hop)?[k % hop])
    }
}

/// Finds where `trace` (step-aligned with `reference`, NaN = missing) best fits in
/// `reference` (NaN = gap): every offset scored, one FFT block at a time, keeping each block's
/// best, its maxima for the null and its counts; the blocks near a pick are scored again to
/// pick the next. The answer is that of holding every offset's key; the memory is a few
/// blocks' whatever the reference's length.
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
    let m = trace.len();
    let min_valid = ((opts.min_overlap * m as f64).ceil() as usize).max(3);
    // deviations from the reference's own mean keep the running sums well conditioned
    let r_mean = reference.finite_mean()?;
    let scorer = Scorer::new(&q, mean - r_mean, reference, r_mean, min_valid, opts.score);
    let hop = scorer.hop;
    let mut cache = KeyCache {
        scorer: &scorer,
        blocks: HashMap::new(),
    };
    let stat = |key: f32| key_to_statistic(opts.score, key as f64);

    // How far scores stay correlated (on the first 2^18 offsets), which sets the blocks of the
    // null: the best score in a stretch of reference unrelated to the trace follows a Gumbel law.
    let sample_len = scorer.n_off.min(1 << 18);
    let first_blocks = (0..sample_len.div_ceil(hop))
        .into_par_iter()
        .map_init(
            || scorer.buffers(),
            |b, bi| {
                let mut keys = Vec::new();
                scorer.block_keys(bi, b, &mut keys).map(|()| (bi, keys))
            },
        )
        .collect::<Result<Vec<_>, MatchError>>()?;
    cache.blocks.extend(first_blocks);
    let mut sample = Vec::with_capacity(sample_len);
    for bi in 0..sample_len.div_ceil(hop) {
        sample.extend(cache.block(bi)?.iter().map(|&k| {
            if k.is_finite() {
                stat(k) as f32
            } else {
                f32::NAN
            }
        }));
    }
    sample.truncate(sample_len);
    let corr_len = score_correlation_length(&sample, m);
    let block_len = ((4.0 * corr_len).ceil() as usize).max(m / 2).max(10);
    let verify_key = match opts.verify {
        Some(k) => Some(cache.key(k)?).filter(|v| v.is_finite()),
        None => None,
    };
    // every block once
    let summaries = (0..scorer.blocks())
        .into_par_iter()
        .map_init(
            || (scorer.buffers(), Vec::new()),
            |(b, keys), bi| -> Result<BlockSummary, MatchError> {
                scorer.block_keys(bi, b, keys)?;
                let lo = bi * hop;
                let mut s = BlockSummary {
                    best: None,
                    scored: 0,
                    better: 0,
                    null_first: lo / block_len,
                    null_max: vec![
                        f32::NAN;
                        (lo + keys.len() - 1) / block_len + 1 - lo / block_len
                    ],
                };
                // a null block's stretch of keys at a time (a division per stretch, not per key)
                let mut i = 0;
                while i < keys.len() {
                    let k0 = lo + i;
                    let j = k0 / block_len;
                    let n = ((j + 1) * block_len - k0).min(keys.len() - i);
                    let part = &keys[i..i + n];
                    // the maximum and the keys with a score in a loop without branches (a key
                    // without a score is NaN, which no comparison passes); where it beats the
                    // block's best so far, its first place
                    let (top, finite) = crate::simd::fast(|| crate::simd::max_and_finite(part));
                    let top = if top == f32::NEG_INFINITY {
                        f32::NAN
                    } else {
                        top
                    };
                    if s.best.map_or(top.is_finite(), |b| top > b.1) {
                        let at = part.iter().position(|&v| v == top).expect("found above");
                        s.best = Some((k0 + at, top));
                    }
                    s.null_max[j - s.null_first] = top;
                    s.scored += finite;
                    if let (Some(key), Some(at)) = (verify_key, opts.verify) {
                        s.better += (k0..)
                            .zip(part)
                            .filter(|&(k, &v)| v > key && k.abs_diff(at) >= opts.exclusion)
                            .count();
                    }
                    i += n;
                }
                Ok(s)
            },
        )
        .collect::<Result<Vec<_>, MatchError>>()?;
    let scored = summaries.iter().map(|s| s.scored).sum();
    let better = summaries.iter().map(|s| s.better).sum::<usize>();
    let mut null_max = vec![f32::NAN; scorer.n_off.div_ceil(block_len)];
    for s in &summaries {
        for (j, &v) in s.null_max.iter().enumerate() {
            let slot = &mut null_max[s.null_first + j];
            if v.is_finite() && (slot.is_nan() || v > *slot) {
                *slot = v;
            }
        }
    }
    let block_best = summaries.iter().map(|s| s.best).collect();
    drop(summaries);
    // every block read: no answer before the reader's checks of what it read
    reference.end_pass()?;

    let picked = pick_best(block_best, hop, opts.top, opts.exclusion, |bi, picked| {
        let keys = cache.block(bi)?;
        Ok(best_in(keys, bi * hop, picked, opts.exclusion))
    })?;
    let best_at = picked.first().copied().unwrap_or(0);
    let maxima: Vec<f64> = null_max
        .iter()
        .enumerate()
        // leave out the blocks near the best offset: they may hold the real match
        .filter(|(i, _)| {
            let (lo, hi) = (i * block_len, (i + 1) * block_len);
            hi + m <= best_at || lo > best_at + m
        })
        .filter(|(_, v)| v.is_finite())
        .map(|(_, &v)| stat(v))
        .collect();
    let tail = TailFit::new(maxima.clone());

    let mut candidates = Vec::with_capacity(picked.len());
    for k in picked {
        let agreement = score_at(&filled, &reference.window(k, m)?);
        let key = cache.key(k)?;
        // sub-step offset from a parabola through the neighbouring scores
        let mut at = |i: Option<usize>| -> Result<Option<f64>, MatchError> {
            Ok(match i {
                Some(i) => Some(cache.key(i)?).filter(|v| v.is_finite()).map(stat),
                None => None,
            })
        };
        let frac = match (at(k.checked_sub(1))?, at(Some(k + 1))?) {
            (Some(a), Some(b)) => {
                let c0 = stat(key);
                let den = a - 2.0 * c0 + b;
                if den < 0.0 {
                    (0.5 * (a - b) / den).clamp(-0.5, 0.5)
                } else {
                    0.0
                }
            }
            _ => 0.0,
        };
        candidates.push(Candidate {
            offset: k as f64 + frac,
            agreement,
            p_value: tail.p_value(stat(key)),
        });
    }
    let verification = match (opts.verify, verify_key) {
        (Some(k), Some(key)) if k + m <= reference.len() => Some(Verification {
            offset: k,
            agreement: score_at(&filled, &reference.window(k, m)?),
            rank: better + 1,
            p_value: tail.p_value(stat(key)),
        }),
        _ => None,
    };
    Ok(MatchResult {
        verification,
        candidates,
        offsets: scored,
        score_corr_len: corr_len,
        null_blocks: maxima.len(),
        block_len,
        tail_u: tail.u,
        tail_beta: tail.beta,
        tail_k: tail.k,
    })
}

/// The best key of `keys` (the first of equals), whose first is offset `lo`, at least
/// `exclusion` from every offset in `picked`.
fn best_in(keys: &[f32], lo: usize, picked: &[usize], exclusion: usize) -> Option<(usize, f32)> {
    let mut best: Option<(usize, f32)> = None;
    for (k, &v) in (lo..).zip(keys) {
        // NaN fails both comparisons
        if best.map_or(v.is_finite(), |b| v > b.1)
            && picked.iter().all(|p| p.abs_diff(k) >= exclusion.max(1))
        {
            best = Some((k, v));
        }
    }
    best
}

/// The `top` best offsets, each at least `exclusion` away from every better one (greedy, ties
/// to the earlier offset), from the best of each chunk of `chunk` offsets; `rescan(c, picked)`
/// gives chunk `c`'s best away from the offsets picked, for the chunks under a pick's
/// exclusion zone.
fn pick_best(
    mut chunk_best: Vec<Option<(usize, f32)>>,
    chunk: usize,
    top: usize,
    exclusion: usize,
    mut rescan: impl FnMut(usize, &[usize]) -> Result<Option<(usize, f32)>, MatchError>,
) -> Result<Vec<usize>, MatchError> {
    let exclusion = exclusion.max(1);
    let mut picked = Vec::with_capacity(top);
    while picked.len() < top {
        let next = chunk_best
            .iter()
            .flatten()
            .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)));
        let Some(&(k, _)) = next else { break };
        picked.push(k);
        let first = k.saturating_sub(exclusion - 1) / chunk;
        let last = ((k + exclusion - 1) / chunk).min(chunk_best.len() - 1);
        for (c, best) in chunk_best.iter_mut().enumerate().take(last + 1).skip(first) {
            *best = rescan(c, &picked)?;
        }
    }
    Ok(picked)
}

/// The `top` best offsets by key, each at least `exclusion` away from every better one
/// (greedy, ties to the earlier offset). Chunk maxima are found in parallel; a pick only
/// makes the chunks under its exclusion zone be scanned again.
pub fn best_offsets(keys: &[f32], top: usize, exclusion: usize) -> Vec<usize> {
    const CHUNK: usize = 4096;
    let scan = |c: usize, picked: &[usize]| {
        let lo = c * CHUNK;
        best_in(
            &keys[lo..(lo + CHUNK).min(keys.len())],
            lo,
            picked,
            exclusion,
        )
    };
    let chunk_best = (0..keys.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| scan(c, &[]))
        .collect();
    pick_best(chunk_best, CHUNK, top, exclusion, |c, p| Ok(scan(c, p)))
        .expect("keys in memory cannot fail to read")
}

/// CC, MAE, RMSE, max error and overlap at one offset, for checking a claimed time.
pub fn score_offset<R: ReferenceValues + ?Sized>(
    trace: &[f64],
    reference: &R,
    k: usize,
) -> Result<Option<Agreement>, MatchError> {
    if k + trace.len() > reference.len() {
        return Ok(None);
    }
    Ok(Some(score_at(
        &fill_gaps(trace),
        &reference.window(k, trace.len())?,
    )))
}
