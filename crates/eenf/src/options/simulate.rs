//! The options of the simulator: the scene, the sensor, the ENF, the outputs and the videos
//! rendered beside a recording.

use std::path::PathBuf;

use eenf_core::spelling::option;
use eenf_core::Grid;
use eenf_events::writers::OutputFormat;
use eenf_sim::{Lamp, Readout, SceneKind, SimConfig};
use serde_json::Value;

use super::{counted, limits, maybe, number, rule, switch, text, whole, within};
use super::{EventOutputSettings, OptionError, OptionSet};
use crate::simulation::{EnfSource, Recipe, DEFAULT_START};

/// The conventional videos rendered beside a simulated recording (`simulate`,
/// `simulate-dataset`).
#[derive(Debug, Clone)]
pub struct VideoRenderSettings {
    /// `video`: cameras, comma-separated (`lr`, `hr`, `hr@0.125`).
    pub video: Option<String>,
    /// `video_scale`: the scale of the videos' frames, (0, 1].
    pub video_scale: f64,
    /// `mp4`: also encode each video as MP4 with ffmpeg.
    pub mp4: bool,
}

impl Default for VideoRenderSettings {
    fn default() -> Self {
        VideoRenderSettings {
            video: None,
            video_scale: 1.0,
            mp4: false,
        }
    }
}

impl OptionSet for VideoRenderSettings {
    fn set(&mut self, name: &str, v: &Value) -> Result<bool, OptionError> {
        match name {
            "video" => self.video = maybe("video", v, text)?,
            "video_scale" => self.video_scale = number("video_scale", v)?,
            "mp4" => self.mp4 = switch("mp4", v)?,
            _ => return Ok(false),
        }
        Ok(true)
    }

    fn check(&self) -> Result<(), OptionError> {
        within("video_scale", self.video_scale, limits::VIDEO_SCALE)
    }
}

impl VideoRenderSettings {
    /// The cameras asked for (none without `video`).
    pub fn cameras(&self) -> Result<Vec<eenf_sim::CameraConfig>, OptionError> {
        match &self.video {
            Some(list) => crate::simulation::parse_cameras(list, self.video_scale),
            None => Ok(Vec::new()),
        }
    }
}

/// The options of one simulated recording (`simulate`).
#[derive(Debug, Clone)]
pub struct SimulateSettings {
    /// `scene`: scene classes, comma-separated.
    pub scene: String,
    /// `lamp`: lamps, comma-separated, each `KIND[@PHASE_DEG][*SHARE]`.
    pub lamp: String,
    /// `duration`: length of the recording, s.
    pub duration: f64,
    /// `enf`: `synthetic`, or a mains WAV or trace CSV, optionally `:START` seconds into it.
    pub enf: String,
    /// `index_step`: seconds between the values of an `index,value` trace CSV.
    pub index_step: f64,
    /// `grid`: the grid of a synthetic ENF, 50 or 60.
    pub grid: u32,
    /// `output`: the recording written.
    pub output: PathBuf,
    /// `resolution`: the sensor, `WxH`.
    pub resolution: String,
    /// `seed`: the random seed.
    pub seed: u64,
    /// `readout`: dvxplorer, prophesee or dvs128.
    pub readout: String,
    /// `illumination`: the overall light level (default: the scene class's).
    pub illumination: Option<f64>,
    /// `ambient`: the share of non-flickering light.
    pub ambient: Option<f64>,
    /// `spot_gain`: how much brighter the first lamp's pool or bulb is.
    pub spot_gain: Option<f64>,
    /// `noise_hz`: background events per pixel per second.
    pub noise_hz: Option<f64>,
    /// `start`: the local start time.
    pub start: String,
    /// `reference_dir`: also write the hourly mains references here.
    pub reference_dir: Option<PathBuf>,
    /// The recording's format.
    pub events: EventOutputSettings,
    /// Videos rendered beside it.
    pub video: VideoRenderSettings,
}

