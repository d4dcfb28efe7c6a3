//! `eenf simulate-dataset`: a synthetic EV-ENFD, laid out like the paper's dataset.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use eenf_cli::dataset::StartTime;
use eenf_cli::output::write_atomic;
use eenf_cli::progress::Progress;
use eenf_cli::refdb::tz_offset;
use eenf_cli::simulation::{write_recording, write_video, EnfTimeline};
use eenf_events::writers::OutputFormat;
use eenf_sim::{Lamp, LampKind, Readout, SceneKind, SimConfig};
use rand::{Rng, SeedableRng};

use super::convert::parse_codec;
use super::simulate::{parse_resolution, VideoArgs};

/// Arguments of `eenf simulate-dataset`.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Folder to create: `static/`, `dynamic/`, `extreme/` with `dvSave-*.aedat4` recordings
    /// (and their `.truth.csv`, `.sim.json`, and with `--video` their `<stem>_lr.y4m` /
    /// `<stem>_hr.y4m`), `ENF_Reference/` with hourly WAVs,
    /// `manifest.csv` and `dataset.json`.
    pub out_dir: PathBuf,
    /// `ev-enfd`: 51 recordings of 180 s (16 static, 25 dynamic, 10 extreme, the paper's
    /// proportions); `small`: 9 recordings of 120 s (3 per class).
    #[arg(long, default_value = "ev-enfd")]
    pub preset: String,
    /// Drive the recordings with these real mains WAVs (hourly files named like
    /// `2022_08_17_Wed_16_00_00.wav`), which become the references. Without it the ENF is
    /// synthetic and the references are synthesized.
    #[arg(long)]
    pub enf_dir: Option<PathBuf>,
    /// Grid of a synthetic ENF: 50 or 60.
    #[arg(long, default_value_t = 50)]
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
    #[arg(long)]
    pub duration: Option<f64>,
    /// Readout: dvxplorer or prophesee.
    #[arg(long, default_value = "dvxplorer")]
    pub readout: String,
    /// AEDAT4 packet compression.
    #[arg(long, default_value = "lz4")]
    pub compression: String,
    /// Random seed of the whole dataset.
    #[arg(long, default_value_t = 2023)]
    pub seed: u64,
    #[command(flatten)]
    pub video: VideoArgs,
}

/// One planned recording.
struct Plan {
    class: &'static str,
    kinds: Vec<SceneKind>,
    local_start: i64,
    config: SimConfig,
}

/// A random lamp set: one to three lamps of the three kinds, on the phases of a three-phase
/// supply when there are several.
fn random_lamps(rng: &mut rand::rngs::StdRng) -> Vec<Lamp> {
    let count = match rng.gen_range(0..10) {
        0..=5 => 1,
        6..=8 => 2,
        _ => 3,
    };
    let phases = [0.0, 120.0, 240.0];
    let offset = rng.gen_range(0..3);
    (0..count)
        .map(|k| {
            let kind = match rng.gen_range(0..10) {
                0..=5 => LampKind::Led {
                    depth: rng.gen_range(0.35..0.6),
                    sharpness: [1.0, 1.0, 2.0][rng.gen_range(0..3)],
                    smoothing_ms: rng.gen_range(0.1..0.6),
                },
                6..=8 => LampKind::Incandescent {
                    tau_ms: rng.gen_range(8.0..20.0),
                },
                _ => LampKind::Fluorescent {
                    lag_rad: rng.gen_range(0.2..0.5),
                    dead: rng.gen_range(0.08..0.2),
                    phosphor_ms: rng.gen_range(0.8..2.5),
                },
            };
            Lamp {
                kind,
                phase_deg: if count > 1 {
                    phases[(offset + k) % 3]
                } else {
                    0.0
                },
                share: rng.gen_range(0.5..1.5),
            }
        })
        .collect()
}

