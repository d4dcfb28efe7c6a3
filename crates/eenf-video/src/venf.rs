//! V-ENF (Su, Hajj-Ahmad, Garg, Wu, ICIP 2014): each row of a rolling-shutter frame is
//! exposed a row time after the one above it, so row means sample the flicker at rows·fps
//! per second, with an idle gap between frames.

use eenf_dsp::enf::{check_near_nominal, line_prominence, MIN_PROMINENCE};
use eenf_dsp::flicker::clock_offset_note;
use eenf_dsp::{butter_bandpass, median_correct, sosfiltfilt, EnfParams, StftTracker};

use crate::source::{FrameSource, VideoInfo};
use crate::VideoError;

/// How scene content is taken out before the flicker is tracked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum SceneRemoval {
    /// The paper's: each frame minus the mean of it and the next one.
    Paper,
    /// Each row minus its own mean over the surrounding second of frames.
    RowMean,
    /// Nothing removed.
    None,
}

impl SceneRemoval {
    /// Every variant, by its command-line name.
    pub const NAMES: [&'static str; 3] = ["paper", "row-mean", "none"];
}

impl std::fmt::Display for SceneRemoval {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(Self::NAMES[*self as usize])
    }
}

impl std::str::FromStr for SceneRemoval {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "paper" => Ok(SceneRemoval::Paper),
            "row-mean" => Ok(SceneRemoval::RowMean),
            "none" => Ok(SceneRemoval::None),
            _ => Err(format!("{s:?}: expected paper, row-mean or none")),
        }
    }
}

impl RowSampling {
    /// Every variant, by its command-line name.
    pub const NAMES: [&'static str; 4] = ["auto", "zero-pad", "naive", "global"];
}

impl std::fmt::Display for RowSampling {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            RowSampling::Auto(_) => "auto",
            RowSampling::ZeroPad(_) => "zero-pad",
            RowSampling::Naive => "naive",
            RowSampling::Global => "global",
        })
    }
}

/// `zero-pad` and `auto` estimate their idle rows ([`IdleRows::Auto`]).
impl std::str::FromStr for RowSampling {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => Ok(RowSampling::Auto(IdleRows::Auto)),
            "zero-pad" => Ok(RowSampling::ZeroPad(IdleRows::Auto)),
            "naive" => Ok(RowSampling::Naive),
            "global" => Ok(RowSampling::Global),
            _ => Err(format!("{s:?}: expected auto, zero-pad, naive or global")),
        }
    }
}

/// How rows become a uniformly sampled signal.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum RowSampling {
    /// Rows concatenated frame after frame at rows·fps, the idle gap ignored.
    Naive,
    /// Each frame padded with zeros for its idle rows: `L` virtual rows per frame, fs = L·fps.
    ZeroPad(IdleRows),
    /// One sample per frame (a global shutter, or frame means only): the flicker line is seen
    /// at its alias |2f0 − k·fps|, and tracked where the alias leaves it room.
    Global,
    /// Rows zero-padded (with these idle rows) or frames, whichever shows the flicker line
    /// stronger.
    Auto(IdleRows),
}

impl RowSampling {
    /// The idle rows this sampling zero-pads with, if it does.
    pub fn idle_rows(self) -> Option<IdleRows> {
        match self {
            RowSampling::ZeroPad(i) | RowSampling::Auto(i) => Some(i),
            _ => None,
        }
    }

    /// `Auto` taken as rows (`ZeroPad`); any other sampling as it is.
    pub fn resolved(self) -> Self {
        match self {
            RowSampling::Auto(i) => RowSampling::ZeroPad(i),
            other => other,
        }
    }

    /// This sampling with its idle rows set to `idle` (where it has any).
    pub fn with_idle_rows(self, idle: IdleRows) -> Self {
        match self {
            RowSampling::ZeroPad(_) => RowSampling::ZeroPad(idle),
            RowSampling::Auto(_) => RowSampling::Auto(idle),
            other => other,
        }
    }
}

