//! The E-ENF pipeline on a sampled flicker signal, and the reference tracker for mains signals.

use rayon::prelude::*;
use realfft::num_complex::Complex64;
use realfft::RealFftPlanner;

use crate::butter::butter_bandpass;
use crate::chirp::{baseband, baseband_block, follow_in_baseband};
use crate::filtfilt::sosfiltfilt;
use crate::postprocess::{median_correct, select_audible_harmonics, HarmonicSelection};
use crate::sampling::{PolaritySequence, SamplingError};
use crate::tracker::{PeakMethod, StftTracker};

/// Every parameter of the method, with the paper's defaults (except the peak refinement).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnfParams {
    /// Nominal grid frequency f0, Hz (50 or 60).
    pub nominal_hz: f64,
    /// Number of flicker harmonics M (2m·f0 for m = 1..M; those at or above Nyquist skipped).
    pub harmonics: usize,
    /// Half width of each band-pass, Hz.
    pub half_band_hz: f64,
    /// Butterworth order of the band-pass prototype.
    pub filter_order: usize,
    /// STFT window, s.
    pub window_s: f64,
    /// STFT step, s.
    pub step_s: f64,
    /// Peak refinement.
    pub peak: PeakMethod,
    /// Bin width of the `paper` refinement, Hz.
    pub paper_bin_hz: f64,
    /// Running-median length of the outlier correction (0 disables it).
    pub median_len: usize,
    /// Outlier threshold on the 2f0 scale, Hz.
    pub median_threshold_hz: f64,
    /// Harmonic-selection segment length, in estimates (T = 10 s at 1 s steps).
    pub segment_len: usize,
    /// Harmonic-selection rule.
    pub selection: HarmonicSelection,
}

impl Default for EnfParams {
    fn default() -> Self {
        use eenf_core::defaults as d;
        EnfParams {
            nominal_hz: 50.0,
            harmonics: d::HARMONICS,
            half_band_hz: d::HALF_BAND_HZ,
            filter_order: d::FILTER_ORDER,
            window_s: d::WINDOW_S,
            step_s: d::STEP_S,
            peak: PeakMethod::Exact,
            paper_bin_hz: d::PAPER_BIN_HZ,
            median_len: d::MEDIAN_LEN,
            median_threshold_hz: d::MEDIAN_THRESHOLD_HZ,
            segment_len: d::SEGMENT_LEN,
            selection: HarmonicSelection::Consensus(HarmonicSelection::DEFAULT_AGREE_HZ),
        }
    }
}

impl EnfParams {
    /// The STFT tracker these parameters describe, at `fs`.
    pub fn tracker(&self, fs: f64) -> StftTracker {
        StftTracker {
            fs,
            window_s: self.window_s,
            step_s: self.step_s,
            peak: self.peak,
            paper_bin_hz: self.paper_bin_hz,
        }
    }
}

/// Why a trace could not be made.
#[derive(Debug, Clone, thiserror::Error)]
pub enum DspError {
    /// Less data than one STFT window.
    #[error(
        "the recording lasts {duration_s:.2} s, shorter than one {window_s} s analysis window"
    )]
    TooShort {
        /// Duration of the input, s.
        duration_s: f64,
        /// Window length, s.
        window_s: f64,
    },
    /// No harmonic band fits below Nyquist.
    #[error(
        "no flicker harmonic of {nominal_hz} Hz fits below the Nyquist frequency {nyquist_hz} Hz"
    )]
    NoHarmonic {
        /// Nominal frequency, Hz.
        nominal_hz: f64,
        /// fs/2, Hz.
        nyquist_hz: f64,
    },
    /// The input has no usable tone.
    #[error("{0}")]
    NoTone(String),
    /// The sampler refused the events.
    #[error(transparent)]
    Sampling(#[from] SamplingError),
    /// A signal kept on disk could not be read back.
    #[error("the signal could not be read back from its temporary file: {0}")]
    Read(String),
}

/// The ENF traced on one flicker harmonic.
#[derive(Debug, Clone, serde::Serialize)]
pub struct HarmonicEstimates {
    /// Harmonic number m: the band is centred on 2m·f0.
    pub harmonic: usize,
    /// Band centre, Hz.
    pub center_hz: f64,
    /// ENF estimates (divided by 2m), after outlier correction.
    pub enf_hz: Vec<f64>,
    /// Each window's line strength over the band's noise, dB.
    pub snr_db: Vec<f64>,
}

