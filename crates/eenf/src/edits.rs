//! Was a recording edited? Cuts and insertions found from the mains hum's phase and frequency
//! (`eenf edits`), in sound, in the flicker an event camera records, and, for frequency steps
//! alone, in an ENF trace.
//!
//! The test itself is [`eenf_dsp::edits`]; this module reads the recording, picks the lines
//! that carry the hum with the same detector `audio` and `extract` use (a recording with no
//! hum is refused), and turns the scan into a report: each edit with its time, kind, phase
//! jump, strength and false-alarm rate, the stretches where the hum is too weak to tell, and
//! the series a figure needs.

use eenf_core::spelling::option;
use std::path::{Path, PathBuf};

use crate::error::{error, fail, Error, Result};
use eenf_dsp::edits::{baseband, scan_phase, wrap, Baseband, BoundaryTest, PhaseScan};
use eenf_dsp::hum::{MAX_HUM_HARMONIC, MIN_CLIP_S};
use eenf_dsp::search_hum;
use serde::Serialize;

pub use eenf_dsp::edits::EditParams;

use crate::audio::{AudioOptions, Sound};
use crate::extract::{flicker_signal, sample_recording, ExtractOptions};
use crate::mains::grids_of;
use crate::progress::Progress;
use crate::recording::Recording;
use crate::trace::Trace;
use eenf_core::Nominal;

/// What kind of edit a finding points to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EditKind {
    /// The hum's phase jumps (a cut, or either end of an insertion).
    PhaseJump,
    /// The phase jumps and the ENF steps with it (material from another time).
    PhaseJumpAndFrequencyStep,
    /// The ENF steps with no phase jump that stands (or no phase to test: a trace).
    FrequencyStep,
    /// The hum vanishes for a while in a recording where it otherwise stands clear (a
    /// stretch of other material, or of silence).
    HumGap,
}

impl std::fmt::Display for EditKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            EditKind::PhaseJump => "phase jump",
            EditKind::PhaseJumpAndFrequencyStep => "phase jump and frequency step",
            EditKind::FrequencyStep => "frequency step",
            EditKind::HumGap => "hum gap",
        })
    }
}

/// One finding.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Edit {
    /// Where, s from the recording's start.
    pub time_s: f64,
    /// For a hum gap, where it ends, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end_s: Option<f64>,
    /// What it looks like.
    pub kind: EditKind,
    /// The jump of the lowest line's phase, degrees (−180, 180].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phase_jump_deg: Option<f64>,
    /// The line that jump is measured on, Hz.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phase_jump_line_hz: Option<f64>,
    /// The hum's shift in time that the jump means, ms (modulo one period of the lowest line:
    /// a cut of d seconds shifts the hum by d modulo 1/f).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_shift_ms: Option<f64>,
    /// The ENF after minus the ENF before, mHz.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frequency_step_mhz: Option<f64>,
    /// The step over the recording's own spread of steps (robust standard deviations).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frequency_step_z: Option<f64>,
    /// The test's statistic over its threshold (≥ 1 when reported for a phase jump).
    pub strength: f64,
    /// How often a recording nobody edited shows a break this strong, per hour: the
    /// recording's noise and the real grid's own stray (see `eenf_dsp::edits::null`).
    pub false_alarms_per_hour: f64,
    /// The chance that an unedited recording shows one anywhere in the stretch examined.
    pub p_value: f64,
    /// What the data show and what they are consistent with: the phase cannot tell a cut
    /// from an insertion or from a recorder that dropped or inverted samples.
    pub reading: String,
}

/// A stretch of the recording.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stretch {
    /// Its start, s.
    pub start_s: f64,
    /// Its end, s.
    pub end_s: f64,
    /// Why it is reported.
    pub why: String,
}

