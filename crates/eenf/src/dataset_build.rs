//! Building a simulated dataset (`simulate-dataset`, Python's `simulate_dataset`) from its
//! plan ([`crate::dataset`]) and the simulator ([`crate::simulation`]): every
//! planned recording written with its truth, videos and metadata, the hourly references that
//! cover them, `manifest.csv` and `dataset.json`, into a folder that is never left half-built.

use std::path::{Path, PathBuf};

use crate::error::{rule, Context, Result};
use eenf_core::spelling::option;
use eenf_core::Grid;
use eenf_events::writers::OutputFormat;
use eenf_events::Compression;
use eenf_sim::CameraConfig;

use crate::dataset::{
    plan_dataset, recording_name, reference_name, relative, scored_against_truth, DatasetSpec,
    PlannedRecording, BUILDING_MARKER,
};
use crate::output::{write_atomic, InProgress};
use crate::progress::Progress;
use crate::simulation::{write_recording, write_video, EnfTimeline};
use crate::time::LocalTime;

/// Where a simulated dataset's ENF comes from.
#[derive(Debug, Clone)]
pub enum DatasetEnf {
    /// Real mains WAVs, hourly files named like `2022_08_17_Wed_16_00_00.wav` in this folder;
    /// they become the references.
    WavDir(PathBuf),
    /// A synthetic `grid` over six hours from `from_local_s` (local seconds); the
    /// references are synthesized.
    Synthetic {
        /// The grid.
        grid: Grid,
        /// Local seconds of the first hour.
        from_local_s: i64,
    },
}

/// A whole simulated dataset to build.
#[derive(Debug, Clone)]
pub struct DatasetBuild {
    /// The folder: `static/`, `dynamic/`, `extreme/`, `ENF_Reference/`, `manifest.csv`,
    /// `dataset.json`.
    pub out_dir: PathBuf,
    /// The preset, lengths, sensor, zone and seed.
    pub spec: DatasetSpec,
    /// Where the ENF comes from.
    pub enf: DatasetEnf,
    /// AEDAT4 packet compression.
    pub compression: Compression,
    /// Conventional cameras to render each recording's scene through.
    pub cameras: Vec<CameraConfig>,
    /// Also encode the videos as MP4 (ffmpeg).
    pub mp4: bool,
}

/// What a dataset build wrote.
#[derive(Debug, Clone)]
pub struct DatasetBuilt {
    /// The hourly reference WAVs.
    pub references: Vec<PathBuf>,
    /// The recordings written.
    pub recordings: usize,
    /// Events in all of them.
    pub events: u64,
    /// Seconds the recordings took.
    pub seconds: f64,
}

