//! The mains line detector: where a recording's hum stands, at which harmonics of which grid,
//! and how far above the noise, measured one way for every input.
//!
//! Each harmonic k·f0 (k = 1 … [`MAX_HUM_HARMONIC`], of a 50 Hz and a 60 Hz grid, times 2 for
//! light flicker) is looked for within k·[`MAX_NOMINAL_OFFSET_HZ`] of its nominal place in a
//! Welch spectrum (Hann segments of up to 16 s, half overlapping). Its strength is the peak's
//! power over the median power of the spectrum 1–6 Hz beyond that window on either side (the
//! local floor), in dB. A line stands when it clears both [`MIN_LINE_DB`] and the height that
//! noise alone reaches at a false-alarm rate of [`FALSE_ALARM`] over every bin searched, which
//! depends on how many segments were averaged (Welch 1967; the chi-square quantile by Wilson
//! and Hilferty 1931). Spectrum combining over harmonics follows Hajj-Ahmad, Garg and Wu
//! (2013): every harmonic that stands may carry the ENF.

use eenf_core::spelling::option;
use rayon::prelude::*;
use realfft::RealFftPlanner;

use crate::blocks::BlockSource;
use crate::enf::{DspError, MAX_NOMINAL_OFFSET_HZ};

/// The highest harmonic looked for: a recorder's hum often stands strongest at 2–4 f0, and
/// eight still fit below 500 Hz, the Nyquist limit of 1 kHz recordings.
pub const MAX_HUM_HARMONIC: usize = 8;

/// A line must stand at least this far above its local floor (dB of power in the Welch
/// spectrum), however many segments were averaged: recordings without hum show lines of
/// up to 2.6 dB at mains harmonics (`enfwhu_H0_01_no_enf_1kHz.wav`, 16 s segments).
pub const MIN_LINE_DB: f64 = 6.0;

/// The chance that noise alone makes some line of a recording stand.
pub const FALSE_ALARM: f64 = 1e-3;

/// The longest Welch segment, s: within 16 s the ENF moves by a few mHz, so its line stays in
/// one bin up to 8 f0.
pub const MAX_SEGMENT_S: f64 = 16.0;

/// At most this many segments are averaged (spread over the recording): more would not lower
/// the threshold below [`MIN_LINE_DB`] and would only cost time on hour-long files.
const MAX_SEGMENTS: usize = 96;

/// How far beyond the search window the local floor begins and ends, Hz.
const FLOOR_GAP_HZ: (f64, f64) = (1.0, 6.0);

/// One harmonic's line.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HumLine {
    /// The grid, 50 or 60 Hz.
    pub grid_hz: f64,
    /// Harmonic number k (the line sits near k·grid·multiple).
    pub harmonic: usize,
    /// Where the line's peak is, divided by k·multiple: the grid frequency it implies, Hz.
    pub f0_hz: f64,
    /// Its power over the local floor, dB.
    pub db: f64,
    /// What it must reach to stand, dB.
    pub threshold_db: f64,
    /// True when the other grid has a harmonic at the same place (300 Hz is 6·50 and 5·60):
    /// such a line cannot tell the grids apart.
    pub shared: bool,
}

impl HumLine {
    /// True when the line stands above noise.
    pub fn stands(&self) -> bool {
        self.db >= self.threshold_db
    }
}

/// Every harmonic's line in a recording.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HumSearch {
    /// Welch segment length, s.
    pub segment_s: f64,
    /// Segments averaged.
    pub segments: usize,
    /// The height noise alone reaches with probability [`FALSE_ALARM`] over every bin
    /// searched, dB over the floor (each line's threshold is this or [`MIN_LINE_DB`]).
    pub noise_db: f64,
    /// 1 for sound (lines at k·f0), 2 for light flicker (k·2f0).
    pub multiple: f64,
    /// The lines, grid by grid, harmonic by harmonic.
    pub lines: Vec<HumLine>,
}

