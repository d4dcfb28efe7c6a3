//! `eenf convert`: any readable event file to any writable format, streamed.

use std::path::PathBuf;

use anyhow::{bail, Result};
use eenf::output::write_events;
use eenf::progress::Progress;
use eenf_events::StreamStats;

use crate::args::{EventOutputArgs, InputArgs};

/// Arguments of `eenf convert`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The input event file (any supported format, found from its content).
    pub input: PathBuf,
    /// The output file.
    pub output: PathBuf,
    #[command(flatten)]
    pub events: EventOutputArgs,
    #[command(flatten)]
    pub read: InputArgs,
}

/// Runs `eenf convert`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    let format = a.events.format_for(&a.output, None)?;
    if a.input.canonicalize().ok() == a.output.canonicalize().ok() && a.output.exists() {
        bail!("{}: input and output are the same file", a.output.display());
    }
    let started = std::time::Instant::now();
    let open = a.read.options();
    let mut reader = eenf_events::open_with(&a.input, &open)?;
    let info = reader.info().clone();
    // the output header needs the geometry: from the input's header, else from a first pass
    let (width, height) = match (info.width, info.height) {
        (Some(w), Some(h)) => (w, h),
        _ => {
            let mut scan = eenf_events::open_with(&a.input, &open)?;
            let s = StreamStats::scan(scan.as_mut())?;
            (
                s.x_range.map_or(1, |r| r.1.saturating_add(1)),
                s.y_range.map_or(1, |r| r.1.saturating_add(1)),
            )
        }
    };
    let bar = progress.events(info.event_count, "converting");
    let n = write_events(&a.output, format, width, height, |writer| {
        while let Some(batch) = reader.next_batch()? {
            writer.write(&batch)?;
            bar.inc(batch.len() as u64);
        }
        Ok(())
    })?;
    bar.finish_and_clear();
    if let Some(d) = reader.damage() {
        eprintln!("warning: {d}");
    }
    let took = started.elapsed().as_secs_f64();
    eprintln!(
        "{} ({}) -> {} ({format}): {n} events, {width}x{height}, in {took:.2} s ({:.1} M events/s)",
        a.input.display(),
        info.format,
        a.output.display(),
        n as f64 / took.max(1e-9) / 1e6
    );
    Ok(())
}
