//! `eenf reference` (alias `audio`): the ENF of a mains recording or of any recording's sound.

use std::path::PathBuf;

use anyhow::Result;
use eenf::mains::audio_trace;
use eenf::progress::Progress;
use eenf::trace::{MainsProvenance, Provenance};

use crate::args::{AudioArgs, TraceOutputArgs, TrackerArgs};

/// Arguments of `eenf reference`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The recording: a mains WAV, or any sound (WAV, FLAC, MP3, M4A/AAC, OGG, or a video's
    /// soundtrack through ffmpeg), at any sample rate.
    pub file: PathBuf,
    #[command(flatten)]
    pub audio: AudioArgs,
    #[command(flatten)]
    pub out: TraceOutputArgs,
    #[command(flatten)]
    pub tracker: TrackerArgs,
}

/// Runs `eenf reference`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    let params = a.tracker.params()?;
    let spin = progress.spinner("tracking the mains frequency");
    let started = std::time::Instant::now();
    let trace = audio_trace(
        &a.file,
        &a.audio.options(),
        &a.audio.hum(&a.tracker),
        a.tracker.nominal,
        &params,
    )?;
    spin.finish_and_clear();
    for w in &trace.warnings {
        eprintln!("warning: {w}");
    }
    a.out.save(&trace, &a.file)?;
    let finite: Vec<f64> = trace.finite().collect();
    let mean = finite.iter().sum::<f64>() / finite.len().max(1) as f64;
    let sd = (finite.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / finite.len().max(1) as f64)
        .sqrt();
    eprintln!(
        "{}: {} Hz grid, {} estimates, mean {mean:.5} Hz, std {:.2} mHz ({} peak) in {:.2} s",
        a.file.display(),
        trace.nominal_hz.unwrap_or(f64::NAN),
        trace.enf_hz.len(),
        sd * 1e3,
        params.peak,
        started.elapsed().as_secs_f64()
    );
    if let Some(lines) = trace.line_text() {
        eprintln!("{lines}");
    }
    if let Some(Provenance::Mains(MainsProvenance { hum: Some(h), .. })) = &trace.provenance {
        if let Some(note) = &h.window_note {
            eprintln!("note: {note}");
        }
        for flag in &h.plausibility.flags {
            eprintln!("warning: {}: {flag}", a.file.display());
        }
    }
    if let Some(&last) = trace.selected.last() {
        let mut taken: Vec<usize> = trace.selected.iter().map(|s| s.harmonic).collect();
        taken.dedup();
        eprintln!(
            "harmonics carrying the trace, segment by segment: {} (last: {} x f0)",
            taken
                .iter()
                .map(|m| format!("{m} x f0"))
                .collect::<Vec<_>>()
                .join(", "),
            last.harmonic
        );
    }
    a.out.report(&trace);
    a.out.print(&trace)
}
