//! `eenf convert`: any readable event file to any writable format, streamed.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use eenf_cli::progress::Progress;
use eenf_events::writers::{create, OutputFormat};
use eenf_events::{Compression, StreamStats};

/// Arguments of `eenf convert`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The input event file (any supported format, found from its content).
    pub input: PathBuf,
    /// The output file.
    pub output: PathBuf,
    /// Output format: aedat4, evt2, evt3, dat, text (default: from the output's extension:
    /// .aedat4, .raw = evt3, .dat, .txt/.csv).
    #[arg(long)]
    pub format: Option<String>,
    /// AEDAT4 packet compression: none, lz4, lz4_high, zstd, zstd_high.
    #[arg(long, default_value = "lz4")]
    pub compression: String,
}

/// `--compression` → the AEDAT4 codec.
pub fn parse_codec(s: &str) -> Result<Compression> {
    Compression::parse(s).with_context(|| {
        format!("--compression {s:?}: expected none, lz4, lz4_high, zstd or zstd_high")
    })
}

/// `--format` → the output format.
pub fn parse_format(f: &str, codec: Compression) -> Result<OutputFormat> {
    OutputFormat::parse(f, codec)
        .with_context(|| format!("--format {f:?}: expected aedat4, evt2, evt3, dat or text"))
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    let codec = parse_codec(&a.compression)?;
    let format = match &a.format {
        Some(f) => parse_format(f, codec)?,
        None => OutputFormat::from_extension(&a.output, codec).with_context(|| {
            format!(
                "{}: cannot tell the output format from the name; pass --format aedat4|evt2|evt3|dat|text",
                a.output.display()
            )
        })?,
    };
    if a.input.canonicalize().ok() == a.output.canonicalize().ok() && a.output.exists() {
        bail!("{}: input and output are the same file", a.output.display());
    }
    let started = std::time::Instant::now();
    let mut reader = eenf_events::open(&a.input)?;
    let info = reader.info().clone();
    // the output header needs the geometry: from the input's header, else from a first pass
    let (width, height) = match (info.width, info.height) {
        (Some(w), Some(h)) => (w, h),
        _ => {
            let mut scan = eenf_events::open(&a.input)?;
            let s = StreamStats::scan(scan.as_mut())?;
            (
                s.x_range.map_or(1, |r| r.1.saturating_add(1)),
                s.y_range.map_or(1, |r| r.1.saturating_add(1)),
            )
        }
    };
    let mut writer = create(&a.output, format, width, height)?;
    let bar = progress.events(info.event_count, "converting");
    while let Some(batch) = reader.next_batch()? {
        writer.write(&batch)?;
        bar.inc(batch.len() as u64);
    }
    bar.finish_and_clear();
    let n = writer.finish()?;
    let took = started.elapsed().as_secs_f64();
    eprintln!(
        "{} ({}) -> {} ({}): {n} events, {width}x{height}, in {took:.2} s ({:.1} M events/s)",
        a.input.display(),
        info.format,
        a.output.display(),
        format.name(),
        n as f64 / took.max(1e-9) / 1e6
    );
    Ok(())
}
