//! `eenf reference`: the reference ENF trace of a mains/audio WAV.

use std::path::PathBuf;

use anyhow::Result;
use eenf::progress::Progress;
use eenf::reference::reference_file;

use super::args::{TraceOutputArgs, TrackerArgs};

/// Arguments of `eenf reference`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The mains (or audio) recording, WAV of any sample rate.
    pub wav: PathBuf,
    #[command(flatten)]
    pub out: TraceOutputArgs,
    #[command(flatten)]
    pub tracker: TrackerArgs,
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    let params = a.tracker.params()?;
    let spin = progress.spinner("tracking the mains frequency");
    let started = std::time::Instant::now();
    let trace = reference_file(&a.wav, a.tracker.nominal, &params)?;
    spin.finish_and_clear();
    a.out.save(&trace)?;
    let finite: Vec<f64> = trace.finite().collect();
    let mean = finite.iter().sum::<f64>() / finite.len().max(1) as f64;
    let sd = (finite.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / finite.len().max(1) as f64)
        .sqrt();
    eprintln!(
        "{}: {} Hz grid, {} estimates, mean {mean:.5} Hz, std {:.2} mHz ({} peak) in {:.2} s",
        a.wav.display(),
        trace.nominal_hz.unwrap_or(f64::NAN),
        trace.enf_hz.len(),
        sd * 1e3,
        params.peak,
        started.elapsed().as_secs_f64()
    );
    a.out.report();
    a.out.print(&trace)
}
