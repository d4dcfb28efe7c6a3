//! `eenf simulate`: an event recording of a flickering scene, with its ground truth.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use eenf_cli::dataset::recording_start;
use eenf_cli::progress::Progress;
use eenf_cli::refdb::{parse_time, tz_offset};
use eenf_cli::simulation::{write_recording, EnfTimeline, Simulated};
use eenf_cli::wav::is_wav;
use eenf_events::writers::OutputFormat;
use eenf_sim::{Lamp, Readout, SceneKind, SimConfig};

pub use eenf_cli::simulation::sibling;

use super::convert::{parse_codec, parse_format};

/// Arguments of `eenf simulate`.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Scene classes, comma-separated (mixes allowed): static, dynamic-object,
    /// dynamic-camera, extreme-dim, extreme-bright.
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
    /// Readout: dvxplorer (scans, shared timestamps, finite bandwidth) or prophesee (µs
    /// timestamps).
    #[arg(long, default_value = "dvxplorer")]
    pub readout: String,
    /// Overall light level (1 = indoor room); the scene classes set their own.
    #[arg(long)]
    pub illumination: Option<f64>,
    /// Share of non-flickering light (daylight), 0..1.
    #[arg(long)]
    pub ambient: Option<f64>,
    /// Local start time of the recording (names, timestamps; a WAV or CSV source named with
    /// its time sets it).
    #[arg(long, default_value = "2022-08-17T16:10:00+08:00")]
    pub start: String,
    /// Also write the hourly mains references (400 Hz WAVs named like the dataset's) that
    /// cover the recording into this folder.
    #[arg(long)]
    pub reference_dir: Option<PathBuf>,
    /// AEDAT4 packet compression: none, lz4, lz4_high, zstd, zstd_high.
    #[arg(long, default_value = "lz4")]
    pub compression: String,
    /// Output format: aedat4, evt2, evt3, dat, text (default: from the extension).
    #[arg(long)]
    pub format: Option<String>,
    #[command(flatten)]
    pub video: VideoArgs,
}

/// The conventional videos rendered beside a recording (shared by `simulate` and
/// `simulate-dataset`).
#[derive(Debug, Clone, clap::Args)]
pub struct VideoArgs {
    /// Also render the same scene through conventional cameras, comma-separated: `lr`
    /// (webcam, 640x480, 30 fps, anti-flicker exposure) and/or `hr` (phone, 1920x1080,
    /// ISO 1600, 1/200 s), written as NAME_lr.y4m / NAME_hr.y4m beside the recording.
    /// `hr@0.125` scales one camera's frame on its own.
    #[arg(long)]
    pub video: Option<String>,
    /// Scale the videos' frames by this factor (0..1], for speed.
    #[arg(long, default_value_t = 1.0)]
    pub video_scale: f64,
    /// Also encode each video as MP4 (H.264 at the camera's CRF: 28 webcam, 20 phone) with
    /// ffmpeg, as the cameras' own pipelines do.
    #[arg(long)]
    pub mp4: bool,
}

impl VideoArgs {
    /// The cameras asked for (none without `--video`).
    pub fn cameras(&self) -> Result<Vec<eenf_sim::CameraConfig>> {
        match &self.video {
            Some(list) => eenf_cli::simulation::parse_cameras(list, self.video_scale),
            None => Ok(Vec::new()),
        }
    }
}

impl Default for Args {
    fn default() -> Self {
        use clap::Parser;
        #[derive(clap::Parser)]
        struct Wrap {
            #[command(flatten)]
            args: Args,
        }
        Wrap::parse_from(["simulate"]).args
    }
}

/// WxH → (W, H).
pub fn parse_resolution(s: &str) -> Result<(u16, u16)> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .with_context(|| format!("--resolution {s:?}: expected WxH, e.g. 320x240"))?;
    let w: u16 = w
        .trim()
        .parse()
        .with_context(|| format!("--resolution {s:?}: bad width"))?;
    let h: u16 = h
        .trim()
        .parse()
        .with_context(|| format!("--resolution {s:?}: bad height"))?;
    if w == 0 || h == 0 || w > 4096 || h > 4096 {
        bail!("--resolution {s:?}: width and height must be 1..4096");
    }
    Ok((w, h))
}

/// `static,dynamic-object` → kinds.
pub fn parse_scene(s: &str) -> Result<Vec<SceneKind>> {
    s.split(',')
        .map(|k| {
            SceneKind::parse(k).with_context(|| {
                format!(
                    "--scene {k:?}: expected static, dynamic-object, dynamic-camera, extreme-dim \
                     or extreme-bright"
                )
            })
        })
        .collect()
}

