//! The ENF of a mains or audio recording: the line detector finds the grid and the harmonics
//! that stand, a window is chosen for the clip and its hum, and the trace must hold its line.

use std::path::Path;

use crate::error::{error, fail, Error, Missing, Result};
use eenf_dsp::blocks::{enf_from_hum_lines_in, reference_enf_in, BlockSource};
use eenf_dsp::hum::search_hum_in;
use eenf_dsp::hum::{MAX_HUM_HARMONIC, MIN_CLIP_S};
use eenf_dsp::{check_holds_line, choose_window, plausibility, EnfParams};

use crate::audio::{AudioOptions, Sound};
use crate::trace::{AudioProvenance, HumReport, MainsProvenance, Provenance, Trace};
use eenf_core::Signal;
use eenf_core::{Grid, Nominal};

/// Decides or checks the nominal frequency of a mains signal: the line detector on f0 alone.
pub fn mains_nominal(sig: &Signal, nominal: Nominal, path: &Path) -> Result<Grid> {
    mains_nominal_in(&sig.samples.as_slice(), sig.fs, nominal, path)
}

/// [`mains_nominal`] of a signal at `fs` read a block at a time.
pub fn mains_nominal_in(
    sig: &dyn BlockSource,
    fs: f64,
    nominal: Nominal,
    path: &Path,
) -> Result<Grid> {
    let err = |e: eenf_dsp::DspError| Error::from(e).context(path.display());
    let grids = grids_of(nominal);
    let top = grids.iter().fold(0.0f64, |a, &b| a.max(b));
    if fs < 2.0 * (top + 8.0) {
        fail!(
            Method,
            "{}: sample rate {} Hz is too low to carry a {top} Hz mains tone",
            path.display(),
            fs
        );
    }
    let search = search_hum_in(sig, fs, 1.0, grids, 1)
        .map_err(err)?
        .ok_or_else(|| {
            err(eenf_dsp::DspError::TooShort {
                duration_s: sig.len() as f64 / fs,
                window_s: 1.0,
            })
        })?;
    grid_of_verdict(search.verdict().map_err(err)?.grid_hz, path)
}

/// The grid a hum search chose (it only tries the grids it was given: 50 and 60 Hz).
fn grid_of_verdict(hz: f64, path: &Path) -> Result<Grid> {
    Grid::of_hz(hz).or_fail(Error::Method, || {
        format!("{}: no grid at {hz} Hz", path.display())
    })
}

/// The grids a `--nominal` leaves open.
pub(crate) fn grids_of(nominal: Nominal) -> &'static [f64] {
    match nominal {
        Nominal::Auto => &[50.0, 60.0],
        Nominal::Grid(Grid::Hz50) => &[50.0],
        Nominal::Grid(Grid::Hz60) => &[60.0],
    }
}

/// The reference trace of a whole mains WAV (every channel mixed, f0 alone: the method's
/// reference tracker).
pub fn reference_file(path: &Path, nominal: Nominal, params: &EnfParams) -> Result<Trace> {
    let hum = HumOptions {
        lines: MainsLines::UpTo(1),
        window_s: Some(params.window_s),
    };
    audio_trace(path, &AudioOptions::default(), &hum, nominal, params)
}

/// Which mains lines a sound is traced on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MainsLines {
    /// Those the line detector finds standing, up to [`MAX_HUM_HARMONIC`]·f0: f0 alone (the
    /// method's reference tracker) when it carries the ENF clearly, else every harmonic that
    /// stands, band by band, combined per segment by the selection rule.
    #[default]
    Auto,
    /// f0 … N·f0 (1: f0 alone, the reference tracker).
    UpTo(usize),
}

impl std::str::FromStr for MainsLines {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "auto" => Ok(MainsLines::Auto),
            _ => match s.parse::<usize>() {
                Ok(n) if (1..=MAX_HUM_HARMONIC).contains(&n) => Ok(MainsLines::UpTo(n)),
                _ => Err(format!(
                    "{s:?}: expected auto or a number of lines from 1 to {MAX_HUM_HARMONIC}"
                )),
            },
        }
    }
}

impl std::fmt::Display for MainsLines {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MainsLines::Auto => f.write_str("auto"),
            MainsLines::UpTo(n) => write!(f, "{n}"),
        }
    }
}

/// How a sound's hum is traced: its lines, and the window (`None`: chosen from the recording
/// and its hum, see [`eenf_dsp::choose_window`]; the default of `params` is the start).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HumOptions {
    /// The lines tracked.
    pub lines: MainsLines,
    /// The analysis window, s, when set.
    pub window_s: Option<f64>,
}

/// f0 alone carries the ENF when its line is the strongest and stands this high (dB over its
/// floor): mains recordings, where harmonics add nothing but distortion.
const F0_ALONE_DB: f64 = 30.0;

/// The ENF of a recording's sound (a mains recording, a voice recorder, a video's soundtrack):
/// read as `audio` says, decimated to what its lines need, and tracked as `hum` says.
pub fn audio_trace(
    path: &Path,
    audio: &AudioOptions,
    hum: &HumOptions,
    nominal: Nominal,
    params: &EnfParams,
) -> Result<Trace> {
    sound_trace(&Sound::File(path), audio, hum, nominal, params)
}