impl Default for SimulateSettings {
    fn default() -> Self {
        SimulateSettings {
            scene: "static".into(),
            lamp: "led".into(),
            duration: 60.0,
            enf: "synthetic".into(),
            index_step: 2.0,
            grid: 50,
            output: PathBuf::from("simulated.aedat4"),
            resolution: "64x48".into(),
            seed: 1,
            readout: "dvxplorer".into(),
            illumination: None,
            ambient: None,
            spot_gain: None,
            noise_hz: None,
            start: DEFAULT_START.into(),
            reference_dir: None,
            events: EventOutputSettings::default(),
            video: VideoRenderSettings::default(),
        }
    }
}

impl OptionSet for SimulateSettings {
    fn set(&mut self, name: &str, v: &Value) -> Result<bool, OptionError> {
        let path = |n, v| text(n, v).map(PathBuf::from);
        match name {
            "scene" => self.scene = text("scene", v)?,
            "lamp" => self.lamp = text("lamp", v)?,
            "duration" => self.duration = number("duration", v)?,
            "enf" => self.enf = text("enf", v)?,
            "index_step" | "enf_step" => self.index_step = number("index_step", v)?,
            "grid" => self.grid = whole("grid", v)?,
            "output" => self.output = path("output", v)?,
            "resolution" => self.resolution = text("resolution", v)?,
            "seed" => self.seed = whole("seed", v)?,
            "readout" => self.readout = text("readout", v)?,
            "illumination" => self.illumination = maybe("illumination", v, number)?,
            "ambient" => self.ambient = maybe("ambient", v, number)?,
            "spot_gain" => self.spot_gain = maybe("spot_gain", v, number)?,
            "noise_hz" => self.noise_hz = maybe("noise_hz", v, number)?,
            "start" => self.start = text("start", v)?,
            "reference_dir" => {
                self.reference_dir = match v {
                    Value::Null => None,
                    _ => Some(path("reference_dir", v)?),
                }
            }
            _ => return Ok(self.events.set(name, v)? || self.video.set(name, v)?),
        }
        Ok(true)
    }

    fn check(&self) -> Result<(), OptionError> {
        within("duration", self.duration, limits::DURATION_S)?;
        within("index_step", self.index_step, limits::INDEX_STEP_S)?;
        counted("grid", self.grid, limits::GRID_HZ)?;
        let optional = |name, v: Option<f64>, range| match v {
            Some(v) => within(name, v, range),
            None => Ok(()),
        };
        optional("illumination", self.illumination, limits::ILLUMINATION)?;
        optional("ambient", self.ambient, limits::AMBIENT)?;
        optional("spot_gain", self.spot_gain, limits::SPOT_GAIN)?;
        optional("noise_hz", self.noise_hz, limits::NOISE_HZ)?;
        self.events.check()?;
        self.video.check()
    }
}

impl SimulateSettings {
    /// The recipe these settings ask for.
    pub fn recipe(&self) -> Result<Recipe, OptionError> {
        self.check()?;
        let format = self.events.format_for(
            &self.output,
            Some(OutputFormat::Aedat4(self.events.compression)),
        )?;
        let enf = self.enf_source()?;
        Ok(Recipe {
            config: self.config()?,
            enf,
            start: self.start.clone(),
            output: self.output.clone(),
            format,
            cameras: self.video.cameras()?,
            mp4: self.video.mp4,
            reference_dir: self.reference_dir.clone(),
        })
    }

    /// The simulation configuration (its start is set from the timeline).
    fn config(&self) -> Result<SimConfig, OptionError> {
        let (width, height) = parse_resolution(&self.resolution)?;
        let readout = parse_readout(&self.readout)?;
        let mut config = SimConfig {
            width,
            height,
            duration_s: self.duration,
            seed: self.seed,
            lamps: parse_lamps(&self.lamp)?,
            readout,
            ..SimConfig::default()
        }
        .with_kinds(&parse_scene(&self.scene)?);
        if let Some(i) = self.illumination {
            config.illumination = i;
        }
        if let Some(x) = self.ambient {
            config.ambient = x;
        }
        if let Some(g) = self.spot_gain {
            let spot = |why: &str| rule("spot_gain", format!("{} {why}", option("spot_gain")));
            match config.scene.bulb.as_mut() {
                Some(b) if g > 0.0 => b.gain = g,
                Some(_) => return Err(spot("must be positive")),
                None => {
                    return Err(spot(
                        "needs a scene with a lamp in view (lamp-spot, extreme-bright)",
                    ))
                }
            }
        }
        if let Some(n) = self.noise_hz {
            config.pixel.shot_noise_hz = n;
            config.pixel.shot_noise_max_hz = config.pixel.shot_noise_max_hz.max(4.0 * n);
        }
        config.check().map_err(|e| rule("scene", e))?;
        Ok(config)
    }