/// How many virtual rows (real plus idle) one frame period holds.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum IdleRows {
    /// Estimated from the flicker's ripple within frames.
    Auto,
    /// From the sensor's readout time (first to last row), s.
    ReadoutS(f64),
    /// Given directly.
    VirtualRows(f64),
}

/// Everything V-ENF needs besides the video.
#[derive(Debug, Clone)]
pub struct VideoOptions {
    /// Grid frequency; `None` detects 50 or 60 Hz from the flicker.
    pub nominal_hz: Option<f64>,
    /// Row sampling.
    pub sampling: RowSampling,
    /// Scene removal.
    pub scene_removal: SceneRemoval,
    /// Tracker settings (window, step, peak refinement, band half width, median filter).
    pub params: EnfParams,
}

impl Default for VideoOptions {
    fn default() -> Self {
        VideoOptions {
            nominal_hz: None,
            sampling: RowSampling::Auto(IdleRows::Auto),
            scene_removal: SceneRemoval::Paper,
            params: EnfParams::default(),
        }
    }
}

/// Row means of every frame (frames × rows), the only thing V-ENF keeps of a video.
#[derive(Debug, Clone)]
pub struct RowMeans {
    /// Size and rate of the video.
    pub info: VideoInfo,
    /// `values[n * rows + i]`: mean of row i of frame n.
    pub values: Vec<f64>,
    /// Start of each frame, s from the first, when the container's frames are not evenly
    /// spaced (variable frame rate); `None` for frames `1/fps` apart.
    pub frame_times: Option<Vec<f64>>,
}

impl RowMeans {
    /// Number of frames.
    pub fn frames(&self) -> usize {
        self.values.len() / self.info.height.max(1)
    }

    /// Seconds from the first frame to the end of the last.
    pub fn duration_s(&self) -> f64 {
        let n = self.frames();
        match &self.frame_times {
            Some(t) if n > 0 => t[n - 1] + 1.0 / self.info.fps,
            _ => n as f64 / self.info.fps,
        }
    }

    /// Reads every frame of `source`; `progress` gets the frames read so far.
    pub fn read(
        source: &mut FrameSource,
        mut progress: impl FnMut(u64),
    ) -> Result<Self, VideoError> {
        let info = source.info();
        let (w, h) = (info.width, info.height);
        let mut values = Vec::new();
        let mut n = 0u64;
        while let Some(frame) = source.next_frame()? {
            for row in frame.chunks_exact(w).take(h) {
                values.push(row.iter().map(|&v| v as u32).sum::<u32>() as f64 / w as f64);
            }
            n += 1;
            if n.is_multiple_of(64) {
                progress(n);
            }
        }
        progress(n);
        // as many times as frames decoded: a frame the decoder lost drops its time, one
        // without a time (a damaged index) follows the last at the mean rate
        let frame_times = source.frame_times().map(|t| {
            let n = n as usize;
            let mut t = t[..t.len().min(n)].to_vec();
            while t.len() < n {
                t.push(t.last().map_or(0.0, |l| l + 1.0 / info.fps));
            }
            t
        });
        Ok(RowMeans {
            info,
            values,
            frame_times,
        })
    }

    /// Frames per second at the median step between frames (the stated rate without times).
    pub fn usual_fps(&self) -> f64 {
        let Some(t) = self.frame_times.as_ref().filter(|t| t.len() > 2) else {
            return self.info.fps;
        };
        let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        let k = steps.len() / 2;
        let median = *steps.select_nth_unstable_by(k, f64::total_cmp).1;
        if median > 0.0 {
            1.0 / median
        } else {
            self.info.fps
        }
    }

    /// Every row of each frame replaced by the frame's mean: what a global shutter would give.
    pub fn frame_means_as_rows(&self) -> RowMeans {
        let h = self.info.height.max(1);
        let values = self
            .values
            .chunks_exact(h)
            .flat_map(|f| {
                let m = f.iter().sum::<f64>() / h as f64;
                std::iter::repeat_n(m, h)
            })
            .collect();
        RowMeans {
            info: self.info,
            values,
            frame_times: self.frame_times.clone(),
        }
    }

