//! The work behind the commands, callable from tests and benchmarks: events → trace, mains
//! recording → reference trace, and the alignment of the two.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use eenf_dsp::{
    check_line, detect_nominal, extract_enf, reference_enf, EnfParams, EnfTrace, PolaritySequence,
    SamplingMethod, TemporalSampler,
};
use eenf_events::StreamInfo;

use crate::dataset::{hourly_references, StartTime};
use crate::progress::Progress;
use crate::wav::{read_wav, Signal};

/// The nominal grid frequency: given, or detected from the data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Nominal {
    /// Decide between 50 and 60 Hz from the spectrum.
    Auto,
    /// A known grid frequency, Hz.
    Hz(f64),
}

impl std::str::FromStr for Nominal {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "auto" => Ok(Nominal::Auto),
            "50" => Ok(Nominal::Hz(50.0)),
            "60" => Ok(Nominal::Hz(60.0)),
            _ => Err(format!("expected 50, 60 or auto, got {s:?}")),
        }
    }
}

/// How events become a trace.
#[derive(Debug, Clone)]
pub struct ExtractOptions {
    /// Temporal sampling variant.
    pub sampling: SamplingMethod,
    /// Sampling interval, µs.
    pub dt_us: i64,
    /// Grid frequency.
    pub nominal: Nominal,
    /// Everything after sampling (`nominal_hz` is set from `nominal`).
    pub params: EnfParams,
}

impl Default for ExtractOptions {
    fn default() -> Self {
        ExtractOptions {
            sampling: SamplingMethod::Paper,
            dt_us: 1000,
            nominal: Nominal::Auto,
            params: EnfParams::default(),
        }
    }
}

/// The result of extracting the ENF from an event file.
#[derive(Debug, Clone)]
pub struct Extraction {
    /// The file.
    pub path: PathBuf,
    /// What its header said.
    pub info: StreamInfo,
    /// Events read.
    pub events: u64,
    /// The polarity sequence's first sample time (the first event), µs.
    pub t0_us: i64,
    /// Seconds covered by the sequence.
    pub duration_s: f64,
    /// Parameters used (with the nominal frequency decided).
    pub params: EnfParams,
    /// Sampling used.
    pub sampling: SamplingMethod,
    /// Sampling interval, µs.
    pub dt_us: i64,
    /// The trace.
    pub trace: EnfTrace,
}

/// Reads an event file into a polarity sequence.
pub fn sample_file(
    path: &Path,
    sampling: SamplingMethod,
    dt_us: i64,
    progress: &Progress,
) -> Result<(StreamInfo, u64, PolaritySequence)> {
    let mut reader = eenf_events::open(path)?;
    let info = reader.info().clone();
    let bar = progress.events(info.event_count, "reading events");
    let mut sampler = TemporalSampler::new(sampling, dt_us);
    while let Some(batch) = reader.next_batch()? {
        sampler
            .push(&batch)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        bar.inc(batch.len() as u64);
    }
    bar.finish_and_clear();
    let events = sampler.events();
    if events == 0 {
        bail!("{}: the event stream is empty", path.display());
    }
    let seq = sampler
        .finish()
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    Ok((info, events, seq))
}

/// E-ENF from an event file.
pub fn extract_file(path: &Path, opts: &ExtractOptions, progress: &Progress) -> Result<Extraction> {
    let (info, events, seq) = sample_file(path, opts.sampling, opts.dt_us, progress)?;
    extract_sequence(path, info, events, &seq, opts, progress)
}

/// E-ENF from a polarity sequence already sampled from `path` (with `opts.sampling` and
/// `opts.dt_us`).
pub fn extract_sequence(
    path: &Path,
    info: StreamInfo,
    events: u64,
    seq: &PolaritySequence,
    opts: &ExtractOptions,
    progress: &Progress,
) -> Result<Extraction> {
    let x: Vec<f64> = seq.values.iter().map(|&v| v as f64).collect();
    let fs = seq.fs();
    let mut params = opts.params.clone();
    let err = |e: eenf_dsp::DspError| anyhow::anyhow!("{}: {e}", path.display());
    if seq.duration_s() < params.window_s {
        return Err(err(eenf_dsp::DspError::TooShort {
            duration_s: seq.duration_s(),
            window_s: params.window_s,
        }));
    }
    params.nominal_hz = match opts.nominal {
        Nominal::Auto => detect_nominal(&x, fs, 2.0).map_err(err)?,
        Nominal::Hz(f) => {
            // the flicker line may be weak at 2f0 yet strong at a higher harmonic
            let ok = (1..=params.harmonics.max(1))
                .any(|m| check_line(&x, fs, f, 2.0 * m as f64).is_ok());
            if !ok {
                check_line(&x, fs, f, 2.0).map_err(err)?;
            }
            f
        }
    };
    let spin = progress.spinner("tracking the ENF");
    let trace = extract_enf(seq, &params).map_err(err)?;
    spin.finish_and_clear();
    Ok(Extraction {
        path: path.to_path_buf(),
        info,
        events,
        t0_us: seq.t0_us,
        duration_s: seq.duration_s(),
        params,
        sampling: opts.sampling,
        dt_us: opts.dt_us,
        trace,
    })
}