/// Local seconds of a local date and hour like `2022-08-17T16` (minutes, if any, ignored).
pub fn parse_local_hour(s: &str) -> Result<i64, crate::error::OptionError> {
    let bad = || {
        rule(
            "start",
            format!(
                "{} {s:?}: expected a local date and hour like 2022-08-17T16",
                option("start")
            ),
        )
    };
    let (date, hour) = s.split_once(['T', ' ']).ok_or_else(bad)?;
    let d: Vec<i16> = date
        .split('-')
        .map(|p| p.parse().map_err(|_| bad()))
        .collect::<Result<_, _>>()?;
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

/// Builds the dataset `b` asks for. A folder made here is removed if the build fails or is
/// interrupted; one that existed is marked as being built until the manifest is written, so
/// that a half-built tree is never scored. What the user should hear as it goes (where the
/// references went, a video without its MP4) goes to `note`.
pub fn build_dataset(
    b: &DatasetBuild,
    progress: &Progress,
    note: &mut dyn FnMut(String),
) -> Result<DatasetBuilt> {
    let timeline = match &b.enf {
        DatasetEnf::WavDir(dir) => EnfTimeline::wav_dir(dir)?,
        DatasetEnf::Synthetic { grid, from_local_s } => {
            let from = *from_local_s as f64;
            EnfTimeline::synthetic(*grid, from, from + 6.0 * 3600.0, b.spec.seed ^ 0xe4f)
        }
    };
    let (plans, duration) = plan_dataset(&b.spec, timeline.coverage()?)?;

    let made = (!b.out_dir.exists()).then(|| InProgress::new(&b.out_dir));
    std::fs::create_dir_all(&b.out_dir).with_context(|| format!("{}", b.out_dir.display()))?;
    let marker = b.out_dir.join(BUILDING_MARKER);
    std::fs::write(&marker, "simulate-dataset is building this folder\n")
        .with_context(|| format!("{}", marker.display()))?;
    for done in ["manifest.csv", "dataset.json"] {
        let _ = std::fs::remove_file(b.out_dir.join(done));
    }
    let built = write_dataset(b, &timeline, &plans, duration, progress, note);
    if built.is_err() {
        if made.is_some() {
            let _ = std::fs::remove_dir_all(&b.out_dir);
        }
        return built;
    }
    std::fs::remove_file(&marker).with_context(|| format!("{}", marker.display()))?;
    drop(made);
    built
}

/// Writes the dataset's recordings, references, manifest and summary into `b.out_dir`.
fn write_dataset(
    b: &DatasetBuild,
    timeline: &EnfTimeline,
    plans: &[PlannedRecording],
    duration: f64,
    progress: &Progress,
    note: &mut dyn FnMut(String),
) -> Result<DatasetBuilt> {
    let (out, tz) = (&b.out_dir, b.spec.tz_s);
    let (width, height) = (plans[0].config.width, plans[0].config.height);
    let ref_dir = out.join("ENF_Reference");
    let last_end = plans
        .iter()
        .map(|p| p.local_start as f64 + duration)
        .fold(f64::MIN, f64::max);
    let first_start = plans
        .iter()
        .map(|p| p.local_start as f64)
        .fold(f64::MAX, f64::min);
    let references =
        timeline.write_references(&ref_dir, first_start, last_end + 20.0, b.spec.seed)?;
    note(format!(
        "references: {} hourly WAVs in {}",
        references.len(),
        ref_dir.display()
    ));

    let bar = progress.steps(plans.len() as u64, "recordings");
    let started = std::time::Instant::now();
    let mut rows = Vec::new();
    let mut total_events = 0u64;
    for plan in plans {
        let (row, events) = write_one(b, timeline, plan, duration, &ref_dir, note)?;
        rows.push(row);
        total_events += events;
        bar.inc(1);
    }
    bar.finish_and_clear();
    write_atomic(&out.join("manifest.csv"), |w| {
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
        "preset": b.spec.preset,
        "recordings": plans.len(),
        "duration_s": duration,
        "resolution": [width, height],
        "enf": timeline.describe(),
        "nominal_hz": timeline.grid().hz(),
        "utc_offset_s": tz,
        "seed": b.spec.seed,
        "events": total_events,
        "videos": b.cameras,
        "seconds": started.elapsed().as_secs_f64(),
    });
    write_atomic(&out.join("dataset.json"), |w| {
        serde_json::to_writer_pretty(&mut *w, &summary)?;
        Ok(())
    })?;
    Ok(DatasetBuilt {
        references,
        recordings: plans.len(),
        events: total_events,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// Writes one planned recording with its videos; returns its manifest row and event count.
fn write_one(
    b: &DatasetBuild,
    timeline: &EnfTimeline,
    plan: &PlannedRecording,
    duration: f64,
    ref_dir: &Path,
    note: &mut dyn FnMut(String),
) -> Result<(String, u64)> {
    let out = &b.out_dir;
    let dir = out.join(plan.class);
    std::fs::create_dir_all(&dir).with_context(|| format!("{}", dir.display()))?;
    let t = LocalTime::from_local_seconds(plan.local_start);
    let path = dir.join(recording_name(&t, "aedat4"));
    let mains = timeline.phase(plan.local_start as f64, duration)?;
    let kinds: Vec<&str> = plan.kinds.iter().map(|k| k.name()).collect();
    let extra = serde_json::json!({
        "class": plan.class,
        "enf": timeline.describe(),
        "local_start": plan.local_start,
        "utc_offset_s": b.spec.tz_s,
    });
    let sim = write_recording(
        &plan.config,
        &mains,
        &path,
        OutputFormat::Aedat4(b.compression),
        extra,
        &Progress::hidden(),
    )?;
    // the flicker line's prominence: what the realistic scenes are calibrated by
    let line = crate::extract::grid_line(&path, &Default::default(), timeline.grid())?;
    let prominence = line.map_or(String::new(), |l| format!("{:.2}", l.prominence));
    let (reference, offset_s) = if scored_against_truth(&b.spec.preset) {
        (relative(out, &sim.truth), 0)
    } else {
        (
            relative(out, &ref_dir.join(reference_name(&t))),
            t.second_of_hour(),
        )
    };
    let mut videos = Vec::new();
    for camera in &b.cameras {
        let hidden = Progress::hidden();
        let v = write_video(&plan.config, camera, &mains, &path, b.mp4, &hidden)?;
        for f in &v.files {
            videos.push(relative(out, f));
        }
        if let Some(n) = v.note {
            note(format!("note: {n}"));
        }
    }
    let lamps: Vec<String> = plan
        .config
        .lamps
        .iter()
        .map(|l| {
            let name = serde_json::to_value(l.kind)
                .ok()
                .and_then(|v| v["kind"].as_str().map(str::to_string))
                .unwrap_or_else(|| "?".into());
            format!("{name}@{}", l.phase_deg)
        })
        .collect();
    let row = format!(
        "{},{},{},{},{},{},{},{},{},{},{}",
        relative(out, &path),
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
    );
    Ok((row, sim.stats.events))
}