    /// The ENF source named by `enf` (`synthetic`, or PATH[:START]: a colon followed by a
    /// number is the start second).
    fn enf_source(&self) -> Result<EnfSource, OptionError> {
        if self.enf == "synthetic" {
            return Ok(EnfSource::Synthetic(grid_of(self.grid)?));
        }
        let (path, offset_s) = match self.enf.rsplit_once(':') {
            Some((p, s)) => match s.parse::<f64>() {
                Ok(start) => (PathBuf::from(p), start),
                Err(_) => (PathBuf::from(&self.enf), 0.0),
            },
            None => (PathBuf::from(&self.enf), 0.0),
        };
        Ok(EnfSource::File {
            path,
            offset_s,
            index_step_s: self.index_step,
        })
    }
}

/// `WxH` → (W, H), each 1..4096.
pub fn parse_resolution(s: &str) -> Result<(u16, u16), OptionError> {
    let bad = |why: &str| {
        rule(
            "resolution",
            format!("{} {s:?}: {why}", option("resolution")),
        )
    };
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| bad("expected WxH, e.g. 320x240"))?;
    let w: u16 = w.trim().parse().map_err(|_| bad("bad width"))?;
    let h: u16 = h.trim().parse().map_err(|_| bad("bad height"))?;
    if w == 0 || h == 0 || w > 4096 || h > 4096 {
        return Err(bad("width and height must be 1..4096"));
    }
    Ok((w, h))
}

/// `static,dynamic-object` → scene kinds.
pub fn parse_scene(s: &str) -> Result<Vec<SceneKind>, OptionError> {
    s.split(',')
        .map(|k| {
            SceneKind::parse(k).ok_or_else(|| {
                rule(
                    "scene",
                    format!(
                        "{} {k:?}: expected static, dynamic-object, dynamic-camera, extreme-dim, \
                         extreme-bright or lamp-spot",
                        option("scene")
                    ),
                )
            })
        })
        .collect()
}

/// `led,fluorescent@120` → lamps (at most [`eenf_sim::MAX_LAMPS`]).
pub fn parse_lamps(s: &str) -> Result<Vec<Lamp>, OptionError> {
    let lamps: Vec<Lamp> = s
        .split(',')
        .map(|l| {
            Lamp::parse(l).ok_or_else(|| {
                rule(
                    "lamp",
                    format!(
                        "{} {l:?}: expected KIND[@PHASE_DEG][*SHARE] with KIND incandescent, \
                         fluorescent, led or sinusoid",
                        option("lamp")
                    ),
                )
            })
        })
        .collect::<Result<_, _>>()?;
    if lamps.len() > eenf_sim::MAX_LAMPS {
        return Err(rule(
            "lamp",
            format!("{}: at most {} lamps", option("lamp"), eenf_sim::MAX_LAMPS),
        ));
    }
    Ok(lamps)
}

/// `dvxplorer`, `prophesee` or `dvs128` → the sensor readout.
pub fn parse_readout(s: &str) -> Result<Readout, OptionError> {
    Readout::named(s).ok_or_else(|| {
        rule(
            "readout",
            format!(
                "{} {s:?}: expected dvxplorer, prophesee or dvs128",
                option("readout")
            ),
        )
    })
}

