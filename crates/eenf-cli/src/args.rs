//! The command line's option sets (flags shared by several commands, and those the Python
//! package takes as keyword arguments), parsed into the library's types. Option names come from
//! the library enums' `FromStr`/`Display` (their `NAMES` list the values `--help` shows).

use std::path::PathBuf;
use std::str::FromStr;

use anyhow::{bail, Context, Result};
use clap::builder::{PossibleValuesParser, TypedValueParser};
use eenf::archive::{ArchiveFormat, ArchiveOptions, DateOrder, ValueUnit};
use eenf::edits::{EditInput, EditOptions, EditParams};
use eenf::extract::ExtractOptions;
use eenf::simulation::{EnfSource, Recipe};
use eenf::time::Zone;
use eenf_core::{defaults, Nominal};
use eenf_dsp::{EnfParams, HarmonicSelection, PeakMethod, SamplingMethod};
use eenf_events::writers::OutputFormat;
use eenf_events::Compression;
use eenf_sim::SimConfig;
use eenf_sim::{Lamp, SceneKind};
use eenf_video::{IdleRows, RowSampling, SceneRemoval, VideoOptions};

/// A clap parser for a library enum: one of `names`, parsed by the enum's `FromStr`.
pub fn one_of<T>(names: &'static [&'static str]) -> impl TypedValueParser<Value = T>
where
    T: FromStr<Err = String> + Clone + Send + Sync + 'static,
{
    PossibleValuesParser::new(names).try_map(|s| s.parse::<T>())
}

/// A number in `lo..=hi`, for flags read from the user: anything else (NaN, inf, out of range)
/// is a one-line error naming the range, before any work or allocation is sized by it.
pub fn number_in(lo: f64, hi: f64) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync {
    move |s: &str| {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| format!("{s:?} is not a number"))?;
        if v.is_finite() && (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            Err(format!("{s} is outside {lo}..={hi}"))
        }
    }
}

/// A whole number in `lo..=hi` (see [`number_in`]).
pub fn count_in(
    lo: usize,
    hi: usize,
) -> impl Fn(&str) -> Result<usize, String> + Clone + Send + Sync {
    move |s: &str| {
        let v: usize = s
            .trim()
            .parse()
            .map_err(|_| format!("{s:?} is not a whole number in {lo}..={hi}"))?;
        if (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            Err(format!("{s} is outside {lo}..={hi}"))
        }
    }
}

/// Tracker flags (shared by `extract`, `reference` and `bench`).
#[derive(Debug, Clone, clap::Args)]
pub struct TrackerArgs {
    /// Nominal grid frequency: 50, 60, or auto (detected from the spectrum).
    #[arg(long, default_value = "auto")]
    pub nominal: Nominal,
    /// Peak refinement of each STFT window: exact (maximise the window's DTFT magnitude,
    /// unbiased) or paper (zero-padded FFT, 0.005 Hz bins, and complex quadratic
    /// interpolation).
    #[arg(long, default_value = "exact", value_parser = one_of::<PeakMethod>(&PeakMethod::NAMES))]
    pub peak: PeakMethod,
    /// STFT window length, s. Default: 16 (the paper's); a recording shorter than that is
    /// traced with a window that fits it, and `audio` lengthens it for weak hum.
    #[arg(long, value_parser = number_in(0.01, 3600.0))]
    pub window: Option<f64>,
    /// STFT step, s (one estimate per step).
    #[arg(long, default_value_t = defaults::STEP_S, value_parser = number_in(0.001, 3600.0))]
    pub step: f64,
    /// Half width of the search band (and band-pass) around each line, Hz.
    #[arg(long, default_value_t = defaults::HALF_BAND_HZ, value_parser = number_in(0.01, 20.0))]
    pub half_band: f64,
}