/// What the detector decided: the grid and the harmonics that carry its ENF.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HumVerdict {
    /// The grid, 50 or 60 Hz.
    pub grid_hz: f64,
    /// The harmonics that stand, strongest first.
    pub carriers: Vec<usize>,
    /// The strongest of them.
    pub strongest: HumLine,
}

/// Lines of `x` (sampled at `fs`) at k·`multiple`·grid for each grid in `grids` and k up to
/// `max_harmonic` (those that fit below Nyquist with their floor). `None` when the signal is
/// shorter than 1 s or no harmonic fits.
pub fn search_hum(
    x: &[f64],
    fs: f64,
    multiple: f64,
    grids: &[f64],
    max_harmonic: usize,
) -> Option<HumSearch> {
    search_lines(&x, fs, multiple, grids, max_harmonic, 0.0)
        .ok()
        .flatten()
}

/// [`search_hum`] over a signal read a block at a time (only the Welch segments are read).
pub fn search_hum_in(
    x: &dyn BlockSource,
    fs: f64,
    multiple: f64,
    grids: &[f64],
    max_harmonic: usize,
) -> Result<Option<HumSearch>, DspError> {
    search_lines(x, fs, multiple, grids, max_harmonic, 0.0)
}

/// A light's flicker lines at 2k·grid (k = 1 … `max_harmonic`), measured as [`search_hum`]
/// measures sound's hum, each looked for further from its nominal place by the share
/// [`FLICKER_CLOCK_SHARE`]: the camera's clock, which times every event or frame, may run
/// off, and moves every line by the same share.
pub fn search_flicker(x: &[f64], fs: f64, grids: &[f64], max_harmonic: usize) -> Option<HumSearch> {
    search_lines(&x, fs, 2.0, grids, max_harmonic, FLICKER_CLOCK_SHARE)
        .ok()
        .flatten()
}

/// How far off a camera's clock may run, as a share, for its flicker lines still to be found:
/// twice the furthest seen in a real recording (a DVS128 0.26 % fast). At 2·50 Hz the search
/// reaches ±1 Hz, at 2·60 Hz ±1.12 Hz.
pub const FLICKER_CLOCK_SHARE: f64 = 0.006;

/// [`search_hum`] with each line looked for `clock_share` of its place further (a clock that
/// runs off).
fn search_lines(
    x: &dyn BlockSource,
    fs: f64,
    multiple: f64,
    grids: &[f64],
    max_harmonic: usize,
    clock_share: f64,
) -> Result<Option<HumSearch>, DspError> {
    let duration = x.len() as f64 / fs;
    if fs.is_nan() || fs <= 0.0 || duration < 1.0 {
        return Ok(None);
    }
    // at least three half-overlapping segments, each at most 16 s
    let segment_s = (duration / 2.0).min(MAX_SEGMENT_S);
    let seg = ((segment_s * fs).round() as usize).max(8);
    let hop = seg / 2;
    let available = (x.len() - seg) / hop + 1;
    let count = available.min(MAX_SEGMENTS);
    let starts: Vec<usize> = (0..count)
        .map(|i| {
            if count == 1 {
                0
            } else {
                i * (available - 1) / (count - 1) * hop
            }
        })
        .collect();
    let segments = starts
        .iter()
        .map(|&s| x.read(s..s + seg))
        .collect::<Result<Vec<_>, _>>()?;
    let Some(power) = welch(&segments) else {
        return Ok(None);
    };
    let nfft = (power.len() - 1) * 2;
    let df = fs / nfft as f64;
    // lines, and their bins searched, before the threshold is known
    let mut found = Vec::new();
    let mut tests = 0usize;
    for &grid in grids {
        for k in 1..=max_harmonic {
            let centre = k as f64 * multiple * grid;
            let reach = k as f64 * multiple * (MAX_NOMINAL_OFFSET_HZ + grid * clock_share);
            if centre + reach + FLOOR_GAP_HZ.1 >= fs / 2.0 {
                break;
            }
            let bin = |f: f64| ((f / df).round().max(0.0) as usize).min(power.len() - 1);
            let (lo, hi) = (bin(centre - reach), bin(centre + reach));
            let (i, peak) =
                (lo..=hi)
                    .map(|i| (i, power[i]))
                    .fold(
                        (lo, f64::NEG_INFINITY),
                        |b, c| if c.1 > b.1 { c } else { b },
                    );
            let mut floor: Vec<f64> = (bin(centre - reach - FLOOR_GAP_HZ.1)
                ..=bin(centre - reach - FLOOR_GAP_HZ.0))
                .chain(bin(centre + reach + FLOOR_GAP_HZ.0)..=bin(centre + reach + FLOOR_GAP_HZ.1))
                .map(|i| power[i])
                .collect();
            let m = floor.len() / 2;
            let median = *floor.select_nth_unstable_by(m, f64::total_cmp).1;
            let db = if median > 0.0 && peak > 0.0 {
                10.0 * (peak / median).log10()
            } else {
                f64::NEG_INFINITY
            };
            let hz = refine(&power, i) * df;
            tests += hi - lo + 1;
            let other = grids
                .iter()
                .any(|&g| g != grid && (centre / (multiple * g)).fract() == 0.0);
            found.push(HumLine {
                grid_hz: grid,
                harmonic: k,
                f0_hz: hz / (k as f64 * multiple),
                db,
                threshold_db: 0.0,
                shared: other,
            });
        }
    }
    if found.is_empty() {
        return Ok(None);
    }
    let threshold_db = noise_threshold_db(effective_segments(starts.len(), hop, seg), tests);
    for l in &mut found {
        l.threshold_db = threshold_db.max(MIN_LINE_DB);
    }
    Ok(Some(HumSearch {
        segment_s: seg as f64 / fs,
        segments: starts.len(),
        noise_db: threshold_db,
        multiple,
        lines: found,
    }))
}