/// Decides or checks the nominal frequency of a mains signal.
pub fn mains_nominal(sig: &Signal, nominal: Nominal, path: &Path) -> Result<f64> {
    let err = |e: eenf_dsp::DspError| anyhow::anyhow!("{}: {e}", path.display());
    if sig.fs < 2.0 * (50.0 + 4.0) {
        bail!(
            "{}: sample rate {} Hz is too low to carry a 50/60 Hz mains tone",
            path.display(),
            sig.fs
        );
    }
    Ok(match nominal {
        Nominal::Auto => detect_nominal(&sig.samples, sig.fs, 1.0).map_err(err)?,
        Nominal::Hz(f) => {
            if sig.fs < 2.0 * (f + 4.0) {
                bail!(
                    "{}: sample rate {} Hz is too low for a {f} Hz mains tone",
                    path.display(),
                    sig.fs
                );
            }
            check_line(&sig.samples, sig.fs, f, 1.0).map_err(err)?;
            f
        }
    })
}

/// The reference trace of a whole mains WAV.
pub fn reference_file(
    path: &Path,
    nominal: Nominal,
    params: &EnfParams,
) -> Result<(f64, Vec<f64>)> {
    let sig = read_wav(path)?;
    let f0 = mains_nominal(&sig, nominal, path)?;
    let p = EnfParams {
        nominal_hz: f0,
        ..params.clone()
    };
    let trace = reference_enf(&sig.samples, sig.fs, &p)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    Ok((f0, trace))
}

/// Days since 1970-01-01 of a civil date (proleptic Gregorian).
pub fn days_from_civil(y: i64, m: u32, d: u32) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m as i64 + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d as i64 - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

fn hour_index(t: &StartTime) -> i64 {
    days_from_civil(t.year as i64, t.month, t.day) * 24 + t.hour as i64
}

/// The reference trace for a recording that starts at `start` (local time from its name) and
/// lasts `seconds` estimates, from a folder of hourly WAVs. Windows near the recording's ends
/// see the mains before and after it, continuing into the next hour's file when needed.
pub fn reference_for_recording(
    dir: &Path,
    start: StartTime,
    seconds: usize,
    nominal: Nominal,
    params: &EnfParams,
) -> Result<(f64, Vec<f64>)> {
    let files = hourly_references(dir)?;
    let first = hour_index(&start);
    let Some(pos) = files.iter().position(|(t, _)| hour_index(t) == first) else {
        bail!(
            "{}: no reference for {} hour {:02} (expected a file like {}_Day_{:02}_00_00.wav)",
            dir.display(),
            start.date(),
            start.hour,
            start.date(),
            start.hour
        );
    };
    let margin = (params.window_s / 2.0).ceil() as usize + 2;
    let from = start.second_of_hour() as usize;
    let need_until = from + seconds + margin;
    let mut samples = Vec::new();
    let mut fs = 0.0;
    let mut f0 = None;
    for (k, (t, path)) in files[pos..].iter().enumerate() {
        if hour_index(t) != first + k as i64 {
            break;
        }
        let sig = read_wav(path)?;
        if k == 0 {
            fs = sig.fs;
            f0 = Some(mains_nominal(&sig, nominal, path)?);
        } else if sig.fs != fs {
            bail!(
                "{}: sample rate {} Hz differs from the previous hour's {fs} Hz",
                path.display(),
                sig.fs
            );
        }
        samples.extend_from_slice(&sig.samples);
        if samples.len() as f64 / fs >= need_until as f64 {
            break;
        }
    }
    let f0 = f0.context("no reference loaded")?;
    let have_s = samples.len() as f64 / fs;
    if (from + seconds) as f64 > have_s + 1.0 {
        bail!(
            "{}: the references cover {:.0} s from {}_{:02}:00:00; the recording needs {} s from second {from}",
            dir.display(),
            have_s,
            start.date(),
            start.hour,
            seconds
        );
    }
    // track a slice starting on a whole second so frames fall on the hour's seconds
    let a = from.saturating_sub(margin);
    let b = ((need_until as f64 * fs) as usize).min(samples.len());
    let p = EnfParams {
        nominal_hz: f0,
        ..params.clone()
    };
    let slice = &samples[(a as f64 * fs) as usize..b];
    let trace =
        reference_enf(slice, fs, &p).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
    let off = from - a;
    let out: Vec<f64> = (0..seconds)
        .map(|i| trace.get(off + i).copied().unwrap_or(f64::NAN))
        .collect();
    Ok((f0, out))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn civil_days() {
        assert_eq!(days_from_civil(1970, 1, 1), 0);
        assert_eq!(days_from_civil(2022, 8, 17), 19_221);
        assert_eq!(days_from_civil(2000, 3, 1), 11_017);
    }

    #[test]
    fn align_matches_times_with_offset() {
        let (t, e, r) = align(
            &[0.0, 1.0, 2.0],
            &[1.0, 2.0, 3.0],
            &[10.0, 11.0, 12.0, 13.0],
            &[5.0, 6.0, 7.0, 8.0],
            11.0,
        );
        assert_eq!(t, vec![0.0, 1.0, 2.0]);
        assert_eq!(e, vec![1.0, 2.0, 3.0]);
        assert_eq!(r, vec![6.0, 7.0, 8.0]);
    }
}
