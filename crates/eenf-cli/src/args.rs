//! The command line's option sets (flags shared by several commands, and those the Python
//! package takes as keyword arguments), parsed into the library's types. Option names come from
//! the library enums' `FromStr`/`Display` (their `NAMES` list the values `--help` shows).

use std::path::PathBuf;
use std::str::FromStr;

use anyhow::Result;
use clap::builder::{PossibleValuesParser, TypedValueParser};
use eenf::archive::{ArchiveFormat, DateOrder, ValueUnit};
use eenf::edits::{EditInput, EditOptions, EditParams};
use eenf::extract::ExtractOptions;
use eenf::options::{self, limits};
use eenf::simulation::Recipe;
use eenf::time::Zone;
use eenf_core::{defaults, Nominal};
use eenf_dsp::{EnfParams, HarmonicSelection, PeakMethod, SamplingMethod};
use eenf_events::writers::OutputFormat;
use eenf_events::Compression;
use eenf_video::{RowSampling, SceneRemoval, VideoOptions};

/// A clap parser for a library enum: one of `names`, parsed by the enum's `FromStr`.
pub fn one_of<T>(names: &'static [&'static str]) -> impl TypedValueParser<Value = T>
where
    T: FromStr<Err = String> + Clone + Send + Sync + 'static,
{
    PossibleValuesParser::new(names).try_map(|s| s.parse::<T>())
}

/// A number in `lo..=hi`, for flags read from the user: anything else (NaN, inf, out of range)
/// is a one-line error naming the range, before any work or allocation is sized by it.
pub fn number_in(
    (lo, hi): (f64, f64),
) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync {
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
    (lo, hi): (usize, usize),
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
    /// traced with a window that fits it, and `audio` and `extract` lengthen it for a weak line.
    #[arg(long, value_parser = number_in(limits::WINDOW_S))]
    pub window: Option<f64>,
    /// STFT step, s (one estimate per step).
    #[arg(long, default_value_t = defaults::STEP_S, value_parser = number_in(limits::STEP_S))]
    pub step: f64,
    /// Half width of the search band (and band-pass) around each line, Hz.
    #[arg(long, default_value_t = defaults::HALF_BAND_HZ, value_parser = number_in(limits::HALF_BAND_HZ))]
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
    #[arg(long, value_parser = clap::value_parser!(i64).range(limits::DT_US.0 as i64..=limits::DT_US.1 as i64))]
    pub dt_us: Option<i64>,
    /// Number of flicker harmonics M (bands at 2m·f0, m = 1..M; those above Nyquist skipped).
    #[arg(long, default_value_t = defaults::HARMONICS as u32, value_parser = clap::value_parser!(u32).range(limits::HARMONICS.0 as i64..=limits::HARMONICS.1 as i64))]
    pub harmonics: u32,
    /// Butterworth order of the band-pass prototype.
    #[arg(long, default_value_t = defaults::FILTER_ORDER as u32, value_parser = clap::value_parser!(u32).range(limits::FILTER_ORDER.0 as i64..=limits::FILTER_ORDER.1 as i64))]
    pub filter_order: u32,
    /// Running-median length of the outlier correction (0 or 1 disables it).
    #[arg(long, default_value_t = defaults::MEDIAN_LEN, value_parser = count_in(limits::MEDIAN_LEN))]
    pub median_len: usize,
    /// Outlier threshold on the 2f0 scale, Hz.
    #[arg(long, default_value_t = defaults::MEDIAN_THRESHOLD_HZ, value_parser = number_in(limits::MEDIAN_THRESHOLD_HZ))]
    pub median_threshold: f64,
    /// Harmonic-selection segment length, in estimates.
    #[arg(long, default_value_t = defaults::SEGMENT_LEN, value_parser = count_in(limits::SEGMENT))]
    pub segment: usize,
    /// Harmonic-selection rule: consensus (the smoothest among harmonics that agree with
    /// another one, within --agree-hz), smoothest (the paper: the smoothest harmonic trace per
    /// segment), journal (follow the 2f0 band; where it jumps by more than --jump-hz or is
    /// missing, take the harmonic that continues the trace best). A band whose line stands less
    /// than 12 dB above its noise is not taken where another's does.
    #[arg(long, default_value = "consensus", value_parser = one_of::<HarmonicSelection>(&HarmonicSelection::NAMES))]
    pub selection: HarmonicSelection,
    /// Largest step of the journal rule's 2f0 trace between estimates, Hz (on the ENF scale).
    #[arg(long, default_value_t = HarmonicSelection::DEFAULT_JUMP_HZ, value_parser = number_in(limits::SELECTION_HZ))]
    pub jump_hz: f64,
    /// Agreement tolerance of the consensus rule, Hz (on the ENF scale).
    #[arg(long, default_value_t = HarmonicSelection::DEFAULT_AGREE_HZ, value_parser = number_in(limits::SELECTION_HZ))]
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
    /// The library's option set.
    pub fn settings(&self) -> options::InputSettings {
        options::InputSettings {
            chip: self.chip.clone(),
            camera: self.camera,
            strict: self.strict,
            max_gap: self.max_gap,
            topic: self.topic.clone(),
        }
    }

    /// The reader options.
    pub fn options(&self) -> eenf_events::OpenOptions {
        self.settings().open_options()
    }
}

