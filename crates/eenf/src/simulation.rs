//! Simulated recordings on a wall-clock timeline: where their ENF comes from (a synthetic grid,
//! a trace CSV, mains WAVs), the hourly reference WAVs that go with them, and writing one
//! recording with its truth and parameters.

use eenf_core::spelling::option;
use std::path::{Path, PathBuf};

use crate::error::{error, fail, rule, Context, Error, Missing, Result};
use eenf_events::writers::OutputFormat;
use eenf_sim::{simulate, CameraConfig, MainsPhase, SimConfig, SimStats, SyntheticEnf};

use crate::audio::read_wav;
use crate::dataset::{hourly_references, reference_name};
use crate::mains::mains_nominal;
use crate::output::{sibling, write_atomic, write_events};
use crate::progress::Progress;
use crate::reference::ReferenceSource;
use crate::time::{offset_of, parse_time, LocalTime};
use crate::trace::Trace;
use crate::wav::write_wav;
use eenf_core::{Grid, Nominal};

/// Sampling rate of synthesized mains references (the dataset's).
pub const REFERENCE_FS: u32 = 400;

/// Where the ENF of simulated recordings comes from, on local wall-clock time (seconds since
/// 1970-01-01 00:00 local).
pub enum EnfTimeline {
    /// A frequency series (synthetic, or read from a trace CSV) from `t0` at `step_s` steps.
    Series {
        /// The grid.
        grid: Grid,
        /// Frequency values, Hz.
        values: Vec<f64>,
        /// Seconds between values.
        step_s: f64,
        /// Local time of the first value.
        t0: f64,
        /// What it is, for the sidecar.
        source: String,
    },
    /// Mains recordings: hourly WAVs (or one WAV) starting at the given local times.
    Mains {
        /// The grid.
        grid: Grid,
        /// (local start, path), sorted.
        files: Vec<(f64, PathBuf)>,
    },
}

impl EnfTimeline {
    /// A synthetic grid covering `from..to` (local seconds), whole hours.
    pub fn synthetic(grid: Grid, from: f64, to: f64, seed: u64) -> Self {
        let t0 = (from / 3600.0).floor() * 3600.0 - 2.0;
        let n = ((to - t0) / 3600.0).ceil() as usize * 3600 + 8;
        EnfTimeline::Series {
            grid,
            values: SyntheticEnf::default().per_second(grid.hz(), n, seed),
            step_s: 1.0,
            t0,
            source: format!("synthetic {grid} Hz grid, seed {seed}"),
        }
    }

    /// A trace CSV (`time_s,enf_hz`, or `index,value` at `step_s`) whose first value is at
    /// local time `t0`.
    pub fn trace(path: &Path, step_s: f64, t0: f64) -> Result<Self> {
        let series = Trace::read(path, Some(step_s))?;
        let (step_s, values) = (series.step_s, series.enf_hz);
        if values.len() < 4 || values.iter().any(|v| !v.is_finite()) {
            fail!(
                Simulation,
                "{}: a trace needs at least 4 finite values",
                path.display()
            );
        }
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let grid = Grid::near(mean).or_fail(Error::Input, || {
            format!(
                "{}: mean {mean:.3} Hz is neither a 50 nor a 60 Hz grid",
                path.display()
            )
        })?;
        Ok(EnfTimeline::Series {
            grid,
            values,
            step_s,
            t0,
            source: format!("trace {}", path.display()),
        })
    }

    /// One mains WAV starting at local time `t0`.
    pub fn wav(path: &Path, t0: f64) -> Result<Self> {
        let sig = read_wav(path)?;
        let grid = mains_nominal(&sig, Nominal::Auto, path)?;
        Ok(EnfTimeline::Mains {
            grid,
            files: vec![(t0, path.to_path_buf())],
        })
    }

    /// A folder of hourly mains WAVs named like the dataset's.
    pub fn wav_dir(dir: &Path) -> Result<Self> {
        let refs = hourly_references(dir)?;
        let first = &refs[0].1;
        let sig = read_wav(first)?;
        let grid = mains_nominal(&sig, Nominal::Auto, first)?;
        Ok(EnfTimeline::Mains {
            grid,
            files: refs
                .into_iter()
                .map(|(t, p)| (t.local_seconds() as f64, p))
                .collect(),
        })
    }

    /// The grid.
    pub fn grid(&self) -> Grid {
        match self {
            EnfTimeline::Series { grid, .. } | EnfTimeline::Mains { grid, .. } => *grid,
        }
    }

