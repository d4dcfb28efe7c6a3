//! `eenf extract`: the E-ENF trace of an event recording.

use std::path::{Path, PathBuf};

use anyhow::Result;
use eenf_cli::output::{extraction_json, times, write_atomic, write_trace_csv};
use eenf_cli::pipeline::{extract_file, Extraction};
use eenf_cli::plot::plot_extraction;
use eenf_cli::progress::Progress;

use super::method::MethodArgs;

/// Arguments of `eenf extract`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The event recording.
    pub file: PathBuf,
    /// Write the trace here: CSV (`time_s,enf_hz`), or JSON when the name ends in .json.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Print the trace and its metadata as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Plot the per-harmonic traces and the selection (.png or .svg).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    #[command(flatten)]
    pub method: MethodArgs,
}

/// Writes the trace to `path` as CSV or (by extension) JSON.
pub fn save(x: &Extraction, path: &Path) -> Result<()> {
    let is_json = path.extension().and_then(|e| e.to_str()) == Some("json");
    write_atomic(path, |w| {
        if is_json {
            serde_json::to_writer_pretty(&mut *w, &extraction_json(x))?;
            writeln!(w)?;
            Ok(())
        } else {
            write_trace_csv(
                w,
                &times(x.trace.enf_hz.len(), x.trace.step_s),
                &x.trace.enf_hz,
            )
        }
    })
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    let opts = a.method.options()?;
    let started = std::time::Instant::now();
    let x = extract_file(&a.file, &opts, &progress)?;
    let took = started.elapsed().as_secs_f64();
    if let Some(out) = &a.output {
        save(&x, out)?;
    }
    if let Some(p) = &a.plot {
        let title = format!(
            "{}: ENF per harmonic, selected per {} s",
            a.file.file_name().unwrap_or_default().to_string_lossy(),
            x.trace.segment_len as f64 * x.trace.step_s
        );
        plot_extraction(p, &title, &x.trace)?;
    }
    let n = x.trace.enf_hz.len();
    let mean = x.trace.enf_hz.iter().filter(|v| v.is_finite()).sum::<f64>() / n.max(1) as f64;
    eprintln!(
        "{}: {} events, {:.1} s, {} Hz grid, {n} estimates (mean {mean:.4} Hz) in {took:.2} s ({:.1} M events/s)",
        a.file.display(),
        x.events,
        x.duration_s,
        x.params.nominal_hz,
        x.events as f64 / took / 1e6
    );
    if let Some(out) = &a.output {
        eprintln!("trace written to {}", out.display());
    }
    if let Some(p) = &a.plot {
        eprintln!("plot written to {}", p.display());
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&extraction_json(&x))?);
    } else if a.output.is_none() {
        let stdout = std::io::stdout();
        let mut lock = stdout.lock();
        write_trace_csv(&mut lock, &times(n, x.trace.step_s), &x.trace.enf_hz)?;
    }
    Ok(())
}