/// Event-method flags (`extract`, `bench`).
#[derive(Debug, Clone, clap::Args)]
pub struct MethodArgs {
    /// The tracker's flags.
    #[command(flatten)]
    pub tracker: TrackerArgs,
    /// Temporal sampling: auto (paper when events come in scan groups that share a timestamp,
    /// as a DVXplorer's; block when each event has its own, as DVS128, DAVIS and Prophesee
    /// sensors stamp them), paper (events at the smallest timestamp ≥ t_n), authors (the group
    /// at the largest timestamp in [t_n, t_n + Δt), previous sample when empty), block (vote
    /// over all events in [t_n, t_n + Δt), the journal version), sum (ON − OFF count of all
    /// events in [t_n, t_n + Δt)).
    #[arg(long, default_value = "auto", value_parser = one_of::<SamplingMethod>(&SamplingMethod::NAMES))]
    pub sampling: SamplingMethod,
    /// Sampling interval Δt, µs. Default: the paper's 1000 for scan groups (paper, authors),
    /// 100 for the vote or sum over per-event stamps (block, sum), whose flicker harmonics
    /// would alias at 1 ms.
    #[arg(long, value_parser = clap::value_parser!(i64).range(10..=1_000_000))]
    pub dt_us: Option<i64>,
    /// Number of flicker harmonics M (bands at 2m·f0, m = 1..M; those above Nyquist skipped).
    #[arg(long, default_value_t = defaults::HARMONICS as u32, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub harmonics: u32,
    /// Butterworth order of the band-pass prototype.
    #[arg(long, default_value_t = defaults::FILTER_ORDER as u32, value_parser = clap::value_parser!(u32).range(1..=8))]
    pub filter_order: u32,
    /// Running-median length of the outlier correction (0 or 1 disables it).
    #[arg(long, default_value_t = defaults::MEDIAN_LEN, value_parser = count_in(0, 10_001))]
    pub median_len: usize,
    /// Outlier threshold on the 2f0 scale, Hz.
    #[arg(long, default_value_t = defaults::MEDIAN_THRESHOLD_HZ, value_parser = number_in(0.0, 10.0))]
    pub median_threshold: f64,
    /// Harmonic-selection segment length, in estimates.
    #[arg(long, default_value_t = defaults::SEGMENT_LEN, value_parser = count_in(1, 100_000))]
    pub segment: usize,
    /// Harmonic-selection rule: consensus (the smoothest among harmonics that agree with
    /// another one, within --agree-hz), smoothest (the paper: the smoothest harmonic trace per
    /// segment), journal (follow the 2f0 band; where it jumps by more than --jump-hz or is
    /// missing, take the harmonic that continues the trace best). A band whose line stands less
    /// than 12 dB above its noise is not taken where another's does.
    #[arg(long, default_value = "consensus", value_parser = one_of::<HarmonicSelection>(&HarmonicSelection::NAMES))]
    pub selection: HarmonicSelection,
    /// Largest step of the journal rule's 2f0 trace between estimates, Hz (on the ENF scale).
    #[arg(long, default_value_t = HarmonicSelection::DEFAULT_JUMP_HZ, value_parser = number_in(0.0, 10.0))]
    pub jump_hz: f64,
    /// Agreement tolerance of the consensus rule, Hz (on the ENF scale).
    #[arg(long, default_value_t = HarmonicSelection::DEFAULT_AGREE_HZ, value_parser = number_in(0.0, 10.0))]
    pub agree_hz: f64,
    /// Trace every pixel. By default, when events are stamped one by one (DVS128, DAVIS,
    /// Prophesee), only the tiles of pixels whose flicker stands out are traced (the
    /// `flicker-map`'s), so that motion and noise elsewhere drop out.
    #[arg(long)]
    pub all_pixels: bool,
    /// How the file is read.
    #[command(flatten)]
    pub input: InputArgs,
}

/// How to read files that leave something open (`info`, `extract`, `convert`, `bench`).
#[derive(Debug, Clone, clap::Args)]
pub struct InputArgs {
    /// The chip of a jAER AEDAT 2.0 file: DVS128, DAVIS240, DAVIS346, DAVIS640 (default: the
    /// header's `# AEChip:` line, else inferred from the addresses).
    #[arg(long)]
    pub chip: Option<String>,
    /// The camera to read in a file with several (a jAER stereo pair: 0 or 1). Default:
    /// `extract` takes the one whose flicker stands highest; `info` and `convert` read all.
    #[arg(long)]
    pub camera: Option<u8>,
    /// Refuse a damaged or cut-short file, or one whose time jumps by more than --max-gap.
    /// Default: read the events before the damage, with a warning that says where it is.
    #[arg(long)]
    pub strict: bool,
    /// The largest step of the event time between two events, seconds, forwards or
    /// backwards: a larger one (a corrupt timestamp) ends the usable stream there.
    #[arg(long, default_value_t = eenf_events::DEFAULT_MAX_GAP_US as f64 * 1e-6)]
    pub max_gap: f64,
    /// The topic to read in a ROS 1 bag or a rosbag2 (default: the first topic of event
    /// messages; `info` lists them all).
    #[arg(long)]
    pub topic: Option<String>,
}

