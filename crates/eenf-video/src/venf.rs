//! V-ENF (Su, Hajj-Ahmad, Garg, Wu, ICIP 2014): each row of a rolling-shutter frame is
//! exposed a row time after the one above it, so row means sample the flicker at rows·fps
//! per second, with an idle gap between frames.

use eenf_dsp::enf::{line_prominence, MIN_PROMINENCE};
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
    pub const NAMES: [&'static str; 3] = ["zero-pad", "naive", "global"];
}

impl std::fmt::Display for RowSampling {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            RowSampling::ZeroPad(_) => "zero-pad",
            RowSampling::Naive => "naive",
            RowSampling::Global => "global",
        })
    }
}

/// `zero-pad` estimates its idle rows ([`IdleRows::Auto`]).
impl std::str::FromStr for RowSampling {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "zero-pad" => Ok(RowSampling::ZeroPad(IdleRows::Auto)),
            "naive" => Ok(RowSampling::Naive),
            "global" => Ok(RowSampling::Global),
            _ => Err(format!("{s:?}: expected zero-pad, naive or global")),
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
    /// One sample per frame (a global shutter): the flicker is tracked at its alias.
    Global,
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
            sampling: RowSampling::ZeroPad(IdleRows::Auto),
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
}

impl RowMeans {
    /// Number of frames.
    pub fn frames(&self) -> usize {
        self.values.len() / self.info.height.max(1)
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
        Ok(RowMeans { info, values })
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
        RowMeans {
            info: self.info,
            values,
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
    /// Video size and rate.
    pub info: VideoInfo,
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

/// The flicker line a sampling sees: 2f0 for rows, its alias |2f0 − k·fps| for one sample per
/// frame; with the sign of the alias (−1 when it runs against the ENF) and k.
fn line_for(sampling: RowSampling, nominal: f64, fps: f64) -> (f64, f64, f64) {
    match sampling {
        RowSampling::Global => {
            let k = (2.0 * nominal / fps).round();
            let a = 2.0 * nominal - k * fps;
            (a.abs(), if a >= 0.0 { 1.0 } else { -1.0 }, k)
        }
        _ => (2.0 * nominal, 1.0, 0.0),
    }
}

/// The row signal as one uniformly sampled sequence, and its rate.
fn sample(rows: &RowMeans, sampling: RowSampling, virtual_rows: Option<f64>) -> (Vec<f64>, f64) {
    let (h, fps) = (rows.info.height, rows.info.fps);
    let n = rows.frames();
    match sampling {
        RowSampling::Naive => (rows.values.clone(), h as f64 * fps),
        RowSampling::Global => (
            (0..n)
                .map(|f| rows.values[f * h..(f + 1) * h].iter().sum::<f64>() / h as f64)
                .collect(),
            fps,
        ),
        RowSampling::ZeroPad(_) => {
            let l = (virtual_rows.unwrap_or(h as f64).round() as usize).max(h);
            let mut x = vec![0.0; n * l];
            for f in 0..n {
                x[f * l..f * l + h].copy_from_slice(&rows.values[f * h..(f + 1) * h]);
            }
            (x, l as f64 * fps)
        }
    }
}

/// V-ENF on row means already read (see [`RowMeans::read`]).
pub fn video_enf_from_rows(
    raw: &RowMeans,
    opts: &VideoOptions,
) -> Result<VideoAnalysis, VideoError> {
    let info = raw.info;
    let p = &opts.params;
    let duration = raw.frames() as f64 / info.fps;
    if duration < p.window_s {
        return Err(VideoError::Signal(format!(
            "the video lasts {duration:.2} s, shorter than one {} s analysis window",
            p.window_s
        )));
    }
    let rows = raw.without_scene(opts.scene_removal);
    let nominals: Vec<f64> = match opts.nominal_hz {
        Some(f) => vec![f],
        None => vec![50.0, 60.0],
    };
    // for each candidate grid: the virtual rows, the signal and how its line stands out
    // (grid, virtual rows, signal, rate, prominence)
    type Candidate = (f64, Option<f64>, Vec<f64>, f64, f64);
    let mut best: Option<Candidate> = None;
    for &nominal in &nominals {
        let virtual_rows = match opts.sampling {
            RowSampling::ZeroPad(IdleRows::VirtualRows(l)) => Some(l),
            RowSampling::ZeroPad(IdleRows::ReadoutS(r)) => {
                Some(info.height as f64 / (r * info.fps))
            }
            RowSampling::ZeroPad(IdleRows::Auto) => Some(estimate_virtual_rows(&rows, nominal)),
            _ => None,
        };
        let (x, fs) = sample(&rows, opts.sampling, virtual_rows);
        let (line, _, _) = line_for(opts.sampling, nominal, info.fps);
        if line < p.half_band_hz + 0.5 || line + p.half_band_hz + 6.0 >= fs / 2.0 {
            if opts.nominal_hz.is_some() {
                return Err(VideoError::Signal(format!(
                    "at {:.3} fps the {:.0} Hz flicker aliases to {line:.2} Hz, too close to 0 or to the Nyquist frequency to track",
                    info.fps,
                    2.0 * nominal
                )));
            }
            continue;
        }
        let prom = line_prominence(&x, fs, line);
        if best.as_ref().is_none_or(|b| prom > b.4) {
            best = Some((nominal, virtual_rows, x, fs, prom));
        }
    }
    let Some((nominal, virtual_rows, x, fs, prominence)) = best else {
        return Err(VideoError::Signal(format!(
            "at {:.3} fps neither a 50 nor a 60 Hz grid's flicker can be tracked",
            info.fps
        )));
    };
    let (line, sign, k) = line_for(opts.sampling, nominal, info.fps);
    if prominence < MIN_PROMINENCE {
        return Err(VideoError::Signal(format!(
            "no flicker in the video: the line at {line:.2} Hz ({nominal} Hz grid) stands only {prominence:.1}x above the noise, {MIN_PROMINENCE}x needed"
        )));
    }
    // band-pass at the line, then keep every D-th sample (nothing is left to alias) so the
    // tracker works at about 1 kHz
    let band = (line - p.half_band_hz, line + p.half_band_hz);
    let sos = butter_bandpass(p.filter_order, band.0, band.1, fs);
    let y = sosfiltfilt(&sos, &x);
    let d = ((fs / (8.0 * band.1).max(1000.0)).floor() as usize).max(1);
    let yd: Vec<f64> = y.iter().step_by(d).copied().collect();
    let tracker = StftTracker {
        fs: fs / d as f64,
        window_s: p.window_s,
        step_s: p.step_s,
        peak: p.peak,
        paper_bin_hz: p.paper_bin_hz,
    };
    let raw_line = tracker.track(&yd, band);
    // back to the 2f scale, outliers corrected there, then halved
    let on_2f: Vec<f64> = raw_line.iter().map(|&a| k * info.fps + sign * a).collect();
    let corrected = if p.median_len > 1 {
        median_correct(&on_2f, p.median_len, p.median_threshold_hz)
    } else {
        on_2f
    };
    Ok(VideoAnalysis {
        step_s: p.step_s,
        enf_hz: corrected.iter().map(|f| f / 2.0).collect(),
        nominal_hz: nominal,
        fs,
        virtual_rows,
        line_hz: line,
        prominence,
        frames: raw.frames(),
        info,
    })
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