    /// The row means with the scene taken out.
    pub fn without_scene(&self, how: SceneRemoval) -> RowMeans {
        let h = self.info.height;
        let n = self.frames();
        let m = &self.values;
        let values = match how {
            SceneRemoval::None => m.clone(),
            SceneRemoval::Paper => (0..n.saturating_sub(1))
                .flat_map(|f| (0..h).map(move |i| 0.5 * (m[f * h + i] - m[(f + 1) * h + i])))
                .collect(),
            SceneRemoval::RowMean => {
                let half = ((self.info.fps / 2.0).round() as usize).max(1);
                let mut out = vec![0.0; m.len()];
                for i in 0..h {
                    // running sum over frames f − half ..= f + half
                    let col = |f: usize| m[f * h + i];
                    let (mut lo, mut hi, mut sum) = (0usize, 0usize, 0.0);
                    for f in 0..n {
                        let (want_lo, want_hi) = (f.saturating_sub(half), (f + half + 1).min(n));
                        while hi < want_hi {
                            sum += col(hi);
                            hi += 1;
                        }
                        while lo < want_lo {
                            sum -= col(lo);
                            lo += 1;
                        }
                        out[f * h + i] = col(f) - sum / (hi - lo) as f64;
                    }
                }
                out
            }
        };
        // the paper's difference of frames f and f + 1 sits at frame f's time
        let frames = values.len() / h.max(1);
        RowMeans {
            info: self.info,
            values,
            frame_times: self
                .frame_times
                .as_ref()
                .map(|t| t[..frames.min(t.len())].to_vec()),
        }
    }
}

/// An ENF trace from a video and how it was made.
#[derive(Debug, Clone, serde::Serialize)]
pub struct VideoAnalysis {
    /// Seconds between estimates; estimate i is centred at i·step_s from the first frame.
    pub step_s: f64,
    /// The ENF, Hz.
    pub enf_hz: Vec<f64>,
    /// Grid frequency used, Hz.
    pub nominal_hz: f64,
    /// The sampling used (`auto` resolved to rows or frames).
    pub sampling: RowSampling,
    /// Why `auto` chose it (`None` when the sampling was given).
    pub sampling_reason: Option<String>,
    /// The scene removal used (`paper` becomes `row-mean` for frames timed by the container).
    pub scene_removal: SceneRemoval,
    /// Sampling rate of the row signal, Hz.
    pub fs: f64,
    /// Virtual rows per frame (zero-padding), if used.
    pub virtual_rows: Option<f64>,
    /// Frequency of the flicker line tracked (2f0, or its alias for a global shutter), Hz.
    pub line_hz: f64,
    /// How far that line stands above the spectrum around it.
    pub prominence: f64,
    /// Frames read.
    pub frames: usize,
    /// True when the frames' times came from the container (variable frame rate).
    pub frame_times: bool,
    /// Size and rate of the video.
    pub info: VideoInfo,
    /// What the caller should be told: a camera clock that seems off.
    pub warnings: Vec<String>,
}

/// Estimates the virtual rows per frame from the flicker's ripple down each frame: the L for
/// which a tone at 2f0/(L·fps) cycles per row is strongest, summed over up to 600 frames.
pub fn estimate_virtual_rows(rows: &RowMeans, nominal_hz: f64) -> f64 {
    let (h, fps) = (rows.info.height, rows.info.fps);
    let frames = rows.frames().min(600);
    let power = |l: f64| {
        let nu = 2.0 * nominal_hz / (l * fps);
        let (s, c) = (2.0 * std::f64::consts::PI * nu).sin_cos();
        let mut total = 0.0;
        for f in 0..frames {
            let frame = &rows.values[f * h..(f + 1) * h];
            let mean = frame.iter().sum::<f64>() / h as f64;
            // phasor recursion along the rows
            let (mut re, mut im, mut pr, mut pi) = (0.0, 0.0, 1.0, 0.0);
            for &v in frame {
                re += (v - mean) * pr;
                im -= (v - mean) * pi;
                (pr, pi) = (pr * c - pi * s, pr * s + pi * c);
            }
            total += re * re + im * im;
        }
        total
    };
    // the readout takes between 20 % and 100 % of the frame period
    let (lo, hi) = (h as f64, 5.0 * h as f64);
    let steps = 400;
    let grid: Vec<f64> = (0..=steps)
        .map(|k| lo * (hi / lo).powf(k as f64 / steps as f64))
        .collect();
    let (mut best, mut best_p) = (lo, -1.0);
    for &l in &grid {
        let p = power(l);
        if p > best_p {
            (best, best_p) = (l, p);
        }
    }
    best
}

