//! Flags shared by several commands, parsed into the library's types. Option names come from
//! the library enums' `FromStr`/`Display` (their `NAMES` list the values `--help` shows).

use std::path::PathBuf;
use std::str::FromStr;

use anyhow::{bail, Context, Result};
use clap::builder::{PossibleValuesParser, TypedValueParser};
use eenf::extract::{ExtractOptions, Nominal};
use eenf_dsp::{EnfParams, HarmonicSelection, PeakMethod, SamplingMethod};
use eenf_events::writers::OutputFormat;
use eenf_events::Compression;
use eenf_sim::{Lamp, SceneKind};

/// A clap parser for a library enum: one of `names`, parsed by the enum's `FromStr`.
pub fn one_of<T>(names: &'static [&'static str]) -> impl TypedValueParser<Value = T>
where
    T: FromStr<Err = String> + Clone + Send + Sync + 'static,
{
    PossibleValuesParser::new(names).try_map(|s| s.parse::<T>())
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
    /// STFT window length, s.
    #[arg(long, default_value_t = 16.0)]
    pub window: f64,
    /// STFT step, s (one estimate per step).
    #[arg(long, default_value_t = 1.0)]
    pub step: f64,
    /// Half width of the search band (and band-pass) around each line, Hz.
    #[arg(long, default_value_t = 2.0)]
    pub half_band: f64,
}

/// Event-method flags (`extract`, `bench`).
#[derive(Debug, Clone, clap::Args)]
pub struct MethodArgs {
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
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub harmonics: u32,
    /// Butterworth order of the band-pass prototype.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=8))]
    pub filter_order: u32,
    /// Running-median length of the outlier correction (0 or 1 disables it).
    #[arg(long, default_value_t = 21)]
    pub median_len: usize,
    /// Outlier threshold on the 2f0 scale, Hz.
    #[arg(long, default_value_t = 0.02)]
    pub median_threshold: f64,
    /// Harmonic-selection segment length, in estimates.
    #[arg(long, default_value_t = 10)]
    pub segment: usize,
    /// Harmonic-selection rule: consensus (the smoothest among harmonics that agree with
    /// another one, within --agree-hz), smoothest (the paper: the smoothest harmonic trace per
    /// segment), journal (follow the 2f0 band; where it jumps by more than --jump-hz or is
    /// missing, take the harmonic that continues the trace best). A band whose line stands less
    /// than 12 dB above its noise is not taken where another's does.
    #[arg(long, default_value = "consensus", value_parser = one_of::<HarmonicSelection>(&HarmonicSelection::NAMES))]
    pub selection: HarmonicSelection,
    /// Largest step of the journal rule's 2f0 trace between estimates, Hz (on the ENF scale).
    #[arg(long, default_value_t = HarmonicSelection::DEFAULT_JUMP_HZ)]
    pub jump_hz: f64,
    /// Agreement tolerance of the consensus rule, Hz (on the ENF scale).
    #[arg(long, default_value_t = HarmonicSelection::DEFAULT_AGREE_HZ)]
    pub agree_hz: f64,
    /// Trace every pixel. By default, when events are stamped one by one (DVS128, DAVIS,
    /// Prophesee), only the tiles of pixels whose flicker stands out are traced (the
    /// `flicker-map`'s), so that motion and noise elsewhere drop out.
    #[arg(long)]
    pub all_pixels: bool,
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
        }
    }
}

impl TrackerArgs {
    /// The tracker part of the parameters.
    pub fn params(&self) -> Result<EnfParams> {
        if !(self.window > 0.0 && self.step > 0.0 && self.half_band > 0.0) {
            bail!("--window, --step and --half-band must be positive");
        }
        Ok(EnfParams {
            peak: self.peak,
            window_s: self.window,
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
            Some(list) => eenf::simulation::parse_cameras(list, self.video_scale),
            None => Ok(Vec::new()),
        }
    }
}

/// Where a trace or report goes: a file (`-o`), and/or JSON on stdout.
#[derive(Debug, Clone, clap::Args)]
pub struct TraceOutputArgs {
    /// Write the trace here: CSV (`time_s,enf_hz`), or JSON when the name ends in .json.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Print the trace and its metadata as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

impl TraceOutputArgs {
    /// Writes the trace file, if one was asked for, and says so on stderr.
    pub fn save(&self, trace: &eenf::trace::Trace) -> Result<()> {
        if let Some(out) = &self.output {
            eenf::output::write_atomic(out, |w| trace.write_for(out, w))?;
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

    /// Says where the trace went (stderr).
    pub fn report(&self) {
        match &self.output {
            Some(out) if eenf::output::is_stdout(out) => {}
            Some(out) => eprintln!("trace written to {}", out.display()),
            None => {}
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