/// The series behind the figure, one value per block.
#[derive(Debug, Clone, Default)]
pub struct EditSeries {
    /// Times, s.
    pub time_s: Vec<f64>,
    /// The hum's phase deviation from a smooth fit, degrees of the lowest line.
    pub phase_deg: Vec<f64>,
    /// The test's statistic over its threshold as the verdict was decided (NaN where not
    /// tested): each finding at its own test, nothing else at 1 or more.
    pub strength: Vec<f64>,
    /// The ENF, Hz.
    pub enf_hz: Vec<f64>,
}

/// What `edits` found in a recording.
#[derive(Debug, Clone, Serialize)]
pub struct EditReport {
    /// The recording.
    pub file: PathBuf,
    /// What was read: `audio`, `events` or `trace`.
    pub input: &'static str,
    /// The grid, Hz.
    pub grid_hz: f64,
    /// The lines whose phase was tested, Hz.
    pub lines_hz: Vec<f64>,
    /// The recording's length, s.
    pub duration_s: f64,
    /// The stretch tested, s (a recording's first and last `min_gap_s` are not).
    pub examined_s: [f64; 2],
    /// The findings, in time order.
    pub edits: Vec<Edit>,
    /// Where the hum is too weak to tell an edit (no evidence either way).
    pub undecided: Vec<Stretch>,
    /// The smallest phase jump of the lowest line found over the recording (its median over
    /// the stretch examined), degrees.
    pub min_jump_deg: Option<f64>,
    /// The threshold of the phase test (its statistic, see `eenf_dsp::edits`).
    pub threshold: Option<f64>,
    /// The side each boundary was tested with, s (the one, up to `--side`, whose smallest
    /// detectable jump is smallest in this recording).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tested_side_s: Option<f64>,
    /// One line for the reader: edited, not shown to be edited, or cannot tell.
    pub verdict: String,
    /// The parameters used.
    pub params: EditParams,
    /// What the user should be told (damage a decoder skipped, notes on the recording).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// The series behind the figure.
    #[serde(skip)]
    pub series: EditSeries,
}

impl EditReport {
    /// The report as JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default() + "\n"
    }
}

/// What `edits` reads a file as.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EditInput {
    /// An event file when its content says so, a trace when it is a CSV or JSON trace, else
    /// sound.
    #[default]
    Auto,
    /// Sound (any container `audio` reads).
    Audio,
    /// An event recording.
    Events,
    /// An ENF trace (frequency steps alone).
    Trace,
}

impl EditInput {
    /// The names `--kind` takes.
    pub const NAMES: [&'static str; 4] = ["auto", "audio", "events", "trace"];
}

impl std::str::FromStr for EditInput {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Ok(match s {
            "auto" => EditInput::Auto,
            "audio" => EditInput::Audio,
            "events" => EditInput::Events,
            "trace" => EditInput::Trace,
            _ => return Err(format!("{s:?}: expected one of {}", Self::NAMES.join(", "))),
        })
    }
}

impl std::fmt::Display for EditInput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(Self::NAMES[*self as usize])
    }
}

/// How `edits` reads and tests a file.
#[derive(Debug, Clone, Default)]
pub struct EditOptions {
    /// The test.
    pub params: EditParams,
    /// What the file is.
    pub input: EditInput,
    /// Seconds between the values of an `index,value` trace CSV.
    pub index_step_s: Option<f64>,
    /// How a sound is read (the channel).
    pub audio: AudioOptions,
    /// How an event file is read and its flicker sampled; its `nominal` is the grid for
    /// every input.
    pub extract: ExtractOptions,
}