    /// Local times covered, `(from, to)`.
    pub fn coverage(&self) -> Result<(f64, f64)> {
        Ok(match self {
            EnfTimeline::Series {
                values, step_s, t0, ..
            } => (
                *t0 + 2.0 * step_s,
                t0 + (values.len() as f64 - 3.0) * step_s,
            ),
            EnfTimeline::Mains { files, .. } => {
                // contiguous run of files from the first
                let mut end = files[0].0;
                for (t, p) in files {
                    if (*t - end).abs() > 1.0 {
                        break;
                    }
                    let (frames, rate) = wav_span(p)?;
                    end = t + frames / rate;
                }
                (files[0].0, end)
            }
        })
    }

    /// The mains phase of `duration_s` seconds from local time `start`.
    pub fn phase(&self, start: f64, duration_s: f64) -> Result<MainsPhase> {
        match self {
            EnfTimeline::Series {
                grid,
                values,
                step_s,
                t0,
                ..
            } => {
                let (from, to) = self.coverage()?;
                if start < from || start + duration_s > to {
                    fail!(
                        Simulation,
                        "the ENF trace covers {:.0} s; {:.0} s from second {:.0} do not fit",
                        to - from,
                        duration_s,
                        start - from
                    );
                }
                // the phase runs on from the series' start, so pieces cut from one series
                // (a recording, the hourly references) join without a phase step
                Ok(MainsPhase::from_frequency(
                    grid.hz(),
                    values,
                    *step_s,
                    start - t0,
                    duration_s,
                    eenf_sim::phase_from_start(values, *step_s, start - t0),
                ))
            }
            EnfTimeline::Mains { grid, files } => {
                // the files holding [start, start + duration], read and joined
                let end = start + duration_s;
                let mut samples = Vec::new();
                let mut fs = 0.0;
                let mut first_t: Option<f64> = None;
                for (t, p) in files {
                    // the header says whether the file matters; only those are read
                    let (frames, rate) = wav_span(p)?;
                    if t + frames / rate <= start - 20.0 || *t >= end + 20.0 {
                        continue;
                    }
                    let sig = read_wav(p)?;
                    if fs != 0.0 && sig.fs != fs {
                        fail!(
                            Simulation,
                            "{}: its rate differs from the previous file's",
                            p.display()
                        );
                    }
                    if let Some(ft) = first_t {
                        let expected = ft + samples.len() as f64 / fs;
                        if (t - expected).abs() > 1.0 {
                            fail!(
                                Simulation,
                                "{}: there is a gap before this file",
                                p.display()
                            );
                        }
                    } else {
                        first_t = Some(*t);
                    }
                    fs = sig.fs;
                    samples.extend_from_slice(&sig.samples);
                }
                let Some(ft) = first_t else {
                    fail!(
                        Simulation,
                        "no mains recording covers local time {start:.0} s"
                    );
                };
                MainsPhase::from_recording(&samples, fs, grid.hz(), start - ft, duration_s)
                    .map_err(|e| error!(Simulation, "{}: {e}", files[0].1.display()))
            }
        }
    }

    /// What drives the ENF, for the sidecar.
    pub fn describe(&self) -> String {
        match self {
            EnfTimeline::Series { source, .. } => source.clone(),
            EnfTimeline::Mains { files, .. } => {
                let names: Vec<String> = files.iter().map(|f| f.1.display().to_string()).collect();
                format!("mains {}", names.join(", "))
            }
        }
    }

    /// Writes the hourly reference WAVs (400 Hz, 16-bit, named like the dataset's) into `dir`:
    /// those covering `from..to` synthesized from a series, or every mains recording copied.
    pub fn write_references(
        &self,
        dir: &Path,
        from: f64,
        to: f64,
        seed: u64,
    ) -> Result<Vec<PathBuf>> {
        std::fs::create_dir_all(dir).with_context(|| format!("{}", dir.display()))?;
        let mut out = Vec::new();
        match self {
            EnfTimeline::Series { .. } => {
                let (have_from, have_to) = self.coverage()?;
                let mut hour = (from / 3600.0).floor() * 3600.0;
                if hour < have_from || (to / 3600.0).ceil() * 3600.0 > have_to {
                    fail!(
                        Simulation,
                        "hourly references need the ENF of whole hours; the trace covers {:.0} s",
                        have_to - have_from
                    );
                }
                while hour < to {
                    let name = reference_name(&LocalTime::from_local_seconds(hour as i64));
                    let path = dir.join(name);
                    let phase = self.phase(hour, 3600.0)?;
                    write_wav(
                        &path,
                        REFERENCE_FS,
                        &phase.voltage(REFERENCE_FS as f64, seed ^ hour as u64),
                    )?;
                    out.push(path);
                    hour += 3600.0;
                }
            }
            EnfTimeline::Mains { files, .. } => {
                // all of them: they are the dataset's references
                for (_, p) in files {
                    let name = p
                        .file_name()
                        .or_fail(Error::Simulation, || "a reference without a file name")?;
                    let dest = dir.join(name);
                    if dest != *p {
                        let tmp = dest.with_extension("wav.tmp");
                        std::fs::copy(p, &tmp).with_context(|| format!("{}", dest.display()))?;
                        std::fs::rename(&tmp, &dest)
                            .with_context(|| format!("{}", dest.display()))?;
                    }
                    out.push(dest);
                }
            }
        }
        Ok(out)
    }
}