impl HumSearch {
    /// The lines of one grid.
    pub fn of_grid(&self, grid_hz: f64) -> impl Iterator<Item = &HumLine> {
        self.lines.iter().filter(move |l| l.grid_hz == grid_hz)
    }

    /// The strongest line of all (for messages).
    pub fn strongest(&self) -> Option<&HumLine> {
        self.lines.iter().max_by(|a, b| a.db.total_cmp(&b.db))
    }

    /// The grid whose strongest line that belongs to it alone stands highest, and its
    /// harmonics that stand. A line further than [`USUAL_OFFSET_HZ`] from nominal must be seen at a
    /// second harmonic at the same place (a clock that runs off moves every harmonic alike). Errors when no line
    /// stands.
    pub fn verdict(&self) -> Result<HumVerdict, DspError> {
        let mut best: Option<HumVerdict> = None;
        let grids: Vec<f64> = {
            let mut g: Vec<f64> = self.lines.iter().map(|l| l.grid_hz).collect();
            g.dedup();
            g
        };
        for grid in grids {
            let standing: Vec<&HumLine> = self.of_grid(grid).filter(|l| l.stands()).collect();
            // a line off nominal by more than a grid's mean strays is believed only when
            // another harmonic implies the same frequency
            let believed: Vec<&HumLine> = standing
                .iter()
                .copied()
                .filter(|l| {
                    (l.f0_hz - grid).abs() <= USUAL_OFFSET_HZ
                        || standing.iter().any(|o| {
                            o.harmonic != l.harmonic
                                && o.db >= o.threshold_db + CONFIRM_MARGIN_DB
                                && self.agree(o, l)
                        })
                })
                .collect();
            let Some(top) = believed
                .iter()
                .filter(|l| !l.shared)
                .max_by(|a, b| a.db.total_cmp(&b.db))
            else {
                continue;
            };
            // the same hum at every harmonic: a line elsewhere in a band is another source
            let mut carriers: Vec<&HumLine> = believed
                .iter()
                .copied()
                .filter(|l| self.agree(l, top))
                .collect();
            carriers.sort_by(|a, b| b.db.total_cmp(&a.db));
            // a line that no other harmonic confirms must clear the noise by a margin
            if carriers.len() == 1 && top.db < self.noise_db + CONFIRM_MARGIN_DB {
                continue;
            }
            if best.as_ref().is_none_or(|b| top.db > b.strongest.db) {
                best = Some(HumVerdict {
                    grid_hz: grid,
                    carriers: carriers.iter().map(|l| l.harmonic).collect(),
                    strongest: **top,
                });
            }
        }
        best.ok_or_else(|| DspError::NoTone(self.refusal()))
    }

