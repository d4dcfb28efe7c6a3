//! `eenf simulate-dataset`: a synthetic EV-ENFD, laid out like the paper's dataset.

use std::path::PathBuf;

use anyhow::Result;
use eenf::dataset::build_dataset;
use eenf::progress::Progress;
use eenf_events::Compression;

use crate::args::{one_of, VideoArgs};

/// Arguments of `eenf simulate-dataset`.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Folder to create: `static/`, `dynamic/`, `extreme/` with `dvSave-*.aedat4` recordings
    /// (and their `.truth.csv`, `.sim.json`, and with `--video` their `<stem>_lr.y4m` /
    /// `<stem>_hr.y4m`), `ENF_Reference/` with hourly WAVs,
    /// `manifest.csv` and `dataset.json`.
    pub out_dir: PathBuf,
    /// `ev-enfd`: 51 recordings of 180 s (16 static, 25 dynamic, 10 extreme, the paper's
    /// proportions); `small`: 9 recordings of 120 s (3 per class); `lamp-spot`: 80 recordings of
    /// 40 s (eight cameras, DVS128-like and Prophesee, ten each) where only a lamp's pool of
    /// light flickers.
    #[arg(long, default_value = "ev-enfd")]
    pub preset: String,
    /// Drive the recordings with these real mains WAVs (hourly files named like
    /// `2022_08_17_Wed_16_00_00.wav`), which become the references. Without it the ENF is
    /// synthetic and the references are synthesized.
    #[arg(long)]
    pub enf_dir: Option<PathBuf>,
    /// Grid of a synthetic ENF: 50 or 60.
    #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u32).range(50..=60))]
    pub grid: u32,
    /// Local date and hour where a synthetic dataset starts (six hours are covered).
    #[arg(long, default_value = "2022-08-17T16")]
    pub start: String,
    /// UTC offset of the recordings' local names (the dataset was recorded in Wuhan).
    #[arg(long, default_value = "+08:00", allow_hyphen_values = true)]
    pub tz: String,
    /// Sensor resolution of every recording (default: the preset's).
    #[arg(long)]
    pub resolution: Option<String>,
    /// Length of every recording, s (default: the preset's).
    #[arg(long, value_parser = crate::args::number_in(eenf::options::limits::DURATION_S))]
    pub duration: Option<f64>,
    /// Readout: dvxplorer, prophesee or dvs128 (the `lamp-spot` preset sets its own).
    #[arg(long, default_value = "dvxplorer")]
    pub readout: String,
    /// AEDAT4 packet compression.
    #[arg(long, default_value = "lz4", value_parser = one_of::<Compression>(&Compression::NAMES))]
    pub compression: Compression,
    /// Random seed of the whole dataset.
    #[arg(long, default_value_t = 2023)]
    pub seed: u64,
    #[command(flatten)]
    pub video: VideoArgs,
}

impl Args {
    /// The library's option set.
    pub fn settings(&self) -> eenf::options::DatasetSettings {
        eenf::options::DatasetSettings {
            preset: self.preset.clone(),
            enf_dir: self.enf_dir.clone(),
            grid: self.grid,
            start: self.start.clone(),
            tz: self.tz.clone(),
            resolution: self.resolution.clone(),
            duration: self.duration,
            readout: self.readout.clone(),
            compression: self.compression,
            seed: self.seed,
            video: self.video.settings(),
        }
    }
}

/// Runs `eenf simulate-dataset`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    let build = a.settings().build(a.out_dir.clone())?;
    let built = build_dataset(&build, &progress, &mut |note| eprintln!("{note}"))?;
    eprintln!(
        "{} recordings ({} events, {:.1} M events/s) in {:.0} s -> {}",
        built.recordings,
        built.events,
        built.events as f64 / built.seconds / 1e6,
        built.seconds,
        a.out_dir.display()
    );
    // the names carry local times without their zone, as the data set's do: say which
    eprintln!(
        "file names are in local time at UTC{} (--tz; give the same to `match` and `refdb build`)",
        a.tz
    );
    Ok(())
}