/// How far a grid's ENF strays from nominal, Hz: on the flicker line (2f) twice as far.
pub const ENF_REACH_HZ: f64 = 0.1;

/// How far a camera's frame clock may be off, as a share: crystals are off by tens of ppm, and
/// a file may state a rounded rate (29.97 for 30000/1001 is 1 ppm off).
pub const CLOCK_TOLERANCE: f64 = 5e-4;

/// Frame means are laid on a grid of at least this many samples per second, so that every
/// grid's flicker line and the 6 Hz around it that [`line_prominence`] measures fit below its
/// Nyquist frequency.
const FRAME_SIGNAL_HZ: f64 = 1000.0;

/// The alias of the flicker line `line_2f` in one sample per frame at `fps`: |2f − k·fps| with
/// the k that brings it nearest 0.
pub fn frame_alias(line_2f: f64, fps: f64) -> f64 {
    (line_2f - (line_2f / fps).round() * fps).abs()
}

/// The share of its half band that a Butterworth band-pass of `order` passes flat (within
/// 0.1 dB): |H|² = 1/(1 + Ω^2N) stays above 10^(−0.01) for Ω under (10^0.01 − 1)^(1/2N)
/// (0.62 for order 4).
fn flat_share(order: usize) -> f64 {
    (10f64.powf(0.01) - 1.0).powf(1.0 / (2.0 * order.max(1) as f64))
}

/// The half band (Hz, around 2f0) the tracker can use when one sample per frame sees the
/// flicker, or why there is none. One sample per frame folds the spectrum at 0 and at fps/2:
/// the line's alias a has a mirror image 2m away, where m is its distance to the nearer fold.
/// The band must keep the line flat over its reach e (the ENF's ±0.1 Hz, doubled on the
/// flicker line, and a frame clock off by up to [`CLOCK_TOLERANCE`]) and the tracker
/// window's main lobe (2/window Hz), and must end before the fold (so the mirror, which comes
/// as close as 2(m − e), lies beyond the filter's edge).
pub fn frame_half_band(nominal_hz: f64, fps: f64, p: &EnfParams) -> Result<f64, String> {
    let line = 2.0 * nominal_hz;
    let a = frame_alias(line, fps);
    let fold = a.min(fps / 2.0 - a);
    let reach = 2.0 * ENF_REACH_HZ + line * CLOCK_TOLERANCE;
    let needed = (reach + 2.0 / p.window_s) / flat_share(p.filter_order);
    let half_band = p.half_band_hz.min(fold - reach);
    if half_band < needed {
        let (edge, at) = if a < fps / 4.0 {
            ("0", "above")
        } else {
            ("the Nyquist frequency", "below")
        };
        return Err(format!(
            "at {fps:.3} fps the {line:.0} Hz flicker aliases to {a:.2} Hz, {fold:.2} Hz {at} {edge}: too close to track (its band needs {needed:.2} Hz each side: the ENF's reach ±{reach:.2} Hz on the line and the {} s window's resolution)",
            p.window_s
        ));
    }
    Ok(half_band)
}

