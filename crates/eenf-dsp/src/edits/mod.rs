//! Edits (cuts and insertions) from the phase of the mains hum: the classic ENF authenticity
//! test (phase discontinuity: Rodríguez, Apolinário and Biscainho, IEEE TIFS 2010; frequency
//! steps: Esquef, Apolinário and Biscainho, IEEE TIFS 2014), as one generalised likelihood
//! ratio test whose noise is measured in the recording itself.
//!
//! Each line that carries the hum (k·f0, or the flicker lines of light) is brought to baseband
//! and averaged over blocks of [`BLOCK_S`]: a whole number of cycles of every mains harmonic,
//! so that the other lines cancel exactly. The blocks are turned back by the phase of a coarse
//! ENF (harmonic-sum peaks of 10 s windows), which leaves a slowly moving residual phase. At
//! every block boundary τ a line of phase is fitted to each side (up to `side_s` long, never
//! across an edit already found); both fits are carried to τ and compared. The residuals of
//! the fits give each side's noise, so each line's phase difference comes with its own
//! variance: a noisy recording, or a noisy stretch, raises its own threshold.
//!
//! A cut or an insertion shifts the hum in time: every line k·f0 jumps by k times the jump
//! Δ of the fundamental. The statistic is the log-likelihood ratio of that model against no
//! jump (von Mises phase noise), maximised over Δ:
//! `T(τ) = max_Δ 2 Σ_k κ_k [cos(d_k − k Δ) − cos d_k]`, with `d_k` the line's phase
//! difference and `κ_k` the inverse of its variance.
//!
//! What T means with no edit is [`null`]'s: the recording's noise makes a χ² field, and the
//! grid's own stray from the smooth phase, measured on 24 real hours, adds a heavy tail in the
//! jump. Short sides see little of that stray and long ones average more noise away, so each
//! recording is tested at the side (of 2, 3, 5 and 10 s, up to `side_s`) whose smallest
//! detectable jump is smallest. A boundary's statistic is given on one scale: the noise
//! statistic with the same false-alarm rate, so the threshold is that of the rate asked for.

mod coarse;
mod fit;
pub mod null;

pub use coarse::coarse_offsets;

use rayon::prelude::*;
use rustfft::num_complex::Complex64;

use fit::{step_fit, Sums};
use null::{NullModel, STRAY_TAILS};

/// Block length, s: 5 cycles of 50 Hz and 6 of 60 Hz, so that every harmonic of either grid
/// but the one demodulated falls on a null of the block average.
pub const BLOCK_S: f64 = 0.1;

/// How the hum's phase is tested.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EditParams {
    /// The longest stretch fitted on each side of a boundary, s: each recording is tested at
    /// the side up to this whose smallest detectable jump is smallest.
    pub side_s: f64,
    /// The shortest side, s: two edits closer than this are not told apart, and the first and
    /// last this much of a recording are not tested.
    pub min_gap_s: f64,
    /// False alarms allowed per hour of unedited recording: sets the threshold.
    pub false_alarms_per_hour: f64,
    /// A stretch where a phase jump this large (degrees of the lowest line) would go unseen is
    /// reported as too weak to tell.
    pub weak_jump_deg: f64,
    /// A frequency step must stand this many robust standard deviations (of the recording's
    /// own steps between neighbouring windows) to be reported.
    pub frequency_step_z: f64,
}

impl Default for EditParams {
    fn default() -> Self {
        EditParams {
            side_s: 10.0,
            min_gap_s: 1.0,
            false_alarms_per_hour: 0.05,
            weak_jump_deg: 90.0,
            frequency_step_z: 10.0,
        }
    }
}