/// An ENF trace and how it was assembled.
#[derive(Debug, Clone, serde::Serialize)]
pub struct EnfEstimates {
    /// Seconds between estimates; estimate i is centred at i·step_s from the start.
    pub step_s: f64,
    /// The ENF, Hz.
    pub enf_hz: Vec<f64>,
    /// The line strength over its noise of each estimate (of the band selected there), dB.
    pub snr_db: Vec<f64>,
    /// Per-harmonic traces.
    pub harmonics: Vec<HarmonicEstimates>,
    /// Harmonic number chosen in each segment.
    pub selected: Vec<usize>,
    /// Segment length of the selection, in estimates.
    pub segment_len: usize,
}

/// E-ENF from a polarity sequence (the output of the temporal sampler).
pub fn extract_enf(seq: &PolaritySequence, p: &EnfParams) -> Result<EnfEstimates, DspError> {
    enf_from_flicker(&seq.signal(), seq.fs(), p)
}

/// The ENF from any signal that flickers at 2·f_e and its harmonics, sampled at `fs`.
pub fn enf_from_flicker(x: &[f64], fs: f64, p: &EnfParams) -> Result<EnfEstimates, DspError> {
    enf_from_lines(x, fs, p, 2.0)
}

/// The ENF from a signal whose lines sit at `multiple`·m·f_e, m = 1..`p.harmonics`: 2 for
/// flicker (light follows the power, twice the mains), 1 for mains hum in audio. Each band is
/// band-passed and tracked, outliers corrected on the scale of the first line, and the bands
/// combined by `p.selection` among those whose line stands above the noise.
pub fn enf_from_lines(
    x: &[f64],
    fs: f64,
    p: &EnfParams,
    multiple: f64,
) -> Result<EnfEstimates, DspError> {
    let all: Vec<usize> = (1..=p.harmonics).collect();
    enf_from_harmonics(x, fs, p, multiple, &all)
}

/// [`enf_from_lines`] on the lines at `multiple`·m·f_e for each m of `harmonics` (those the
/// line detector found standing, say), `p.harmonics` aside.
pub fn enf_from_harmonics(
    x: &[f64],
    fs: f64,
    p: &EnfParams,
    multiple: f64,
    harmonics: &[usize],
) -> Result<EnfEstimates, DspError> {
    harmonics_enf(x, fs, p, multiple, harmonics, false)
}

/// [`enf_from_harmonics`] for hum in sound (`multiple` 1), each band's estimates followed
/// through the window's sweep ([`crate::chirp::follow_chirps`]) when the peak is the exact one: weak hum at
/// k·f0 sweeps k times as fast as the ENF, and its line then spreads over several bins. Only
/// bands whose line a fast swing moves by two bins or more within a window are followed (4 f0
/// in the 32 s windows weak hum gets, say), and only in recordings of
/// [`FOLLOW_MIN_WINDOWS`] windows or more.
pub fn enf_from_hum_lines(
    x: &[f64],
    fs: f64,
    p: &EnfParams,
    harmonics: &[usize],
) -> Result<EnfEstimates, DspError> {
    // the sweep rate is fitted to the neighbours within half a window: a clip of fewer than
    // three windows has too few of them on both sides for most of its estimates
    let long_enough = x.len() as f64 / fs >= FOLLOW_MIN_WINDOWS * p.window_s;
    harmonics_enf(
        x,
        fs,
        p,
        1.0,
        harmonics,
        p.peak == PeakMethod::Exact && long_enough,
    )
}

/// How far from the least-squares line through its neighbours a followed estimate may move,
/// on the f0 scale, Hz: the grids' largest swing within one window stays under it.
const FOLLOW_REACH_HZ: f64 = 0.025;

/// Recordings of fewer windows than this are tracked without following the sweep.
pub const FOLLOW_MIN_WINDOWS: f64 = 3.0;

/// A real grid's swing at its fast moments, Hz/s (the Wuhan mains hours' one-second mean
/// frequencies step by 2.5 mHz std).
const FAST_SWING_HZ_PER_S: f64 = 0.001;

/// A band is followed when such a swing moves its line this many bins within a window: 4 f0
/// in 32 s windows (4.1 bins), not 4 f0 in 16 s ones (1.0), where following gains nothing.
const FOLLOW_MIN_SWEEP_BINS: f64 = 2.0;

