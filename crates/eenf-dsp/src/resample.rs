//! Resampling onto a regular grid of steps, one way for every series eenf reads: the value of
//! a step is the mean of the samples within half a step of its time (a finer series is
//! averaged, never picked from), and a coarser series is interpolated linearly between two
//! samples no farther apart than the caller allows. Gaps stay gaps.
//!
//! Steps sit on a grid anchored at time 0 (for absolute times, the Unix epoch), so that two
//! files of one archive fall on the same steps.

/// Steps a page of [`StepAverager`] holds: a page is allocated when a sample first lands in
/// it, so memory follows the steps that have samples, not the span between the first and last.
const PAGE: i64 = 1 << 14;

/// The sums and counts of the samples of a page's steps.
type Page = (Box<[f64]>, Box<[u32]>);

/// Accumulates samples `(time, value)` in any order into steps of `step` seconds.
#[derive(Debug, Clone)]
pub struct StepAverager {
    step: f64,
    /// Page number (step index / [`PAGE`]) → sums and counts of its steps.
    pages: std::collections::BTreeMap<i64, Page>,
    /// The first and last step indices with a sample.
    span: Option<(i64, i64)>,
    max_steps: usize,
}

/// A regular series: `values[i]` is the value at `start + i·step` (NaN: no value).
#[derive(Debug, Clone, PartialEq)]
pub struct Steps {
    /// Time of the first value, s.
    pub start: f64,
    /// Seconds between values.
    pub step: f64,
    /// The values; NaN marks a gap.
    pub values: Vec<f64>,
}

impl StepAverager {
    /// An empty accumulator of `step`-second steps that refuses samples that would make it
    /// span more than `max_steps` steps (a wild time must not become a huge allocation).
    pub fn new(step: f64, max_steps: usize) -> Self {
        assert!(step > 0.0 && step.is_finite(), "a positive step");
        StepAverager {
            step,
            pages: Default::default(),
            span: None,
            max_steps,
        }
    }

    /// The step, s.
    pub fn step(&self) -> f64 {
        self.step
    }

    /// The index of the step whose half-open span `[t − step/2, t + step/2)` holds `time`.
    pub fn index(&self, time: f64) -> i64 {
        // the small bias keeps 0.1·k samples on the side of the step they name
        (time / self.step + 0.5 + 1e-9).floor() as i64
    }

    /// Adds a sample. A value that is not finite is ignored; `false` when its time lies so
    /// far from the others that the series would exceed its bound (it is not added).
    pub fn push(&mut self, time: f64, value: f64) -> bool {
        if !time.is_finite() || (time / self.step).abs() > 1e15 {
            return false;
        }
        if !value.is_finite() {
            return true;
        }
        let k = self.index(time);
        let (lo, hi) = self.span.map_or((k, k), |(a, b)| (a.min(k), b.max(k)));
        if (hi - lo) as u64 >= self.max_steps as u64 {
            return false;
        }
        self.span = Some((lo, hi));
        let (sums, counts) = self.pages.entry(k.div_euclid(PAGE)).or_insert_with(|| {
            (
                vec![0.0; PAGE as usize].into_boxed_slice(),
                vec![0; PAGE as usize].into_boxed_slice(),
            )
        });
        let i = k.rem_euclid(PAGE) as usize;
        sums[i] += value;
        counts[i] = counts[i].saturating_add(1);
        true
    }

    /// Number of samples added.
    pub fn samples(&self) -> u64 {
        self.pages
            .values()
            .flat_map(|(_, c)| c.iter())
            .map(|&c| c as u64)
            .sum()
    }

    /// The series from the first step with a value to the last. Steps without a sample that
    /// lie between two with samples at most `interpolate_s` seconds apart are interpolated
    /// linearly (a series coarser than the step); other empty steps are gaps.
    pub fn finish(self, interpolate_s: f64) -> Steps {
        let step = self.step;
        self.finish_pieces(interpolate_s, u64::MAX)
            .pop()
            .unwrap_or(Steps {
                start: 0.0,
                step,
                values: Vec::new(),
            })
    }

    /// As [`StepAverager::finish`], but in pieces: a run of more than `max_gap` empty steps
    /// ends one piece and the next sample starts another, so that a stray sample far from
    /// the rest costs one value, not the span between.
    pub fn finish_pieces(self, interpolate_s: f64, max_gap: u64) -> Vec<Steps> {
        let reach = (interpolate_s / self.step + 1e-9).floor() as i64;
        let step = self.step;
        let mut pieces = Vec::new();
        let mut cur: Option<(i64, Vec<f64>)> = None;
        let mut last = i64::MIN;
        for (page, (sums, counts)) in &self.pages {
            for (i, (&sum, &count)) in sums.iter().zip(counts.iter()).enumerate() {
                if count == 0 {
                    continue;
                }
                let k = page * PAGE + i as i64;
                let v = sum / count as f64;
                let gap = if cur.is_some() {
                    (k - last - 1) as u64
                } else {
                    0
                };
                match &mut cur {
                    Some((_, values)) if gap <= max_gap => {
                        let before = values.last().copied().unwrap_or(f64::NAN);
                        let n = gap as usize;
                        if n >= 1 && (n as i64) < reach {
                            let q = (n + 1) as f64;
                            values.extend((1..=n).map(|j| before + (v - before) * j as f64 / q));
                        } else {
                            values.resize(values.len() + n, f64::NAN);
                        }
                        values.push(v);
                    }
                    _ => {
                        if let Some((first, values)) = cur.take() {
                            pieces.push(Steps {
                                start: first as f64 * step,
                                step,
                                values,
                            });
                        }
                        cur = Some((k, vec![v]));
                    }
                }
                last = k;
            }
        }
        if let Some((first, values)) = cur {
            pieces.push(Steps {
                start: first as f64 * step,
                step,
                values,
            });
        }
        pieces
    }
}

/// Resamples a regular series from `from_step` to `to_step` seconds: value `j` is at
/// `j·to_step` from the first value. Finer to coarser averages the samples within half a step;
/// coarser to finer interpolates between neighbouring samples. NaN marks gaps, in and out.
pub fn resample(x: &[f64], from_step: f64, to_step: f64) -> Vec<f64> {
    if (from_step - to_step).abs() < 1e-9 || x.len() < 2 {
        return x.to_vec();
    }
    let span = (x.len() - 1) as f64 * from_step;
    let n = (span / to_step + 1e-9).floor() as usize + 1;
    let mut acc = StepAverager::new(to_step, n + 1);
    for (i, &v) in x.iter().enumerate() {
        acc.push(i as f64 * from_step, v);
    }
    // neighbouring samples only: a NaN between two values leaves a gap
    let s = acc.finish(from_step * 1.5);
    if s.values.is_empty() {
        return vec![f64::NAN; n];
    }
    let lead = (s.start / to_step).round() as usize;
    let mut out = vec![f64::NAN; n];
    for (j, v) in s.values.iter().enumerate() {
        if let Some(slot) = out.get_mut(lead + j) {
            *slot = *v;
        }
    }
    out
}
