//! The EV-ENFD layout: recordings `dvSave-YYYY_MM_DD_HH_MM_SS.*` (local start time), hourly
//! references `YYYY_MM_DD_Day_HH_00_00.wav`, and the plan of a simulated dataset (classes,
//! scenes, lamps and start times of its recordings).

use eenf_core::spelling::option;
use std::path::{Path, PathBuf};

use crate::error::{fail, rule, Context, Result};
use eenf_sim::{Lamp, LampKind, Readout, SceneKind, SimConfig};
use rand::{Rng, SeedableRng};

use crate::time::LocalTime;

/// The dataset's recording name, `dvSave-YYYY_MM_DD_HH_MM_SS.<ext>`.
pub fn recording_name(t: &LocalTime, ext: &str) -> String {
    format!(
        "dvSave-{}_{:02}_{:02}_{:02}.{ext}",
        t.date(),
        t.hour(),
        t.minute(),
        t.second()
    )
}

/// The dataset's name of the hourly reference holding `t`, `YYYY_MM_DD_Day_HH_00_00.wav`.
pub fn reference_name(t: &LocalTime) -> String {
    format!("{}_{}_{:02}_00_00.wav", t.date(), t.weekday(), t.hour())
}

/// Finds `dvSave-YYYY_MM_DD_HH_MM_SS` in a path's file name.
pub fn recording_start(path: &Path) -> Option<LocalTime> {
    let name = path.file_name()?.to_str()?;
    let i = name.find("dvSave-")?;
    let d: Vec<i16> = name[i + 7..]
        .split(['_', '.', '-'])
        .take(6)
        .map(|s| s.parse().ok())
        .collect::<Option<Vec<i16>>>()?;
    if d.len() < 6 || d[1..].iter().any(|&v| !(0..=99).contains(&v)) {
        return None;
    }
    LocalTime::new(
        d[0], d[1] as i8, d[2] as i8, d[3] as i8, d[4] as i8, d[5] as i8,
    )
}

/// The start time of an hourly reference named `YYYY_MM_DD_Day_HH_00_00.wav`.
pub fn reference_hour(path: &Path) -> Option<LocalTime> {
    let stem = path.file_stem()?.to_str()?;
    let parts: Vec<&str> = stem.split('_').collect();
    if parts.len() != 7 {
        return None;
    }
    let n = |s: &str| s.parse::<i8>().ok();
    LocalTime::new(
        parts[0].parse().ok()?,
        n(parts[1])?,
        n(parts[2])?,
        n(parts[4])?,
        n(parts[5])?,
        n(parts[6])?,
    )
}

/// The hourly reference WAVs of a folder, sorted by time.
pub fn hourly_references(dir: &Path) -> Result<Vec<(LocalTime, PathBuf)>> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(|| format!("{}", dir.display()))? {
        let p = entry?.path();
        if p.extension()
            .and_then(|e| e.to_str())
            .map(|e| e.eq_ignore_ascii_case("wav"))
            != Some(true)
        {
            continue;
        }
        if let Some(t) = reference_hour(&p) {
            out.push((t, p));
        }
    }
    out.sort();
    if out.is_empty() {
        fail!(
            Input,
            "{}: no hourly reference WAVs named like 2022_08_17_Wed_16_00_00.wav",
            dir.display()
        );
    }
    Ok(out)
}

/// One recording of a simulated dataset.
#[derive(Debug, Clone)]
pub struct PlannedRecording {
    /// Its class folder: `static`, `dynamic` or `extreme`.
    pub class: &'static str,
    /// Its scene kinds.
    pub kinds: Vec<SceneKind>,
    /// Local start time, seconds since 1970-01-01 00:00 local.
    pub local_start: i64,
    /// The simulation.
    pub config: SimConfig,
}

