//! Uniform-interval temporal sampling of an event stream into a flicker signal: the paper's
//! polarity sequence E(n) ∈ {−1, 0, +1} (majority vote of the polarities in each sample), or
//! the signed count ON − OFF of every event in each bin for sensors that stamp events one by one.

use eenf_core::EventBatch;

/// How events are chosen for sample n (t_n = t_1 + n·Δt). See `docs/method.md`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SamplingMethod {
    /// The paper: the events at the smallest timestamp ≥ t_n (the nearest future group).
    Paper,
    /// The authors' first code: the group at the largest timestamp in [t_n, t_n + Δt);
    /// when that interval is empty the previous sample is repeated.
    Authors,
    /// The journal version: vote over all events in [t_n, t_n + Δt).
    Block,
    /// ON − OFF count of all events in [t_n, t_n + Δt): every event counts, as sensors that
    /// stamp events one by one (DVS128, DAVIS, Prophesee) need.
    Sum,
    /// Chooses from the stream: `paper` when events come in scan groups that share a timestamp
    /// (DVXplorer), `block` (the vote over every event of the bin) otherwise. See
    /// [`Grouping`].
    Auto,
}

impl SamplingMethod {
    /// The sampling interval that suits the method, µs: the paper's 1 ms for the samplers of
    /// scan groups; 100 µs for the vote and sum over per-event stamps, whose bins see every
    /// event, so that the flicker's harmonics up to 5 kHz do not alias onto the bands (at
    /// 1 ms the 6th, 8th, … harmonics of a 100 Hz flicker fold onto the 4th, 2nd, …).
    pub fn default_dt_us(self) -> i64 {
        match self {
            SamplingMethod::Block | SamplingMethod::Sum => 100,
            _ => 1000,
        }
    }

    /// Every variant, by its command-line name.
    pub const NAMES: [&'static str; 5] = ["paper", "authors", "block", "sum", "auto"];
    const ALL: [SamplingMethod; 5] = [
        SamplingMethod::Paper,
        SamplingMethod::Authors,
        SamplingMethod::Block,
        SamplingMethod::Sum,
        SamplingMethod::Auto,
    ];
}

/// How a stream's timestamps group, measured on its first events: what `auto` sampling goes by.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Grouping {
    /// Events looked at.
    pub events: usize,
    /// Mean events per distinct timestamp.
    pub events_per_timestamp: f64,
    /// Median step between distinct timestamps, µs.
    pub median_step_us: f64,
    /// Share of the steps shorter than a quarter of the median: none on a scan clock (no two
    /// scans closer than a scan period), about 16 % for events at random at any rate.
    pub short_share: f64,
}

impl Grouping {
    /// Events looked at to decide.
    pub const SAMPLE: usize = 100_000;

    /// Measures the first [`Grouping::SAMPLE`] timestamps (in time order).
    pub fn measure(t: &[i64]) -> Self {
        let t = &t[..t.len().min(Self::SAMPLE)];
        let mut steps: Vec<i64> = t
            .windows(2)
            .map(|w| w[1] - w[0])
            .filter(|&d| d > 0)
            .collect();
        let distinct = steps.len() + usize::from(!t.is_empty());
        let median = if steps.is_empty() {
            0.0
        } else {
            let k = steps.len() / 2;
            *steps.select_nth_unstable(k).1 as f64
        };
        let short = steps
            .iter()
            .filter(|&&d| (d as f64) < 0.25 * median)
            .count();
        let short_share = short as f64 / steps.len().max(1) as f64;
        Grouping {
            events: t.len(),
            events_per_timestamp: t.len() as f64 / distinct.max(1) as f64,
            median_step_us: median,
            short_share,
        }
    }

    /// Scan groups: timestamps a scan apart (a DVXplorer reads its array every ~200 µs), with
    /// several events per timestamp, or never closer than a scan when a quiet scene leaves a
    /// scan only an event or two. Dense µs-stamped streams share timestamps too, but 1 µs
    /// apart; sparse ones come at random, and a sixth of their steps are short.
    pub fn is_scanned(&self) -> bool {
        self.median_step_us >= 20.0 && (self.events_per_timestamp >= 8.0 || self.short_share < 0.03)
    }

    /// The sampling `auto` picks, and why, in words.
    pub fn choice(&self) -> (SamplingMethod, String) {
        let measured = format!(
            "{:.1} events per timestamp, {:.0} µs apart (median), {:.0} % of the steps under a quarter of that, in the first {} events",
            self.events_per_timestamp,
            self.median_step_us,
            100.0 * self.short_share,
            self.events
        );
        if self.is_scanned() {
            (SamplingMethod::Paper, format!("scan groups: {measured}"))
        } else {
            (
                SamplingMethod::Block,
                format!("events stamped one by one: {measured}"),
            )
        }
    }
}

impl std::fmt::Display for SamplingMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(Self::NAMES[*self as usize])
    }
}