/// Frames and sampling rate of a WAV, from its header.
fn wav_span(path: &Path) -> Result<(f64, f64)> {
    let reader = hound::WavReader::open(path)
        .with_context(|| format!("{}: not a readable WAV", path.display()))?;
    Ok((reader.duration() as f64, reader.spec().sample_rate as f64))
}

/// A finished simulated recording.
pub struct Simulated {
    /// The event file.
    pub recording: PathBuf,
    /// Its ground-truth trace.
    pub truth: PathBuf,
    /// What was generated.
    pub stats: SimStats,
    /// Seconds it took.
    pub seconds: f64,
}

/// Simulates `config` under `mains` into `output` (format `format`), with the truth beside it
/// as NAME.truth.csv and every parameter as NAME.sim.json. `extra` joins the sidecar.
///
/// The truth is `mains.truth(duration)`: the reference tracker on the clean mains of the
/// recording's own span, its windows zero-padded at the ends as an estimator that sees only
/// the recording has them, so that a perfect estimator scores MAE ≈ 0. (A reference recorded
/// around the recording differs at the first and last ~8 s, where its windows see beyond it.)
pub fn write_recording(
    config: &SimConfig,
    mains: &MainsPhase,
    output: &Path,
    format: OutputFormat,
    extra: serde_json::Value,
    progress: &Progress,
) -> Result<Simulated> {
    config
        .check()
        .map_err(|e| error!(Simulation, "{}: {e}", output.display()))?;
    let started = std::time::Instant::now();
    let step_us = config.readout.step_us();
    let bar = progress.steps(
        (config.duration_s * 1e6 / step_us as f64) as u64,
        "simulating",
    );
    if let Some(parent) = output.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).with_context(|| format!("{}", parent.display()))?;
    }
    let mut stats = None;
    write_events(output, format, config.width, config.height, |writer| {
        stats = Some(simulate(config, mains, |b| {
            bar.inc(250);
            writer.write(b).map_err(Error::from)
        })?);
        Ok(())
    })?;
    let stats = stats.or_fail(Error::Simulation, || "the simulation gave no statistics")?;
    bar.finish_and_clear();
    let truth = Trace::new(1.0, mains.truth(config.duration_s));
    let truth_path = sibling(output, "truth.csv");
    write_atomic(&truth_path, |w| truth.write_csv(w))?;
    let seconds = started.elapsed().as_secs_f64();
    let sidecar = serde_json::json!({
        "recording": output,
        "truth": truth_path,
        "nominal_hz": mains.nominal_hz,
        "seed": config.seed,
        "config": config,
        "stats": stats,
        "seconds": seconds,
        "eenf_version": env!("CARGO_PKG_VERSION"),
        "extra": extra,
    });
    write_atomic(&sibling(output, "sim.json"), |w| {
        serde_json::to_writer_pretty(&mut *w, &sidecar)?;
        Ok(())
    })?;
    Ok(Simulated {
        recording: output.to_path_buf(),
        truth: truth_path,
        stats,
        seconds,
    })
}