/// Recordings of a preset: (class, scene kinds) each.
type Classes = Vec<(&'static str, Vec<SceneKind>)>;

/// The classes and scene kinds of a preset, and its recording length and resolution.
fn preset(name: &str) -> Result<(Classes, f64, &'static str)> {
    use SceneKind::*;
    let cycle = |class: &'static str, n: usize, kinds: &[&[SceneKind]]| {
        (0..n)
            .map(|i| (class, kinds[i % kinds.len()].to_vec()))
            .collect::<Vec<_>>()
    };
    let dynamic: &[&[SceneKind]] = &[
        &[DynamicObject],
        &[DynamicCamera],
        &[DynamicObject, DynamicCamera],
    ];
    let extreme: &[&[SceneKind]] = &[&[ExtremeDim], &[ExtremeBright]];
    let (n, duration, res) = match name {
        "ev-enfd" => ([16, 25, 10], 180.0, "48x36"),
        "small" => ([3, 3, 3], 120.0, "48x36"),
        other => bail!("--preset {other:?}: expected ev-enfd or small"),
    };
    let mut plans = cycle("static", n[0], &[&[Static]]);
    plans.extend(cycle("dynamic", n[1], dynamic));
    plans.extend(cycle("extreme", n[2], extreme));
    Ok((plans, duration, res))
}

