//! Writing result files whole or not at all, and reading/writing trace files.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// Writes `path` through a temporary file beside it, renamed into place when `write` succeeds.
pub fn write_atomic(path: &Path, write: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
    let tmp = eenf_events::tmp_path_for(path);
    let res = (|| -> Result<()> {
        let f = std::fs::File::create(&tmp)?;
        let mut w = std::io::BufWriter::new(f);
        write(&mut w)?;
        let f = w.into_inner().map_err(|e| e.into_error())?;
        f.sync_all()?;
        Ok(())
    })();
    match res {
        Ok(()) => eenf_events::commit_tmp(&tmp, path).with_context(|| {
            format!(
                "{}: cannot move the finished file into place",
                path.display()
            )
        }),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e.context(format!("{}: cannot write", path.display())))
        }
    }
}

/// An ENF trace as stored on disk: one estimate per step from the recording's start.
#[derive(Debug, Clone, Default)]
pub struct TraceFile {
    /// Seconds from the recording's start.
    pub time_s: Vec<f64>,
    /// ENF estimates, Hz.
    pub enf_hz: Vec<f64>,
    /// The recording the trace came from, when known (JSON metadata or the file name).
    pub source: Option<PathBuf>,
}

/// The CSV header of trace files.
pub const TRACE_HEADER: &str = "time_s,enf_hz";

/// Writes a trace as CSV (`time_s,enf_hz`).
pub fn write_trace_csv(w: &mut dyn Write, time_s: &[f64], enf_hz: &[f64]) -> Result<()> {
    writeln!(w, "{TRACE_HEADER}")?;
    for (t, f) in time_s.iter().zip(enf_hz) {
        if f.is_finite() {
            writeln!(w, "{t},{f}")?;
        } else {
            writeln!(w, "{t},")?;
        }
    }
    Ok(())
}

/// Reads a trace from a CSV (`time_s,enf_hz`) or JSON file written by eenf.
pub fn read_trace(path: &Path) -> Result<TraceFile> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let trimmed = text.trim_start();
    if trimmed.starts_with('{') {
        let v: serde_json::Value = serde_json::from_str(trimmed)
            .with_context(|| format!("{}: not valid JSON", path.display()))?;
        let nums = |key: &str| -> Result<Vec<f64>> {
            v[key]
                .as_array()
                .with_context(|| format!("{}: JSON has no {key:?} array", path.display()))?
                .iter()
                .map(|x| Ok(x.as_f64().unwrap_or(f64::NAN)))
                .collect()
        };
        let trace = TraceFile {
            time_s: nums("time_s")?,
            enf_hz: nums("enf_hz")?,
            source: v["file"].as_str().map(PathBuf::from),
        };
        if trace.time_s.len() != trace.enf_hz.len() {
            bail!("{}: time_s and enf_hz differ in length", path.display());
        }
        return Ok(trace);
    }
    let mut lines = text
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'));
    let header = lines.next().unwrap_or("");
    let cols: Vec<&str> = header.split(',').map(|s| s.trim()).collect();
    let (Some(ti), Some(fi)) = (
        cols.iter().position(|c| *c == "time_s"),
        cols.iter().position(|c| *c == "enf_hz"),
    ) else {
        bail!(
            "{}: not a trace file (expected a CSV with header {TRACE_HEADER:?} or eenf JSON)",
            path.display()
        );
    };
    let mut trace = TraceFile {
        source: Some(path.to_path_buf()),
        ..TraceFile::default()
    };
    for (n, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').map(|s| s.trim()).collect();
        let get = |i: usize| f.get(i).copied().unwrap_or("");
        let t: f64 = get(ti).parse().with_context(|| {
            format!(
                "{}: line {}: bad time_s {:?}",
                path.display(),
                n + 2,
                get(ti)
            )
        })?;
        let v = if get(fi).is_empty() {
            f64::NAN
        } else {
            get(fi).parse().with_context(|| {
                format!(
                    "{}: line {}: bad enf_hz {:?}",
                    path.display(),
                    n + 2,
                    get(fi)
                )
            })?
        };
        trace.time_s.push(t);
        trace.enf_hz.push(v);
    }
    if trace.time_s.is_empty() {
        bail!("{}: the trace is empty", path.display());
    }
    Ok(trace)
}

/// Seconds `0, step, 2·step, …` for `n` estimates.
pub fn times(n: usize, step: f64) -> Vec<f64> {
    (0..n).map(|i| i as f64 * step).collect()
}

/// A µs Unix timestamp as ISO 8601 UTC, e.g. `2022-08-17T08:10:00.000000Z`.
pub fn utc_string(us: i64) -> String {
    let secs = us.div_euclid(1_000_000);
    let micros = us.rem_euclid(1_000_000);
    let t = crate::dataset::StartTime::from_local_seconds(secs);
    format!(
        "{:04}-{:02}-{:02}T{:02}:{:02}:{:02}.{micros:06}Z",
        t.year, t.month, t.day, t.hour, t.minute, t.second
    )
}