impl InputArgs {
    /// The reader options.
    pub fn options(&self) -> eenf_events::OpenOptions {
        eenf_events::OpenOptions {
            chip: self.chip.clone(),
            camera: self.camera,
            strict: self.strict,
            // NaN and negatives: no step is allowed; huge values: any is
            max_gap_us: Some((self.max_gap * 1e6).clamp(0.0, i64::MAX as f64) as i64),
            topic: self.topic.clone(),
        }
    }
}

impl TrackerArgs {
    /// The tracker part of the parameters.
    pub fn params(&self) -> Result<EnfParams> {
        let window = self.window.unwrap_or(EnfParams::default().window_s);
        if !(window > 0.0 && self.step > 0.0 && self.half_band > 0.0) {
            bail!("--window, --step and --half-band must be positive");
        }
        Ok(EnfParams {
            peak: self.peak,
            window_s: window,
            step_s: self.step,
            half_band_hz: self.half_band,
            ..EnfParams::default()
        })
    }
}

impl MethodArgs {
    /// The options of the extraction.
    pub fn options(&self) -> Result<ExtractOptions> {
        let mut params = self.tracker.params()?;
        params.harmonics = self.harmonics as usize;
        params.filter_order = self.filter_order as usize;
        params.median_len = self.median_len;
        params.median_threshold_hz = self.median_threshold;
        params.segment_len = self.segment.max(1);
        params.selection = match self.selection {
            HarmonicSelection::Consensus(_) => HarmonicSelection::Consensus(self.agree_hz),
            HarmonicSelection::Journal(_) => HarmonicSelection::Journal(self.jump_hz),
            other => other,
        };
        Ok(ExtractOptions {
            sampling: self.sampling,
            dt_us: self.dt_us,
            nominal: self.tracker.nominal,
            params,
            open: self.input.options(),
            flicker_tiles: !self.all_pixels,
        })
    }
}

/// Event-file output flags (`convert`, `simulate`).
#[derive(Debug, Clone, clap::Args)]
pub struct EventOutputArgs {
    /// Output format: aedat4, evt2, evt3, dat, text (default: from the output's extension:
    /// .aedat4, .raw = evt3, .dat, .txt/.csv).
    #[arg(long, value_parser = one_of::<OutputFormat>(&OutputFormat::NAMES))]
    pub format: Option<OutputFormat>,
    /// AEDAT4 packet compression: none, lz4, lz4_high, zstd, zstd_high.
    #[arg(long, default_value = "lz4", value_parser = one_of::<Compression>(&Compression::NAMES))]
    pub compression: Compression,
}

impl EventOutputArgs {
    /// The format for `path`: `--format`, else its extension, else `fallback`.
    pub fn format_for(
        &self,
        path: &std::path::Path,
        fallback: Option<OutputFormat>,
    ) -> Result<OutputFormat> {
        let f = match self.format {
            Some(f) => f,
            None => OutputFormat::from_extension(path, self.compression)
                .or(fallback)
                .with_context(|| {
                    format!(
                        "{}: cannot tell the output format from the name; pass --format aedat4|evt2|evt3|dat|text",
                        path.display()
                    )
                })?,
        };
        Ok(f.with_compression(self.compression))
    }
}

/// The conventional videos rendered beside a simulated recording (`simulate`,
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
    #[arg(long, default_value_t = 1.0, value_parser = number_in(0.001, 1.0))]
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
            Some(list) => eenf::simulation::parse_cameras(list, self.video_scale),
            None => Ok(Vec::new()),
        }
    }
}