/// The lines of a recording at baseband, one complex value per block.
#[derive(Debug, Clone)]
pub struct Baseband {
    /// The grid frequency, Hz.
    pub f0_hz: f64,
    /// Each line's frequency as a multiple of `f0_hz` (2, 4, … for light flicker).
    pub multiples: Vec<u32>,
    /// Block length, s (as close to [`BLOCK_S`] as the sample rate allows).
    pub block_s: f64,
    /// Per line, the block means of the signal turned down by the line's nominal frequency.
    pub blocks: Vec<Vec<Complex64>>,
}

/// Brings the lines `multiples`·`f0_hz` of `x` (sampled at `fs`) to baseband, in blocks.
pub fn baseband(x: &[f64], fs: f64, f0_hz: f64, multiples: &[u32]) -> Baseband {
    let nb = ((BLOCK_S * fs).round() as usize).max(1);
    let n = x.len() / nb;
    let blocks = multiples
        .par_iter()
        .map(|&m| {
            let w = -2.0 * std::f64::consts::PI * m as f64 * f0_hz / fs;
            let step = Complex64::from_polar(1.0, w);
            (0..n)
                .map(|b| {
                    // each block starts from its phase computed from the sample index (no drift
                    // over hours) and turns sample by sample within it
                    let start = (w * (b * nb) as f64).rem_euclid(std::f64::consts::TAU);
                    let mut turn = Complex64::from_polar(1.0, start);
                    let mut acc = Complex64::new(0.0, 0.0);
                    for &v in &x[b * nb..(b + 1) * nb] {
                        acc += turn * v;
                        turn *= step;
                    }
                    acc / nb as f64
                })
                .collect()
        })
        .collect();
    Baseband {
        f0_hz,
        multiples: multiples.to_vec(),
        block_s: nb as f64 / fs,
        blocks,
    }
}

impl Baseband {
    /// Blocks per line.
    pub fn len(&self) -> usize {
        self.blocks.first().map_or(0, Vec::len)
    }

    /// True when there are no blocks.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The test at one block boundary.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BoundaryTest {
    /// The boundary, in blocks from the start.
    pub block: usize,
    /// The statistic: the noise statistic with the same false-alarm rate as this boundary's
    /// (see [`NullModel::statistic_for`]), so that it compares with the scan's threshold.
    pub statistic: f64,
    /// The jump of the fundamental that fits best, radians.
    pub jump_rad: f64,
    /// The test's precision for a jump of the fundamental from the recording's noise,
    /// Σ κ_k·k², rad⁻²: noise alone gives a jump of variance 1/precision.
    pub precision: f64,
    /// The statistic from the recording's noise alone, T (the module's documentation).
    pub noise_statistic: f64,
    /// False alarms per hour of unedited recording at this boundary's jump and noise.
    pub false_alarms_per_hour: f64,
    /// The smallest jump of the fundamental that would pass the threshold here, radians
    /// (infinite where even a half-turn would not).
    pub min_jump_rad: f64,
    /// The ENF after the boundary minus the ENF before it, Hz.
    pub frequency_step_hz: f64,
    /// Its standard error from the fits' noise, Hz.
    pub frequency_step_se_hz: f64,
}

/// The whole phase analysis of a recording.
#[derive(Debug, Clone)]
pub struct PhaseScan {
    /// The lines at baseband (the input).
    pub multiples: Vec<u32>,
    /// The grid, Hz.
    pub f0_hz: f64,
    /// Block length, s.
    pub block_s: f64,
    /// The threshold on the statistic for `params.false_alarms_per_hour`.
    pub threshold: f64,
    /// The side the recording was tested at, s.
    pub side_s: f64,
    /// The null model the statistic and rates come from.
    pub null: NullModel,
    /// The coarse ENF, Hz, one value per block.
    pub enf_hz: Vec<f64>,
    /// The residual phase of the lowest line in degrees of the fundamental, one value per
    /// block: what is left once the coarse ENF's phase is taken out (NaN where the line fades).
    pub phase_deg: Vec<f64>,
    /// The test at every boundary tested (after the edits found were taken into account).
    pub tests: Vec<BoundaryTest>,
    /// The statistic at every block boundary as the verdict was decided (NaN where untested):
    /// each side ends at the neighbouring findings, and at a finding it is the finding's own
    /// test. Nothing in it passes the threshold but the findings.
    pub statistic: Vec<f64>,
    /// The tests at the boundaries where T passed the threshold, in time order (each side
    /// ends at the neighbouring edits).
    pub jumps: Vec<BoundaryTest>,
    /// The hum's presence in each second: the lines' power there over what noise alone gives
    /// (each line's coherent power in the second over its noise per block, summed; noise alone
    /// gives a Gamma(lines, 1) variable).
    pub presence: Vec<f64>,
    /// What noise alone exceeds once in a thousand seconds.
    pub presence_threshold: f64,
    /// The parameters used.
    pub params: EditParams,
}

