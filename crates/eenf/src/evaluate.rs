//! Scoring a trace against its reference: where the reference comes from (a trace, a mains
//! WAV, a dataset's hourly WAVs), how the two are aligned, and the metrics. Shared by
//! `compare` and `bench`, so both give the same numbers.

use eenf_core::spelling::option;
use std::path::{Path, PathBuf};

use crate::error::{fail, Error, Missing, Result};
use eenf_dsp::{agreement, Agreement, EnfParams};

use crate::dataset::{recording_start, reference_hour};
use crate::mains::reference_file;
use crate::output::folder_of;
use crate::reference::{reference_for_recording, ReferenceSource};
use crate::time::LocalTime;
use crate::trace::Trace;
use eenf_core::Nominal;

/// Where a recording's reference ENF comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum Reference {
    /// A folder of hourly mains WAVs (`2022_08_17_Wed_16_00_00.wav`); the recording starts at
    /// `start` (local wall-clock time), and runs on into the next hour's file when it must.
    Hourly {
        /// The folder.
        dir: PathBuf,
        /// When the recording started.
        start: LocalTime,
    },
    /// One mains WAV, traced whole; the estimate's time 0 is at `offset_s` into it.
    Wav(PathBuf),
    /// A trace CSV/JSON in the reference's own time; an `index,value` CSV has a value every
    /// `index_step_s` seconds.
    Trace {
        /// The file.
        path: PathBuf,
        /// Seconds between the rows of an `index,value` CSV.
        index_step_s: f64,
    },
}

