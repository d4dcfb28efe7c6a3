//! `eenf simulate-dataset`: a synthetic EV-ENFD, laid out like the paper's dataset.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use eenf::dataset::{
    plan_dataset, recording_name, reference_name, relative, scored_against_truth, DatasetSpec,
    PlannedRecording, BUILDING_MARKER,
};
use eenf::output::{write_atomic, InProgress};
use eenf::progress::Progress;
use eenf::simulation::{write_recording, write_video, EnfTimeline};
use eenf::time::{tz_offset, LocalTime};
use eenf_events::writers::OutputFormat;
use eenf_events::Compression;

use crate::args::{one_of, VideoArgs};
use eenf::options::simulate::{parse_readout, parse_resolution};

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

/// Local seconds of `2022-08-17T16` (date and hour, minutes optional).
fn parse_local_hour(s: &str) -> Result<i64> {
    let bad =
        || anyhow::anyhow!("--start {s:?}: expected a local date and hour like 2022-08-17T16");
    let (date, hour) = s.split_once(['T', ' ']).ok_or_else(bad)?;
    let d: Vec<i16> = date
        .split('-')
        .map(|p| p.parse().map_err(|_| bad()))
        .collect::<Result<_>>()?;
    let h: i8 = hour
        .split(':')
        .next()
        .and_then(|h| h.parse().ok())
        .ok_or_else(bad)?;
    if d.len() != 3 || !(1..=12).contains(&d[1]) || !(1..=31).contains(&d[2]) {
        return Err(bad());
    }
    let t = LocalTime::new(d[0], d[1] as i8, d[2] as i8, h, 0, 0).ok_or_else(bad)?;
    Ok(t.local_seconds())
}

/// Runs `eenf simulate-dataset`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    let spec = DatasetSpec {
        preset: a.preset.clone(),
        duration_s: a.duration,
        resolution: a.resolution.as_deref().map(parse_resolution).transpose()?,
        readout: parse_readout(&a.readout)?,
        tz_s: tz_offset(&a.tz)?,
        seed: a.seed,
    };
    let codec = a.compression;
    let cameras = a.video.cameras()?;
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
    let (plans, duration) = plan_dataset(&spec, timeline.coverage()?)?;

    // a folder made here is removed if the run fails or is interrupted; one that existed is
    // marked as being built until the manifest is written, so that a half-built tree is
    // never scored
    let made = (!a.out_dir.exists()).then(|| InProgress::new(&a.out_dir));
    std::fs::create_dir_all(&a.out_dir).with_context(|| format!("{}", a.out_dir.display()))?;
    let marker = a.out_dir.join(BUILDING_MARKER);
    std::fs::write(&marker, "simulate-dataset is building this folder\n")
        .with_context(|| format!("{}", marker.display()))?;
    for done in ["manifest.csv", "dataset.json"] {
        let _ = std::fs::remove_file(a.out_dir.join(done));
    }
    let built = build(
        &a, &spec, &timeline, &plans, duration, &cameras, codec, &progress,
    );
    if built.is_err() {
        if made.is_some() {
            let _ = std::fs::remove_dir_all(&a.out_dir);
        }
        return built;
    }
    std::fs::remove_file(&marker).with_context(|| format!("{}", marker.display()))?;
    drop(made);
    Ok(())
}

/// Writes the dataset's recordings, references, manifest and summary into `a.out_dir`.
#[allow(clippy::too_many_arguments)]
fn build(
    a: &Args,
    spec: &DatasetSpec,
    timeline: &EnfTimeline,
    plans: &[PlannedRecording],
    duration: f64,
    cameras: &[eenf_sim::CameraConfig],
    codec: Compression,
    progress: &Progress,
) -> Result<()> {
    let tz = spec.tz_s;
    let (width, height) = (plans[0].config.width, plans[0].config.height);
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
    for plan in plans {
        let dir = a.out_dir.join(plan.class);
        std::fs::create_dir_all(&dir).with_context(|| format!("{}", dir.display()))?;
        let t = LocalTime::from_local_seconds(plan.local_start);
        let path = dir.join(recording_name(&t, "aedat4"));
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
        // the flicker line's prominence: what the realistic scenes are calibrated by
        let line = eenf::extract::grid_line(&path, &Default::default(), timeline.nominal_hz())?;
        let prominence = line.map_or(String::new(), |l| format!("{:.2}", l.prominence));
        let (reference, offset_s) = if scored_against_truth(&a.preset) {
            (relative(&a.out_dir, &sim.truth), 0)
        } else {
            (
                relative(&a.out_dir, &ref_dir.join(reference_name(&t))),
                t.second_of_hour(),
            )
        };
        let mut videos = Vec::new();
        for camera in cameras {
            let hidden = Progress::hidden();
            let v = write_video(&plan.config, camera, &mains, &path, a.video.mp4, &hidden)?;
            for f in &v.files {
                videos.push(relative(&a.out_dir, f));
            }
            if let Some(n) = v.note {
                eprintln!("note: {n}");
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
            "{},{},{},{},{},{},{},{},{},{},{}",
            relative(&a.out_dir, &path),
            plan.class,
            reference,
            offset_s,
            videos.join(";"),
            kinds.join("+"),
            lamps.join("+"),
            duration,
            plan.config.seed,
            sim.stats.events,
            prominence
        ));
        bar.inc(1);
    }
    bar.finish_and_clear();
    write_atomic(&a.out_dir.join("manifest.csv"), |w| {
        writeln!(
            w,
            "recording,class,reference,offset_s,videos,scene,lamps,duration_s,seed,events,prominence"
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
    // the names carry local times without their zone, as the data set's do: say which
    eprintln!(
        "file names are in local time at UTC{} (--tz; give the same to `match` and `refdb build`)",
        a.tz
    );
    Ok(())
}