/// A two-column CSV: `time_s,enf_hz` (eenf traces) or `index,value` (needs `step`).
pub fn read_series_csv(path: &Path, step: Option<f64>) -> Result<(f64, Vec<f64>)> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let header = text.lines().next().unwrap_or("").to_ascii_lowercase();
    if header.contains("time_s") {
        let t = read_trace(path)?;
        let step = if t.time_s.len() > 1 {
            t.time_s[1] - t.time_s[0]
        } else {
            1.0
        };
        return Ok((step, t.enf_hz));
    }
    let step = step.with_context(|| format!("{}: an index CSV needs --step", path.display()))?;
    // a header row is one whose first field is not a number
    let skip = usize::from(
        text.lines()
            .next()
            .and_then(|l| l.split(',').next())
            .map(|f| f.trim().parse::<f64>().is_err())
            .unwrap_or(false),
    );
    let mut vals = Vec::new();
    for (i, line) in text.lines().skip(skip).enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let v = line
            .split(',')
            .nth(1)
            .and_then(|v| v.trim().parse::<f64>().ok())
            .with_context(|| {
                format!(
                    "{}: line {}: expected index,value",
                    path.display(),
                    i + 1 + skip
                )
            })?;
        vals.push(v);
    }
    Ok((step, vals))
}

/// The JSON form of an extraction.
pub fn extraction_json(x: &crate::pipeline::Extraction) -> serde_json::Value {
    let t = times(x.trace.enf_hz.len(), x.trace.step_s);
    let seg = x.trace.segment_len as f64 * x.trace.step_s;
    let selected: Vec<_> = x
        .trace
        .selected
        .iter()
        .enumerate()
        .map(|(i, m)| serde_json::json!({"start_s": i as f64 * seg, "harmonic": m}))
        .collect();
    let nan_to_null =
        |v: &[f64]| -> Vec<Option<f64>> { v.iter().map(|f| f.is_finite().then_some(*f)).collect() };
    let harmonics: Vec<_> = x
        .trace
        .harmonics
        .iter()
        .map(|h| {
            serde_json::json!({"harmonic": h.harmonic, "center_hz": h.center_hz,
                "enf_hz": nan_to_null(&h.enf_hz)})
        })
        .collect();
    serde_json::json!({
        "file": x.path,
        "format": x.info.format,
        "start_t_us": x.t0_us,
        "start_utc": utc_string(x.t0_us),
        "events": x.events,
        "duration_s": x.duration_s,
        "nominal_hz": x.params.nominal_hz,
        "sampling": x.sampling.name(),
        "dt_us": x.dt_us,
        "params": x.params,
        "step_s": x.trace.step_s,
        "time_s": t,
        "enf_hz": nan_to_null(&x.trace.enf_hz),
        "harmonics": harmonics,
        "selected": selected,
    })
}

/// The JSON form of a video trace (readable by `compare`).
pub fn video_json(
    path: &Path,
    t: &eenf_video::VideoTrace,
    opts: &eenf_video::VideoOptions,
) -> serde_json::Value {
    let enf: Vec<Option<f64>> = t
        .enf_hz
        .iter()
        .map(|f| f.is_finite().then_some(*f))
        .collect();
    serde_json::json!({
        "file": path,
        "method": "v-enf",
        "width": t.info.width,
        "height": t.info.height,
        "fps": t.info.fps,
        "frames": t.frames,
        "nominal_hz": t.nominal_hz,
        "sampling": opts.sampling,
        "scene_removal": opts.scene_removal,
        "virtual_rows": t.virtual_rows,
        "fs_hz": t.fs,
        "line_hz": t.line_hz,
        "prominence": t.prominence,
        "params": opts.params,
        "step_s": t.step_s,
        "time_s": times(t.enf_hz.len(), t.step_s),
        "enf_hz": enf,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_formatting() {
        assert_eq!(utc_string(0), "1970-01-01T00:00:00.000000Z");
        assert_eq!(
            utc_string(1_660_723_800_000_001),
            "2022-08-17T08:10:00.000001Z"
        );
    }

    #[test]
    fn trace_csv_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.csv");
        write_atomic(&p, |w| write_trace_csv(w, &[0.0, 1.0], &[50.01, f64::NAN])).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert_eq!(text, "time_s,enf_hz\n0,50.01\n1,\n");
        let t = read_trace(&p).unwrap();
        assert_eq!(t.time_s, vec![0.0, 1.0]);
        assert_eq!(t.enf_hz[0], 50.01);
        assert!(t.enf_hz[1].is_nan());
        std::fs::write(&p, "a,b\n1,2\n").unwrap();
        assert!(read_trace(&p).is_err());
    }
}
