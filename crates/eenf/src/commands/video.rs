//! `eenf video`: the V-ENF trace of a conventional (rolling-shutter) video.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use eenf_cli::output::{times, video_json, write_atomic, write_trace_csv};
use eenf_cli::progress::Progress;
use eenf_dsp::{EnfParams, PeakMethod};
use eenf_video::{
    video_enf, FrameSource, IdleRows, RowSampling, SceneRemoval, VideoOptions, VideoTrace,
};

/// Arguments of `eenf video`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The video: Y4M read natively, any other container through ffmpeg.
    pub file: PathBuf,
    /// Write the trace here: CSV (`time_s,enf_hz`), or JSON when the name ends in .json.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Print the trace and its metadata as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Grid frequency, 50 or 60 (default: detected from the flicker).
    #[arg(long)]
    pub nominal: Option<f64>,
    /// The sensor's readout time (first row to last row), ms: sets the idle rows.
    #[arg(long, conflicts_with_all = ["idle", "virtual_rows"])]
    pub readout_ms: Option<f64>,
    /// Idle rows: `auto` estimates them from the flicker's ripple within frames.
    #[arg(long, value_parser = ["auto"])]
    pub idle: Option<String>,
    /// Virtual rows per frame period (real plus idle), if known.
    #[arg(long, conflicts_with = "idle")]
    pub virtual_rows: Option<f64>,
    /// Row sampling: zero-pad (idle rows as zeros), naive (rows concatenated), global (one
    /// sample per frame, tracked at the alias of the flicker).
    #[arg(long, default_value = "zero-pad", value_parser = ["zero-pad", "naive", "global"])]
    pub sampling: String,
    /// Scene removal: paper (each frame minus the mean of it and the next), row-mean (each
    /// row minus its mean over a second), none.
    #[arg(long, default_value = "paper", value_parser = ["paper", "row-mean", "none"])]
    pub scene_removal: String,
    /// Peak refinement of the tracker: exact or paper.
    #[arg(long, default_value = "exact", value_parser = ["exact", "paper"])]
    pub peak: String,
    /// STFT window, s.
    #[arg(long, default_value_t = 16.0)]
    pub window: f64,
}

impl Args {
    /// The V-ENF options these arguments ask for.
    pub fn options(&self) -> Result<VideoOptions> {
        if let Some(n) = self.nominal {
            if n != 50.0 && n != 60.0 {
                bail!("--nominal must be 50 or 60, not {n}");
            }
        }
        let idle = match (self.readout_ms, self.virtual_rows) {
            (Some(ms), _) if ms > 0.0 => IdleRows::ReadoutS(ms / 1e3),
            (Some(ms), _) => bail!("--readout-ms must be positive, not {ms}"),
            (None, Some(l)) if l > 0.0 => IdleRows::VirtualRows(l),
            (None, Some(l)) => bail!("--virtual-rows must be positive, not {l}"),
            (None, None) => IdleRows::Auto,
        };
        let sampling = match self.sampling.as_str() {
            "naive" => RowSampling::Naive,
            "global" => RowSampling::Global,
            _ => RowSampling::ZeroPad(idle),
        };
        let params = EnfParams {
            nominal_hz: self.nominal.unwrap_or(50.0),
            window_s: self.window,
            peak: if self.peak == "paper" {
                PeakMethod::Paper
            } else {
                PeakMethod::Exact
            },
            ..EnfParams::default()
        };
        Ok(VideoOptions {
            nominal_hz: self.nominal,
            sampling,
            scene_removal: SceneRemoval::parse(&self.scene_removal).expect("checked by clap"),
            params,
        })
    }
}

/// Traces `file`; the progress bar counts frames.
pub fn trace_file(path: &Path, opts: &VideoOptions, progress: &Progress) -> Result<VideoTrace> {
    let mut source = FrameSource::open(path)?;
    let bar = progress.steps(0, "frames");
    let trace = video_enf(&mut source, opts, |n| bar.set_position(n))?;
    bar.finish_and_clear();
    Ok(trace)
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    let opts = a.options()?;
    let started = std::time::Instant::now();
    let t = trace_file(&a.file, &opts, &progress).map_err(|e| anyhow::anyhow!("{e}"))?;
    let took = started.elapsed().as_secs_f64();
    if let Some(out) = &a.output {
        let is_json = out.extension().and_then(|e| e.to_str()) == Some("json");
        write_atomic(out, |w| {
            if is_json {
                serde_json::to_writer_pretty(&mut *w, &video_json(&a.file, &t, &opts))?;
                writeln!(w)?;
                Ok(())
            } else {
                write_trace_csv(w, &times(t.enf_hz.len(), t.step_s), &t.enf_hz)
            }
        })?;
    }
    let n = t.enf_hz.len();
    let mean = t.enf_hz.iter().filter(|v| v.is_finite()).sum::<f64>() / n.max(1) as f64;
    let rows = t
        .virtual_rows
        .map(|l| format!(", {l:.1} virtual rows"))
        .unwrap_or_default();
    eprintln!(
        "{}: {} frames {}x{} at {:.3} fps{rows}, {} Hz grid, line {:.2} Hz ({:.0}x above the noise), {n} estimates (mean {mean:.4} Hz) in {took:.2} s",
        a.file.display(),
        t.frames,
        t.info.width,
        t.info.height,
        t.info.fps,
        t.nominal_hz,
        t.line_hz,
        t.prominence
    );
    if let Some(out) = &a.output {
        eprintln!("trace written to {}", out.display());
    }
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&video_json(&a.file, &t, &opts))?
        );
    } else if a.output.is_none() {
        let stdout = std::io::stdout();
        let mut lock = stdout.lock();
        write_trace_csv(&mut lock, &times(n, t.step_s), &t.enf_hz)?;
    }
    Ok(())
}