impl TrackerArgs {
    /// The library's option set.
    pub fn settings(&self) -> options::TrackerSettings {
        options::TrackerSettings {
            nominal: self.nominal,
            peak: self.peak,
            window: self.window,
            step: self.step,
            half_band: self.half_band,
        }
    }

    /// The tracker part of the parameters.
    pub fn params(&self) -> Result<EnfParams> {
        Ok(self.settings().params()?)
    }
}

impl MethodArgs {
    /// The library's option set.
    pub fn settings(&self) -> options::ExtractSettings {
        options::ExtractSettings {
            tracker: self.tracker.settings(),
            sampling: self.sampling,
            dt_us: self.dt_us,
            harmonics: self.harmonics,
            filter_order: self.filter_order,
            median_len: self.median_len,
            median_threshold: self.median_threshold,
            segment: self.segment,
            selection: self.selection,
            jump_hz: self.jump_hz,
            agree_hz: self.agree_hz,
            all_pixels: self.all_pixels,
            input: self.input.settings(),
        }
    }

    /// The options of the extraction.
    pub fn options(&self) -> Result<ExtractOptions> {
        Ok(self.settings().options()?)
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
    /// The library's option set.
    pub fn settings(&self) -> options::EventOutputSettings {
        options::EventOutputSettings {
            format: self.format,
            compression: self.compression,
        }
    }

    /// The format for `path`: `--format`, else its extension, else `fallback`.
    pub fn format_for(
        &self,
        path: &std::path::Path,
        fallback: Option<OutputFormat>,
    ) -> Result<OutputFormat> {
        Ok(self.settings().format_for(path, fallback)?)
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
    #[arg(long, default_value_t = 1.0, value_parser = number_in(limits::VIDEO_SCALE))]
    pub video_scale: f64,
    /// Also encode each video as MP4 (H.264 at the camera's CRF: 28 webcam, 20 phone) with
    /// ffmpeg, as the cameras' own pipelines do.
    #[arg(long)]
    pub mp4: bool,
}

impl VideoArgs {
    /// The library's option set.
    pub fn settings(&self) -> options::VideoRenderSettings {
        options::VideoRenderSettings {
            video: self.video.clone(),
            video_scale: self.video_scale,
            mp4: self.mp4,
        }
    }

    /// The cameras asked for (none without `--video`).
    pub fn cameras(&self) -> Result<Vec<eenf_sim::CameraConfig>> {
        Ok(self.settings().cameras()?)
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
            trace.write_json(&mut lock)?;
        } else if self.output.is_none() {
            trace.write_csv(&mut lock)?;
        }
        Ok(())
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
    /// The library's option set.
    pub fn settings(&self) -> options::AudioSettings {
        options::AudioSettings {
            channel: self.channel,
            harmonics: self.harmonics,
        }
    }

    /// How the hum is traced: these lines, and the tracker's `--window` if one was given.
    pub fn hum(&self, tracker: &TrackerArgs) -> eenf::mains::HumOptions {
        self.settings().hum(&tracker.settings())
    }

    /// The reading options (the rate follows from the harmonics tracked).
    pub fn options(&self) -> eenf::audio::AudioOptions {
        self.settings().options()
    }
}

/// V-ENF flags (`video`).
#[derive(Debug, Clone, clap::Args)]
pub struct VideoMethodArgs {
    /// Nominal grid frequency: 50, 60, or auto (detected from the flicker).
    #[arg(long, default_value = "auto")]
    pub nominal: Nominal,
    /// The sensor's readout time (first row to last row), ms: sets the idle rows.
    #[arg(long, conflicts_with_all = ["idle", "virtual_rows"], value_parser = number_in(limits::READOUT_MS))]
    pub readout_ms: Option<f64>,
    /// Idle rows: `auto` estimates them from the flicker's ripple within frames.
    #[arg(long, value_parser = ["auto"])]
    pub idle: Option<String>,
    /// Virtual rows per frame period (real plus idle), if known.
    #[arg(long, conflicts_with = "idle", value_parser = number_in(limits::VIRTUAL_ROWS))]
    pub virtual_rows: Option<f64>,
    /// Sampling: auto (rows zero-padded or frame means, whichever shows the flicker line
    /// stronger; the trace says which and why), zero-pad (rows, idle rows as zeros), naive
    /// (rows concatenated), global (one sample per frame: a global shutter, or frame means
    /// only; the flicker is seen at its alias and tracked where the alias leaves it room).
    #[arg(long, default_value = "auto", value_parser = one_of::<RowSampling>(&RowSampling::NAMES))]
    pub sampling: RowSampling,
    /// Scene removal: paper (each frame minus the mean of it and the next), row-mean (each
    /// row minus its mean over a second), none.
    #[arg(long, default_value = "paper", value_parser = one_of::<SceneRemoval>(&SceneRemoval::NAMES))]
    pub scene_removal: SceneRemoval,
    /// Peak refinement of the tracker: exact or paper.
    #[arg(long, default_value = "exact", value_parser = one_of::<PeakMethod>(&PeakMethod::NAMES))]
    pub peak: PeakMethod,
    /// STFT window, s.
    #[arg(long, default_value_t = defaults::WINDOW_S, value_parser = number_in(limits::WINDOW_S))]
    pub window: f64,
}

impl VideoMethodArgs {
    /// The library's option set.
    pub fn settings(&self) -> options::VideoSettings {
        options::VideoSettings {
            nominal: self.nominal,
            readout_ms: self.readout_ms,
            idle: self.idle.clone(),
            virtual_rows: self.virtual_rows,
            sampling: self.sampling,
            scene_removal: self.scene_removal,
            peak: self.peak,
            window: self.window,
        }
    }

    /// The V-ENF options these arguments ask for.
    pub fn options(&self) -> Result<VideoOptions> {
        Ok(self.settings().options()?)
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
    #[arg(long, default_value_t = 60.0, value_parser = number_in(limits::DURATION_S))]
    pub duration: f64,
    /// Where the ENF comes from: `synthetic` (a grid-like random process), a mains WAV or a
    /// trace CSV (`time_s,enf_hz`, or `index,value` at --index-step), optionally with a start
    /// second (`ref.wav:600`).
    #[arg(long, default_value = "synthetic")]
    pub enf: String,
    /// Seconds between the values of an `index,value` trace CSV.
    #[arg(long, alias = "enf-step", default_value_t = 2.0, value_parser = number_in(limits::INDEX_STEP_S))]
    pub index_step: f64,
    /// Grid frequency of a synthetic ENF: 50 or 60 (a WAV's or trace's own is detected).
    #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u32).range(limits::GRID_HZ.0 as i64..=limits::GRID_HZ.1 as i64))]
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
    #[arg(long, value_parser = number_in(limits::ILLUMINATION))]
    pub illumination: Option<f64>,
    /// Share of non-flickering light (daylight), 0..1.
    #[arg(long, value_parser = number_in(limits::AMBIENT))]
    pub ambient: Option<f64>,
    /// How much brighter the first lamp is inside its pool (`lamp-spot`) or bulb
    /// (`extreme-bright`) than elsewhere: sets how strongly those pixels flicker.
    #[arg(long, value_parser = number_in(limits::SPOT_GAIN))]
    pub spot_gain: Option<f64>,
    /// Background activity: each pixel's noise events per second under an indoor room's
    /// light (more in the dark), e.g. 0.5 for an old DVS128. Default: the simulator's 0.02.
    #[arg(long, value_parser = number_in(limits::NOISE_HZ))]
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

impl SimulateArgs {
    /// The library's option set.
    pub fn settings(&self) -> options::SimulateSettings {
        options::SimulateSettings {
            scene: self.scene.clone(),
            lamp: self.lamp.clone(),
            duration: self.duration,
            enf: self.enf.clone(),
            index_step: self.index_step,
            grid: self.grid,
            output: self.output.clone(),
            resolution: self.resolution.clone(),
            seed: self.seed,
            readout: self.readout.clone(),
            illumination: self.illumination,
            ambient: self.ambient,
            spot_gain: self.spot_gain,
            noise_hz: self.noise_hz,
            start: self.start.clone(),
            reference_dir: self.reference_dir.clone(),
            events: self.events.settings(),
            video: self.video.settings(),
        }
    }

    /// The recipe these flags ask for.
    pub fn recipe(&self) -> Result<Recipe> {
        Ok(self.settings().recipe()?)
    }
}

/// Search flags (`match`).
#[derive(Debug, Clone, clap::Args)]
pub struct MatchArgs {
    /// Candidates to list.
    #[arg(long, default_value_t = 5, value_parser = count_in(limits::TOP))]
    pub top: usize,
    /// Check a claimed start time (e.g. 2022-08-17T16:10:00+08:00): its score, rank and
    /// significance.
    #[arg(long)]
    pub verify: Option<String>,
    /// Ranking score: `combined` (shape and level) or `cc` (shape only, robust to a bias).
    #[arg(long, default_value = "combined", value_parser = one_of::<eenf_dsp::matching::Score>(&eenf_dsp::matching::Score::NAMES))]
    pub score: eenf_dsp::matching::Score,
    /// A candidate is a match when its p-value is below this.
    #[arg(long, default_value_t = eenf_dsp::matching::DEFAULT_ALPHA, value_parser = number_in(limits::ALPHA))]
    pub alpha: f64,
    /// Zone of the local times in hourly WAV names and grid archives: an IANA name
    /// (Europe/Berlin, Asia/Shanghai; summer time followed) or a UTC offset (+08:00, Z); also
    /// the zone results are shown in beside UTC. Local times need it: none is assumed.
    #[arg(long, allow_hyphen_values = true)]
    pub tz: Option<Zone>,
}

impl MatchArgs {
    /// The library's option set.
    pub fn settings(&self) -> options::MatchSettings {
        options::MatchSettings {
            top: self.top,
            verify: self.verify.clone(),
            score: self.score,
            alpha: self.alpha,
            tz: self.tz.clone(),
        }
    }

    /// What the search asks for.
    pub fn query(&self) -> Result<eenf::locate::MatchQuery> {
        Ok(self.settings().query()?)
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
    #[arg(long, default_value_t = EditParams::default().side_s, value_parser = number_in(limits::SIDE_S))]
    pub side: f64,
    /// The shortest stretch between two edits told apart, s (also the shortest side fitted:
    /// the first and last this much of a recording are not tested).
    #[arg(long, default_value_t = EditParams::default().min_gap_s, value_parser = number_in(limits::MIN_GAP_S))]
    pub min_gap: f64,
    /// False alarms allowed per hour of unedited recording: sets the phase test's threshold
    /// from the noise measured in the recording and the real grid's own phase stray, measured
    /// on 24 continuous hours of real mains (0 findings there at the default 0.05, 95 % upper
    /// bound 0.12 per hour; in a phone's noise 3 in 130 hours of clips of them).
    #[arg(long, default_value_t = EditParams::default().false_alarms_per_hour, value_parser = number_in(limits::FALSE_ALARMS))]
    pub false_alarms: f64,
    /// Report stretches where a phase jump this large (degrees of the lowest line) would go
    /// unseen as too weak to tell.
    #[arg(long, default_value_t = EditParams::default().weak_jump_deg, value_parser = number_in(limits::WEAK_JUMP_DEG))]
    pub weak_jump: f64,
    /// A frequency step is reported when it stands this many robust standard deviations of
    /// the recording's own steps.
    #[arg(long, default_value_t = EditParams::default().frequency_step_z, value_parser = number_in(limits::STEP_Z))]
    pub step_z: f64,
    /// The channel of a sound: `mix` (the mean of all) or a number from 0.
    #[arg(long, default_value = "mix")]
    pub channel: eenf::audio::Channel,
    /// Seconds between the values of an `index,value` trace CSV (a grid archive's day of
    /// values, for instance); a `time_s,enf_hz` CSV or eenf JSON carries its own times.
    #[arg(long, value_parser = number_in(limits::INDEX_STEP_S))]
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
    /// The library's option set.
    pub fn settings(&self) -> options::EditSettings {
        options::EditSettings {
            nominal: self.nominal,
            side: self.side,
            min_gap: self.min_gap,
            false_alarms: self.false_alarms,
            weak_jump: self.weak_jump,
            step_z: self.step_z,
            channel: self.channel,
            index_step: self.index_step,
            kind: self.kind,
            input: self.input.settings(),
        }
    }

    /// Everything `edits` needs: the test, the grid, how sound and events are read.
    pub fn options(&self) -> Result<EditOptions> {
        Ok(self.settings().options()?)
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
    #[arg(long, alias = "step", value_parser = number_in(limits::INDEX_STEP_S))]
    pub index_step: Option<f64>,
}

impl StoreInputArgs {
    /// The library's option set.
    pub fn settings(&self) -> options::StoreInputSettings {
        options::StoreInputSettings {
            grid: self.grid.clone(),
            tz: self.tz.clone(),
            format: self.format,
            value_unit: self.value_unit,
            date_order: self.date_order,
            nominal: self.nominal,
            start: self.start.clone(),
            no_wait: self.no_wait,
            index_step: self.index_step,
        }
    }

    /// The build of `inputs`, as the library takes it.
    pub fn build(&self, inputs: Vec<String>) -> Result<eenf::reference::StoreBuild> {
        Ok(self.settings().build(inputs)?)
    }
}

/// Arguments of `eenf simulate-dataset`.
#[derive(Debug, Clone, clap::Args)]
pub struct DatasetArgs {
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
    #[arg(long, value_parser = number_in(eenf::options::limits::DURATION_S))]
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
    /// Videos rendered beside each recording.
    #[command(flatten)]
    pub video: VideoArgs,
}

impl DatasetArgs {
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

/// The option sets the Python package and the page take, by name: each with the flags' library
/// names, defaults, help and choices, as `eenf::options::DOCS_JSON` holds them (a test keeps
/// that file equal to this, so that the help is written once, here).
pub fn option_docs() -> serde_json::Value {
    use clap::Args as _;
    /// Adds an option set's flags to a command.
    type Augment = fn(clap::Command) -> clap::Command;
    let sets: [(&str, Augment); 10] = [
        ("input", InputArgs::augment_args),
        ("extract", MethodArgs::augment_args),
        ("reference", |c| {
            TrackerArgs::augment_args(AudioArgs::augment_args(c))
        }),
        ("video", VideoMethodArgs::augment_args),
        ("simulate", SimulateArgs::augment_args),
        ("simulate_dataset", DatasetArgs::augment_args),
        ("match", MatchArgs::augment_args),
        ("write", EventOutputArgs::augment_args),
        ("edits", EditArgs::augment_args),
        ("refdb_build", StoreInputArgs::augment_args),
    ];
    let mut out = serde_json::Map::new();
    for (name, augment) in sets {
        let cmd = augment(clap::Command::new("eenf"));
        let options: Vec<serde_json::Value> = cmd
            .get_arguments()
            .filter_map(|a| {
                let long = a.get_long().filter(|l| *l != "help")?;
                let default = a
                    .get_default_values()
                    .first()
                    .map(|v| v.to_string_lossy().into_owned());
                let help = a
                    .get_long_help()
                    .or(a.get_help())
                    .map(|h| library_names(&h.to_string()))
                    .unwrap_or_default();
                let choices: Vec<String> = a
                    .get_possible_values()
                    .iter()
                    .map(|v| v.get_name().to_string())
                    .collect();
                Some(serde_json::json!({
                    "name": long.replace('-', "_"),
                    "switch": !a.get_action().takes_values(),
                    "default": default,
                    "help": help,
                    "choices": choices,
                }))
            })
            .collect();
        out.insert(name.to_string(), options.into());
    }
    out.into()
}

/// `text` with each flag it names (`--max-gap`) as the option's library name (`max_gap`), for
/// the front ends that do not take flags.
fn library_names(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find("--") {
        out.push_str(&rest[..at]);
        let tail = &rest[at + 2..];
        let len = tail
            .find(|c: char| !(c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'))
            .unwrap_or(tail.len());
        if tail.starts_with(|c: char| c.is_ascii_lowercase()) {
            out.push_str(&tail[..len].replace('-', "_"));
            rest = &tail[len..];
        } else {
            out.push_str("--");
            rest = tail;
        }
    }
    out.push_str(rest);
    out
}