/// Local seconds of `2022-08-17T16` (date and hour, minutes optional).
fn parse_local_hour(s: &str) -> Result<i64> {
    let bad =
        || anyhow::anyhow!("--start {s:?}: expected a local date and hour like 2022-08-17T16");
    let (date, hour) = s.split_once(['T', ' ']).ok_or_else(bad)?;
    let d: Vec<u32> = date
        .split('-')
        .map(|p| p.parse().map_err(|_| bad()))
        .collect::<Result<_>>()?;
    let h: u32 = hour
        .split(':')
        .next()
        .and_then(|h| h.parse().ok())
        .ok_or_else(bad)?;
    if d.len() != 3 || !(1..=12).contains(&d[1]) || !(1..=31).contains(&d[2]) || h > 23 {
        return Err(bad());
    }
    Ok(eenf_cli::pipeline::days_from_civil(d[0] as i64, d[1], d[2]) * 86_400 + h as i64 * 3600)
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    let (classes, preset_duration, preset_res) = preset(&a.preset)?;
    let duration = a.duration.unwrap_or(preset_duration);
    if !(20.0..=3600.0).contains(&duration) {
        bail!("--duration must be between 20 and 3600 s");
    }
    let (width, height) = parse_resolution(a.resolution.as_deref().unwrap_or(preset_res))?;
    let readout = Readout::named(&a.readout)
        .with_context(|| format!("--readout {:?}: expected dvxplorer or prophesee", a.readout))?;
    let codec = parse_codec(&a.compression)?;
    let cameras = a.video.cameras()?;
    let tz = tz_offset(&a.tz)?;

    let timeline = match &a.enf_dir {
        Some(dir) => EnfTimeline::wav_dir(dir)?,
        None => {
            if a.grid != 50 && a.grid != 60 {
                bail!("--grid must be 50 or 60");
            }
            let from = parse_local_hour(&a.start)? as f64;
            EnfTimeline::synthetic(a.grid as f64, from, from + 6.0 * 3600.0, a.seed ^ 0xe4f)
        }
    };
    let (from, to) = timeline.coverage()?;
    // recordings start at distinct whole seconds spread over the coverage, 30 s from its ends
    // (one may run across an hour: the references continue in the next file)
    let (lo, hi) = (from.ceil() as i64 + 30, (to - duration).floor() as i64 - 30);
    if hi <= lo + classes.len() as i64 {
        bail!(
            "the ENF covers {:.0} s, too little for {} recordings of {duration} s",
            to - from,
            classes.len()
        );
    }
    let mut rng = rand::rngs::StdRng::seed_from_u64(a.seed);
    let mut starts: Vec<i64> = Vec::new();
    while starts.len() < classes.len() {
        let s = rng.gen_range(lo..hi);
        if starts.iter().all(|&t| (t - s).abs() > 5) {
            starts.push(s);
        }
    }
    let plans: Vec<Plan> = classes
        .into_iter()
        .zip(starts)
        .enumerate()
        .map(|(i, ((class, kinds), local_start))| {
            let seed = a.seed.wrapping_mul(1000).wrapping_add(i as u64);
            let mut r = rand::rngs::StdRng::seed_from_u64(seed ^ 0x1a4b);
            let mut config = SimConfig {
                width,
                height,
                duration_s: duration,
                start_us: ((local_start as f64 - tz) * 1e6) as i64,
                seed,
                lamps: random_lamps(&mut r),
                ambient: r.gen_range(0.05..0.35),
                illumination: r.gen_range(0.5..2.0),
                readout: readout.clone(),
                ..SimConfig::default()
            }
            .with_kinds(&kinds);
            // a little variety in the sensor's bias settings
            config.pixel.threshold = r.gen_range(0.17..0.25);
            if kinds.contains(&SceneKind::ExtremeDim) {
                // night scenes from ~1 to ~6 lux on a white wall
                config.illumination = r.gen_range(0.004..0.02);
            }
            Plan {
                class,
                kinds,
                local_start,
                config,
            }
        })
        .collect();

    std::fs::create_dir_all(&a.out_dir).with_context(|| format!("{}", a.out_dir.display()))?;
    let ref_dir = a.out_dir.join("ENF_Reference");
    let last_end = plans
        .iter()
        .map(|p| p.local_start as f64 + duration)
        .fold(f64::MIN, f64::max);
    let first_start = plans
        .iter()
        .map(|p| p.local_start as f64)
        .fold(f64::MAX, f64::min);
    let references = timeline.write_references(&ref_dir, first_start, last_end + 20.0, a.seed)?;
    eprintln!(
        "references: {} hourly WAVs in {}",
        references.len(),
        ref_dir.display()
    );

    let bar = progress.steps(plans.len() as u64, "recordings");
    let started = std::time::Instant::now();
    let mut rows = Vec::new();
    let mut total_events = 0u64;
    for plan in &plans {
        let dir = a.out_dir.join(plan.class);
        std::fs::create_dir_all(&dir).with_context(|| format!("{}", dir.display()))?;
        let t = StartTime::from_local_seconds(plan.local_start);
        let path = dir.join(t.recording_name("aedat4"));
        let mains = timeline.phase(plan.local_start as f64, duration)?;
        let kinds: Vec<&str> = plan.kinds.iter().map(|k| k.name()).collect();
        let extra = serde_json::json!({
            "class": plan.class,
            "enf": timeline.describe(),
            "local_start": plan.local_start,
            "utc_offset_s": tz,
        });
        let sim = write_recording(
            &plan.config,
            &mains,
            &path,
            OutputFormat::Aedat4(codec),
            extra,
            &Progress::hidden(),
        )?;
        total_events += sim.stats.events;
        let mut videos = Vec::new();
        for camera in &cameras {
            let hidden = Progress::hidden();
            for v in write_video(&plan.config, camera, &mains, &path, a.video.mp4, &hidden)? {
                videos.push(rel(&a.out_dir, &v));
            }
        }
        let lamps: Vec<String> = plan
            .config
            .lamps
            .iter()
            .map(|l| {
                let name = serde_json::to_value(l.kind).unwrap()["kind"]
                    .as_str()
                    .unwrap_or("?")
                    .to_string();
                format!("{name}@{}", l.phase_deg)
            })
            .collect();
        rows.push(format!(
            "{},{},{},{},{},{},{},{},{},{}",
            rel(&a.out_dir, &path),
            plan.class,
            rel(&a.out_dir, &ref_dir.join(t.reference_name())),
            t.second_of_hour(),
            videos.join(";"),
            kinds.join("+"),
            lamps.join("+"),
            duration,
            plan.config.seed,
            sim.stats.events
        ));
        bar.inc(1);
    }
    bar.finish_and_clear();
    write_atomic(&a.out_dir.join("manifest.csv"), |w| {
        writeln!(
            w,
            "recording,class,reference,offset_s,videos,scene,lamps,duration_s,seed,events"
        )?;
        for r in &rows {
            writeln!(w, "{r}")?;
        }
        Ok(())
    })?;
    let summary = serde_json::json!({
        "preset": a.preset,
        "recordings": plans.len(),
        "duration_s": duration,
        "resolution": [width, height],
        "enf": timeline.describe(),
        "nominal_hz": timeline.nominal_hz(),
        "utc_offset_s": tz,
        "seed": a.seed,
        "events": total_events,
        "videos": cameras,
        "seconds": started.elapsed().as_secs_f64(),
    });
    write_atomic(&a.out_dir.join("dataset.json"), |w| {
        serde_json::to_writer_pretty(&mut *w, &summary)?;
        Ok(())
    })?;
    let secs = started.elapsed().as_secs_f64();
    eprintln!(
        "{} recordings ({} events, {:.1} M events/s) in {:.0} s -> {}",
        plans.len(),
        total_events,
        total_events as f64 / secs / 1e6,
        secs,
        a.out_dir.display()
    );
    Ok(())
}

/// `path` relative to `base` (with `/`), for the manifest.
fn rel(base: &Path, path: &Path) -> String {
    path.strip_prefix(base)
        .unwrap_or(path)
        .to_string_lossy()
        .replace('\\', "/")
}