    /// True when two lines imply the same grid frequency: each peak is placed to within
    /// [`CONFIRM_BINS`] of a Welch bin at its harmonic, a bin that shrinks by k on the f0
    /// scale (a periodic signal's comb of lines 1 Hz apart, 349 and 400 Hz, implies 49.857 and
    /// 50.000 Hz at 7 and 8 f0: not one grid).
    fn agree(&self, a: &HumLine, b: &HumLine) -> bool {
        let bin = 1.0 / (self.segment_s * self.multiple);
        let tolerance = CONFIRM_BINS * bin * (1.0 / a.harmonic as f64 + 1.0 / b.harmonic as f64);
        (a.f0_hz - b.f0_hz).abs() <= tolerance
    }

    fn refusal(&self) -> String {
        // sound names the harmonic of f0, flicker the multiple of f0 it sits at
        let name =
            |l: &HumLine| format!("{} x {} Hz", l.harmonic as f64 * self.multiple, l.grid_hz);
        let mut grids: Vec<String> = self.lines.iter().map(|l| l.grid_hz.to_string()).collect();
        grids.dedup();
        let grids = grids.join(" or ");
        let standing: Vec<&HumLine> = self.lines.iter().filter(|l| l.stands()).collect();
        if !standing.is_empty() && standing.iter().all(|l| l.shared) {
            let l = standing[0];
            return format!(
                "the only mains line, at {:.3} Hz, is a harmonic of both grids ({}): name the grid with {}",
                l.f0_hz * l.harmonic as f64 * self.multiple,
                standing
                    .iter()
                    .map(|l| format!("{} x {} Hz", l.harmonic as f64 * self.multiple, l.grid_hz))
                    .collect::<Vec<_>>()
                    .join(" = "),
                option("nominal")
            );
        }
        match self.strongest() {
            Some(l) if l.stands() && (l.f0_hz - l.grid_hz).abs() <= USUAL_OFFSET_HZ => format!(
                "no mains line: the strongest, {}, stands {:.1} dB above its local floor, but no other harmonic confirms it and a line alone must clear {:.1} dB",
                name(l),
                l.db,
                self.noise_db + CONFIRM_MARGIN_DB
            ),
            Some(l) if l.stands() => format!(
                "no mains line: the only line that stands, {} ({:.3} Hz), lies {:.0} mHz from its grid at that one harmonic alone (a tone, not the mains)",
                name(l),
                l.f0_hz * l.harmonic as f64 * self.multiple,
                1e3 * (l.f0_hz - l.grid_hz).abs()
            ),
            Some(l) => format!(
                "no mains line at any harmonic of {} Hz: the strongest, {}, stands {:.1} dB above its local floor, {:.1} dB needed",
                grids,
                name(l),
                l.db,
                l.threshold_db
            ),
            None => "no mains line: no harmonic fits below the Nyquist frequency".into(),
        }
    }
}

/// How closely a Welch peak is placed, in bins, for two harmonics to confirm each other.
const CONFIRM_BINS: f64 = 0.3;

/// A line confirms another far from nominal only when it clears its threshold by this much,
/// dB, and a line that no other harmonic confirms must clear the noise's height by as much: a
/// marginal peak lands within the tolerance by chance (a 7 Hz square wave's 399 Hz line, 125
/// mHz below 8·50 Hz, was "confirmed" by noise 9.8 dB high at 3 f0, threshold 8.8 dB), and a
/// 44.1 kHz square wave holds weak steady lines (9–10 dB at 480.3 Hz) that no grid made.
const CONFIRM_MARGIN_DB: f64 = 3.0;

