//! Scoring a trace against its reference: where the reference comes from (a trace, a mains
//! WAV, a dataset's hourly WAVs), how the two are aligned, and the metrics. Shared by
//! `compare` and `bench`, so both give the same numbers.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use eenf_dsp::{agreement, Agreement, EnfParams};

use crate::dataset::{recording_start, reference_hour, StartTime};
use crate::output::{read_trace, times};
use crate::pipeline::{align, reference_file, reference_for_recording, Nominal};
use crate::wav::is_wav;

/// Where a recording's reference ENF comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum Reference {
    /// A folder of hourly mains WAVs (`2022_08_17_Wed_16_00_00.wav`); the recording starts at
    /// `start` (local wall-clock time), and runs on into the next hour's file when it must.
    Hourly {
        /// The folder.
        dir: PathBuf,
        /// When the recording started.
        start: StartTime,
    },
    /// One mains WAV, traced whole; the estimate's time 0 is at `offset_s` into it.
    Wav(PathBuf),
    /// A trace CSV/JSON in the reference's own time.
    Trace(PathBuf),
}

impl Reference {
    /// The reference `path` for a recording named `recording` (whose `dvSave-…` name gives its
    /// start when `path` is a folder), and the offset left to add to the estimate's times.
    /// `offset_s` (whole seconds into an hourly WAV) turns that WAV into the folder form, so
    /// that a recording running past the hour continues in the next file.
    pub fn resolve(path: &Path, recording: &Path, offset_s: f64) -> Result<(Reference, f64)> {
        if path.is_dir() {
            let start = recording_start(recording).with_context(|| {
                format!(
                    "{}: cannot tell when the recording started: its name has no dvSave-YYYY_MM_DD_HH_MM_SS",
                    recording.display()
                )
            })?;
            return Ok((
                Reference::Hourly {
                    dir: path.to_path_buf(),
                    start,
                },
                offset_s,
            ));
        }
        if !is_wav(path) {
            return Ok((Reference::Trace(path.to_path_buf()), offset_s));
        }
        match reference_hour(path) {
            // an hourly WAV and whole seconds into it: the folder form, from that second
            Some(hour) if offset_s >= 0.0 && offset_s.fract() == 0.0 => {
                let dir = path
                    .parent()
                    .filter(|d| !d.as_os_str().is_empty())
                    .unwrap_or(Path::new("."));
                let start = StartTime::from_local_seconds(hour.local_seconds() + offset_s as i64);
                Ok((
                    Reference::Hourly {
                        dir: dir.to_path_buf(),
                        start,
                    },
                    0.0,
                ))
            }
            _ => Ok((Reference::Wav(path.to_path_buf()), offset_s)),
        }
    }
}

/// The outcome of a comparison.
#[derive(Debug, Clone)]
pub struct Comparison {
    /// Metrics over the common seconds.
    pub agreement: Agreement,
    /// Times (s from the recording start) compared.
    pub time_s: Vec<f64>,
    /// Estimate at those times.
    pub estimate: Vec<f64>,
    /// Reference at those times.
    pub reference: Vec<f64>,
    /// The reference's grid, when it was traced from mains WAVs.
    pub nominal_hz: Option<f64>,
}

/// Compares the estimate (`time_s`, `enf_hz`; named `what` in errors) with `reference`,
/// shifting estimate times by `offset_s`. A WAV reference is traced with `params` (its peak
/// method, window and step).
pub fn compare(
    time_s: &[f64],
    enf_hz: &[f64],
    what: &Path,
    reference: &Reference,
    offset_s: f64,
    nominal: Nominal,
    params: &EnfParams,
) -> Result<Comparison> {
    let (ref_t, ref_v, nominal_hz) = match reference {
        Reference::Hourly { dir, start } => {
            let step = params.step_s;
            let last = time_s.iter().copied().fold(0.0, f64::max);
            let seconds = ((last + offset_s) / step).floor().max(0.0) as usize + 1;
            let (f0, trace) = reference_for_recording(dir, *start, seconds, nominal, params)?;
            (times(trace.len(), step), trace, Some(f0))
        }
        Reference::Wav(path) => {
            let (f0, trace) = reference_file(path, nominal, params)?;
            (times(trace.len(), params.step_s), trace, Some(f0))
        }
        Reference::Trace(path) => {
            let r = read_trace(path)?;
            (r.time_s, r.enf_hz, None)
        }
    };
    let (t, e, r) = align(time_s, enf_hz, &ref_t, &ref_v, offset_s);
    let Some(agreement) = agreement(&e, &r) else {
        bail!(
            "{} and its reference share fewer than two seconds at offset {offset_s} s",
            what.display()
        );
    };
    Ok(Comparison {
        agreement,
        time_s: t,
        estimate: e,
        reference: r,
        nominal_hz,
    })
}