fn harmonics_enf(
    x: &[f64],
    fs: f64,
    p: &EnfParams,
    multiple: f64,
    harmonics: &[usize],
    follow: bool,
) -> Result<EnfEstimates, DspError> {
    let bands = bands_of(x.len(), fs, p, multiple, harmonics)?;
    let tracker = p.tracker(fs);
    let tracks: Vec<BandTrack> = bands
        .par_iter()
        .map(|&m| {
            let b = BandTrack::new(m, p, multiple, follow);
            let y = sosfiltfilt(&b.filter(fs, p), x);
            BandTrack {
                tracked: tracker.track_with_snr(&y, b.band),
                base: b
                    .follows
                    .then(|| baseband(&y, 0, fs, b.center_hz, baseband_block(fs))),
                ..b
            }
        })
        .collect();
    finish_bands(tracks, fs, p, multiple)
}

/// The bands a recording of `len` samples at `fs` is tracked in: the `harmonics` whose band
/// fits below the Nyquist frequency, in order. Errors when it is shorter than a window or
/// none fits.
pub fn bands_of(
    len: usize,
    fs: f64,
    p: &EnfParams,
    multiple: f64,
    harmonics: &[usize],
) -> Result<Vec<usize>, DspError> {
    let duration_s = len as f64 / fs;
    if duration_s < p.window_s {
        return Err(DspError::TooShort {
            duration_s,
            window_s: p.window_s,
        });
    }
    let nyquist = fs / 2.0;
    let mut bands: Vec<usize> = harmonics
        .iter()
        .copied()
        .filter(|&m| m >= 1 && multiple * m as f64 * p.nominal_hz + p.half_band_hz < nyquist)
        .collect();
    bands.sort_unstable();
    bands.dedup();
    if bands.is_empty() {
        return Err(DspError::NoHarmonic {
            nominal_hz: p.nominal_hz,
            nyquist_hz: nyquist,
        });
    }
    Ok(bands)
}

/// One band's tracking before the estimates are corrected and chosen: the tracker's peak and
/// line strength per window, and (when the band is followed through its sweep) the line's
/// baseband.
#[derive(Debug, Clone)]
pub struct BandTrack {
    /// The harmonic m (the band sits at m·multiple·f0).
    pub harmonic: usize,
    /// The band's centre, Hz.
    pub center_hz: f64,
    /// The band, Hz.
    pub band: (f64, f64),
    /// Whether the band is followed through its sweep ([`crate::chirp::follow_chirps`]).
    pub follows: bool,
    /// The tracker's (frequency, line strength in dB) per window.
    pub tracked: Vec<(f64, f64)>,
    /// The band-passed line's baseband ([`baseband`]), when followed.
    pub base: Option<Vec<Complex64>>,
}

impl BandTrack {
    /// Band `m` before tracking; `follow` when following is asked for (exact peaks over
    /// enough windows).
    pub fn new(m: usize, p: &EnfParams, multiple: f64, follow: bool) -> Self {
        let center = multiple * m as f64 * p.nominal_hz;
        // bins a fast swing of the grid moves this band's line within one window
        let sweep_bins = multiple * m as f64 * FAST_SWING_HZ_PER_S * p.window_s.powi(2);
        BandTrack {
            harmonic: m,
            center_hz: center,
            band: (center - p.half_band_hz, center + p.half_band_hz),
            follows: follow && sweep_bins >= FOLLOW_MIN_SWEEP_BINS,
            tracked: Vec::new(),
            base: None,
        }
    }

    /// The band-pass the band's line is taken through.
    pub fn filter(&self, fs: f64, p: &EnfParams) -> Vec<crate::butter::Section> {
        butter_bandpass(p.filter_order, self.band.0, self.band.1, fs)
    }
}

