//! E-ENF: an event recording → its polarity sequence → a [`Trace`].

use std::path::Path;

use anyhow::{bail, Result};
use eenf_dsp::{
    check_line, detect_nominal, extract_enf, EnfParams, PolaritySequence, SamplingMethod,
    TemporalSampler,
};
use eenf_events::StreamInfo;

use crate::progress::Progress;
use crate::trace::{EventsProvenance, Trace};

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
pub fn extract_file(path: &Path, opts: &ExtractOptions, progress: &Progress) -> Result<Trace> {
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
) -> Result<Trace> {
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
    let estimates = extract_enf(seq, &params).map_err(err)?;
    spin.finish_and_clear();
    let provenance = EventsProvenance {
        format: info.format.to_string(),
        start_t_us: seq.t0_us,
        start_utc: crate::time::utc_micros(seq.t0_us),
        events,
        duration_s: seq.duration_s(),
        sampling: opts.sampling,
        dt_us: opts.dt_us,
        params,
    };
    Ok(Trace::from_events(path, &estimates, provenance))
}