/// The edits of the file at `path`, read as `opts.input` says (by default: an event file when
/// its content says so, a trace when its name ends in .csv or .json, else sound).
pub fn file_edits(path: &Path, opts: &EditOptions, progress: &Progress) -> Result<EditReport> {
    let kind = match opts.input {
        EditInput::Auto => {
            let ext = path
                .extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase);
            if matches!(ext.as_deref(), Some("csv" | "json")) {
                EditInput::Trace
            } else if eenf_events::probe(path).is_ok() {
                EditInput::Events
            } else {
                EditInput::Audio
            }
        }
        k => k,
    };
    match kind {
        EditInput::Trace => {
            let trace = Trace::read(path, opts.index_step_s)?;
            trace_edits(&trace, path, &opts.params)
        }
        EditInput::Events => event_edits(
            &Recording::file(path),
            &opts.extract,
            &opts.params,
            progress,
        ),
        _ => sound_edits(
            &Sound::File(path),
            &opts.audio,
            opts.extract.nominal,
            &opts.params,
        ),
    }
}

/// The edits of a sound (a file in any container `audio` reads, or samples in memory).
pub fn sound_edits(
    sound: &Sound,
    audio: &AudioOptions,
    nominal: Nominal,
    params: &EditParams,
) -> Result<EditReport> {
    let path = sound.name();
    let hum = sound_baseband(sound, audio, nominal)?;
    let scan =
        scan_phase(&hum.baseband, params).ok_or_else(|| too_short(path, hum.duration_s, params))?;
    let mut r = report(path, "audio", &scan, hum.duration_s);
    r.warnings.extend(hum.warning);
    Ok(r)
}

/// A sound's hum at baseband: the lines the detector picks, ready for the phase test.
#[derive(Debug, Clone)]
pub struct SoundHum {
    /// The lines at baseband.
    pub baseband: Baseband,
    /// The sound's length, s.
    pub duration_s: f64,
    /// Damage the decoder skipped, if any.
    pub warning: Option<String>,
}

/// Reads a sound and brings the lines that carry its hum to baseband (a sound with no hum is
/// refused, as `audio` refuses it).
pub fn sound_baseband(sound: &Sound, audio: &AudioOptions, nominal: Nominal) -> Result<SoundHum> {
    let path = sound.name();
    let err = |e: eenf_dsp::DspError| Error::from(e).context(path.display());
    let grids = grids_of(nominal);
    let top_grid = grids.iter().fold(0.0f64, |a, &b| a.max(b));
    let top_of = |k: usize| k as f64 * top_grid + 10.0;
    let a = sound.read(&AudioOptions {
        top_hz: Some(top_of(MAX_HUM_HARMONIC)),
        ..*audio
    })?;
    let duration_s = a.signal.duration_s();
    if duration_s < MIN_CLIP_S {
        return Err(err(eenf_dsp::DspError::TooShort {
            duration_s,
            window_s: MIN_CLIP_S,
        }));
    }
    let search = eenf_dsp::hum::search_hum_in(&a.signal, a.signal.fs, 1.0, grids, MAX_HUM_HARMONIC)
        .map_err(err)?
        .ok_or_else(|| {
            error!(Method,
                "{}: sample rate {} Hz is too low to carry a mains line with its noise floor beside it",
                path.display(),
                a.signal.fs
            )
        })?;
    let verdict = search.verdict().map_err(err)?;
    let mut carriers = verdict.carriers.clone();
    carriers.sort_unstable();
    let highest = carriers.last().copied().unwrap_or(1);
    let narrowed = a.narrowed(top_of(highest))?;
    let sig = narrowed.as_ref().unwrap_or(&a.signal);
    let multiples: Vec<u32> = carriers.iter().map(|&k| k as u32).collect();
    Ok(SoundHum {
        baseband: baseband(&sig.to_vec()?, sig.fs, verdict.grid_hz, &multiples),
        duration_s,
        warning: a.warning,
    })
}