/// Lays frames of `h` values each on a uniform grid of `l` ≥ `h` slots per frame period (the
/// rest zeros): frame f at f·l, or at its time from the container. The signal and its rate.
fn place(values: &[f64], h: usize, l: usize, fps: f64, times: Option<&[f64]>) -> (Vec<f64>, f64) {
    let fs = l as f64 * fps;
    let n = values.len() / h.max(1);
    let starts: Vec<usize> = match times {
        None => (0..n).map(|f| f * l).collect(),
        Some(t) => {
            let mut next = 0usize;
            t[..n]
                .iter()
                .map(|&s| {
                    let at = ((s * fs).round().max(0.0) as usize).max(next);
                    next = at + h;
                    at
                })
                .collect()
        }
    };
    let mut x = vec![0.0; starts.last().map_or(0, |&s| s + l)];
    for (f, &s) in starts.iter().enumerate() {
        x[s..s + h].copy_from_slice(&values[f * h..(f + 1) * h]);
    }
    (x, fs)
}

/// The row signal as one uniformly sampled sequence, and its rate.
fn sample(rows: &RowMeans, sampling: RowSampling, virtual_rows: Option<f64>) -> (Vec<f64>, f64) {
    let (h, fps) = (rows.info.height, rows.info.fps);
    let n = rows.frames();
    let times = rows.frame_times.as_deref();
    match sampling {
        RowSampling::Naive => (rows.values.clone(), h as f64 * fps),
        RowSampling::Global => {
            // frame means as impulses: the flicker line stays at 2f, its alias's images
            // at 2f ± j·fps
            let means: Vec<f64> = (0..n)
                .map(|f| rows.values[f * h..(f + 1) * h].iter().sum::<f64>() / h as f64)
                .collect();
            let slots = (FRAME_SIGNAL_HZ / fps).ceil().max(1.0) as usize;
            place(&means, 1, slots, fps, times)
        }
        RowSampling::ZeroPad(_) | RowSampling::Auto(_) => {
            let l = (virtual_rows.unwrap_or(h as f64).round() as usize).max(h);
            place(&rows.values, h, l, fps, times)
        }
    }
}

/// Where frames cannot be used, `auto` samples by rows only when their line stands this many
/// times higher than the same rows flattened to their frame means.
const MIN_ROWS_GAIN: f64 = 1.2;

/// One way of sampling one grid's flicker, measured.
struct Candidate {
    nominal: f64,
    sampling: RowSampling,
    virtual_rows: Option<f64>,
    /// The signal, its rate and the half band around 2f0 it can be tracked in.
    x: Vec<f64>,
    fs: f64,
    half_band: f64,
    prominence: f64,
}

/// Samples `rows` for the `nominal` grid's flicker with `sampling`, or says why it cannot.
fn candidate(
    rows: &RowMeans,
    nominal: f64,
    sampling: RowSampling,
    p: &EnfParams,
) -> Result<Candidate, String> {
    let info = rows.info;
    let line = 2.0 * nominal;
    let half_band = match sampling {
        // frames timed by the container: their usual step folds the spectrum as well as
        // their mean rate does (a 10 fps stream with one gap is still 10 fps)
        RowSampling::Global => {
            let usual = rows.usual_fps();
            frame_half_band(nominal, usual, p)?.min(frame_half_band(nominal, info.fps, p)?)
        }
        _ => p.half_band_hz,
    };
    let virtual_rows = match sampling.idle_rows() {
        Some(IdleRows::VirtualRows(l)) => Some(l),
        Some(IdleRows::ReadoutS(r)) => Some(info.height as f64 / (r * info.fps)),
        Some(IdleRows::Auto) => Some(estimate_virtual_rows(rows, nominal)),
        None => None,
    };
    let (x, fs) = sample(rows, sampling, virtual_rows);
    if line + half_band + 6.0 >= fs / 2.0 {
        return Err(format!(
            "rows sampled at {fs:.0} Hz leave no room for the {line:.0} Hz flicker"
        ));
    }
    let prominence = line_prominence(&x, fs, line);
    // `auto` asks rows for more than frames could give where one sample per frame cannot
    // tell the line from its mirror: a global shutter's rows, all exposed at once, hold the
    // frames' information only, and would be tracked between the two
    if let (RowSampling::Auto(_), Err(_)) = (sampling, frame_half_band(nominal, info.fps, p)) {
        let flat = rows.frame_means_as_rows();
        let (y, _) = sample(&flat, sampling, virtual_rows);
        let frames_only = line_prominence(&y, fs, line);
        if prominence < MIN_ROWS_GAIN * frames_only {
            return Err(format!(
                "the rows show the {line:.0} Hz line no stronger than their frame means do ({prominence:.1}x against {frames_only:.1}x): no rolling shutter's ripple to track it by where the frames cannot"
            ));
        }
    }
    Ok(Candidate {
        nominal,
        sampling: sampling.resolved(),
        virtual_rows,
        x,
        fs,
        half_band,
        prominence,
    })
}