impl std::str::FromStr for SamplingMethod {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let i = Self::NAMES.iter().position(|n| *n == s);
        i.map(|i| Self::ALL[i])
            .ok_or_else(|| format!("{s:?}: expected {}", Self::NAMES.join(", ")))
    }
}

/// The sampled flicker signal.
#[derive(Debug, Clone, PartialEq)]
pub struct PolaritySequence {
    /// Time of sample 0 (the first event), µs.
    pub t0_us: i64,
    /// Sampling interval, µs.
    pub dt_us: i64,
    /// E(n) ∈ {−1, 0, +1} (the votes), or ON − OFF per bin (`sum`).
    pub values: Vec<f32>,
    /// The sampling used (`auto` resolved).
    pub method: SamplingMethod,
    /// Why, when `auto` chose it.
    pub reason: Option<String>,
}

impl PolaritySequence {
    /// Sampling rate in Hz.
    pub fn fs(&self) -> f64 {
        1e6 / self.dt_us as f64
    }

    /// The values as the filters and trackers take them.
    pub fn signal(&self) -> Vec<f64> {
        self.values.iter().map(|&v| v as f64).collect()
    }

    /// Duration covered, in seconds.
    pub fn duration_s(&self) -> f64 {
        self.values.len() as f64 * self.dt_us as f64 * 1e-6
    }
}

/// A timestamp far outside the recording (a corrupt file) would ask for an unbounded sequence.
#[derive(Debug, Clone, thiserror::Error)]
#[error("event timestamp {t_us} µs is {span_s:.0} s after the first event, beyond the {limit_s:.0} s limit")]
pub struct SamplingError {
    /// The offending timestamp.
    pub t_us: i64,
    /// Its distance from the first event, s.
    pub span_s: f64,
    /// The limit, s.
    pub limit_s: f64,
}

const EMPTY: i8 = i8::MIN;

/// Turns event batches into a polarity sequence, one batch at a time.
pub struct TemporalSampler {
    method: SamplingMethod,
    dt: i64,
    t0: Option<i64>,
    values: Vec<i8>,
    /// Paper: the group at the end of the last batch, which may continue in the next one.
    carry: Option<(i64, i64)>,
    /// Block and Sum: ON − OFF per bin; Authors: the current group's (time, bin, ON − OFF).
    counts: Vec<i32>,
    reason: Option<String>,
    group: Option<(i64, usize, i64)>,
    max_samples: usize,
    events: u64,
    /// The interval follows the method (`auto` decides both at the first events).
    auto_dt: bool,
}

fn sign(v: i64) -> i8 {
    v.signum() as i8
}

impl TemporalSampler {
    /// A sampler with interval `dt_us`, or the method's own
    /// ([`SamplingMethod::default_dt_us`]) when `None`.
    pub fn with_interval(method: SamplingMethod, dt_us: Option<i64>) -> Self {
        let mut s = Self::new(method, dt_us.unwrap_or(method.default_dt_us()));
        s.auto_dt = dt_us.is_none();
        s
    }

    fn set_interval(&mut self, dt_us: i64) {
        self.dt = dt_us;
        self.max_samples = (48 * 3600 * 1_000_000 / dt_us) as usize;
    }

    /// The sampling interval, µs (with `auto`, decided at the first events).
    pub fn dt_us(&self) -> i64 {
        self.dt
    }

    /// A sampler with interval `dt_us` (1000 for the paper's 1 ms).
    pub fn new(method: SamplingMethod, dt_us: i64) -> Self {
        assert!(dt_us > 0, "sampling interval must be positive");
        TemporalSampler {
            auto_dt: false,
            method,
            dt: dt_us,
            t0: None,
            values: Vec::new(),
            carry: None,
            counts: Vec::new(),
            group: None,
            max_samples: (48 * 3600 * 1_000_000 / dt_us) as usize,
            events: 0,
            reason: None,
        }
    }

    /// The sampling in use: `auto` stays `auto` until the first events decide it.
    pub fn method(&self) -> SamplingMethod {
        self.method
    }

    /// Events seen so far.
    pub fn events(&self) -> u64 {
        self.events
    }

    fn check_bin(&self, t: i64, n: usize) -> Result<(), SamplingError> {
        if n >= self.max_samples {
            return Err(SamplingError {
                t_us: t,
                span_s: (t - self.t0.unwrap_or(t)) as f64 * 1e-6,
                limit_s: self.max_samples as f64 * self.dt as f64 * 1e-6,
            });
        }
        Ok(())
    }

    /// Adds a batch (events in time order, continuing the previous batch).
    pub fn push(&mut self, batch: &EventBatch) -> Result<(), SamplingError> {
        if batch.is_empty() {
            return Ok(());
        }
        self.events += batch.len() as u64;
        let t0 = *self.t0.get_or_insert(batch.t[0]);
        if self.method == SamplingMethod::Auto {
            let (method, reason) = Grouping::measure(&batch.t).choice();
            self.method = method;
            self.reason = Some(reason);
            if self.auto_dt {
                self.set_interval(method.default_dt_us());
            }
        }
        match self.method {
            SamplingMethod::Paper => self.push_paper(batch, t0),
            SamplingMethod::Authors => self.push_authors(batch, t0),
            SamplingMethod::Block | SamplingMethod::Sum | SamplingMethod::Auto => {
                self.push_block(batch, t0)
            }
        }
    }