/// The options of a simulated dataset (`simulate-dataset`, Python's `simulate_dataset`).
#[derive(Debug, Clone)]
pub struct DatasetSettings {
    /// `preset`: `ev-enfd`, `small` or `lamp-spot`.
    pub preset: String,
    /// `enf_dir`: drive the recordings with these hourly mains WAVs (default: synthetic ENF).
    pub enf_dir: Option<PathBuf>,
    /// `grid`: the grid of a synthetic ENF, 50 or 60.
    pub grid: u32,
    /// `start`: the local date and hour where a synthetic dataset starts.
    pub start: String,
    /// `tz`: the UTC offset of the recordings' local names.
    pub tz: String,
    /// `resolution`: every recording's sensor, `WxH` (default: the preset's).
    pub resolution: Option<String>,
    /// `duration`: every recording's length, s (default: the preset's).
    pub duration: Option<f64>,
    /// `readout`: dvxplorer, prophesee or dvs128.
    pub readout: String,
    /// `compression`: AEDAT4 packet compression.
    pub compression: eenf_events::Compression,
    /// `seed`: the random seed of the whole dataset.
    pub seed: u64,
    /// Videos rendered beside each recording.
    pub video: VideoRenderSettings,
}

impl Default for DatasetSettings {
    fn default() -> Self {
        DatasetSettings {
            preset: "ev-enfd".into(),
            enf_dir: None,
            grid: 50,
            start: "2022-08-17T16".into(),
            tz: "+08:00".into(),
            resolution: None,
            duration: None,
            readout: "dvxplorer".into(),
            compression: eenf_events::Compression::Lz4,
            seed: 2023,
            video: VideoRenderSettings::default(),
        }
    }
}

impl OptionSet for DatasetSettings {
    fn set(&mut self, name: &str, v: &Value) -> Result<bool, OptionError> {
        match name {
            "preset" => self.preset = text("preset", v)?,
            "enf_dir" => self.enf_dir = maybe("enf_dir", v, text)?.map(PathBuf::from),
            "grid" => self.grid = whole("grid", v)?,
            "start" => self.start = text("start", v)?,
            "tz" => self.tz = text("tz", v)?,
            "resolution" => self.resolution = maybe("resolution", v, text)?,
            "duration" => self.duration = maybe("duration", v, number)?,
            "readout" => self.readout = text("readout", v)?,
            "compression" => self.compression = super::named("compression", v)?,
            "seed" => self.seed = whole("seed", v)?,
            _ => return self.video.set(name, v),
        }
        Ok(true)
    }

    fn check(&self) -> Result<(), OptionError> {
        counted("grid", self.grid, limits::GRID_HZ)?;
        if let Some(d) = self.duration {
            within("duration", d, limits::DURATION_S)?;
        }
        self.video.check()
    }
}

impl DatasetSettings {
    /// The build of a dataset into `out_dir`.
    pub fn build(&self, out_dir: PathBuf) -> crate::Result<crate::dataset_build::DatasetBuild> {
        use crate::dataset::DatasetSpec;
        use crate::dataset_build::{parse_local_hour, DatasetBuild, DatasetEnf};
        self.check()?;
        Ok(DatasetBuild {
            out_dir,
            spec: DatasetSpec {
                preset: self.preset.clone(),
                duration_s: self.duration,
                resolution: self
                    .resolution
                    .as_deref()
                    .map(parse_resolution)
                    .transpose()?,
                readout: parse_readout(&self.readout)?,
                tz_s: crate::time::tz_offset(&self.tz)?,
                seed: self.seed,
            },
            enf: match &self.enf_dir {
                Some(dir) => DatasetEnf::WavDir(dir.clone()),
                None => DatasetEnf::Synthetic {
                    grid: grid_of(self.grid)?,
                    from_local_s: parse_local_hour(&self.start)?,
                },
            },
            compression: self.compression,
            cameras: self.video.cameras()?,
            mp4: self.video.mp4,
        })
    }
}

/// The grid the option `grid` names: 50 or 60.
fn grid_of(hz: u32) -> Result<Grid, OptionError> {
    Grid::of_hz(f64::from(hz))
        .ok_or_else(|| rule("grid", format!("{} must be 50 or 60", option("grid"))))
}