/// Where a trace or report goes: a file (`-o`), JSON on stdout, and/or a figure (`--plot`).
#[derive(Debug, Clone, clap::Args)]
pub struct TraceOutputArgs {
    /// Write the trace here: CSV (`time_s,enf_hz`), or JSON when the name ends in .json.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Print the trace and its metadata as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Plot the trace and each band's estimate, with the band taken (.png or .svg).
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

impl TraceOutputArgs {
    /// Writes the trace file and the figure, if they were asked for (`source`: the recording,
    /// named in the figure's title).
    pub fn save(&self, trace: &eenf::trace::Trace, source: &std::path::Path) -> Result<()> {
        if let Some(out) = &self.output {
            eenf::output::write_atomic(out, |w| trace.write_for(out, w))?;
        }
        if let Some(p) = &self.plot {
            let title = format!(
                "{}: ENF, and each band's estimate (the band taken per {} s below)",
                eenf_figures::title_name(source),
                trace.segment_s().unwrap_or(0.0)
            );
            eenf_figures::plot_extraction(p, &title, trace)?;
        }
        Ok(())
    }

    /// Prints the trace on stdout: JSON with `--json`, else CSV unless it went to a file.
    pub fn print(&self, trace: &eenf::trace::Trace) -> Result<()> {
        let stdout = std::io::stdout();
        let mut lock = stdout.lock();
        if self.json {
            trace.write_json(&mut lock)
        } else if self.output.is_none() {
            trace.write_csv(&mut lock)
        } else {
            Ok(())
        }
    }