/// What a simulated dataset is made of.
#[derive(Debug, Clone)]
pub struct DatasetSpec {
    /// `ev-enfd` (51 recordings of 180 s), `small` (9 of 120 s) or `lamp-spot` (80 of 40 s:
    /// eight cameras, ten recordings each, where the flicker lives in a lamp's pool).
    pub preset: String,
    /// Recording length, s (default: the preset's).
    pub duration_s: Option<f64>,
    /// Sensor resolution (default: the preset's).
    pub resolution: Option<(u16, u16)>,
    /// Sensor readout.
    pub readout: Readout,
    /// UTC offset of the recordings' local names, s.
    pub tz_s: f64,
    /// Seed of the whole dataset.
    pub seed: u64,
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

/// One camera of the `lamp-spot` preset: its class folder, readout and sensor side, and the
/// range of the lamp's gain in its pool (log-uniform), set so that the flicker line's
/// prominence spreads over about 6–60, the real recordings' 10–20 among them.
pub struct LampSpotClass {
    /// The class folder.
    pub name: &'static str,
    /// The camera's readout.
    pub readout: fn() -> Readout,
    /// The sensor's side, pixels.
    pub side: u16,
    /// The lamp's gain in its pool, lowest and highest.
    pub gain: (f64, f64),
}

/// Whether a preset's manifest scores each recording against its simulated truth (`lamp-spot`:
/// short recordings, where the hourly references' own tracking error would dominate) rather
/// than the hourly mains references, as the EV-ENFD does.
pub fn scored_against_truth(preset: &str) -> bool {
    preset == "lamp-spot"
}

/// Recordings per camera of the `lamp-spot` preset.
pub const LAMP_SPOT_SEEDS: usize = 10;

/// The cameras of the `lamp-spot` preset: DVS128-like and Prophesee readouts (each event its
/// own µs timestamp) at 16×16 to 128×128. A smaller sensor has fewer pixels in the pool, so it
/// needs a brighter pool for the same prominence.
pub const LAMP_SPOT_CLASSES: [LampSpotClass; 8] = {
    const fn c(
        name: &'static str,
        readout: fn() -> Readout,
        side: u16,
        gain: (f64, f64),
    ) -> LampSpotClass {
        LampSpotClass {
            name,
            readout,
            side,
            gain,
        }
    }
    [
        c("dvs128-16", Readout::dvs128, 16, (11e3, 19e3)),
        c("dvs128-32", Readout::dvs128, 32, (10e3, 17e3)),
        c("dvs128-64", Readout::dvs128, 64, (8e3, 13e3)),
        c("dvs128-128", Readout::dvs128, 128, (8e3, 12e3)),
        c("prophesee-16", Readout::prophesee, 16, (11e3, 19e3)),
        c("prophesee-32", Readout::prophesee, 32, (10e3, 17e3)),
        c("prophesee-64", Readout::prophesee, 64, (8e3, 13e3)),
        c("prophesee-128", Readout::prophesee, 128, (8e3, 12e3)),
    ]
};

/// Makes `config` a camera of the `lamp-spot` preset: a room lit by daylight where only the
/// lamp's pool (5 % of the view) flickers enough to fire pixels, a person walking by, and a
/// DVS128's background activity (0.3 events/s per pixel).
fn lamp_spot_camera(config: &mut SimConfig, class: &LampSpotClass, r: &mut rand::rngs::StdRng) {
    config.width = class.side;
    config.height = class.side;
    config.readout = (class.readout)();
    let (lo, hi): (f64, f64) = class.gain;
    let gain = (lo.ln() + r.gen::<f64>() * (hi / lo).ln()).exp();
    if let Some(b) = config.scene.bulb.as_mut() {
        b.gain = gain;
    }
    config.pixel.shot_noise_hz = 0.3;
    config.pixel.shot_noise_max_hz = 5.0;
    // one LED lamp and one threshold: the gain alone sets how strongly the pool flickers
    config.pixel.threshold = 0.2;
    config.lamps = vec![Lamp {
        kind: LampKind::Led {
            depth: r.gen_range(0.4..0.6),
            sharpness: 1.0,
            smoothing_ms: r.gen_range(0.1..0.6),
        },
        phase_deg: 0.0,
        share: 1.0,
    }];
}

/// Recordings of a preset: (class, scene kinds) each.
type Classes = Vec<(&'static str, Vec<SceneKind>)>;

/// The classes and scene kinds of a preset, and its recording length and resolution.
fn preset(name: &str) -> Result<(Classes, f64, (u16, u16))> {
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
    let (n, duration) = match name {
        "ev-enfd" => ([16, 25, 10], 180.0),
        "small" => ([3, 3, 3], 120.0),
        "lamp-spot" => {
            let plans = LAMP_SPOT_CLASSES
                .iter()
                .flat_map(|c| cycle(c.name, LAMP_SPOT_SEEDS, &[&[LampSpot]]))
                .collect();
            return Ok((plans, 40.0, (64, 64)));
        }
        other => {
            return Err(rule(
                "preset",
                format!(
                    "{} {other:?}: expected ev-enfd, small or lamp-spot",
                    option("preset")
                ),
            )
            .into())
        }
    };
    let mut plans = cycle("static", n[0], &[&[Static]]);
    plans.extend(cycle("dynamic", n[1], dynamic));
    plans.extend(cycle("extreme", n[2], extreme));
    Ok((plans, duration, (48, 36)))
}

/// The recordings of a dataset whose ENF covers local times `from..to`: start times spread
/// over the coverage (distinct whole seconds, 30 s from its ends; one may run across an hour,
/// the references continue in the next file), lamps, light and sensor biases drawn from
/// the seed.
pub fn plan_dataset(
    spec: &DatasetSpec,
    (from, to): (f64, f64),
) -> Result<(Vec<PlannedRecording>, f64)> {
    let (classes, preset_duration, preset_res) = preset(&spec.preset)?;
    let duration = spec.duration_s.unwrap_or(preset_duration);
    if !(20.0..=3600.0).contains(&duration) {
        return Err(rule(
            "duration",
            format!("{} must be between 20 and 3600 s", option("duration")),
        )
        .into());
    }
    let (width, height) = spec.resolution.unwrap_or(preset_res);
    let (lo, hi) = (from.ceil() as i64 + 30, (to - duration).floor() as i64 - 30);
    if hi <= lo + classes.len() as i64 {
        fail!(
            Input,
            "the ENF covers {:.0} s, too little for {} recordings of {duration} s",
            to - from,
            classes.len()
        );
    }
    let mut rng = rand::rngs::StdRng::seed_from_u64(spec.seed);
    let mut starts: Vec<i64> = Vec::new();
    while starts.len() < classes.len() {
        let s = rng.gen_range(lo..hi);
        if starts.iter().all(|&t| (t - s).abs() > 5) {
            starts.push(s);
        }
    }
    let plans = classes
        .into_iter()
        .zip(starts)
        .enumerate()
        .map(|(i, ((class, kinds), local_start))| {
            let seed = spec.seed.wrapping_mul(1000).wrapping_add(i as u64);
            let mut r = rand::rngs::StdRng::seed_from_u64(seed ^ 0x1a4b);
            let mut config = SimConfig {
                width,
                height,
                duration_s: duration,
                start_us: ((local_start as f64 - spec.tz_s) * 1e6) as i64,
                seed,
                lamps: random_lamps(&mut r),
                ambient: r.gen_range(0.05..0.35),
                illumination: r.gen_range(0.5..2.0),
                readout: spec.readout.clone(),
                ..SimConfig::default()
            }
            .with_kinds(&kinds);
            // a little variety in the sensor's bias settings
            config.pixel.threshold = r.gen_range(0.17..0.25);
            if let Some(c) = LAMP_SPOT_CLASSES.iter().find(|c| c.name == class) {
                lamp_spot_camera(&mut config, c, &mut r);
            }
            if kinds.contains(&SceneKind::ExtremeDim) {
                // night scenes from ~1 to ~6 lux on a white wall
                config.illumination = r.gen_range(0.004..0.02);
            }
            PlannedRecording {
                class,
                kinds,
                local_start,
                config,
            }
        })
        .collect();
    Ok((plans, duration))
}

/// `path` relative to `base` (with `/`), for the manifest.
pub fn relative(base: &Path, path: &Path) -> String {
    path.strip_prefix(base)
        .unwrap_or(path)
        .to_string_lossy()
        .replace('\\', "/")
}

/// The file `simulate-dataset` keeps in a dataset folder while it builds it: a folder that
/// holds it was left half-built (the run was killed) and is not scored.
pub const BUILDING_MARKER: &str = ".eenf-building";

/// Refuses a dataset (its folder, or a manifest in it) that `simulate-dataset` did not finish
/// building.
pub fn check_complete(dataset: &Path) -> Result<()> {
    let dir = if dataset.is_dir() {
        dataset
    } else {
        crate::output::folder_of(dataset)
    };
    if dir.join(BUILDING_MARKER).exists() {
        fail!(Input,
            "{}: simulate-dataset did not finish building this dataset (it holds {BUILDING_MARKER}); build it again",
            dir.display()
        );
    }
    Ok(())
}
