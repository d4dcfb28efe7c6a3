//! `eenf reference`: the reference ENF trace of a mains/audio WAV.

use std::path::PathBuf;

use anyhow::Result;
use eenf_cli::output::{times, write_atomic, write_trace_csv};
use eenf_cli::pipeline::reference_file;
use eenf_cli::progress::Progress;

use super::method::TrackerArgs;

/// Arguments of `eenf reference`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The mains (or audio) recording, WAV of any sample rate.
    pub wav: PathBuf,
    /// Write the trace here: CSV (`time_s,enf_hz`), or JSON when the name ends in .json.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Print the trace as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub tracker: TrackerArgs,
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    let params = a.tracker.params()?;
    let spin = progress.spinner("tracking the mains frequency");
    let started = std::time::Instant::now();
    let (f0, trace) = reference_file(&a.wav, a.tracker.nominal, &params)?;
    spin.finish_and_clear();
    let t = times(trace.len(), params.step_s);
    let json = || {
        serde_json::json!({
            "file": a.wav, "nominal_hz": f0, "peak": params.peak.name(),
            "window_s": params.window_s, "step_s": params.step_s,
            "time_s": t, "enf_hz": trace.iter().map(|f| f.is_finite().then_some(*f)).collect::<Vec<_>>(),
        })
    };
    if let Some(out) = &a.output {
        let is_json = out.extension().and_then(|e| e.to_str()) == Some("json");
        write_atomic(out, |w| {
            if is_json {
                serde_json::to_writer_pretty(&mut *w, &json())?;
                writeln!(w)?;
                Ok(())
            } else {
                write_trace_csv(w, &t, &trace)
            }
        })?;
    }
    let finite: Vec<f64> = trace.iter().copied().filter(|v| v.is_finite()).collect();
    let mean = finite.iter().sum::<f64>() / finite.len().max(1) as f64;
    let sd = (finite.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / finite.len().max(1) as f64)
        .sqrt();
    eprintln!(
        "{}: {f0} Hz grid, {} estimates, mean {mean:.5} Hz, std {:.2} mHz ({} peak) in {:.2} s",
        a.wav.display(),
        trace.len(),
        sd * 1e3,
        params.peak.name(),
        started.elapsed().as_secs_f64()
    );
    if let Some(out) = &a.output {
        eprintln!("trace written to {}", out.display());
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&json())?);
    } else if a.output.is_none() {
        let stdout = std::io::stdout();
        write_trace_csv(&mut stdout.lock(), &t, &trace)?;
    }
    Ok(())
}