    /// Says where the trace and the figure went, and which of the trace's estimates stand at
    /// the noise level (stderr).
    pub fn report(&self, trace: &eenf::trace::Trace) {
        if let Some(note) = trace.noise_note() {
            eprintln!("warning: {note}");
        }
        if let Some(out) = self.output.as_ref().filter(|o| !eenf::output::is_stdout(o)) {
            crate::terminal::announce("trace", out);
        }
        if let Some(p) = &self.plot {
            crate::terminal::announce("plot", p);
        }
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
                    "--scene {k:?}: expected static, dynamic-object, dynamic-camera, extreme-dim, \
                     extreme-bright or lamp-spot"
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

/// `--readout` → the sensor readout.
pub fn parse_readout(s: &str) -> Result<eenf_sim::Readout> {
    eenf_sim::Readout::named(s)
        .with_context(|| format!("--readout {s:?}: expected dvxplorer, prophesee or dvs128"))
}

/// How a recording's sound is read and tracked (`reference`).
#[derive(Debug, Clone, clap::Args)]
pub struct AudioArgs {
    /// The channel traced: `mix` (the mean of all) or a number from 0.
    #[arg(long, default_value = "mix")]
    pub channel: eenf::audio::Channel,
    /// Mains lines tracked: auto (every harmonic of 50 and 60 Hz up to 8·f0 is looked for;
    /// f0 alone is tracked when it carries the ENF clearly, else every harmonic that stands
    /// above its noise, band by band, the selection rule picking per segment); 1 tracks f0
    /// alone (the method's reference tracker); N tracks f0 … N·f0.
    #[arg(long, default_value = "auto")]
    pub harmonics: eenf::mains::MainsLines,
}

impl AudioArgs {
    /// How the hum is traced: these lines, and the tracker's `--window` if one was given.
    pub fn hum(&self, tracker: &TrackerArgs) -> eenf::mains::HumOptions {
        eenf::mains::HumOptions {
            lines: self.harmonics,
            window_s: tracker.window,
        }
    }

    /// The reading options (the rate follows from the harmonics tracked).
    pub fn options(&self) -> eenf::audio::AudioOptions {
        eenf::audio::AudioOptions {
            channel: self.channel,
            top_hz: None,
        }
    }
}

/// V-ENF flags (`video`).
#[derive(Debug, Clone, clap::Args)]
pub struct VideoMethodArgs {
    /// Nominal grid frequency: 50, 60, or auto (detected from the flicker).
    #[arg(long, default_value = "auto")]
    pub nominal: Nominal,
    /// The sensor's readout time (first row to last row), ms: sets the idle rows.
    #[arg(long, conflicts_with_all = ["idle", "virtual_rows"], value_parser = number_in(0.0, 1000.0))]
    pub readout_ms: Option<f64>,
    /// Idle rows: `auto` estimates them from the flicker's ripple within frames.
    #[arg(long, value_parser = ["auto"])]
    pub idle: Option<String>,
    /// Virtual rows per frame period (real plus idle), if known.
    #[arg(long, conflicts_with = "idle", value_parser = number_in(0.0, 100_000.0))]
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
    #[arg(long, default_value_t = defaults::WINDOW_S, value_parser = number_in(0.01, 3600.0))]
    pub window: f64,
}

impl VideoMethodArgs {
    /// The V-ENF options these arguments ask for.
    pub fn options(&self) -> Result<VideoOptions> {
        let nominal_hz = match self.nominal {
            Nominal::Hz(f) => Some(f),
            Nominal::Auto => None,
        };
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
            nominal_hz: nominal_hz.unwrap_or(50.0),
            window_s: self.window,
            peak: self.peak,
            ..EnfParams::default()
        };
        Ok(VideoOptions {
            nominal_hz,
            sampling,
            scene_removal: self.scene_removal,
            params,
        })
    }
}

/// Simulation flags (`simulate`): the scene, the sensor, the ENF, the outputs.
#[derive(Debug, Clone, clap::Args)]
pub struct SimulateArgs {
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
    #[arg(long, default_value_t = 60.0, value_parser = number_in(0.01, 86_400.0))]
    pub duration: f64,
    /// Where the ENF comes from: `synthetic` (a grid-like random process), a mains WAV or a
    /// trace CSV (`time_s,enf_hz`, or `index,value` at --index-step), optionally with a start
    /// second (`ref.wav:600`).
    #[arg(long, default_value = "synthetic")]
    pub enf: String,
    /// Seconds between the values of an `index,value` trace CSV.
    #[arg(long, alias = "enf-step", default_value_t = 2.0, value_parser = number_in(0.001, 3600.0))]
    pub index_step: f64,
    /// Grid frequency of a synthetic ENF: 50 or 60 (a WAV's or trace's own is detected).
    #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u32).range(50..=60))]
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
    #[arg(long, value_parser = number_in(0.0, 1e6))]
    pub illumination: Option<f64>,
    /// Share of non-flickering light (daylight), 0..1.
    #[arg(long, value_parser = number_in(0.0, 1.0))]
    pub ambient: Option<f64>,
    /// How much brighter the first lamp is inside its pool (`lamp-spot`) or bulb
    /// (`extreme-bright`) than elsewhere: sets how strongly those pixels flicker.
    #[arg(long, value_parser = number_in(0.0, 1e6))]
    pub spot_gain: Option<f64>,
    /// Background activity: each pixel's noise events per second under an indoor room's
    /// light (more in the dark), e.g. 0.5 for an old DVS128. Default: the simulator's 0.02.
    #[arg(long, value_parser = number_in(0.0, 10_000.0))]
    pub noise_hz: Option<f64>,
    /// Local start time of the recording (names, timestamps; a WAV or CSV source named with
    /// its time sets it).
    #[arg(long, default_value = eenf::simulation::DEFAULT_START)]
    pub start: String,
    /// Also write the hourly mains references (400 Hz WAVs named like the dataset's) that
    /// cover the recording into this folder.
    #[arg(long)]
    pub reference_dir: Option<PathBuf>,
    /// The recording's format.
    #[command(flatten)]
    pub events: EventOutputArgs,
    /// Videos rendered beside it.
    #[command(flatten)]
    pub video: VideoArgs,
}

/// The simulation configuration from the arguments (its start is set from the timeline).
fn config(a: &SimulateArgs) -> Result<SimConfig> {
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
fn enf_source(a: &SimulateArgs) -> Result<EnfSource> {
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
        index_step_s: a.index_step,
    })
}

impl SimulateArgs {
    /// The recipe these flags ask for.
    pub fn recipe(&self) -> Result<Recipe> {
        let a = self;
        let format = a
            .events
            .format_for(&a.output, Some(OutputFormat::Aedat4(a.events.compression)))?;
        let enf = enf_source(a)?;
        if let EnfSource::Synthetic(grid) = enf {
            if grid != 50.0 && grid != 60.0 {
                bail!("--grid must be 50 or 60");
            }
        }
        Ok(Recipe {
            config: config(a)?,
            enf,
            start: a.start.clone(),
            output: a.output.clone(),
            format,
            cameras: a.video.cameras()?,
            mp4: a.video.mp4,
            reference_dir: a.reference_dir.clone(),
        })
    }
}

/// Search flags (`match`).
#[derive(Debug, Clone, clap::Args)]
pub struct MatchArgs {
    /// Candidates to list.
    #[arg(long, default_value_t = 5, value_parser = count_in(1, 10_000))]
    pub top: usize,
    /// Check a claimed start time (e.g. 2022-08-17T16:10:00+08:00): its score, rank and
    /// significance.
    #[arg(long)]
    pub verify: Option<String>,
    /// Ranking score: `combined` (shape and level) or `cc` (shape only, robust to a bias).
    #[arg(long, default_value = "combined", value_parser = one_of::<eenf_dsp::matching::Score>(&eenf_dsp::matching::Score::NAMES))]
    pub score: eenf_dsp::matching::Score,
    /// A candidate is a match when its p-value is below this.
    #[arg(long, default_value_t = eenf_dsp::matching::DEFAULT_ALPHA, value_parser = number_in(1e-300, 1.0))]
    pub alpha: f64,
    /// Zone of the local times in hourly WAV names and grid archives: an IANA name
    /// (Europe/Berlin, Asia/Shanghai; summer time followed) or a UTC offset (+08:00, Z); also
    /// the zone results are shown in beside UTC. Local times need it: none is assumed.
    #[arg(long, allow_hyphen_values = true)]
    pub tz: Option<Zone>,
}

impl MatchArgs {
    /// What the search asks for.
    pub fn query(&self) -> eenf::locate::MatchQuery {
        eenf::locate::MatchQuery {
            top: self.top,
            score: self.score,
            verify: self.verify.clone(),
            alpha: self.alpha,
        }
    }
}

/// How `edits` tests a recording (also the Python package's `edits` keywords).
#[derive(Debug, Clone, clap::Args)]
pub struct EditArgs {
    /// Nominal grid frequency: 50, 60, or auto (from the hum).
    #[arg(long, default_value = "auto")]
    pub nominal: Nominal,
    /// The longest stretch whose phase is fitted on each side of a boundary, s: each recording
    /// is tested at the side up to this (2, 3, 5 or 10 s) whose smallest detectable jump is
    /// smallest, given its noise and the real grid's stray at that side.
    #[arg(long, default_value_t = EditParams::default().side_s, value_parser = number_in(1.0, 600.0))]
    pub side: f64,
    /// The shortest stretch between two edits told apart, s (also the shortest side fitted:
    /// the first and last this much of a recording are not tested).
    #[arg(long, default_value_t = EditParams::default().min_gap_s, value_parser = number_in(0.3, 600.0))]
    pub min_gap: f64,
    /// False alarms allowed per hour of unedited recording: sets the phase test's threshold
    /// from the noise measured in the recording and the real grid's own phase stray, measured
    /// on 24 continuous hours of real mains (0 findings there at the default 0.05, 95 % upper
    /// bound 0.12 per hour; in a phone's noise 3 in 130 hours of clips of them).
    #[arg(long, default_value_t = EditParams::default().false_alarms_per_hour, value_parser = number_in(1e-9, 100.0))]
    pub false_alarms: f64,
    /// Report stretches where a phase jump this large (degrees of the lowest line) would go
    /// unseen as too weak to tell.
    #[arg(long, default_value_t = EditParams::default().weak_jump_deg, value_parser = number_in(1.0, 180.0))]
    pub weak_jump: f64,
    /// A frequency step is reported when it stands this many robust standard deviations of
    /// the recording's own steps.
    #[arg(long, default_value_t = EditParams::default().frequency_step_z, value_parser = number_in(1.0, 1000.0))]
    pub step_z: f64,
    /// The channel of a sound: `mix` (the mean of all) or a number from 0.
    #[arg(long, default_value = "mix")]
    pub channel: eenf::audio::Channel,
    /// Seconds between the values of an `index,value` trace CSV (a grid archive's day of
    /// values, for instance); a `time_s,enf_hz` CSV or eenf JSON carries its own times.
    #[arg(long, value_parser = number_in(0.001, 3600.0))]
    pub index_step: Option<f64>,
    /// What the file is: auto (an event file when its content says so, a trace when its
    /// name ends in .csv or .json, else sound), audio, events, or trace.
    #[arg(long, default_value = "auto", value_parser = one_of::<EditInput>(&EditInput::NAMES))]
    pub kind: EditInput,
    /// How an event file is read.
    #[command(flatten)]
    pub input: InputArgs,
}

impl EditArgs {
    /// The test's parameters.
    pub fn params(&self) -> EditParams {
        EditParams {
            side_s: self.side,
            min_gap_s: self.min_gap.min(self.side),
            false_alarms_per_hour: self.false_alarms,
            weak_jump_deg: self.weak_jump,
            frequency_step_z: self.step_z,
        }
    }

