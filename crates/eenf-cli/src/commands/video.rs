//! `eenf video`: the V-ENF trace of a conventional (rolling-shutter) video.

use std::path::PathBuf;

use anyhow::Result;
use eenf::progress::Progress;
use eenf::trace::Provenance;

use crate::args::{TraceOutputArgs, VideoMethodArgs};

/// Arguments of `eenf video`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The video: Y4M read natively, any other container through ffmpeg.
    pub file: PathBuf,
    #[command(flatten)]
    pub out: TraceOutputArgs,
    #[command(flatten)]
    pub method: VideoMethodArgs,
}

/// Runs `eenf video`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    let opts = a.method.options()?;
    let started = std::time::Instant::now();
    let trace = eenf::video::trace_video(&a.file, &opts, &progress)?;
    let took = started.elapsed().as_secs_f64();
    a.out.save(&trace, &a.file)?;
    for w in &trace.warnings {
        eprintln!("warning: {w}");
    }
    if let Some(Provenance::Video(v)) = &trace.provenance {
        if let Some(why) = &v.sampling_reason {
            eprintln!("sampling: {why}");
        }
        let rows = v
            .virtual_rows
            .map(|l| format!(", {l:.1} virtual rows"))
            .unwrap_or_default();
        eprintln!(
            "{}: {} frames {}x{} at {:.3} fps{}{rows}, {} Hz grid, {} sampling, line {:.2} Hz ({:.0}x above the noise), {} estimates (mean {:.4} Hz) in {took:.2} s",
            a.file.display(),
            v.frames,
            v.width,
            v.height,
            v.fps,
            if v.frame_times {
                " (variable: frame times from the container)"
            } else {
                ""
            },
            trace.nominal_hz.unwrap_or(f64::NAN),
            v.sampling,
            v.line_hz,
            v.prominence,
            trace.enf_hz.len(),
            trace.mean_hz(),
        );
    }
    a.out.report(&trace);
    a.out.print(&trace)
}