/// The average power spectrum of Hann-windowed segments of `x` of `seg` samples starting at
/// `starts` (zero-padded to a power of two), computed on every core.
fn welch(segments: &[Vec<f64>]) -> Option<Vec<f64>> {
    let seg = segments.first()?.len();
    let nfft = seg.next_power_of_two();
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(nfft);
    let window: Vec<f64> = (0..seg)
        .map(|i| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / seg as f64).cos())
        .collect();
    let sum = segments
        .par_iter()
        .fold(
            || {
                (
                    vec![0.0; nfft / 2 + 1],
                    fft.make_input_vec(),
                    fft.make_output_vec(),
                )
            },
            |(mut acc, mut input, mut spec), part| {
                let mean = part.iter().sum::<f64>() / seg as f64;
                for ((d, v), w) in input.iter_mut().zip(part).zip(&window) {
                    *d = (v - mean) * w;
                }
                input[seg..].iter_mut().for_each(|d| *d = 0.0);
                if fft.process(&mut input, &mut spec).is_ok() {
                    for (a, c) in acc.iter_mut().zip(&spec) {
                        *a += c.norm_sqr();
                    }
                }
                (acc, input, spec)
            },
        )
        .map(|(acc, _, _)| acc)
        .reduce_with(|mut a, b| {
            a.iter_mut().zip(&b).for_each(|(a, b)| *a += b);
            a
        })?;
    sum.iter().all(|v| v.is_finite()).then_some(sum)
}

/// The peak's place in bins, refined by a parabola through the log powers of its neighbours.
fn refine(power: &[f64], i: usize) -> f64 {
    if i == 0 || i + 1 >= power.len() || power[i - 1] <= 0.0 || power[i + 1] <= 0.0 {
        return i as f64;
    }
    let (l, c, r) = (power[i - 1].ln(), power[i].ln(), power[i + 1].ln());
    let den = l - 2.0 * c + r;
    if den < 0.0 {
        i as f64 + (0.5 * (l - r) / den).clamp(-0.5, 0.5)
    } else {
        i as f64
    }
}

/// The degrees of freedom (in pairs) of an average of `m` Hann segments of `seg` samples,
/// `hop` apart: Welch's variance of overlapping segments (a Hann window overlapped by half
/// correlates neighbours' powers by 0.167²), for `hop` ≥ seg/2.
fn effective_segments(m: usize, hop: usize, seg: usize) -> f64 {
    let m = m as f64;
    let rho2 = if 2 * hop <= seg {
        0.167f64.powi(2)
    } else {
        0.0
    };
    m / (1.0 + 2.0 * rho2 * (m - 1.0) / m)
}

/// How far above the median of the floor (dB) noise alone reaches in one of `tests` bins with
/// probability [`FALSE_ALARM`] in all, for an average of `nu` segments: each bin's power is
/// then a Gamma(ν) variable over its mean, whose quantiles and median follow from Wilson and
/// Hilferty's cube-root normal approximation.
pub fn noise_threshold_db(nu: f64, tests: usize) -> f64 {
    let p = FALSE_ALARM / tests.max(1) as f64;
    let z = normal_quantile(1.0 - p);
    let c = 1.0 / (9.0 * nu);
    let quantile = (1.0 - c + z * c.sqrt()).powi(3);
    let median = (1.0 - c).powi(3);
    10.0 * (quantile / median).log10()
}

/// The standard normal quantile for p in (0.5, 1) (Abramowitz and Stegun 26.2.23, error below
/// 4.5·10⁻⁴).
pub fn normal_quantile(p: f64) -> f64 {
    let q = (1.0 - p).clamp(1e-300, 0.5);
    let t = (-2.0 * q.ln()).sqrt();
    t - (2.515517 + 0.802853 * t + 0.010328 * t * t)
        / (1.0 + 1.432788 * t + 0.189269 * t * t + 0.001308 * t * t * t)
}