/// The estimates from every band's tracking: outliers corrected, followed bands dechirped,
/// the band chosen per segment, and the trace checked against nominal.
pub fn finish_bands(
    tracks: Vec<BandTrack>,
    fs: f64,
    p: &EnfParams,
    multiple: f64,
) -> Result<EnfEstimates, DspError> {
    let harmonics: Vec<HarmonicEstimates> = tracks
        .into_par_iter()
        .map(|b| {
            let m = b.harmonic;
            // correct outliers on the first line's scale, report on the f_e scale
            let on_first: Vec<f64> = b.tracked.iter().map(|(f, _)| f / m as f64).collect();
            let mut corrected = if p.median_len > 1 {
                median_correct(&on_first, p.median_len, p.median_threshold_hz)
            } else {
                on_first
            };
            if let Some(base) = b.base.as_deref().filter(|_| b.follows) {
                // twice: the first pass's steps bend the sweep rates the second one uses
                let m = m as f64;
                let reach = FOLLOW_REACH_HZ * m;
                let line: Vec<f64> = corrected.iter().map(|f| f * m).collect();
                let followed = follow_in_baseband(
                    base,
                    fs,
                    b.center_hz,
                    &line,
                    p.window_s,
                    p.step_s,
                    reach,
                    2,
                );
                corrected = followed.iter().map(|f| f / m).collect();
            }
            HarmonicEstimates {
                harmonic: m,
                center_hz: b.center_hz,
                enf_hz: corrected.iter().map(|f| f / multiple).collect(),
                snr_db: b.tracked.iter().map(|(_, s)| *s).collect(),
            }
        })
        .collect();
    let traces: Vec<Vec<f64>> = harmonics.iter().map(|h| h.enf_hz.clone()).collect();
    let audible = audibility(&harmonics, p.segment_len);
    let (enf_hz, chosen) = select_audible_harmonics(&traces, &audible, p.segment_len, p.selection);
    if enf_hz.iter().all(|v| !v.is_finite()) {
        return Err(DspError::NoTone(
            "no line inside the bands (each window's peak sat at a band's edge, or they hold no signal)".into(),
        ));
    }
    check_near_nominal(&enf_hz, p.nominal_hz)?;
    // the journal rule chooses per estimate
    let seg = match p.selection {
        HarmonicSelection::Journal(_) => 1,
        _ => p.segment_len.max(1),
    };
    let snr_db = (0..enf_hz.len())
        .map(|i| {
            harmonics[chosen[i / seg]]
                .snr_db
                .get(i)
                .copied()
                .unwrap_or(f64::NAN)
        })
        .collect();
    Ok(EnfEstimates {
        step_s: p.step_s,
        enf_hz,
        snr_db,
        selected: chosen.iter().map(|&i| harmonics[i].harmonic).collect(),
        harmonics,
        segment_len: seg,
    })
}

/// A band's line must stand this far above its noise (mean over a selection segment, dB) for
/// the selection to take it there while another band's does. Noise alone peaks at about 8 dB
/// over the band's median power.
pub const MIN_BAND_SNR_DB: f64 = 12.0;

/// For each harmonic and selection segment: does the band's line stand [`MIN_BAND_SNR_DB`]
/// above its noise there?
pub fn audibility(harmonics: &[HarmonicEstimates], segment: usize) -> Vec<Vec<bool>> {
    let segment = segment.max(1);
    // each band's mean line strength per segment
    let means: Vec<Vec<f64>> = harmonics
        .iter()
        .map(|h| {
            h.snr_db
                .chunks(segment)
                .map(|c| {
                    let v: Vec<f64> = c.iter().copied().filter(|s| s.is_finite()).collect();
                    if v.is_empty() {
                        f64::NEG_INFINITY
                    } else {
                        v.iter().sum::<f64>() / v.len() as f64
                    }
                })
                .collect()
        })
        .collect();
    let segments = means.iter().map(Vec::len).max().unwrap_or(0);
    let best: Vec<f64> = (0..segments)
        .map(|k| {
            means
                .iter()
                .filter_map(|m| m.get(k).copied())
                .fold(f64::NEG_INFINITY, f64::max)
        })
        .collect();
    means
        .iter()
        .map(|m| {
            m.iter()
                .zip(&best)
                // where no band clears the bar, the strongest stands for it
                .map(|(&v, &b)| v >= MIN_BAND_SNR_DB || (v.is_finite() && v >= b))
                .collect()
        })
        .collect()
}

/// What the reference tracker (`reference_enf_with_snr`) needs of a signal of `len` samples at `fs`: a window's
/// length, and f0's band below the Nyquist frequency.
pub(crate) fn check_reference(len: usize, fs: f64, p: &EnfParams) -> Result<(), DspError> {
    let duration_s = len as f64 / fs;
    if duration_s < p.window_s {
        return Err(DspError::TooShort {
            duration_s,
            window_s: p.window_s,
        });
    }
    if p.nominal_hz + p.half_band_hz >= fs / 2.0 {
        return Err(DspError::NoHarmonic {
            nominal_hz: p.nominal_hz,
            nyquist_hz: fs / 2.0,
        });
    }
    Ok(())
}

