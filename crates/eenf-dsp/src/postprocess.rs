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

/// How the harmonic of each segment is chosen.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum HarmonicSelection {
    /// The paper's rule: the smoothest trace (smallest Σ|f[n] − f[n−1]|) in the segment.
    Smoothest,
    /// The smoothest among the traces that agree with at least one other trace (within the
    /// tolerance, Hz, on the ENF scale) for the most estimates of the segment. A band that
    /// locked onto noise is flat after outlier correction, so the paper's rule alone prefers it.
    Consensus(f64),
    /// The journal version's fine-tuning: follow the 2f0 band, and where its estimate jumps by
    /// more than the tolerance (Hz, on the ENF scale) from the trace so far or is missing,
    /// take the harmonic's estimate that keeps the trace smoothest there. Chosen per estimate.
    Journal(f64),
}

impl HarmonicSelection {
    /// Every rule, by its command-line name.
    pub const NAMES: [&'static str; 3] = ["smoothest", "consensus", "journal"];
    /// The consensus rule's default tolerance, Hz.
    pub const DEFAULT_AGREE_HZ: f64 = 0.005;
    /// The journal rule's default jump, Hz per estimate (the grid moves ~1 mHz a second).
    pub const DEFAULT_JUMP_HZ: f64 = 0.005;
}

impl std::fmt::Display for HarmonicSelection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            HarmonicSelection::Smoothest => "smoothest",
            HarmonicSelection::Consensus(_) => "consensus",
            HarmonicSelection::Journal(_) => "journal",
        })
    }
}

/// `consensus` takes the default tolerance.
impl std::str::FromStr for HarmonicSelection {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "smoothest" => Ok(HarmonicSelection::Smoothest),
            "consensus" => Ok(HarmonicSelection::Consensus(Self::DEFAULT_AGREE_HZ)),
            "journal" => Ok(HarmonicSelection::Journal(Self::DEFAULT_JUMP_HZ)),
            _ => Err(format!("{s:?}: expected smoothest, consensus or journal")),
        }
    }
}

/// Picks a trace per segment of `segment` estimates. `traces` are on a common scale (the ENF).
/// Returns the combined trace and the index of the trace chosen for each segment.
pub fn select_harmonics(
    traces: &[Vec<f64>],
    segment: usize,
    rule: HarmonicSelection,
) -> (Vec<f64>, Vec<usize>) {
    select_audible_harmonics(traces, &[], segment, rule)
}

/// [`select_harmonics`], taking in each segment only the traces marked audible there
/// (`audible[trace][segment]`; a missing mark counts as audible) when any of the rule's picks,
/// or any trace at all, is: a band whose line does not stand above its noise is never taken
/// where another does.
pub fn select_audible_harmonics(
    traces: &[Vec<f64>],
    audible: &[Vec<bool>],
    segment: usize,
    rule: HarmonicSelection,
) -> (Vec<f64>, Vec<usize>) {
    if let HarmonicSelection::Journal(jump) = rule {
        return follow_2f0(traces, jump);
    }
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
        let mut candidates: Vec<usize> = (0..traces.len()).collect();
        if let HarmonicSelection::Consensus(tol) = rule {
            // agreement score: estimates of the segment at which another trace is within tol
            let score = |a: usize| -> usize {
                (start..end)
                    .filter(|&i| {
                        (0..traces.len())
                            .any(|b| b != a && (traces[a][i] - traces[b][i]).abs() <= tol)
                    })
                    .count()
            };
            let scores: Vec<usize> = candidates.iter().map(|&a| score(a)).collect();
            let best = scores.iter().copied().max().unwrap_or(0);
            if best > 0 {
                candidates.retain(|&a| scores[a] == best);
            }
        }
        let heard = |a: &usize| {
            audible
                .get(*a)
                .and_then(|m| m.get(start / segment))
                .copied()
                .unwrap_or(true)
        };
        if !candidates.iter().any(heard) {
            // the rule's picks are all noise: any audible trace instead
            let others: Vec<usize> = (0..traces.len()).filter(|a| heard(a)).collect();
            if !others.is_empty() {
                candidates = others;
            }
        }
        if candidates.iter().any(heard) {
            candidates.retain(heard);
        }
        let pick = candidates
            .iter()
            .copied()
            .min_by(|&a, &b| roughness(&traces[a]).total_cmp(&roughness(&traces[b])))
            .unwrap_or(0);
        chosen.push(pick);
        out.extend_from_slice(&traces[pick][start..end]);
    }
    (out, chosen)
}

/// The journal rule: the first trace (the 2f0 band) where it continues the trace, else the
/// trace whose estimate is closest to the last one taken. Returns the trace and the index of
/// the band taken at every estimate.
fn follow_2f0(traces: &[Vec<f64>], jump: f64) -> (Vec<f64>, Vec<usize>) {
    let n = traces.iter().map(|t| t.len()).min().unwrap_or(0);
    let mut out = Vec::with_capacity(n);
    let mut chosen = Vec::with_capacity(n);
    let mut last: Option<f64> = None;
    for i in 0..n {
        let base = traces.first().map_or(f64::NAN, |t| t[i]);
        let pick = match last {
            Some(prev) if !(base.is_finite() && (base - prev).abs() <= jump) => (0..traces.len())
                .filter(|&k| traces[k][i].is_finite())
                .min_by(|&a, &b| {
                    (traces[a][i] - prev)
                        .abs()
                        .total_cmp(&(traces[b][i] - prev).abs())
                })
                .unwrap_or(0),
            None if !base.is_finite() => (0..traces.len())
                .find(|&k| traces[k][i].is_finite())
                .unwrap_or(0),
            _ => 0,
        };
        let v = traces.get(pick).map_or(f64::NAN, |t| t[i]);
        if v.is_finite() {
            last = Some(v);
        }
        out.push(v);
        chosen.push(pick);
    }
    (out, chosen)
}