/// Grid frequencies from the same hum at every harmonic a trace was made from: how far the
/// trace sits from nominal, and how steady it is, against what grids do.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Plausibility {
    /// Median of the trace minus nominal, Hz.
    pub offset_hz: f64,
    /// Robust spread of the trace (1.4826 × its median absolute deviation), Hz, over the
    /// estimates whose windows lie wholly inside the recording.
    pub spread_hz: f64,
    /// Seconds those estimates span.
    pub span_s: f64,
    /// Remarks: far from nominal, steadier than a grid.
    pub flags: Vec<String>,
}

/// A grid's mean over a recording stays within this of nominal in normal operation
/// (ENTSO-E's standard frequency range is ±50 mHz). A line further off at one harmonic alone
/// is a tone, not the mains (a musical F4 at 349.2 Hz lies 110 mHz below 7·50 Hz); seen at
/// two harmonics that agree, it is traced and flagged (a recorder's clock that runs off
/// moves every harmonic alike).
pub const USUAL_OFFSET_HZ: f64 = 0.05;

/// Below this robust spread over [`STEADY_SPAN_S`] or more, Hz, a trace is steadier than any
/// grid measured: over 100 s, the three days of 60 Hz traces in `shared/enf-traces-60hz` never
/// fell below 0.84 mHz; the six 50 Hz hours in `shared/enf-reference` reach 0.064 mHz (that
/// grid idles at −40 mHz for minutes).
fn least_grid_spread_hz(grid_hz: f64) -> f64 {
    if grid_hz == 60.0 {
        0.6e-3
    } else {
        0.05e-3
    }
}

/// The span of estimates over which steadiness is judged, s.
pub const STEADY_SPAN_S: f64 = 100.0;

/// Checks a trace against what grids do: its median within [`USUAL_OFFSET_HZ`] of `nominal_hz`
/// and, over at least [`STEADY_SPAN_S`], a spread no smaller than a grid's. `edge` estimates at
/// each end (half a window) are left out of the spread.
pub fn plausibility(enf_hz: &[f64], step_s: f64, nominal_hz: f64, edge: usize) -> Plausibility {
    let mut all: Vec<f64> = enf_hz.iter().copied().filter(|v| v.is_finite()).collect();
    let inner: Vec<f64> = enf_hz
        .get(edge..enf_hz.len().saturating_sub(edge))
        .unwrap_or(&[])
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    let median = |v: &mut Vec<f64>| -> f64 {
        if v.is_empty() {
            return f64::NAN;
        }
        let m = v.len() / 2;
        *v.select_nth_unstable_by(m, f64::total_cmp).1
    };
    let offset_hz = median(&mut all) - nominal_hz;
    let spread_hz = crate::metrics::robust_spread(&inner);
    let span_s = inner.len() as f64 * step_s;
    let mut flags = Vec::new();
    if offset_hz.abs() > USUAL_OFFSET_HZ {
        flags.push(format!(
            "the line sits {:.0} mHz {} {nominal_hz} Hz, further than a grid's mean strays in normal operation (±{:.0} mHz): the recorder's clock may run {:.3} % {}, or the hum is not the mains; read its absolute frequency with care",
            1e3 * offset_hz.abs(),
            if offset_hz < 0.0 { "below" } else { "above" },
            1e3 * USUAL_OFFSET_HZ,
            100.0 * offset_hz.abs() / nominal_hz,
            if offset_hz < 0.0 { "slow" } else { "fast" },
        ));
    }
    let least = least_grid_spread_hz(nominal_hz);
    if span_s >= STEADY_SPAN_S && spread_hz < least {
        flags.push(format!(
            "the line is steadier than any {nominal_hz} Hz grid measured: it varies by {:.2} mHz over {span_s:.0} s, where grids vary by at least {:.2} mHz: it may be a tone (a device's oscillator), not the mains",
            1e3 * spread_hz,
            1e3 * least
        ));
    }
    Plausibility {
        offset_hz,
        spread_hz,
        span_s,
        flags,
    }
}