/// The ENF of a sound, from a file or from samples in memory (see [`audio_trace`]): the line
/// detector finds the grid and the harmonics that stand, a window is chosen for the clip and
/// its hum, the trace must hold its line, and it is checked against what grids do (offset,
/// steadiness).
pub fn sound_trace(
    sound: &Sound,
    audio: &AudioOptions,
    hum: &HumOptions,
    nominal: Nominal,
    params: &EnfParams,
) -> Result<Trace> {
    let path = sound.name();
    let err = |e: eenf_dsp::DspError| Error::from(e).context(path.display());
    let grids = grids_of(nominal);
    let top_grid = grids.iter().fold(0.0f64, |a, &b| a.max(b));
    let most = match hum.lines {
        MainsLines::Auto => MAX_HUM_HARMONIC,
        MainsLines::UpTo(n) => n.max(1),
    };
    // room for every line looked for and its floor beside it
    let top_of = |k: usize| k as f64 * top_grid + params.half_band_hz.max(6.0) + 4.0;
    let first_top = match hum.lines {
        MainsLines::Auto => top_of(most),
        // as these lines were always read (a reference's rate unchanged)
        MainsLines::UpTo(n) => n as f64 * top_grid + params.half_band_hz + 4.0,
    };
    let a = sound.read(&AudioOptions {
        top_hz: Some(first_top),
        ..*audio
    })?;
    let provenance_audio = |fs: f64| AudioProvenance {
        decoder: a.decoder.to_string(),
        source_rate_hz: a.source_rate,
        rate_hz: fs,
        channels: a.channels,
        channel: audio.channel.to_string(),
        frames: a.frames,
    };
    let duration_s = a.signal.duration_s();
    if let MainsLines::UpTo(1) = hum.lines {
        // the method's reference tracker: f0 alone, unfiltered
        let f0 = mains_nominal_in(&a.signal, a.signal.fs, nominal, path)?;
        let p = EnfParams {
            nominal_hz: f0.hz(),
            window_s: hum.window_s.unwrap_or(params.window_s),
            ..params.clone()
        };
        let (enf, snr_db) = reference_enf_in(&a.signal, a.signal.fs, &p).map_err(err)?;
        let mut t = Trace::from_mains(path, f0, &p, enf);
        t.snr_db = snr_db;
        if let Some(Provenance::Mains(m)) = t.provenance.as_mut() {
            // a plain mains WAV at its own rate keeps the bare provenance it always had
            if a.source_rate != a.signal.fs || a.channels > 1 || a.decoder != "symphonia" {
                m.audio = Some(provenance_audio(a.signal.fs));
            }
        }
        t.warnings.extend(a.warning.clone());
        return Ok(t);
    }
    if duration_s < MIN_CLIP_S {
        return Err(err(eenf_dsp::DspError::TooShort {
            duration_s,
            window_s: MIN_CLIP_S,
        }));
    }
    let search = search_hum_in(&a.signal, a.signal.fs, 1.0, grids, most)
        .map_err(err)?
        .ok_or_else(|| {
            error!(
                Method,
                "{}: sample rate {} Hz is too low to carry a mains line with its noise floor beside it",
                path.display(),
                a.signal.fs
            )
        })?;
    let verdict = search.verdict().map_err(err)?;
    let grid = grid_of_verdict(verdict.grid_hz, path)?;
    let f0 = grid.hz();
    let (window_s, window_note) = match hum.window_s {
        Some(w) => (w, None),
        None => choose_window(
            duration_s,
            params.window_s,
            verdict.strongest.db,
            search.segment_s,
        )
        .map_err(err)?,
    };
    let f0_alone = verdict.strongest.harmonic == 1 && verdict.strongest.db >= F0_ALONE_DB;
    let carriers: Vec<usize> = if f0_alone {
        vec![1]
    } else {
        verdict.carriers.clone()
    };
    let highest = carriers.iter().copied().max().unwrap_or(1);
    let narrowed = a.narrowed(top_of(highest))?;
    let sig = narrowed.as_ref().unwrap_or(&a.signal);
    let p = EnfParams {
        nominal_hz: f0,
        harmonics: highest,
        window_s,
        ..params.clone()
    };
    let edge = (window_s / 2.0 / p.step_s).ceil() as usize;
    let mut trace = if f0_alone {
        let (enf, snr_db) = reference_enf_in(sig, sig.fs, &p).map_err(err)?;
        Trace {
            snr_db,
            ..Trace::from_mains(path, grid, &p, enf)
        }
    } else {
        let estimates = enf_from_hum_lines_in(sig, sig.fs, &p, &carriers).map_err(err)?;
        Trace::from_mains_lines(
            path,
            grid,
            &estimates,
            MainsProvenance {
                peak: p.peak,
                window_s,
                mains_lines: carriers.len(),
                audio: None,
                hum: None,
            },
        )
    };
    check_holds_line(&trace.enf_hz, p.step_s, window_s).map_err(err)?;
    let plausibility = plausibility(&trace.enf_hz, p.step_s, f0, edge);
    if let Some(Provenance::Mains(m)) = trace.provenance.as_mut() {
        m.audio = Some(provenance_audio(sig.fs));
        m.hum = Some(HumReport {
            search,
            carriers,
            window_note,
            plausibility,
        });
    }
    trace.warnings.extend(a.warning.clone());
    Ok(trace)
}