/// The edits of an event recording, from the flicker signal E-ENF samples (light flickers at
/// 2 f0 and its multiples, so its lines are 2k·f0).
pub fn event_edits(
    rec: &Recording,
    opts: &ExtractOptions,
    params: &EditParams,
    progress: &Progress,
) -> Result<EditReport> {
    let path = rec.name();
    let err = |e: eenf_dsp::DspError| Error::from(e).context(path.display());
    let s = sample_recording(rec, opts, progress)?;
    let seq = &s.seq;
    let grids = grids_of(opts.nominal);
    let top_grid = grids.iter().fold(0.0f64, |a, &b| a.max(b));
    // the flicker's lines up to 4·2f0, each with its floor beside it
    const FLICKER_LINES: usize = 4;
    let (x, fs) = flicker_signal(seq, 2.0 * top_grid * FLICKER_LINES as f64 + 10.0);
    let duration_s = seq.duration_s();
    let search = search_hum(&x, fs, 2.0, grids, FLICKER_LINES).ok_or_else(|| {
        error!(Method,
            "{}: the recording ({duration_s:.1} s, flicker sampled at {fs} Hz) is too short or too coarse to hold a flicker line",
            path.display()
        )
    })?;
    let verdict = search.verdict().map_err(err)?;
    let multiples: Vec<u32> = {
        let mut m: Vec<u32> = verdict.carriers.iter().map(|&k| 2 * k as u32).collect();
        m.sort_unstable();
        m
    };
    let bb = baseband(&x, fs, verdict.grid_hz, &multiples);
    let scan = scan_phase(&bb, params).ok_or_else(|| too_short(path, duration_s, params))?;
    let mut r = report(path, "events", &scan, duration_s);
    r.warnings.extend(s.notes);
    r.warnings.extend(s.damage.map(|d| d.to_string()));
    Ok(r)
}

/// The longest side of the frequency-step test on a trace, s.
const TRACE_SIDE_S: f64 = 5.0;

/// How often real continuous traces show a frequency step of z robust standard deviations:
/// `A·e^(−z/b)` per hour, measured on 96 hours (the 24 hours of `../shared/mains-day` and
/// `enf-reference` traced by `audio`, the three 60 Hz days of `enf-traces-60hz` at 2 s;
/// `tools/trace_null.py`): fitted to the rates between 0.1 and 10 per hour (b = 0.694) and
/// raised to bound every rate resting on two peaks or more (A = 1325, rounded up).
const TRACE_STEP_TAIL: (f64, f64) = (1400.0, 0.694);

