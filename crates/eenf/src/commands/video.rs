//! `eenf video`: the V-ENF trace of a conventional (rolling-shutter) video.

use std::path::PathBuf;

use anyhow::{bail, Result};
use eenf::progress::Progress;
use eenf::trace::Provenance;
use eenf_dsp::{EnfParams, PeakMethod};
use eenf_video::{IdleRows, RowSampling, SceneRemoval, VideoOptions};

use super::args::{one_of, TraceOutputArgs};

/// Arguments of `eenf video`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The video: Y4M read natively, any other container through ffmpeg.
    pub file: PathBuf,
    #[command(flatten)]
    pub out: TraceOutputArgs,
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
    #[arg(long, default_value = "zero-pad", value_parser = one_of::<RowSampling>(&RowSampling::NAMES))]
    pub sampling: RowSampling,
    /// Scene removal: paper (each frame minus the mean of it and the next), row-mean (each
    /// row minus its mean over a second), none.
    #[arg(long, default_value = "paper", value_parser = one_of::<SceneRemoval>(&SceneRemoval::NAMES))]
    pub scene_removal: SceneRemoval,
    /// Peak refinement of the tracker: exact or paper.
    #[arg(long, default_value = "exact", value_parser = one_of::<PeakMethod>(&PeakMethod::NAMES))]
    pub peak: PeakMethod,
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
        let sampling = match self.sampling {
            RowSampling::ZeroPad(_) => RowSampling::ZeroPad(idle),
            other => other,
        };
        let params = EnfParams {
            nominal_hz: self.nominal.unwrap_or(50.0),
            window_s: self.window,
            peak: self.peak,
            ..EnfParams::default()
        };
        Ok(VideoOptions {
            nominal_hz: self.nominal,
            sampling,
            scene_removal: self.scene_removal,
            params,
        })
    }
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    let opts = a.options()?;
    let started = std::time::Instant::now();
    let trace = eenf::video::trace_video(&a.file, &opts, &progress)?;
    let took = started.elapsed().as_secs_f64();
    a.out.save(&trace)?;
    if let Some(Provenance::Video(v)) = &trace.provenance {
        let rows = v
            .virtual_rows
            .map(|l| format!(", {l:.1} virtual rows"))
            .unwrap_or_default();
        eprintln!(
            "{}: {} frames {}x{} at {:.3} fps{rows}, {} Hz grid, line {:.2} Hz ({:.0}x above the noise), {} estimates (mean {:.4} Hz) in {took:.2} s",
            a.file.display(),
            v.frames,
            v.width,
            v.height,
            v.fps,
            trace.nominal_hz.unwrap_or(f64::NAN),
            v.line_hz,
            v.prominence,
            trace.enf_hz.len(),
            trace.mean_hz(),
        );
    }
    a.out.report();
    a.out.print(&trace)
}