impl Reference {
    /// The reference `path` for a recording named `recording` (whose `dvSave-…` name gives its
    /// start when `path` is a folder or one hourly WAV and no offset is given), and the offset
    /// left to add to the estimate's times. `offset_s` (whole seconds into an hourly WAV) turns
    /// that WAV into the folder form, so that a recording running past the hour continues in
    /// the next file. An `index,value` trace CSV has a value every `index_step_s` seconds.
    pub fn resolve(
        path: &Path,
        recording: &Path,
        offset_s: f64,
        index_step_s: f64,
    ) -> Result<(Reference, f64)> {
        let source = ReferenceSource::open(path)?;
        if let ReferenceSource::Store(dir) = &source {
            fail!(Method,
                "{}: a reference store: `match` searches stores; compare takes a trace, a WAV or a folder of hourly WAVs",
                dir.display()
            );
        }
        if let ReferenceSource::Archive(p) = &source {
            fail!(Method,
                "{}: a grid archive: add it to a store with `refdb build` and search it with `match`",
                p.display()
            );
        }
        if let ReferenceSource::HourlyFolder(_) = source {
            let start = recording_start(recording).or_fail(Error::Input, || {
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
        if let ReferenceSource::Trace(_) = source {
            let reference = Reference::Trace {
                path: path.to_path_buf(),
                index_step_s,
            };
            return Ok((reference, offset_s));
        }
        match (reference_hour(path), recording_start(recording)) {
            // an hourly WAV, no offset given, and a recording whose name says when it started:
            // placed by its name, as in a folder (the next hour's file is read if it runs on)
            (Some(hour), Some(start)) if offset_s == 0.0 => {
                if start.hour_index() != hour.hour_index() {
                    fail!(Method,
                        "{}: the recording {} starts at {} {:02}:{:02}:{:02}, outside this hour's reference (pass the folder of hourly WAVs, or {})",
                        path.display(),
                        recording.display(),
                        start.date(),
                        start.hour(),
                        start.second_of_hour() / 60,
                        start.second_of_hour() % 60,
                        option("offset_s")
                    );
                }
                Ok((
                    Reference::Hourly {
                        dir: folder_of(path).to_path_buf(),
                        start,
                    },
                    0.0,
                ))
            }
            _ => Self::resolve_wav(path, offset_s),
        }
    }

    /// One WAV with an explicit offset: an hourly one becomes the folder form from that second.
    fn resolve_wav(path: &Path, offset_s: f64) -> Result<(Reference, f64)> {
        match reference_hour(path) {
            // an hourly WAV and whole seconds into it: the folder form, from that second
            Some(hour) if offset_s >= 0.0 && offset_s.fract() == 0.0 => {
                let start = LocalTime::from_local_seconds(hour.local_seconds() + offset_s as i64);
                Ok((
                    Reference::Hourly {
                        dir: folder_of(path).to_path_buf(),
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

impl Comparison {
    /// The agreement as `eenf compare --json` and Python's `compare` report it: `cc`,
    /// `mae_hz`, `rmse_hz`, `max_err_hz` (Hz), `seconds` compared, and the `offset_s` that was
    /// added to the estimate's times. Each front end adds what it has besides (file names, the
    /// aligned values).
    pub fn summary_json(&self, offset_s: f64) -> serde_json::Value {
        let m = &self.agreement;
        serde_json::json!({
            "cc": m.cc, "mae_hz": m.mae_hz, "rmse_hz": m.rmse_hz, "max_err_hz": m.max_err_hz,
            "seconds": m.n, "offset_s": offset_s,
        })
    }
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
    let r = match reference {
        Reference::Hourly { dir, start } => {
            let step = params.step_s;
            let last = time_s.iter().copied().fold(0.0, f64::max);
            let seconds = ((last + offset_s) / step).floor().max(0.0) as usize + 1;
            reference_for_recording(dir, *start, seconds, nominal, params)?
        }
        Reference::Wav(path) => reference_file(path, nominal, params)?,
        Reference::Trace { path, index_step_s } => Trace {
            nominal_hz: None,
            ..Trace::read(path, Some(*index_step_s))?
        },
    };
    compare_with(time_s, enf_hz, what, &r, offset_s)
}

/// Compares the estimate (`time_s`, `enf_hz`; named `what` in errors) with a reference trace
/// already at hand, shifting estimate times by `offset_s`.
pub fn compare_with(
    time_s: &[f64],
    enf_hz: &[f64],
    what: &Path,
    r: &Trace,
    offset_s: f64,
) -> Result<Comparison> {
    let (t, e, ref_v) = align(time_s, enf_hz, &r.time_s, &r.enf_hz, offset_s);
    let Some(agreement) = agreement(&e, &ref_v) else {
        fail!(
            Method,
            "{} and its reference share fewer than two seconds at offset {offset_s} s",
            what.display()
        );
    };
    Ok(Comparison {
        agreement,
        time_s: t,
        estimate: e,
        reference: ref_v,
        nominal_hz: r.nominal_hz,
    })
}

/// Compares `estimate` (read from `estimate_path`) with the reference at `reference`: a trace,
/// a mains WAV, or a folder of hourly WAVs, where the recording's `dvSave-` name (from the
/// trace's metadata, else the trace file's own name) places it.
pub fn compare_trace(
    estimate: &Trace,
    estimate_path: &Path,
    reference: &Path,
    offset_s: f64,
    index_step_s: f64,
    nominal: Nominal,
    params: &EnfParams,
) -> Result<Comparison> {
    let source = estimate
        .file
        .clone()
        .unwrap_or_else(|| estimate_path.to_path_buf());
    let named = if recording_start(&source).is_some() {
        source
    } else {
        estimate_path.to_path_buf()
    };
    let (reference, offset) = Reference::resolve(reference, &named, offset_s, index_step_s)?;
    compare(
        &estimate.time_s,
        &estimate.enf_hz,
        estimate_path,
        &reference,
        offset,
        nominal,
        params,
    )
}

/// Pairs of (time, estimate, reference) where the reference holds a value at estimate time +
/// `offset_s` (times matched to the millisecond).
pub fn align(
    est_t: &[f64],
    est: &[f64],
    ref_t: &[f64],
    reference: &[f64],
    offset_s: f64,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let key = |t: f64| (t * 1000.0).round() as i64;
    let map: std::collections::HashMap<i64, f64> = ref_t
        .iter()
        .zip(reference)
        .map(|(t, v)| (key(*t), *v))
        .collect();
    let mut out = (Vec::new(), Vec::new(), Vec::new());
    for (t, e) in est_t.iter().zip(est) {
        if let Some(r) = map.get(&key(t + offset_s)) {
            if e.is_finite() && r.is_finite() {
                out.0.push(*t);
                out.1.push(*e);
                out.2.push(*r);
            }
        }
    }
    out
}