/// Parses `lr,hr` into camera presets, scaled by `scale` (0 < scale ≤ 1); `hr@0.125` gives a
/// camera its own scale.
pub fn parse_cameras(
    list: &str,
    scale: f64,
) -> Result<Vec<eenf_sim::CameraConfig>, crate::error::OptionError> {
    list.split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|item| {
            let (name, own) = match item.trim().split_once('@') {
                Some((n, f)) => (
                    n,
                    f.parse::<f64>().map_err(|_| {
                        rule(
                            "video",
                            format!("{} {item:?}: bad scale {f:?}", option("video")),
                        )
                    })?,
                ),
                None => (item.trim(), scale),
            };
            if !(own > 0.0 && own <= 1.0) {
                return Err(rule(
                    "video_scale",
                    format!("{} must lie in (0, 1], not {own}", option("video_scale")),
                ));
            }
            eenf_sim::CameraConfig::named(name)
                .map(|c| c.scaled(own))
                .ok_or_else(|| {
                    rule(
                        "video",
                        format!("{} {name:?}: expected lr or hr", option("video")),
                    )
                })
        })
        .collect()
}

/// Renders the same scene and lighting as `config` through `camera` into
/// `<stem>_<camera>.y4m` beside `output` (and `.mp4` too when `mp4` and ffmpeg is there).
/// Returns the files written, and a note when the MP4 could not be made.
pub fn write_video(
    config: &SimConfig,
    camera: &eenf_sim::CameraConfig,
    mains: &MainsPhase,
    output: &Path,
    mp4: bool,
    progress: &Progress,
) -> Result<VideoFiles> {
    camera
        .check()
        .map_err(|e| error!(Simulation, "camera {}: {e}", camera.name))?;
    let stem = output.file_stem().unwrap_or_default().to_string_lossy();
    let y4m = output.with_file_name(format!("{stem}_{}.y4m", camera.name));
    let frames = (config.duration_s * camera.fps).floor() as u64;
    let bar = progress.steps(frames, &format!("{} frames", camera.name));
    let (w, h) = (camera.width as usize, camera.height as usize);
    write_atomic(&y4m, |out| {
        let mut writer = eenf_video::Y4mWriter::new(out, w, h, camera.fps)?;
        eenf_sim::render_video(config, camera, mains, |frame| {
            bar.inc(1);
            writer.write_frame(frame)
        })?;
        Ok(())
    })?;
    bar.finish_and_clear();
    let mut written = vec![y4m.clone()];
    let mut note = None;
    if mp4 {
        let mp4_path = y4m.with_extension("mp4");
        let tool = std::env::var("EENF_FFMPEG").unwrap_or_else(|_| "ffmpeg".into());
        let status = std::process::Command::new(&tool)
            .args(["-v", "error", "-y", "-i"])
            .arg(&y4m)
            .args([
                "-c:v", "libx264", "-preset", "veryfast", "-pix_fmt", "yuv420p",
            ])
            .arg("-crf")
            .arg(camera.crf.to_string())
            .arg(&mp4_path)
            .status();
        match status {
            Ok(s) if s.success() => written.push(mp4_path),
            Ok(s) => fail!(Simulation, "{}: ffmpeg failed ({s})", mp4_path.display()),
            Err(e) => note = Some(format!("no MP4 ({tool}: {e}); the Y4M is written")),
        }
    }
    Ok(VideoFiles {
        files: written,
        note,
    })
}

/// What [`write_video`] wrote.
pub struct VideoFiles {
    /// The Y4M, then the MP4 when one was made.
    pub files: Vec<PathBuf>,
    /// Why no MP4 was made when one was asked for (ffmpeg missing).
    pub note: Option<String>,
}

/// Where a simulated recording's ENF comes from.
#[derive(Debug, Clone)]
pub enum EnfSource {
    /// A synthetic grid of this nominal frequency (50 or 60 Hz).
    Synthetic(Grid),
    /// A mains WAV or a trace CSV, from `offset_s` into it; an `index,value` CSV has values
    /// `index_step_s` apart.
    File {
        /// The file.
        path: PathBuf,
        /// Seconds into it where the recording starts.
        offset_s: f64,
        /// Step of an `index,value` CSV.
        index_step_s: f64,
    },
}

/// Everything one simulated recording is made from.
#[derive(Debug, Clone)]
pub struct Recipe {
    /// The scene, lamps and sensor (`start_us` is set from `start`).
    pub config: SimConfig,
    /// Where the ENF comes from.
    pub enf: EnfSource,
    /// Local start time with its UTC offset, e.g. `2022-08-17T16:10:00+08:00` (a source named
    /// like the dataset's hourly references fixes the time instead).
    pub start: String,
    /// The recording.
    pub output: PathBuf,
    /// Its format.
    pub format: OutputFormat,
    /// Conventional cameras to render the same scene through.
    pub cameras: Vec<CameraConfig>,
    /// Also encode the videos as MP4.
    pub mp4: bool,
    /// Write the hourly mains references covering the recording here.
    pub reference_dir: Option<PathBuf>,
}