/// How far a grid's frequency moves in one window's time, as the median over a recording of
/// the change between estimates one window apart, Hz: real grids reach 35 mHz over 16 s (the
/// six 50 Hz hours of `shared/enf-reference`, 40 s spans; 28 mHz for the 60 Hz traces). A
/// tracker that follows noise jumps across its band instead (a median near 150 mHz at 8 f0).
pub const MAX_WINDOW_CHANGE_HZ: f64 = 0.05;

/// Refuses a trace that does not hold a line: one whose estimates one window apart differ by
/// more than [`MAX_WINDOW_CHANGE_HZ`] in the median (the peak wandered over noise).
pub fn check_holds_line(enf_hz: &[f64], step_s: f64, window_s: f64) -> Result<(), DspError> {
    let lag = ((window_s / step_s).round() as usize).max(1);
    let mut changes: Vec<f64> = enf_hz
        .iter()
        .zip(enf_hz.iter().skip(lag))
        .map(|(a, b)| (b - a).abs())
        .filter(|d| d.is_finite())
        .collect();
    if changes.is_empty() {
        return Ok(());
    }
    let m = changes.len() / 2;
    let median = *changes.select_nth_unstable_by(m, f64::total_cmp).1;
    if median > MAX_WINDOW_CHANGE_HZ {
        return Err(DspError::NoTone(format!(
            "no mains line holds: the traced frequency moves by {:.0} mHz from one {window_s} s window to the next (the median), where a grid moves by at most {:.0} mHz; the peak is following noise",
            1e3 * median,
            1e3 * MAX_WINDOW_CHANGE_HZ
        )));
    }
    Ok(())
}

/// The analysis window for a recording of `duration_s` whose hum stands `line_db` above its
/// floor in Welch segments of `segment_s`: the `default_s` window when the recording holds it
/// and the line is strong enough there; a shorter one (16, 8 or 4 s) for a shorter clip; a
/// longer one (twice the default, when the recording holds three) for weak hum, since a window's line grows
/// 3 dB over the noise for each doubling. Returns the window and why, or an error for a clip
/// shorter than [`MIN_CLIP_S`].
pub fn choose_window(
    duration_s: f64,
    default_s: f64,
    line_db: f64,
    segment_s: f64,
) -> Result<(f64, Option<String>), DspError> {
    if duration_s < MIN_CLIP_S {
        return Err(DspError::TooShort {
            duration_s,
            window_s: MIN_CLIP_S,
        });
    }
    if duration_s < default_s {
        let mut w = default_s;
        while w > duration_s && w > MIN_CLIP_S {
            w /= 2.0;
        }
        let w = w.max(MIN_CLIP_S.min(duration_s));
        return Ok((
            w,
            Some(format!(
                "the recording lasts {duration_s:.2} s, shorter than the {default_s} s window: traced with a {w} s window (frequency resolution {:.3} Hz)",
                1.0 / w
            )),
        ));
    }
    // the line's height in a rectangular window of w s, from its Welch height (a Hann
    // segment's noise bandwidth is 1.5 bins)
    let at = |w: f64| line_db + 10.0 * (w / segment_s).log10() + 10.0 * 1.5f64.log10();
    let mut w = default_s;
    while at(w) < WINDOW_LINE_DB && 2.0 * w <= 2.0 * default_s && 6.0 * w <= duration_s {
        w *= 2.0;
    }
    if w > default_s {
        return Ok((
            w,
            Some(format!(
                "the mains line is weak ({line_db:.1} dB over its floor in {segment_s:.0} s segments): traced with a {w} s window, where it stands about {:.0} dB (frequency resolution {:.3} Hz)",
                at(w),
                1.0 / w
            )),
        ));
    }
    Ok((w, None))
}

/// The shortest clip traced, s: four seconds hold a few hundred cycles of the hum.
pub const MIN_CLIP_S: f64 = 4.0;

/// The height (dB over the window's median in-band power) a line should reach in each
/// analysis window for its peak to be found reliably: noise alone peaks at about 8 dB.
const WINDOW_LINE_DB: f64 = 13.0;
