//! `eenf simulate`: an event recording of a flickering scene, with its ground truth.

use std::path::PathBuf;

use anyhow::{bail, Result};
use eenf::dataset::{recording_name, recording_start};
use eenf::progress::Progress;
use eenf::simulation::{simulate_recording, EnfSource, Recipe};
use eenf_events::writers::OutputFormat;
use eenf_sim::SimConfig;

use super::args::{
    parse_lamps, parse_readout, parse_resolution, parse_scene, EventOutputArgs, VideoArgs,
};

/// Arguments of `eenf simulate`.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Scene classes, comma-separated (mixes allowed): static, dynamic-object,
    /// dynamic-camera, extreme-dim, extreme-bright, lamp-spot (a daylit room where only a
    /// lamp's pool, ~5 % of the view, flickers, and a person walks by).
    #[arg(long, default_value = "static")]
    pub scene: String,
    /// Lamps, comma-separated (at most 3), each KIND[@PHASE_DEG][*SHARE] with KIND one of
    /// incandescent, fluorescent, led, sinusoid; e.g. `led,fluorescent@120`.
    #[arg(long, default_value = "led")]
    pub lamp: String,
    /// Length of the recording, s.
    #[arg(long, default_value_t = 60.0)]
    pub duration: f64,
    /// Where the ENF comes from: `synthetic` (a grid-like random process), a mains WAV or a
    /// trace CSV (`time_s,enf_hz`, or `index,value` at --enf-step), optionally with a start
    /// second (`ref.wav:600`).
    #[arg(long, default_value = "synthetic")]
    pub enf: String,
    /// Seconds between the values of an `index,value` trace CSV.
    #[arg(long, default_value_t = 2.0)]
    pub enf_step: f64,
    /// Grid frequency of a synthetic ENF: 50 or 60 (a WAV's or trace's own is detected).
    #[arg(long, default_value_t = 50)]
    pub grid: u32,
    /// Output recording; the format follows the extension (.aedat4, .raw = EVT 3.0, .dat,
    /// .txt) unless --format says. The truth goes beside it as NAME.truth.csv, every
    /// parameter as NAME.sim.json.
    #[arg(short, long, default_value = "simulated.aedat4")]
    pub output: PathBuf,
    /// Sensor resolution WxH.
    #[arg(long, default_value = "64x48")]
    pub resolution: String,
    /// Random seed (same seed, same recording).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Readout: dvxplorer (scans, shared timestamps, finite bandwidth), prophesee (µs
    /// timestamps) or dvs128 (an arbiter serving one event at a time, each with its own µs).
    #[arg(long, default_value = "dvxplorer")]
    pub readout: String,
    /// Overall light level (1 = indoor room); the scene classes set their own.
    #[arg(long)]
    pub illumination: Option<f64>,
    /// Share of non-flickering light (daylight), 0..1.
    #[arg(long)]
    pub ambient: Option<f64>,
    /// How much brighter the first lamp is inside its pool (`lamp-spot`) or bulb
    /// (`extreme-bright`) than elsewhere: sets how strongly those pixels flicker.
    #[arg(long)]
    pub spot_gain: Option<f64>,
    /// Background activity: each pixel's noise events per second under an indoor room's
    /// light (more in the dark), e.g. 0.5 for an old DVS128. Default: the simulator's 0.02.
    #[arg(long)]
    pub noise_hz: Option<f64>,
    /// Local start time of the recording (names, timestamps; a WAV or CSV source named with
    /// its time sets it).
    #[arg(long, default_value = eenf::simulation::DEFAULT_START)]
    pub start: String,
    /// Also write the hourly mains references (400 Hz WAVs named like the dataset's) that
    /// cover the recording into this folder.
    #[arg(long)]
    pub reference_dir: Option<PathBuf>,
    #[command(flatten)]
    pub events: EventOutputArgs,
    #[command(flatten)]
    pub video: VideoArgs,
}

