//! `eenf extract`: the E-ENF trace of an event recording.

use std::path::PathBuf;

use anyhow::Result;
use eenf::extract::extract_file;
use eenf::progress::Progress;

use crate::args::{MethodArgs, TraceOutputArgs};

/// Arguments of `eenf extract`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The event recording.
    pub file: PathBuf,
    #[command(flatten)]
    pub out: TraceOutputArgs,
    #[command(flatten)]
    pub method: MethodArgs,
}

/// Runs `eenf extract`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    let opts = a.method.options()?;
    let started = std::time::Instant::now();
    let trace = extract_file(&a.file, &opts, &progress)?;
    let took = started.elapsed().as_secs_f64();
    a.out.save(&trace, &a.file)?;
    if let Some(x) = trace.events() {
        for n in &x.notes {
            eprintln!("note: {n}");
        }
        if let Some(d) = &x.damage {
            eprintln!("warning: {d}");
        }
        eprintln!(
            "{}: {} events, {:.1} s, {} Hz grid{}, {} sampling, {} estimates (mean {:.4} Hz) in {took:.2} s ({:.1} M events/s)",
            a.file.display(),
            x.events,
            x.duration_s,
            x.params.nominal_hz,
            x.flicker
                .map(|l| format!(" (flicker {:.3} Hz, {})", l.hz, l.strength()))
                .unwrap_or_default(),
            x.sampling,
            trace.enf_hz.len(),
            trace.mean_hz(),
            x.events as f64 / took / 1e6
        );
    }
    a.out.report(&trace);
    a.out.print(&trace)
}