/// Frequency steps in an ENF trace (no phase to test): at each estimate, a line fitted to the
/// `side_s` after it and one fitted to the `side_s` before, both carried to the boundary; the
/// difference over the trace's own spread of such differences.
pub fn trace_edits(trace: &Trace, path: &Path, params: &EditParams) -> Result<EditReport> {
    let step = trace.step_s;
    let n = trace.enf_hz.len();
    // short sides: a line over 10 s of a grid that swings every 20–30 s misses the level by
    // several mHz, over 5 s by one
    let side = ((params.side_s.min(TRACE_SIDE_S) / step).round() as usize).max(3);
    if n < 2 * side + 1 {
        fail!(
            Method,
            "{}: the trace holds {n} estimates ({:.0} s); frequency steps need at least {:.0} s",
            path.display(),
            n as f64 * step,
            (2 * side + 1) as f64 * step
        );
    }
    let grid_hz = trace.grid_or_err(path)?.hz();
    // a line fitted to each side, both carried to the boundary: the grid's own ramps cancel,
    // a jump of the level stays
    let end_value = |a: usize, b: usize, at: f64| -> Option<f64> {
        let pts: Vec<(f64, f64)> = (a..b)
            .filter(|&i| trace.enf_hz[i].is_finite())
            .map(|i| (i as f64, trace.enf_hz[i]))
            .collect();
        if pts.len() * 2 < b - a || pts.len() < 3 {
            return None;
        }
        let m = pts.len() as f64;
        let (mx, my) = pts
            .iter()
            .fold((0.0, 0.0), |(x, y), p| (x + p.0 / m, y + p.1 / m));
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        Some(my + sxy / sxx.max(1e-12) * (at - mx))
    };
    let steps: Vec<(usize, f64)> = (side..=n - side)
        .filter_map(|i| {
            let at = i as f64 - 0.5;
            Some((i, end_value(i, i + side, at)? - end_value(i - side, i, at)?))
        })
        .collect();
    let scale = robust_scale(steps.iter().map(|s| s.1));
    let duration_s = n as f64 * step;
    let hours = ((n - 2 * side) as f64 * step / 3600.0).max(1e-9);
    let mut edits = Vec::new();
    for (i, d) in peaks(&steps, side, scale, params.frequency_step_z) {
        let z = d / scale;
        let rate = TRACE_STEP_TAIL.0 * (-z.abs() / TRACE_STEP_TAIL.1).exp();
        edits.push(Edit {
            time_s: trace.time_s.get(i).copied().unwrap_or(i as f64 * step) - step / 2.0,
            end_s: None,
            kind: EditKind::FrequencyStep,
            phase_jump_deg: None,
            phase_jump_line_hz: None,
            time_shift_ms: None,
            frequency_step_mhz: Some(d * 1e3),
            frequency_step_z: Some(z),
            strength: z.abs() / params.frequency_step_z,
            false_alarms_per_hour: rate,
            p_value: -(-rate * hours).exp_m1(),
            reading: format!(
                "the ENF steps by {:+.1} mHz, {:.0} times the trace's own spread of steps: consistent with a cut or an insertion from another time, or with a sudden change of load on the grid",
                d * 1e3,
                z.abs()
            ),
        });
    }
    let verdict = if edits.is_empty() {
        "no frequency step stands out in the trace (a trace holds no phase: cuts that keep the ENF level cannot be seen here)".to_string()
    } else {
        format!(
            "{} frequency step{} stand{} out in the trace",
            edits.len(),
            if edits.len() == 1 { "" } else { "s" },
            if edits.len() == 1 { "s" } else { "" }
        )
    };
    Ok(EditReport {
        file: path.to_path_buf(),
        input: "trace",
        grid_hz,
        lines_hz: Vec::new(),
        duration_s,
        examined_s: [side as f64 * step, (n - side) as f64 * step],
        edits,
        undecided: Vec::new(),
        min_jump_deg: None,
        threshold: None,
        tested_side_s: None,
        verdict,
        params: params.clone(),
        warnings: trace.warnings.clone(),
        series: EditSeries {
            time_s: trace.time_s.clone(),
            phase_deg: Vec::new(),
            strength: Vec::new(),
            enf_hz: trace.enf_hz.clone(),
        },
    })
}

fn too_short(path: &Path, duration_s: f64, params: &EditParams) -> Error {
    error!(Method,
        "{}: the recording lasts {duration_s:.2} s; the phase test needs at least {:.1} s (twice {})",
        path.display(),
        2.0 * params.min_gap_s,
        option("min_gap")
    )
}

/// The recording's own spread of frequency steps (see [`eenf_dsp::robust_spread`]), kept off
/// zero so that a perfectly smooth trace divides safely.
fn robust_scale(v: impl Iterator<Item = f64>) -> f64 {
    let v: Vec<f64> = v.collect();
    eenf_dsp::robust_spread(&v).max(1e-12)
}

/// The places where |value| / `scale` passes `z`, strongest first, none within `radius` of a
/// stronger one; returned in time order.
fn peaks(values: &[(usize, f64)], radius: usize, scale: f64, z: f64) -> Vec<(usize, f64)> {
    let mut order: Vec<&(usize, f64)> =
        values.iter().filter(|v| (v.1 / scale).abs() >= z).collect();
    order.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
    let mut kept: Vec<(usize, f64)> = Vec::new();
    for &(i, v) in order {
        if kept.iter().all(|k| k.0.abs_diff(i) > radius) {
            kept.push((i, v));
        }
    }
    kept.sort_by_key(|k| k.0);
    kept
}