/// Wraps an angle into (−π, π].
pub fn wrap(a: f64) -> f64 {
    let w = (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    if w <= -std::f64::consts::PI {
        w + std::f64::consts::TAU
    } else {
        w
    }
}

/// The lines' sums, turned back by the coarse ENF.
struct Lines {
    /// What the statistic means with no edit.
    null: NullModel,
    /// The false-alarm rate asked for, per hour.
    rate: f64,
    turned: Vec<Vec<Complex64>>,
    sums: Vec<Sums>,
    multiples: Vec<f64>,
    coarse_sum: Vec<f64>,
    block_s: f64,
    /// The coarse ENF, Hz off the grid, per block.
    coarse: Vec<f64>,
    /// The lowest line's residual phase, degrees of the fundamental (for the figure).
    phase_deg: Vec<f64>,
}

impl Lines {
    /// The lines of `bb` turned back by its coarse ENF, with their running sums, tested
    /// against `rate` false alarms per hour (the null model for `side_s` until a side is
    /// chosen).
    fn new(bb: &Baseband, rate: f64, side_s: f64) -> Self {
        let tb = bb.block_s;
        let n = bb.len();
        let coarse = coarse_offsets(bb);
        let mut coarse_sum = Vec::with_capacity(n + 1);
        coarse_sum.push(0.0);
        let mut theta = Vec::with_capacity(n);
        let (mut acc, mut ph) = (0.0, 0.0);
        for &c in &coarse {
            acc += c;
            coarse_sum.push(acc);
            theta.push(ph);
            ph += std::f64::consts::TAU * c * tb;
        }
        let turned: Vec<Vec<Complex64>> = bb
            .blocks
            .iter()
            .zip(&bb.multiples)
            .map(|(z, &m)| {
                z.iter()
                    .zip(&theta)
                    .map(|(v, &t)| v * Complex64::from_polar(1.0, -(m as f64) * t))
                    .collect()
            })
            .collect();
        // the lowest line, the one the jumps are reported on: a harmonic's phase cannot show
        // every jump (a half-turn of the fundamental is a whole turn at 2f0), and the line with
        // the most power, noise and all, may be mostly noise whose phase slips by turns
        let lowest = (0..bb.multiples.len())
            .min_by_key(|&i| bb.multiples[i])
            .unwrap_or(0);
        let phase_deg = residual_phase_deg(&turned[lowest], bb.multiples[lowest] as f64);
        Lines {
            null: NullModel::new(bb.multiples.len(), side_s, None),
            rate,
            sums: turned.iter().map(|z| Sums::new(z)).collect(),
            turned,
            multiples: bb.multiples.iter().map(|&m| m as f64).collect(),
            coarse_sum,
            block_s: tb,
            coarse,
            phase_deg,
        }
    }

    /// Where within `tau ± reach` a step found at `tau` sits: the boundary that best splits
    /// `lo..hi` into two constant complex means once each line is turned by the slope both
    /// sides share (the change-in-mean estimator; the sliding test, whose free slopes absorb
    /// part of a step near a side's end, places it less sharply).
    fn locate(&self, lo: usize, tau: usize, hi: usize, reach: usize, min_side: usize) -> usize {
        let first = tau.saturating_sub(reach).max(lo + min_side);
        let last = (tau + reach).min(hi.saturating_sub(min_side));
        if first >= last {
            return tau;
        }
        let mut score = vec![0.0; last - first + 1];
        for (z, s) in self.turned.iter().zip(&self.sums) {
            let (l, r) = (s.fit(lo, tau), s.fit(tau, hi));
            let (wl, wr) = (1.0 / l.slope_variance(), 1.0 / r.slope_variance());
            let slope = (l.slope * wl + r.slope * wr) / (wl + wr);
            let noise = 0.5 * (l.noise + r.noise);
            let mut prefix = Vec::with_capacity(hi - lo + 1);
            let mut acc = Complex64::new(0.0, 0.0);
            prefix.push(acc);
            for (i, v) in z[lo..hi].iter().enumerate() {
                acc += v * Complex64::from_polar(1.0, -slope * i as f64);
                prefix.push(acc);
            }
            for (j, sc) in score.iter_mut().enumerate() {
                let cut = first + j - lo;
                let (a, b) = (prefix[cut], acc - prefix[cut]);
                *sc += (a.norm_sqr() / cut as f64 + b.norm_sqr() / (hi - lo - cut) as f64) / noise;
            }
        }
        let best = score
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map_or(0, |(j, _)| j);
        first + best
    }

    /// The test at boundary `tau` with sides `lo..tau` and `tau..hi`, its statistic and rates
    /// from the null model.
    fn test(&self, lo: usize, tau: usize, hi: usize) -> BoundaryTest {
        let m = self.measure(lo, tau, hi);
        let rate = self.null.rate(m.noise_statistic, m.jump_rad, m.precision);
        BoundaryTest {
            block: tau,
            statistic: self.null.statistic_for(rate),
            jump_rad: m.jump_rad,
            precision: m.precision,
            noise_statistic: m.noise_statistic,
            false_alarms_per_hour: rate,
            min_jump_rad: self.null.min_jump(m.precision, self.rate),
            frequency_step_hz: m.frequency_step_hz,
            frequency_step_se_hz: m.frequency_step_se_hz,
        }
    }

    /// What the fits at boundary `tau` measure, before any null model.
    fn measure(&self, lo: usize, tau: usize, hi: usize) -> Measured {
        let k = self.sums.len();
        let mut d = [0.0f64; 16];
        let mut kappa = [0.0f64; 16];
        let (mut wl, mut wr, mut fl, mut fr) = (0.0, 0.0, 0.0, 0.0);
        let tb = self.block_s;
        for (i, s) in self.sums.iter().enumerate().take(16) {
            let l = s.fit(lo, tau);
            let r = s.fit(tau, hi);
            let (step, var) = step_fit(&self.turned[i], lo, tau, hi);
            d[i] = step;
            kappa[i] = 1.0 / var;
            // each line's residual ENF at the boundary, Hz, weighted by its precision
            let to_hz = 1.0 / (std::f64::consts::TAU * self.multiples[i] * tb);
            let (sl, sr) = (l.slope, r.slope);
            let (vl, vr) = (
                l.slope_variance() * to_hz * to_hz,
                r.slope_variance() * to_hz * to_hz,
            );
            wl += 1.0 / vl;
            fl += sl * to_hz / vl;
            wr += 1.0 / vr;
            fr += sr * to_hz / vr;
        }
        let k = k.min(16);
        let mean_coarse =
            |a: usize, b: usize| (self.coarse_sum[b] - self.coarse_sum[a]) / (b - a) as f64;
        let f_left = mean_coarse(lo, tau) + fl / wl;
        let f_right = mean_coarse(tau, hi) + fr / wr;
        let ll = |delta: f64| -> f64 {
            (0..k)
                .map(|i| 2.0 * kappa[i] * ((d[i] - self.multiples[i] * delta).cos() - d[i].cos()))
                .sum()
        };
        // the best jump of the fundamental: each line alone is best at (d_k + 2πj)/m_k; from
        // each of those, Newton's steps climb Σ κ_k cos(d_k − m_k Δ) to its nearest peak
        let (mut jump, mut best) = (0.0, 0.0);
        for i in 0..k {
            let m = self.multiples[i];
            for j in 0..(m.round() as usize).max(1) {
                let mut x = wrap((d[i] + std::f64::consts::TAU * j as f64) / m);
                for _ in 0..4 {
                    let (mut g, mut h) = (0.0, 0.0);
                    for l in 0..k {
                        let ml = self.multiples[l];
                        let (sn, cs) = (d[l] - ml * x).sin_cos();
                        g += kappa[l] * ml * sn;
                        h -= kappa[l] * ml * ml * cs;
                    }
                    if h >= 0.0 {
                        break;
                    }
                    x = wrap(x - g / h);
                }
                let v = ll(x);
                if v > best {
                    best = v;
                    jump = x;
                }
            }
        }
        let info: f64 = (0..k)
            .map(|i| kappa[i] * self.multiples[i] * self.multiples[i])
            .sum();
        // the grid's own stray from the fit, common to the lines: T ≈ Δ²·info becomes
        // Δ² / (1/info + stray²)
        Measured {
            jump_rad: jump,
            precision: info,
            noise_statistic: best.max(0.0),
            frequency_step_hz: f_right - f_left,
            frequency_step_se_hz: (1.0 / wl + 1.0 / wr).sqrt(),
        }
    }
}

/// The jump of the fundamental (rad) and its noise precision (rad⁻²) at every block boundary
/// of `bb`, with sides of `side_s` and nothing taken out: what [`null`]'s tails are measured
/// on. `None` when the recording is shorter than two sides.
pub fn boundary_jumps(bb: &Baseband, side_s: f64) -> Option<Vec<(usize, f64, f64)>> {
    let n = bb.len();
    let side = ((side_s / bb.block_s).round() as usize).max(3);
    if bb.blocks.is_empty() || n < 2 * side {
        return None;
    }
    let lines = Lines::new(bb, EditParams::default().false_alarms_per_hour, side_s);
    Some(
        (side..=n - side)
            .into_par_iter()
            .map(|tau| {
                let m = lines.measure(tau - side, tau, tau + side);
                (tau, m.jump_rad, m.precision)
            })
            .collect(),
    )
}

/// What one boundary's fits measure.
#[derive(Debug, Clone, Copy)]
struct Measured {
    jump_rad: f64,
    precision: f64,
    noise_statistic: f64,
    frequency_step_hz: f64,
    frequency_step_se_hz: f64,
}

/// Tests every block boundary of `bb` for a jump of the hum's phase, as `params` says; the
/// edits found are taken out one by one, strongest first, so that a side never spans one.
/// `None` when the recording is shorter than two sides of `params.min_gap_s`.
pub fn scan_phase(bb: &Baseband, params: &EditParams) -> Option<PhaseScan> {
    let n = bb.len();
    let tb = bb.block_s;
    let longest = ((params.side_s / tb).round() as usize).max(3);
    let min_side = ((params.min_gap_s / tb).round() as usize).clamp(3, longest);
    if bb.blocks.is_empty() || n < 2 * min_side {
        return None;
    }
    let mut lines = Lines::new(bb, params.false_alarms_per_hour, params.side_s);
    let (side, null) = choose_side(&lines, n, min_side, longest, params);
    lines.null = null;
    let threshold = null.statistic_for(params.false_alarms_per_hour);
    let min_side = min_side.min(side);
    let sides = |tau: usize, cuts: &[usize]| -> Option<(usize, usize)> {
        let prev = cuts.iter().copied().filter(|&c| c < tau).max().unwrap_or(0);
        let next = cuts.iter().copied().filter(|&c| c > tau).min().unwrap_or(n);
        let lo = tau.saturating_sub(side).max(prev);
        let hi = (tau + side).min(next);
        (tau - lo >= min_side && hi - tau >= min_side && !cuts.contains(&tau)).then_some((lo, hi))
    };
    let retest = |tests: &mut [Option<BoundaryTest>], around: usize, cuts: &[usize]| {
        let lo = around.saturating_sub(side);
        let hi = (around + side).min(n);
        let redo: Vec<(usize, Option<BoundaryTest>)> = (lo..=hi)
            .into_par_iter()
            .map(|tau| (tau, sides(tau, cuts).map(|(l, h)| lines.test(l, tau, h))))
            .collect();
        for (tau, t) in redo {
            tests[tau] = t;
        }
    };
    // each edit tested with its sides ending at its neighbours
    let final_tests = |cuts: &[usize]| -> Vec<BoundaryTest> {
        cuts.iter()
            .enumerate()
            .map(|(i, &c)| {
                let prev = if i > 0 { cuts[i - 1] } else { 0 };
                let next = cuts.get(i + 1).copied().unwrap_or(n);
                lines.test(c.saturating_sub(side).max(prev), c, (c + side).min(next))
            })
            .collect()
    };
    let mut cuts: Vec<usize> = Vec::new();
    let mut tests: Vec<Option<BoundaryTest>> = (0..=n)
        .into_par_iter()
        .map(|tau| sides(tau, &cuts).map(|(lo, hi)| lines.test(lo, tau, hi)))
        .collect();
    let mut jumps = Vec::new();
    // at most one edit per two minimal sides: a hostile file cannot make these loops long
    let mut budget = (n / (2 * min_side)).max(1);
    for _round in 0..3 {
        while budget > 0 {
            budget -= 1;
            let best = tests
                .iter()
                .flatten()
                .max_by(|a, b| a.statistic.total_cmp(&b.statistic))
                .copied();
            let Some(best) = best.filter(|b| b.statistic >= threshold) else {
                break;
            };
            // placed by the sharper estimator within a second of where the test peaked
            let (l, h) = sides(best.block, &cuts).unwrap_or((0, n));
            let reach = ((1.0 / tb).round() as usize).max(1);
            let at = lines.locate(l, best.block, h, reach, min_side);
            cuts.push(at);
            cuts.sort_unstable();
            retest(&mut tests, at, &cuts);
            // the peak's own boundary, when the estimator moved the edit off it
            tests[best.block] = sides(best.block, &cuts).map(|(l, h)| lines.test(l, best.block, h));
        }
        // one that stood only with a side across another edit is dropped, weakest first, and
        // the boundaries around it tested again without it
        jumps = final_tests(&cuts);
        let mut dropped = false;
        while let Some(weakest) = jumps
            .iter()
            .filter(|t| t.statistic < threshold)
            .min_by(|a, b| a.statistic.total_cmp(&b.statistic))
            .map(|t| t.block)
        {
            cuts.retain(|&c| c != weakest);
            retest(&mut tests, weakest, &cuts);
            jumps = final_tests(&cuts);
            dropped = true;
        }
        if !dropped {
            break;
        }
    }
    // the statistic the verdict rests on: every boundary with its final sides, each finding
    // its own final test
    let mut statistic: Vec<f64> = tests
        .iter()
        .map(|t| t.map_or(f64::NAN, |t| t.statistic))
        .collect();
    for j in &jumps {
        statistic[j.block] = j.statistic;
    }
    let (presence, presence_threshold) = presence_per_second(&lines.turned, tb);
    Some(PhaseScan {
        multiples: bb.multiples.clone(),
        f0_hz: bb.f0_hz,
        block_s: tb,
        threshold,
        side_s: side as f64 * tb,
        null,
        enf_hz: lines.coarse.iter().map(|c| bb.f0_hz + c).collect(),
        phase_deg: std::mem::take(&mut lines.phase_deg),
        tests: tests.into_iter().flatten().collect(),
        jumps,
        statistic,
        presence,
        presence_threshold,
        params: params.clone(),
    })
}

/// The side a recording is tested at, in blocks, with its null model: of the sides whose
/// stray was measured (from `min_side` up, and `longest` itself), the one whose smallest
/// detectable jump, at the
/// recording's median precision there, is smallest. Each candidate is measured at a boundary
/// every half side; the spread of its jumps, less their noise, is the recording's own stray.
fn choose_side(
    lines: &Lines,
    n: usize,
    min_side: usize,
    longest: usize,
    params: &EditParams,
) -> (usize, NullModel) {
    let tb = lines.block_s;
    let k = lines.multiples.len();
    let mut candidates: Vec<usize> = STRAY_TAILS
        .iter()
        .map(|t| (t.side_s / tb).round() as usize)
        // a side never shorter than the shortest gap asked for (`min_gap_s`)
        .filter(|&c| c < longest && c >= min_side)
        .collect();
    candidates.push(longest);
    let fits = |c: usize| 2 * c < n;
    if candidates.iter().any(|&c| fits(c)) {
        candidates.retain(|&c| fits(c));
    } else {
        candidates.truncate(1);
    }
    let mut best: Option<(f64, usize, NullModel)> = None;
    for c in candidates {
        let c = c.max(min_side);
        let step = (c / 2).max(1);
        let taus: Vec<usize> = (c..=n.saturating_sub(c).max(c)).step_by(step).collect();
        let measured: Vec<Measured> = taus
            .par_iter()
            .map(|&tau| lines.measure(tau.saturating_sub(c), tau.min(n), (tau + c).min(n)))
            .filter(|m| m.precision.is_finite() && m.precision > 0.0)
            .collect();
        if measured.is_empty() {
            continue;
        }
        let median = |mut v: Vec<f64>| -> f64 {
            let mid = v.len() / 2;
            *v.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        let precision = median(measured.iter().map(|m| m.precision).collect());
        let mad = 1.4826 * median(measured.iter().map(|m| m.jump_rad.abs()).collect());
        let noise_var = median(measured.iter().map(|m| 1.0 / m.precision).collect());
        // the stray is measured only where the noise is small beside it: under noise, the
        // jumps' spread also holds the likelihood's other peaks (one per line's turn), an
        // edit's neighbourhood and the spreads' small biases, and widening the stray there
        // would change little but the smallest jump
        let calibrated = NullModel::new(k, c as f64 * tb, None).stray_spread_rad;
        let stray_var = mad * mad - noise_var;
        let own_deg = (noise_var < 4.0 * calibrated * calibrated && stray_var > 0.5 * noise_var)
            .then(|| stray_var.sqrt().to_degrees());
        let null = NullModel::new(k, c as f64 * tb, own_deg);
        let jump = null.min_jump(precision, params.false_alarms_per_hour);
        if best.as_ref().is_none_or(|b| jump < b.0) {
            best = Some((jump, c, null));
        }
    }
    best.map_or_else(
        || (longest, NullModel::new(k, longest as f64 * tb, None)),
        |(_, c, null)| (c, null),
    )
}

/// Per second, the lines' coherent power over noise (see [`PhaseScan::presence`]); the noise
/// per block is each line's median spread within a second, over the recording.
fn presence_per_second(turned: &[Vec<Complex64>], tb: f64) -> (Vec<f64>, f64) {
    let per = ((1.0 / tb).round() as usize).max(2);
    let seconds = turned.first().map_or(0, |z| z.len() / per);
    let mut total = vec![0.0; seconds];
    for z in turned {
        let mut spread: Vec<f64> = z
            .chunks_exact(per)
            .map(|c| {
                let m = c.iter().sum::<Complex64>() / per as f64;
                c.iter().map(|v| (v - m).norm_sqr()).sum::<f64>() / (per - 1) as f64
            })
            .collect();
        if spread.is_empty() {
            break;
        }
        let mid = spread.len() / 2;
        // the median of a spread that is χ²(2(per−1))/(2(per−1)) distributed is a little
        // below its mean
        let noise =
            *spread.select_nth_unstable_by(mid, f64::total_cmp).1 / median_of_scaled_chi2(per);
        for (t, c) in total.iter_mut().zip(z.chunks_exact(per)) {
            let s: Complex64 = c.iter().sum();
            *t += s.norm_sqr() / (per as f64 * noise.max(1e-300));
        }
    }
    // Gamma(K, 1) exceeds x with probability e^{-x} Σ_{i<K} x^i / i!
    let k = turned.len().max(1);
    let tail = |x: f64| -> f64 {
        let mut term = 1.0;
        let mut sum = 1.0;
        for i in 1..k {
            term *= x / i as f64;
            sum += term;
        }
        (-x).exp() * sum
    };
    let (mut lo, mut hi) = (0.0, 200.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if tail(mid) > 1e-3 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (total, hi)
}

/// The median of χ²(2(n−1)) / (2(n−1)): the median of a complex sample variance over its
/// expectation (Wilson–Hilferty).
fn median_of_scaled_chi2(n: usize) -> f64 {
    let nu = 2.0 * (n as f64 - 1.0);
    (1.0 - 2.0 / (9.0 * nu)).powi(3)
}

/// The unwrapped residual phase of one line, in degrees of the fundamental, with its moving
/// mean over 20 s taken out: what the eye reads as "deviation from a smooth fit" at about the
/// scale the test looks at (a minute's mean left the coarse ENF's slow misses as swings of
/// tens of degrees that read like edits).
fn residual_phase_deg(z: &[Complex64], multiple: f64) -> Vec<f64> {
    // a second's mean first: single blocks of weak hum are mostly noise
    let smooth: Vec<Complex64> = (0..z.len())
        .map(|i| {
            let lo = i.saturating_sub(5);
            let hi = (i + 5).min(z.len());
            z[lo..hi].iter().sum::<Complex64>()
        })
        .collect();
    // where the line fades, its phase is noise and unwrapping it slips by whole turns of the
    // line (360°/m of the fundamental), which would read as jumps the test does not see: left
    // out (NaN) where the line stands under a third of its median
    let mut mags: Vec<f64> = smooth.iter().map(|v| v.norm()).collect();
    let median = if mags.is_empty() {
        0.0
    } else {
        let mid = mags.len() / 2;
        *mags.select_nth_unstable_by(mid, f64::total_cmp).1
    };
    let mut out = Vec::with_capacity(z.len());
    let mut prev = 0.0;
    let mut acc = 0.0;
    for v in &smooth {
        if v.norm() < median / 3.0 {
            out.push(f64::NAN);
            continue;
        }
        let a = v.arg();
        acc += wrap(a - prev);
        prev = a;
        out.push(acc.to_degrees() / multiple);
    }
    let half = 100usize;
    let mut sum = vec![0.0; out.len() + 1];
    let mut count = vec![0usize; out.len() + 1];
    for (i, v) in out.iter().enumerate() {
        let ok = v.is_finite();
        sum[i + 1] = sum[i] + if ok { *v } else { 0.0 };
        count[i + 1] = count[i] + ok as usize;
    }
    (0..out.len())
        .map(|i| {
            let lo = i.saturating_sub(half);
            let hi = (i + half).min(out.len());
            out[i] - (sum[hi] - sum[lo]) / (count[hi] - count[lo]).max(1) as f64
        })
        .collect()
}