/// V-ENF on row means already read (see [`RowMeans::read`]).
pub fn video_enf_from_rows(
    raw: &RowMeans,
    opts: &VideoOptions,
) -> Result<VideoAnalysis, VideoError> {
    let info = raw.info;
    let p = &opts.params;
    let duration = raw.duration_s();
    if duration < p.window_s {
        return Err(VideoError::Signal(format!(
            "the video lasts {duration:.2} s, shorter than one {} s analysis window",
            p.window_s
        )));
    }
    // the paper's removal differences consecutive frames, which at uneven spacing mixes the
    // flicker's phases: frames timed by the container have each row's running mean taken out
    let removal = match (opts.scene_removal, &raw.frame_times) {
        (SceneRemoval::Paper, Some(_)) => SceneRemoval::RowMean,
        (how, _) => how,
    };
    let rows = raw.without_scene(removal);
    let nominals: Vec<f64> = match opts.nominal_hz {
        Some(f) => vec![f],
        None => vec![50.0, 60.0],
    };
    let samplings = match opts.sampling {
        // rows tried as `Auto`: see `candidate`
        RowSampling::Auto(idle) => vec![RowSampling::Auto(idle), RowSampling::Global],
        s => vec![s],
    };
    // every (grid, sampling) measured; the strongest line kept
    let mut best: Option<Candidate> = None;
    let mut tried: Vec<(f64, RowSampling, Result<f64, String>)> = Vec::new();
    for &nominal in &nominals {
        for &sampling in &samplings {
            let c = candidate(&rows, nominal, sampling, p);
            tried.push((
                nominal,
                sampling.resolved(),
                c.as_ref().map(|c| c.prominence).map_err(Clone::clone),
            ));
            if let Ok(c) = c {
                if best.as_ref().is_none_or(|b| c.prominence > b.prominence) {
                    best = Some(c);
                }
            }
        }
    }
    let refused: Vec<&str> = tried
        .iter()
        .filter_map(|t| t.2.as_ref().err())
        .map(String::as_str)
        .collect();
    let Some(c) = best else {
        return Err(VideoError::Signal(if refused.len() == 1 {
            refused[0].to_string()
        } else {
            format!(
                "at {:.3} fps neither a 50 nor a 60 Hz grid's flicker can be tracked ({})",
                info.fps,
                refused.join("; ")
            )
        }));
    };
    let line_2f = 2.0 * c.nominal;
    let line = match c.sampling {
        RowSampling::Global => frame_alias(line_2f, info.fps),
        _ => line_2f,
    };
    if c.prominence < MIN_PROMINENCE {
        let also = if refused.is_empty() {
            String::new()
        } else {
            format!("; {}", refused.join("; "))
        };
        return Err(VideoError::Signal(format!(
            "no flicker in the video: the line at {line:.2} Hz ({} Hz grid) stands only {:.1}x above the noise, {MIN_PROMINENCE}x needed{also}",
            c.nominal, c.prominence
        )));
    }
    let sampling_reason = (samplings.len() > 1).then(|| auto_reason(&c, &tried));
    // band-pass at 2f0, then keep every D-th sample (nothing is left to alias) so the
    // tracker works at about 1 kHz
    let band = (line_2f - c.half_band, line_2f + c.half_band);
    let sos = butter_bandpass(p.filter_order, band.0, band.1, c.fs);
    let y = sosfiltfilt(&sos, &c.x);
    drop(c.x);
    let d = ((c.fs / (8.0 * band.1).max(1000.0)).floor() as usize).max(1);
    let yd: Vec<f64> = y.iter().step_by(d).copied().collect();
    let tracker = StftTracker {
        fs: c.fs / d as f64,
        window_s: p.window_s,
        step_s: p.step_s,
        peak: p.peak,
        paper_bin_hz: p.paper_bin_hz,
    };
    let on_2f = tracker.track(&yd, band);
    // outliers corrected on the 2f scale, then halved
    let corrected = if p.median_len > 1 {
        median_correct(&on_2f, p.median_len, p.median_threshold_hz)
    } else {
        on_2f
    };
    let enf_hz: Vec<f64> = corrected.iter().map(|f| f / 2.0).collect();
    // a line further off than any grid strays is not the mains (as for events and sound)
    check_near_nominal(&enf_hz, c.nominal).map_err(|e| VideoError::Signal(e.to_string()))?;
    let warnings = clock_offset_note(2.0 * mean_of(&enf_hz), line_2f)
        .into_iter()
        .collect();
    Ok(VideoAnalysis {
        step_s: p.step_s,
        enf_hz,
        nominal_hz: c.nominal,
        sampling: c.sampling,
        sampling_reason,
        scene_removal: removal,
        fs: c.fs,
        virtual_rows: c.virtual_rows,
        line_hz: line,
        prominence: c.prominence,
        frames: raw.frames(),
        frame_times: raw.frame_times.is_some(),
        info,
        warnings,
    })
}