    /// Emits `vote` for every sample n with t_n ≤ t.
    fn emit_upto(&mut self, t: i64, vote: i8, t0: i64) -> Result<(), SamplingError> {
        let last_n = ((t - t0).max(0) / self.dt) as usize;
        self.check_bin(t, last_n)?;
        if self.values.len() <= last_n {
            self.values.resize(last_n + 1, vote);
        }
        Ok(())
    }

    fn push_paper(&mut self, b: &EventBatch, t0: i64) -> Result<(), SamplingError> {
        let t = &b.t;
        let n = t.len();
        let mut i = 0;
        if let Some((tc, votes)) = self.carry.take() {
            // the group at the end of the previous batch may continue here
            let k = t.partition_point(|&v| v <= tc);
            let extra: i64 = (0..k).map(|j| if b.p[j] { 1 } else { -1 }).sum();
            if k == n {
                self.carry = Some((tc, votes + extra));
                return Ok(());
            }
            self.emit_upto(tc, sign(votes + extra), t0)?;
            i = k;
        }
        while i < n {
            // next sample time, and the first event at or after it
            let tn = t0 + self.values.len() as i64 * self.dt;
            let j = i + t[i..].partition_point(|&v| v < tn);
            if j == n {
                break;
            }
            let tg = t[j];
            let k = j + t[j..].partition_point(|&v| v <= tg);
            let votes: i64 = b.p[j..k].iter().map(|&p| if p { 1 } else { -1 }).sum();
            if k == n {
                self.carry = Some((tg, votes));
                break;
            }
            self.emit_upto(tg, sign(votes), t0)?;
            i = k;
        }
        Ok(())
    }

    fn flush_group(&mut self) -> Result<(), SamplingError> {
        if let Some((t, bin, votes)) = self.group.take() {
            self.check_bin(t, bin)?;
            if self.values.len() <= bin {
                self.values.resize(bin + 1, EMPTY);
            }
            // later groups in the same bin overwrite earlier ones: the last group wins
            self.values[bin] = sign(votes);
        }
        Ok(())
    }

    fn push_authors(&mut self, b: &EventBatch, t0: i64) -> Result<(), SamplingError> {
        for (&t, &p) in b.t.iter().zip(&b.p) {
            let v = if p { 1 } else { -1 };
            match &mut self.group {
                Some((gt, _, votes)) if *gt == t => *votes += v,
                _ => {
                    self.flush_group()?;
                    if t >= t0 {
                        self.group = Some((t, ((t - t0) / self.dt) as usize, v));
                    }
                }
            }
        }
        Ok(())
    }

    fn push_block(&mut self, b: &EventBatch, t0: i64) -> Result<(), SamplingError> {
        let last = *b.t.last().unwrap();
        let last_bin = ((last - t0).max(0) / self.dt) as usize;
        self.check_bin(last, last_bin)?;
        if self.counts.len() <= last_bin {
            self.counts.resize(last_bin + 1, 0);
        }
        for (&t, &p) in b.t.iter().zip(&b.p) {
            if t < t0 {
                continue;
            }
            let bin = ((t - t0) / self.dt) as usize;
            // out-of-order timestamps beyond the batch's last one are clamped, not trusted
            let bin = bin.min(last_bin);
            self.counts[bin] += if p { 1 } else { -1 };
        }
        Ok(())
    }

    /// Ends the stream and returns the sequence (empty when there were no events).
    pub fn finish(mut self) -> Result<PolaritySequence, SamplingError> {
        let t0 = self.t0.unwrap_or(0);
        match self.method {
            SamplingMethod::Paper => {
                if let Some((tc, votes)) = self.carry.take() {
                    self.emit_upto(tc, sign(votes), t0)?;
                }
            }
            SamplingMethod::Authors => {
                self.flush_group()?;
                let mut prev = 0;
                for v in &mut self.values {
                    if *v == EMPTY {
                        *v = prev;
                    }
                    prev = *v;
                }
            }
            SamplingMethod::Block => {
                self.values = self.counts.iter().map(|&c| c.signum() as i8).collect();
            }
            SamplingMethod::Sum | SamplingMethod::Auto => {
                return Ok(PolaritySequence {
                    t0_us: t0,
                    dt_us: self.dt,
                    values: self.counts.iter().map(|&c| c as f32).collect(),
                    method: SamplingMethod::Sum,
                    reason: self.reason,
                });
            }
        }
        Ok(PolaritySequence {
            t0_us: t0,
            dt_us: self.dt,
            values: self.values.iter().map(|&v| v as f32).collect(),
            method: self.method,
            reason: self.reason,
        })
    }
}