/// `led,fluorescent@120` → lamps.
pub fn parse_lamps(s: &str) -> Result<Vec<Lamp>> {
    let lamps: Vec<Lamp> = s
        .split(',')
        .map(|l| {
            Lamp::parse(l).with_context(|| {
                format!(
                    "--lamp {l:?}: expected KIND[@PHASE_DEG][*SHARE] with KIND incandescent, \
                     fluorescent, led or sinusoid"
                )
            })
        })
        .collect::<Result<_>>()?;
    if lamps.len() > eenf_sim::MAX_LAMPS {
        bail!("--lamp: at most {} lamps", eenf_sim::MAX_LAMPS);
    }
    Ok(lamps)
}

/// The local start time (seconds) and UTC offset of `--start`.
fn local_start(a: &Args, source: Option<&Path>, source_start: f64) -> Result<(f64, f64)> {
    let tz_part = a
        .start
        .rfind(['+', 'Z'])
        .filter(|&i| i > 10)
        .or_else(|| a.start.rfind('-').filter(|&i| i > 10))
        .map(|i| &a.start[i..])
        .unwrap_or("Z");
    let tz = tz_offset(tz_part)?;
    // a source named like the dataset's hourly references fixes the time
    if let Some(t) = source.and_then(eenf_cli::dataset::reference_hour) {
        return Ok((t.local_seconds() as f64 + source_start, tz));
    }
    let utc = parse_time(&a.start).with_context(|| "--start")?;
    Ok((utc + tz, tz))
}

/// The timeline and the recording's local start.
fn timeline(a: &Args) -> Result<(EnfTimeline, f64, f64)> {
    if a.enf == "synthetic" {
        if a.grid != 50 && a.grid != 60 {
            bail!("--grid must be 50 or 60");
        }
        let (start, tz) = local_start(a, None, 0.0)?;
        let t = EnfTimeline::synthetic(a.grid as f64, start, start + a.duration, a.seed ^ 0x5eed);
        return Ok((t, start, tz));
    }
    // PATH[:START]; a colon followed by a number is the start second
    let (path, offset) = match a.enf.rsplit_once(':') {
        Some((p, s)) if s.parse::<f64>().is_ok() => (PathBuf::from(p), s.parse::<f64>()?),
        _ => (PathBuf::from(&a.enf), 0.0),
    };
    if !path.exists() {
        bail!("{}: no such file", path.display());
    }
    let (start, tz) = local_start(a, Some(&path), offset)?;
    let t0 = start - offset;
    let t = if is_wav(&path) {
        EnfTimeline::wav(&path, t0)?
    } else {
        EnfTimeline::trace(&path, a.enf_step, t0)?
    };
    Ok((t, start, tz))
}

/// The simulation configuration from the arguments.
pub fn config(a: &Args, start_utc_us: i64) -> Result<SimConfig> {
    if !(a.duration > 0.0 && a.duration <= 24.0 * 3600.0) {
        bail!("--duration must be between 0 and 86400 s");
    }
    let (width, height) = parse_resolution(&a.resolution)?;
    let readout = Readout::named(&a.readout)
        .with_context(|| format!("--readout {:?}: expected dvxplorer or prophesee", a.readout))?;
    let mut config = SimConfig {
        width,
        height,
        duration_s: a.duration,
        start_us: start_utc_us,
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
    config.check().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(config)
}

pub fn run(a: Args, progress: Progress) -> Result<Simulated> {
    let codec = parse_codec(&a.compression)?;
    let format = match &a.format {
        Some(f) => parse_format(f, codec)?,
        None => {
            OutputFormat::from_extension(&a.output, codec).unwrap_or(OutputFormat::Aedat4(codec))
        }
    };
    let (timeline, start, tz) = timeline(&a)?;
    let config = config(&a, ((start - tz) * 1e6).round() as i64)?;
    let mains = timeline.phase(start, a.duration)?;
    let extra = serde_json::json!({
        "enf": timeline.describe(),
        "local_start": start,
        "utc_offset_s": tz,
    });
    let cameras = a.video.cameras()?;
    let sim = write_recording(&config, &mains, &a.output, format, extra, &progress)?;
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
    for camera in &cameras {
        for p in eenf_cli::simulation::write_video(
            &config,
            camera,
            &mains,
            &a.output,
            a.video.mp4,
            &progress,
        )? {
            eprintln!("video      {}", p.display());
        }
    }
    if let Some(dir) = &a.reference_dir {
        let written = timeline.write_references(dir, start, start + a.duration, a.seed)?;
        for p in written {
            eprintln!("reference  {}", p.display());
        }
    }
    // a recording named like the dataset's must carry its own start time
    if let Some(t) = recording_start(&a.output) {
        if (t.local_seconds() as f64 - start.floor()).abs() > 0.5 {
            eprintln!(
                "note: the name says {}, the recording starts at local second {:.0} of the day",
                t.recording_name("…"),
                start.rem_euclid(86_400.0)
            );
        }
    }
    Ok(sim)
}