/// The mean of the finite values (NaN when there is none).
fn mean_of(x: &[f64]) -> f64 {
    let (s, n) = x
        .iter()
        .filter(|v| v.is_finite())
        .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        s / n as f64
    }
}

/// Why `auto` sampled by rows or by frames: the line's height both ways on the chosen grid.
fn auto_reason(chosen: &Candidate, tried: &[(f64, RowSampling, Result<f64, String>)]) -> String {
    let by = |s: RowSampling| match s {
        RowSampling::Global => "frame means",
        _ => "rows",
    };
    let other = tried
        .iter()
        .find(|t| t.0 == chosen.nominal && t.1 != chosen.sampling);
    let rest = match other.map(|t| (t.1, &t.2)) {
        Some((s, Ok(p))) => format!(", {p:.1}x in the {}", by(s)),
        Some((s, Err(why))) => format!("; the {} cannot be used: {why}", by(s)),
        None => String::new(),
    };
    format!(
        "{}: the flicker line stands {:.1}x above the noise in the {}{rest}",
        chosen.sampling,
        chosen.prominence,
        by(chosen.sampling)
    )
}

/// V-ENF on a video: row means, scene removal, row sampling, band-pass at the flicker line,
/// the STFT tracker, halved.
pub fn video_enf(
    source: &mut FrameSource,
    opts: &VideoOptions,
    progress: impl FnMut(u64),
) -> Result<VideoAnalysis, VideoError> {
    let rows = RowMeans::read(source, progress)?;
    if rows.frames() == 0 {
        return Err(VideoError::Signal("the video holds no frame".into()));
    }
    video_enf_from_rows(&rows, opts)
}

/// The strongest line of the row signal between `lo` and `hi` Hz (for checking where a
/// sampling puts the flicker).
pub fn strongest_line(
    rows: &RowMeans,
    sampling: RowSampling,
    virtual_rows: Option<f64>,
    lo: f64,
    hi: f64,
) -> f64 {
    let (x, fs) = sample(rows, sampling, virtual_rows);
    let n = x.len().next_power_of_two();
    let fft = realfft::RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let mut input = fft.make_input_vec();
    input[..x.len()].copy_from_slice(&x);
    let mut spec = fft.make_output_vec();
    fft.process(&mut input, &mut spec)
        .expect("sized by the plan");
    let df = fs / n as f64;
    let k_lo = (lo / df).ceil() as usize;
    let k_hi = ((hi / df).floor() as usize).min(spec.len() - 1);
    let k = (k_lo..=k_hi)
        .max_by(|&a, &b| spec[a].norm_sqr().total_cmp(&spec[b].norm_sqr()))
        .unwrap_or(k_lo);
    k as f64 * df
}
