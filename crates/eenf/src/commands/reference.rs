//! `eenf reference` (alias `audio`): the ENF of a mains recording or of any recording's sound.

use std::path::PathBuf;

use anyhow::Result;
use eenf::progress::Progress;
use eenf::reference::audio_trace;

use super::args::{TraceOutputArgs, TrackerArgs};

/// Arguments of `eenf reference`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The recording: a mains WAV, or any sound (WAV, FLAC, MP3, M4A/AAC, OGG, or a video's
    /// soundtrack through ffmpeg), at any sample rate.
    pub wav: PathBuf,
    /// The channel traced: `mix` (the mean of all) or a number from 0.
    #[arg(long, default_value = "mix")]
    pub channel: eenf::audio::Channel,
    /// Mains lines tracked: 1 tracks f0 alone (the method's reference tracker); N tracks f0 …
    /// N·f0 band by band and takes, per segment, the band the selection rule picks among those
    /// that stand above their noise (hum is often stronger at 2f0 or 3f0).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=8))]
    pub harmonics: u32,
    #[command(flatten)]
    pub out: TraceOutputArgs,
    #[command(flatten)]
    pub tracker: TrackerArgs,
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    let params = a.tracker.params()?;
    let spin = progress.spinner("tracking the mains frequency");
    let started = std::time::Instant::now();
    let audio = eenf::audio::AudioOptions {
        channel: a.channel,
        top_hz: None,
    };
    let trace = audio_trace(
        &a.wav,
        &audio,
        a.harmonics as usize,
        a.tracker.nominal,
        &params,
    )?;
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
    a.out.report();
    a.out.print(&trace)
}