/// The simulation configuration from the arguments (its start is set from the timeline).
fn config(a: &Args) -> Result<SimConfig> {
    if !(a.duration > 0.0 && a.duration <= 24.0 * 3600.0) {
        bail!("--duration must be between 0 and 86400 s");
    }
    let (width, height) = parse_resolution(&a.resolution)?;
    let readout = parse_readout(&a.readout)?;
    let mut config = SimConfig {
        width,
        height,
        duration_s: a.duration,
        seed: a.seed,
        lamps: parse_lamps(&a.lamp)?,
        readout,
        ..SimConfig::default()
    }
    .with_kinds(&parse_scene(&a.scene)?);
    if let Some(i) = a.illumination {
        config.illumination = i;
    }
    if let Some(x) = a.ambient {
        config.ambient = x;
    }
    if let Some(g) = a.spot_gain {
        match config.scene.bulb.as_mut() {
            Some(b) if g > 0.0 => b.gain = g,
            Some(_) => bail!("--spot-gain must be positive"),
            None => {
                bail!("--spot-gain needs a scene with a lamp in view (lamp-spot, extreme-bright)")
            }
        }
    }
    if let Some(n) = a.noise_hz {
        if !(n >= 0.0 && n.is_finite()) {
            bail!("--noise-hz must be zero or positive");
        }
        config.pixel.shot_noise_hz = n;
        config.pixel.shot_noise_max_hz = config.pixel.shot_noise_max_hz.max(4.0 * n);
    }
    config.check().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(config)
}

/// The ENF source named by `--enf` (`synthetic`, or PATH[:START]: a colon followed by a
/// number is the start second).
fn enf_source(a: &Args) -> Result<EnfSource> {
    if a.enf == "synthetic" {
        return Ok(EnfSource::Synthetic(a.grid as f64));
    }
    let (path, offset_s) = match a.enf.rsplit_once(':') {
        Some((p, s)) if s.parse::<f64>().is_ok() => (PathBuf::from(p), s.parse::<f64>()?),
        _ => (PathBuf::from(&a.enf), 0.0),
    };
    Ok(EnfSource::File {
        path,
        offset_s,
        index_step_s: a.enf_step,
    })
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    let format = a
        .events
        .format_for(&a.output, Some(OutputFormat::Aedat4(a.events.compression)))?;
    let enf = enf_source(&a)?;
    if let EnfSource::Synthetic(grid) = enf {
        if grid != 50.0 && grid != 60.0 {
            bail!("--grid must be 50 or 60");
        }
    }
    let recipe = Recipe {
        config: config(&a)?,
        enf,
        start: a.start.clone(),
        output: a.output.clone(),
        format,
        cameras: a.video.cameras()?,
        mp4: a.video.mp4,
        reference_dir: a.reference_dir.clone(),
    };
    let r = simulate_recording(&recipe, &progress)?;
    let (sim, config) = (&r.sim, &r.config);
    eprintln!(
        "simulated {:.0} s at {}x{}: {} events ({:.1} M events/s generated) in {:.1} s",
        a.duration,
        config.width,
        config.height,
        sim.stats.events,
        sim.stats.events as f64 / sim.seconds / 1e6,
        sim.seconds
    );
    if sim.stats.dropped_events + sim.stats.delayed_events > 0 {
        eprintln!(
            "readout: {} events delayed, {} dropped (bandwidth)",
            sim.stats.delayed_events, sim.stats.dropped_events
        );
    }
    eprintln!("recording  {}", a.output.display());
    eprintln!("truth      {}", sim.truth.display());
    for p in &r.videos {
        eprintln!("video      {}", p.display());
    }
    for p in &r.references {
        eprintln!("reference  {}", p.display());
    }
    // a recording named like the dataset's must carry its own start time
    if let Some(t) = recording_start(&a.output) {
        if (t.local_seconds() as f64 - r.local_start.floor()).abs() > 0.5 {
            eprintln!(
                "note: the name says {}, the recording starts at local second {:.0} of the day",
                recording_name(&t, "…"),
                r.local_start.rem_euclid(86_400.0)
            );
        }
    }
    Ok(())
}