/// What a break in the phase shows and what it is consistent with (the phase cannot tell
/// intent: a cut, an insertion and a recorder's fault all break it).
fn phase_reading(kind: EditKind, jump_deg: f64, line_hz: f64, step_hz: f64) -> String {
    let shift_ms = jump_deg / 360.0 / line_hz * 1e3;
    let what = format!("the {line_hz:.0} Hz hum's phase turns by {jump_deg:+.0}° at once ({shift_ms:+.2} ms of the hum's time)");
    if jump_deg.abs() >= 150.0 && kind == EditKind::PhaseJump {
        format!("{what}, about half a cycle: consistent with inverted samples, or with a cut or an insertion of a whole number of cycles and a half")
    } else if kind == EditKind::PhaseJumpAndFrequencyStep {
        format!(
            "{what} and the ENF steps by {:+.1} mHz: consistent with a cut, or an insertion of material recorded at another time",
            step_hz * 1e3
        )
    } else {
        format!("{what}: consistent with a cut, an insertion, or the recorder dropping samples")
    }
}

/// The report of a phase scan (times from the recording's start).
fn report(path: &Path, input: &'static str, scan: &PhaseScan, duration_s: f64) -> EditReport {
    let p = &scan.params;
    let tb = scan.block_s;
    let lowest = scan.multiples.first().copied().unwrap_or(1) as f64;
    let at = |block: usize| block as f64 * tb;
    let examined = match (scan.tests.first(), scan.tests.last()) {
        (Some(a), Some(b)) => [at(a.block), at(b.block)],
        _ => [0.0, 0.0],
    };
    let hours = ((examined[1] - examined[0]) / 3600.0).max(1e-9);
    // frequency steps over the recording's own spread of them
    let scale = robust_scale(scan.tests.iter().map(|t| t.frequency_step_hz));
    let mut edits: Vec<Edit> = scan
        .jumps
        .iter()
        .map(|t: &BoundaryTest| {
            let fa = t.false_alarms_per_hour;
            let step = Some(t.frequency_step_hz);
            let z = step.map(|s| s / scale);
            let stepped = z.is_some_and(|z| z.abs() >= p.frequency_step_z);
            let jump = wrap(lowest * t.jump_rad).to_degrees();
            let kind = if stepped {
                EditKind::PhaseJumpAndFrequencyStep
            } else {
                EditKind::PhaseJump
            };
            Edit {
                time_s: at(t.block),
                end_s: None,
                kind,
                reading: phase_reading(kind, jump, lowest * scan.f0_hz, t.frequency_step_hz),
                phase_jump_deg: Some(jump),
                phase_jump_line_hz: Some(lowest * scan.f0_hz),
                time_shift_ms: Some(jump / 360.0 / (lowest * scan.f0_hz) * 1e3),
                frequency_step_mhz: step.map(|s| s * 1e3),
                frequency_step_z: z,
                strength: t.statistic / scan.threshold,
                false_alarms_per_hour: fa,
                // exp_m1 keeps the small p-values that 1 − e^(−x) would round to 0
                p_value: -(-fa * hours).exp_m1(),
            }
        })
        .collect();
    // A step of the ENF alone is not reported where the phase was tested: on real mains the
    // grid ramps by as much within seconds (10 s sides see steps of 10–50 mHz), so the phase
    // decides, and the step is reported with each jump (a trace has no phase: `trace_edits`).
    // gaps in a hum that otherwise stands clear
    let mut sorted = scan.presence.clone();
    sorted.sort_by(f64::total_cmp);
    let typical = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let clear = typical >= 8.0 * scan.presence_threshold;
    if clear {
        let mut i = 0;
        while i < scan.presence.len() {
            if scan.presence[i] < scan.presence_threshold {
                let start = i;
                while i < scan.presence.len() && scan.presence[i] < scan.presence_threshold {
                    i += 1;
                }
                if i - start >= 2 {
                    edits.push(Edit {
                        time_s: start as f64,
                        end_s: Some(i as f64),
                        kind: EditKind::HumGap,
                        phase_jump_deg: None,
                        phase_jump_line_hz: None,
                        time_shift_ms: None,
                        frequency_step_mhz: None,
                        frequency_step_z: None,
                        strength: typical / scan.presence_threshold,
                        false_alarms_per_hour: f64::NAN,
                        p_value: f64::NAN,
                        reading: format!(
                            "the hum, clear elsewhere, vanishes for {} s: consistent with an insertion of other material or silence, or with the recorder losing its input",
                            i - start
                        ),
                    });
                }
            }
            i += 1;
        }
    }
    edits.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    // where a jump as large as `weak_jump_deg` would go unseen
    let min_jump = |t: &BoundaryTest| -> f64 { (lowest * t.min_jump_rad).to_degrees() };
    let mut undecided = Vec::new();
    let mut run: Option<(f64, f64)> = None;
    for t in &scan.tests {
        let weak = min_jump(t) > p.weak_jump_deg;
        match (&mut run, weak) {
            (Some(r), true) => r.1 = at(t.block),
            (None, true) => run = Some((at(t.block), at(t.block))),
            (Some(r), false) => {
                if r.1 - r.0 >= 1.0 {
                    undecided.push(*r);
                }
                run = None;
            }
            (None, false) => {}
        }
    }
    if let Some(r) = run.filter(|r| r.1 - r.0 >= 1.0) {
        undecided.push(r);
    }
    let undecided: Vec<Stretch> = undecided
        .into_iter()
        .map(|(a, b)| Stretch {
            start_s: a,
            end_s: b,
            why: format!(
                "the hum is too weak here: a phase jump of {:.0}° of the {:.0} Hz line would go unseen",
                p.weak_jump_deg,
                lowest * scan.f0_hz
            ),
        })
        .collect();
    let mut mins: Vec<f64> = scan.tests.iter().map(min_jump).collect();
    let min_jump_deg = (!mins.is_empty()).then(|| {
        let mid = mins.len() / 2;
        *mins.select_nth_unstable_by(mid, f64::total_cmp).1
    });
    let weak_s: f64 = undecided.iter().map(|s| s.end_s - s.start_s).sum();
    let span = examined[1] - examined[0];
    let verdict = if !edits.is_empty() {
        format!(
            "discontinuous: {} break{} in the hum (see edits)",
            edits.len(),
            if edits.len() == 1 { "" } else { "s" }
        )
    } else if weak_s >= 0.9 * span {
        "cannot tell: the hum is too weak to show an edit anywhere in the recording".to_string()
    } else if weak_s > 0.0 {
        format!(
            "no edit found where the hum can tell ({weak_s:.0} s of {span:.0} s too weak to tell)"
        )
    } else {
        format!(
            "no edit found: the hum's phase is continuous over {span:.0} s (jumps from {:.0}° would show)",
            min_jump_deg.unwrap_or(f64::NAN)
        )
    };
    let n = scan.enf_hz.len();
    let strength: Vec<f64> = (0..n)
        .map(|b| {
            scan.statistic
                .get(b)
                .map_or(f64::NAN, |t| t / scan.threshold)
        })
        .collect();
    EditReport {
        file: path.to_path_buf(),
        input,
        grid_hz: scan.f0_hz,
        lines_hz: scan
            .multiples
            .iter()
            .map(|&m| m as f64 * scan.f0_hz)
            .collect(),
        duration_s,
        examined_s: examined,
        edits,
        undecided,
        min_jump_deg,
        threshold: Some(scan.threshold),
        tested_side_s: Some(scan.side_s),
        verdict,
        params: p.clone(),
        warnings: Vec::new(),
        series: EditSeries {
            time_s: (0..n).map(at).collect(),
            phase_deg: scan.phase_deg.iter().map(|d| d * lowest).collect(),
            strength,
            enf_hz: scan.enf_hz.clone(),
        },
    }
}