/// The local start of a simulated recording unless told otherwise: 16:10 in Wuhan on the
/// day of the shared references.
pub const DEFAULT_START: &str = "2022-08-17T16:10:00+08:00";

impl Recipe {
    /// `config` on a synthetic 50 Hz grid from [`DEFAULT_START`], as LZ4 AEDAT4 to `output`.
    pub fn new(config: SimConfig, output: PathBuf) -> Self {
        Recipe {
            config,
            enf: EnfSource::Synthetic(Grid::Hz50),
            start: DEFAULT_START.to_string(),
            output,
            format: OutputFormat::Aedat4(eenf_events::Compression::Lz4),
            cameras: Vec::new(),
            mp4: false,
            reference_dir: None,
        }
    }
}

/// A simulated recording and everything written with it.
pub struct SimulatedRecording {
    /// The recording, its truth and statistics.
    pub sim: Simulated,
    /// The simulation as run.
    pub config: SimConfig,
    /// Local start, seconds since 1970-01-01 00:00 local.
    pub local_start: f64,
    /// Videos written.
    pub videos: Vec<PathBuf>,
    /// Reference WAVs written.
    pub references: Vec<PathBuf>,
    /// What the caller should be told (a video without its MP4).
    pub notes: Vec<String>,
}

/// The local start (seconds) and UTC offset of a recording starting at `start`, or
/// `source_start` seconds into a source named like an hourly reference.
fn local_start(start: &str, source: Option<&Path>, source_start: f64) -> Result<(f64, f64)> {
    let tz = offset_of(start)?;
    if let Some(t) = source.and_then(crate::dataset::reference_hour) {
        return Ok((t.local_seconds() as f64 + source_start, tz));
    }
    let utc = parse_time(start).with_context(|| option("start"))?;
    Ok((utc + tz, tz))
}

/// The ENF timeline of a recipe, and the recording's local start and UTC offset.
pub fn recipe_timeline(r: &Recipe) -> Result<(EnfTimeline, f64, f64)> {
    let duration = r.config.duration_s;
    match &r.enf {
        EnfSource::Synthetic(grid) => {
            let (start, tz) = local_start(&r.start, None, 0.0)?;
            let seed = r.config.seed ^ 0x5eed;
            let t = EnfTimeline::synthetic(*grid, start, start + duration, seed);
            Ok((t, start, tz))
        }
        EnfSource::File {
            path,
            offset_s,
            index_step_s,
        } => {
            if !path.exists() {
                fail!(Simulation, "{}: no such file", path.display());
            }
            let (start, tz) = local_start(&r.start, Some(path), *offset_s)?;
            let t0 = start - offset_s;
            let t = match ReferenceSource::open(path)? {
                ReferenceSource::Wav(_) => EnfTimeline::wav(path, t0)?,
                ReferenceSource::Trace(_) => EnfTimeline::trace(path, *index_step_s, t0)?,
                _ => fail!(Simulation,
                    "{}: a mains WAV or a trace file is needed here (not a folder or a grid archive)",
                    path.display()
                ),
            };
            Ok((t, start, tz))
        }
    }
}

/// Simulates a recipe: the recording with its truth and sidecar, its videos and references.
pub fn simulate_recording(r: &Recipe, progress: &Progress) -> Result<SimulatedRecording> {
    let (timeline, start, tz) = recipe_timeline(r)?;
    let config = SimConfig {
        start_us: ((start - tz) * 1e6).round() as i64,
        ..r.config.clone()
    };
    config.check().map_err(|e| error!(Simulation, "{e}"))?;
    let mains = timeline.phase(start, config.duration_s)?;
    let extra = serde_json::json!({
        "enf": timeline.describe(),
        "local_start": start,
        "utc_offset_s": tz,
    });
    let sim = write_recording(&config, &mains, &r.output, r.format, extra, progress)?;
    let mut videos = Vec::new();
    let mut notes = Vec::new();
    for camera in &r.cameras {
        let v = write_video(&config, camera, &mains, &r.output, r.mp4, progress)?;
        videos.extend(v.files);
        notes.extend(v.note);
    }
    let references = match &r.reference_dir {
        Some(dir) => {
            timeline.write_references(dir, start, start + config.duration_s, config.seed)?
        }
        None => Vec::new(),
    };
    Ok(SimulatedRecording {
        sim,
        config,
        local_start: start,
        videos,
        references,
        notes,
    })
}