/// How far from its nominal a grid's frequency may stay for the length of a recording: grids
/// are held within ±0.2 Hz outside emergencies (ENTSO-E's alert level is ±200 mHz; North
/// America's deviations are a few tens of mHz). A steady tone beyond it is not the mains.
pub const MAX_NOMINAL_OFFSET_HZ: f64 = 0.2;

/// Refuses a trace whose median lies more than [`MAX_NOMINAL_OFFSET_HZ`] from `nominal_hz`.
pub fn check_near_nominal(enf_hz: &[f64], nominal_hz: f64) -> Result<(), DspError> {
    let mut finite: Vec<f64> = enf_hz.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.is_empty() {
        return Ok(());
    }
    let m = finite.len() / 2;
    let median = *finite.select_nth_unstable_by(m, f64::total_cmp).1;
    if (median - nominal_hz).abs() > MAX_NOMINAL_OFFSET_HZ {
        return Err(DspError::NoTone(format!(
            "the line sits at {median:.3} Hz, {:.0} mHz from {nominal_hz} Hz: no grid stays \
             that far off (at most {:.0} mHz); it is not the mains",
            1e3 * (median - nominal_hz).abs(),
            1e3 * MAX_NOMINAL_OFFSET_HZ
        )));
    }
    Ok(())
}

/// How far a spectral line at `target` Hz stands above the spectrum around it (ratio of the
/// peak magnitude within ±1 Hz to the median magnitude in 1.5–6 Hz either side). Uses at most
/// the first 64 s.
pub fn line_prominence(x: &[f64], fs: f64, target: f64) -> f64 {
    let len = x.len().min((64.0 * fs) as usize);
    if len < 16 || target + 6.0 >= fs / 2.0 {
        return 0.0;
    }
    let nfft = len.next_power_of_two();
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(nfft);
    let mut input = fft.make_input_vec();
    let mean = x[..len].iter().sum::<f64>() / len as f64;
    for (d, s) in input.iter_mut().zip(&x[..len]) {
        *d = s - mean;
    }
    let mut spec = fft.make_output_vec();
    if fft.process(&mut input, &mut spec).is_err() {
        return 0.0;
    }
    let df = fs / nfft as f64;
    let bin = |f: f64| ((f / df).round() as usize).min(spec.len() - 1);
    let peak = spec[bin(target - 1.0)..=bin(target + 1.0)]
        .iter()
        .map(|c| c.norm())
        .fold(0.0, f64::max);
    let mut around: Vec<f64> = spec[bin(target - 6.0)..=bin(target - 1.5)]
        .iter()
        .chain(&spec[bin(target + 1.5)..=bin(target + 6.0)])
        .map(|c| c.norm())
        .collect();
    around.sort_by(|a, b| a.total_cmp(b));
    let median = around.get(around.len() / 2).copied().unwrap_or(0.0);
    if median > 0.0 {
        peak / median
    } else if peak > 0.0 {
        f64::INFINITY
    } else {
        0.0
    }
}

/// A line must stand this many times above its surroundings to count as a mains tone.
pub const MIN_PROMINENCE: f64 = 8.0;

/// Decides between a 50 Hz and a 60 Hz grid from the line at `multiple`·f0 (1 for mains
/// recordings, 2 for light flicker). Errors when neither line stands out.
pub fn detect_nominal(x: &[f64], fs: f64, multiple: f64) -> Result<f64, DspError> {
    let p50 = line_prominence(x, fs, 50.0 * multiple);
    let p60 = line_prominence(x, fs, 60.0 * multiple);
    let (best, prom) = if p50 >= p60 { (50.0, p50) } else { (60.0, p60) };
    if prom < MIN_PROMINENCE {
        return Err(DspError::NoTone(format!(
            "no mains line at {} or {} Hz (strongest stands {:.1}x above the noise, {MIN_PROMINENCE}x needed)",
            50.0 * multiple,
            60.0 * multiple,
            prom
        )));
    }
    Ok(best)
}

/// Checks that the line at `multiple`·`nominal` stands out; errors otherwise.
pub fn check_line(x: &[f64], fs: f64, nominal: f64, multiple: f64) -> Result<(), DspError> {
    let prom = line_prominence(x, fs, nominal * multiple);
    if prom < MIN_PROMINENCE {
        return Err(DspError::NoTone(format!(
            "no {} Hz mains line ({} Hz grid): it stands only {:.1}x above the noise, {MIN_PROMINENCE}x needed",
            nominal * multiple,
            nominal,
            prom
        )));
    }
    Ok(())
}