    /// Everything `edits` needs: the test, the grid, how sound and events are read.
    pub fn options(&self) -> EditOptions {
        EditOptions {
            params: self.params(),
            input: self.kind,
            index_step_s: self.index_step,
            audio: eenf::audio::AudioOptions {
                channel: self.channel,
                top_hz: None,
            },
            extract: ExtractOptions {
                nominal: self.nominal,
                open: self.input.options(),
                ..ExtractOptions::default()
            },
        }
    }
}

/// How `refdb build` reads its inputs and where their values go (also the Python package's
/// `refdb_build` keywords).
#[derive(Debug, Clone, clap::Args)]
pub struct StoreInputArgs {
    /// Grid name (default: `grid50` or `grid60` from the data).
    #[arg(long)]
    pub grid: Option<String>,
    /// Zone of local times (in WAV names and in archives whose times carry none): an IANA
    /// name (Europe/Berlin, America/New_York; summer time followed) or a UTC offset (+08:00,
    /// Z). Local times need it: none is assumed.
    #[arg(long, allow_hyphen_values = true)]
    pub tz: Option<Zone>,
    /// Layout of grid archives: auto (sniffed from the header and first rows), ngeso (UK,
    /// `dtm,f`, UTC), fingrid (Finland, `Time,Value`, 0.1 s), transnetbw (Germany,
    /// `DD.MM.YYYY HH:MM:SS`), osf (`year;month;day;hour;minute;second;value`, UTC).
    #[arg(long, default_value = "auto", value_parser = one_of::<ArchiveFormat>(&ArchiveFormat::NAMES))]
    pub format: ArchiveFormat,
    /// What an archive's value column holds: auto (Hz when near 50 or 60; a deviation when
    /// the header says so), hz, mhz-deviation or hz-deviation.
    #[arg(long, default_value = "auto", value_parser = one_of::<ValueUnit>(&ValueUnit::NAMES))]
    pub value_unit: ValueUnit,
    /// The order of day and month in an archive's dates like 05/06/2022: auto, dmy or mdy.
    #[arg(long, default_value = "auto", value_parser = one_of::<DateOrder>(&DateOrder::NAMES))]
    pub date_order: DateOrder,
    /// Nominal grid frequency of archives that give deviations: 50, 60, or auto (told from the
    /// archive's values).
    #[arg(long, default_value = "auto")]
    pub nominal: Nominal,
    /// Start time of the first trace CSV (UTC, or with an offset).
    #[arg(long)]
    pub start: Option<String>,
    /// Fail at once when another build is changing the store, instead of waiting for it.
    #[arg(long)]
    pub no_wait: bool,
    /// Seconds between values of `index,value` CSVs.
    #[arg(long, alias = "step", value_parser = number_in(0.001, 3600.0))]
    pub index_step: Option<f64>,
}

impl StoreInputArgs {
    /// The build of `inputs`, as the library takes it.
    pub fn build(&self, inputs: Vec<String>) -> Result<eenf::reference::StoreBuild> {
        Ok(eenf::reference::StoreBuild {
            inputs,
            grid: self.grid.clone(),
            zone: self.tz.clone(),
            archive: ArchiveOptions {
                format: self.format,
                zone: None,
                unit: self.value_unit,
                date_order: self.date_order,
                nominal_hz: match self.nominal {
                    Nominal::Hz(f) => Some(f),
                    Nominal::Auto => None,
                },
            },
            start: self
                .start
                .as_deref()
                .map(eenf::time::parse_time)
                .transpose()?,
            index_step_s: self.index_step,
            wait: !self.no_wait,
        })
    }
}
