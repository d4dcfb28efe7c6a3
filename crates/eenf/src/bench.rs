//! Evaluating methods over a dataset, as the paper's Table 2 does: the recordings of an
//! EV-ENFD-like tree or a manifest, each traced by E-ENF and by V-ENF on its videos, scored
//! against its reference, and summarised per class and method.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use eenf_dsp::{spectrogram, EnfTrace, PeakMethod, SamplingMethod, Spectrogram};
use eenf_video::{video_enf, FrameSource, RowSampling, SceneRemoval, VideoOptions};
use serde::Serialize;

use crate::evaluate::{compare, Comparison, Reference};
use crate::output::{extraction_json, video_json};
use crate::pipeline::{extract_sequence, sample_file, ExtractOptions};
use crate::progress::Progress;

/// An ENF method and the data it reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum Method {
    /// E-ENF on the event recording.
    #[serde(rename = "e-enf")]
    EEnf,
    /// V-ENF on the low-resolution (webcam) video.
    #[serde(rename = "v-enf-lr")]
    VEnfLr,
    /// V-ENF on the high-resolution (phone) video.
    #[serde(rename = "v-enf-hr")]
    VEnfHr,
}

impl Method {
    /// Every method, in the paper's row order.
    pub const ALL: [Method; 3] = [Method::VEnfLr, Method::VEnfHr, Method::EEnf];

    /// `e-enf`, `v-enf-lr`, `v-enf-hr`.
    pub fn name(self) -> &'static str {
        match self {
            Method::EEnf => "e-enf",
            Method::VEnfLr => "v-enf-lr",
            Method::VEnfHr => "v-enf-hr",
        }
    }

    /// The data and method as the paper's Table 2 names them.
    pub fn label(self) -> &'static str {
        match self {
            Method::EEnf => "Events, E-ENF",
            Method::VEnfLr => "Video-LR, V-ENF",
            Method::VEnfHr => "Video-HR, V-ENF",
        }
    }

    /// Parses a comma-separated list.
    pub fn parse_list(s: &str) -> Result<Vec<Method>> {
        let mut out = Vec::new();
        for name in s.split(',').map(str::trim).filter(|n| !n.is_empty()) {
            let m = Method::ALL
                .into_iter()
                .find(|m| m.name() == name)
                .with_context(|| {
                    format!("--methods: unknown method {name:?} (e-enf, v-enf-lr, v-enf-hr)")
                })?;
            if !out.contains(&m) {
                out.push(m);
            }
        }
        if out.is_empty() {
            bail!("--methods: no method given");
        }
        out.sort_by_key(|m| Method::ALL.iter().position(|a| a == m));
        Ok(out)
    }

    /// The video suffix this method reads (`lr`, `hr`), if any.
    fn camera(self) -> Option<&'static str> {
        match self {
            Method::EEnf => None,
            Method::VEnfLr => Some("lr"),
            Method::VEnfHr => Some("hr"),
        }
    }
}

/// One class's cell of the paper's table: (class, mean CC, mean MAE in mHz).
pub type PaperCell = (&'static str, f64, f64);

/// The paper's Table 2 (mean CC, MAE in mHz; real EV-ENFD), per method and class.
pub const PAPER_TABLE2: [(Method, [PaperCell; 3]); 3] = [
    (
        Method::VEnfLr,
        [
            ("static", 0.6434, 13.7),
            ("dynamic", 0.3970, 24.2),
            ("extreme", 0.0557, 32.7),
        ],
    ),
    (
        Method::VEnfHr,
        [
            ("static", 0.8906, 6.2),
            ("dynamic", 0.7538, 11.1),
            ("extreme", 0.7602, 10.1),
        ],
    ),
    (
        Method::EEnf,
        [
            ("static", 0.9862, 1.9),
            ("dynamic", 0.9553, 2.1),
            ("extreme", 0.9867, 2.0),
        ],
    ),
];

/// The paper's (CC, MAE mHz) for a method and class.
pub fn paper_value(method: Method, class: &str) -> Option<(f64, f64)> {
    PAPER_TABLE2
        .iter()
        .find(|(m, _)| *m == method)
        .and_then(|(_, cells)| cells.iter().find(|c| c.0 == class))
        .map(|c| (c.1, c.2))
}

/// One recording of a dataset.
#[derive(Debug, Clone, Serialize)]
pub struct Recording {
    /// The event file.
    pub path: PathBuf,
    /// Its class (`static`, `dynamic`, `extreme`, or any folder name).
    pub class: String,
    /// Its reference: a folder of hourly WAVs, a WAV, or a trace.
    pub reference: PathBuf,
    /// Seconds into the reference where the recording starts (a WAV or trace reference).
    pub offset_s: f64,
    /// Its videos (`<stem>_lr.*`, `<stem>_hr.*`).
    pub videos: Vec<PathBuf>,
    /// Its length if the manifest says it, s (for the memory budget).
    pub duration_s: Option<f64>,
}

impl Recording {
    /// The recording's name for tables: `class/stem`.
    pub fn name(&self) -> String {
        let stem = self.path.file_stem().unwrap_or_default().to_string_lossy();
        format!("{}/{stem}", self.class)
    }

    /// Its video from camera `lr` or `hr`: the coded one (MP4, …) when there are several, as
    /// that is what a camera delivers; else the Y4M.
    pub fn video(&self, camera: &str) -> Option<&Path> {
        let suffix = format!("_{camera}");
        let mut found: Vec<&PathBuf> = self
            .videos
            .iter()
            .filter(|v| {
                v.file_stem()
                    .and_then(|s| s.to_str())
                    .is_some_and(|s| s.ends_with(&suffix))
            })
            .collect();
        found.sort_by_key(|v| is_y4m(v));
        found.first().map(|p| p.as_path())
    }
}

fn is_y4m(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("y4m"))
}

/// File extensions of event recordings looked for in a dataset tree.
const EVENT_EXTENSIONS: [&str; 5] = ["aedat4", "aedat", "raw", "dat", "evt"];
/// File extensions of videos looked for beside them.
const VIDEO_EXTENSIONS: [&str; 6] = ["y4m", "mp4", "mkv", "avi", "mov", "webm"];

fn has_extension(p: &Path, list: &[&str]) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| list.iter().any(|x| e.eq_ignore_ascii_case(x)))
}

/// The recordings of `dataset`: a manifest CSV, or a folder laid out like the EV-ENFD (one
/// folder per class holding event files and their `<stem>_lr.*`/`<stem>_hr.*` videos, and
/// `ENF_Reference/` with hourly WAVs).
pub fn discover(dataset: &Path) -> Result<Vec<Recording>> {
    if dataset.is_dir() {
        scan_tree(dataset)
    } else if dataset.is_file() {
        read_manifest(dataset)
    } else {
        bail!("{}: no such dataset folder or manifest", dataset.display())
    }
}

/// Class folders first in the paper's order, then the others alphabetically.
pub fn class_rank(class: &str) -> (usize, String) {
    let known = ["static", "dynamic", "extreme"];
    (
        known
            .iter()
            .position(|k| *k == class)
            .unwrap_or(known.len()),
        class.to_string(),
    )
}

fn scan_tree(dir: &Path) -> Result<Vec<Recording>> {
    let references = dir.join("ENF_Reference");
    if !references.is_dir() {
        bail!(
            "{}: no ENF_Reference folder (an EV-ENFD-like tree has one folder per class and ENF_Reference/ with the hourly WAVs; or pass a manifest CSV)",
            dir.display()
        );
    }
    let mut out = Vec::new();
    let mut classes: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("{}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir() && p.file_name() != Some("ENF_Reference".as_ref()))
        .filter(|p| {
            !p.file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .starts_with('.')
        })
        .collect();
    classes.sort();
    for class_dir in classes {
        let class = class_dir.file_name().unwrap().to_string_lossy().to_string();
        let mut files: Vec<PathBuf> = std::fs::read_dir(&class_dir)
            .with_context(|| format!("{}", class_dir.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_file())
            .collect();
        files.sort();
        for f in files.iter().filter(|f| has_extension(f, &EVENT_EXTENSIONS)) {
            let stem = f
                .file_stem()
                .unwrap_or_default()
                .to_string_lossy()
                .to_string();
            let videos = files
                .iter()
                .filter(|v| has_extension(v, &VIDEO_EXTENSIONS))
                .filter(|v| {
                    let s = v.file_stem().unwrap_or_default().to_string_lossy();
                    s == format!("{stem}_lr") || s == format!("{stem}_hr")
                })
                .cloned()
                .collect();
            out.push(Recording {
                path: f.clone(),
                class: class.clone(),
                reference: references.clone(),
                offset_s: 0.0,
                videos,
                duration_s: None,
            });
        }
    }
    if out.is_empty() {
        bail!(
            "{}: no event recordings ({}) in its class folders",
            dir.display(),
            EVENT_EXTENSIONS.join(", ")
        );
    }
    out.sort_by(|a, b| {
        class_rank(&a.class)
            .cmp(&class_rank(&b.class))
            .then(a.path.cmp(&b.path))
    });
    Ok(out)
}

/// Reads a manifest: a CSV with a header holding at least `recording`, `class` and
/// `reference`, and optionally `offset_s` (seconds into the reference) and `videos`
/// (`;`-separated). Paths are relative to the manifest's folder.
pub fn read_manifest(path: &Path) -> Result<Vec<Recording>> {
    let base = path.parent().unwrap_or(Path::new("."));
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .with_context(|| format!("{}", path.display()))?;
    let headers = reader
        .headers()
        .with_context(|| format!("{}: no CSV header", path.display()))?
        .clone();
    let col = |name: &str| headers.iter().position(|h| h == name);
    let (Some(rec_c), Some(class_c), Some(ref_c)) =
        (col("recording"), col("class"), col("reference"))
    else {
        bail!(
            "{}: a manifest needs the columns recording, class, reference (and optionally offset_s, videos); found {:?}",
            path.display(),
            headers.iter().collect::<Vec<_>>()
        );
    };
    let (off_c, vid_c, dur_c) = (col("offset_s"), col("videos"), col("duration_s"));
    let mut out = Vec::new();
    for (i, row) in reader.records().enumerate() {
        let line = i + 2;
        let row = row.with_context(|| format!("{}: line {line}", path.display()))?;
        let get = |c: usize| row.get(c).unwrap_or("").to_string();
        let field = |c: Option<usize>| c.map(get).unwrap_or_default();
        let recording = get(rec_c);
        if recording.is_empty() {
            bail!("{}: line {line}: empty recording", path.display());
        }
        let offset_s = match field(off_c).as_str() {
            "" => 0.0,
            s => s
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .with_context(|| {
                    format!(
                        "{}: line {line}: offset_s {s:?} is not a number",
                        path.display()
                    )
                })?,
        };
        let videos = field(vid_c)
            .split(';')
            .map(str::trim)
            .filter(|v| !v.is_empty())
            .map(|v| base.join(v))
            .collect();
        out.push(Recording {
            path: base.join(&recording),
            class: match get(class_c) {
                c if c.is_empty() => "unclassified".into(),
                c => c,
            },
            reference: base.join(get(ref_c)),
            offset_s,
            videos,
            duration_s: field(dur_c).parse().ok(),
        });
    }
    if out.is_empty() {
        bail!("{}: the manifest lists no recordings", path.display());
    }
    Ok(out)
}

/// The settings of one run over the dataset.
#[derive(Debug, Clone)]
pub struct Settings {
    /// What a `--sweep` set (key, value) for this run; empty for the defaults.
    pub label: Vec<(String, String)>,
    /// E-ENF options.
    pub extract: ExtractOptions,
    /// V-ENF options.
    pub video: VideoOptions,
}

impl Settings {
    /// `harmonics=2, peak=paper`, or `defaults`.
    pub fn describe(&self) -> String {
        if self.label.is_empty() {
            "defaults".into()
        } else {
            self.label
                .iter()
                .map(|(k, v)| format!("{k}={v}"))
                .collect::<Vec<_>>()
                .join(", ")
        }
    }

    /// Sets `key` to `value`.
    fn set(&mut self, key: &str, value: &str) -> Result<()> {
        let bad = || anyhow::anyhow!("--sweep {key}={value}: not a valid value");
        let p = &mut self.extract.params;
        match key {
            "harmonics" => p.harmonics = value.parse().ok().filter(|h| *h >= 1).ok_or_else(bad)?,
            "sampling" => {
                self.extract.sampling = match value {
                    "paper" => SamplingMethod::Paper,
                    "authors" => SamplingMethod::Authors,
                    "block" => SamplingMethod::Block,
                    _ => return Err(bad()),
                }
            }
            "peak" => {
                let peak = match value {
                    "exact" => PeakMethod::Exact,
                    "paper" => PeakMethod::Paper,
                    _ => return Err(bad()),
                };
                p.peak = peak;
                self.video.params.peak = peak;
            }
            "window" => {
                let w: f64 = value.parse().ok().filter(|w| *w > 0.0).ok_or_else(bad)?;
                p.window_s = w;
                self.video.params.window_s = w;
            }
            "dt-us" => {
                self.extract.dt_us = value
                    .parse()
                    .ok()
                    .filter(|d| (10..=1_000_000).contains(d))
                    .ok_or_else(bad)?
            }
            "selection" => {
                p.selection = match value {
                    "smoothest" => eenf_dsp::HarmonicSelection::Smoothest,
                    "consensus" => eenf_dsp::HarmonicSelection::Consensus(0.005),
                    _ => return Err(bad()),
                }
            }
            "segment" => p.segment_len = value.parse().ok().filter(|s| *s >= 1).ok_or_else(bad)?,
            "median-len" => p.median_len = value.parse().map_err(|_| bad())?,
            "scene-removal" => {
                self.video.scene_removal = SceneRemoval::parse(value).ok_or_else(bad)?
            }
            "video-sampling" => {
                self.video.sampling = match value {
                    "zero-pad" => RowSampling::ZeroPad(eenf_video::IdleRows::Auto),
                    "naive" => RowSampling::Naive,
                    "global" => RowSampling::Global,
                    _ => return Err(bad()),
                }
            }
            _ => bail!(
                "--sweep {key}: unknown setting (harmonics, sampling, peak, window, dt-us, selection, segment, median-len, scene-removal, video-sampling)"
            ),
        }
        self.label.push((key.to_string(), value.to_string()));
        Ok(())
    }
}

/// Parses `key=v1,v2,…` sweeps into every combination of `base` with those values (the first
/// sweep varies slowest).
pub fn sweep(base: &Settings, sweeps: &[String]) -> Result<Vec<Settings>> {
    let mut out = vec![base.clone()];
    for s in sweeps {
        let (key, values) = s
            .split_once('=')
            .with_context(|| format!("--sweep {s:?}: expected key=value,value,…"))?;
        let values: Vec<&str> = values
            .split(',')
            .map(str::trim)
            .filter(|v| !v.is_empty())
            .collect();
        if values.is_empty() {
            bail!("--sweep {s:?}: no values");
        }
        let mut next = Vec::new();
        for settings in &out {
            for v in &values {
                let mut s2 = settings.clone();
                s2.set(key.trim(), v)?;
                next.push(s2);
            }
        }
        out = next;
    }
    Ok(out)
}

/// Agreement of one trace with its reference.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Scores {
    /// Pearson correlation.
    pub cc: f64,
    /// Mean absolute error, Hz.
    pub mae_hz: f64,
    /// Root-mean-square error, Hz.
    pub rmse_hz: f64,
    /// Largest absolute error, Hz.
    pub max_err_hz: f64,
    /// Seconds compared.
    pub seconds: usize,
}

/// What a method gave on a recording, kept for plots and trace files.
#[derive(Debug, Clone)]
pub struct Details {
    /// The trace against its reference.
    pub comparison: Comparison,
    /// E-ENF's per-harmonic traces and selection.
    pub trace: Option<EnfTrace>,
    /// The polarity sequence's spectrogram around 2f0 (E-ENF, when plots are asked for).
    pub spectrogram: Option<Spectrogram>,
    /// Grid frequency used, Hz.
    pub nominal_hz: f64,
    /// The trace as `extract`/`video` write it in JSON.
    pub json: serde_json::Value,
}

/// One method on one recording.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Index of the recording in the dataset.
    pub recording: usize,
    /// The method.
    pub method: Method,
    /// Scores, or why there are none.
    pub result: std::result::Result<Scores, String>,
    /// Seconds the method took (tracing and scoring).
    pub run_s: f64,
    /// The traces, when scored.
    pub details: Option<Details>,
}

/// Runs `method` on `rec` with `settings`; `spectrum` also computes the E-ENF spectrogram.
/// Errors are caught into the outcome: one bad recording does not stop a benchmark.
pub fn evaluate(
    index: usize,
    rec: &Recording,
    method: Method,
    settings: &Settings,
    spectrum: bool,
) -> Outcome {
    let started = std::time::Instant::now();
    let res = run_method(rec, method, settings, spectrum);
    let run_s = started.elapsed().as_secs_f64();
    match res {
        Ok(d) => {
            let a = d.comparison.agreement;
            Outcome {
                recording: index,
                method,
                result: Ok(Scores {
                    cc: a.cc,
                    mae_hz: a.mae_hz,
                    rmse_hz: a.rmse_hz,
                    max_err_hz: a.max_err_hz,
                    seconds: a.n,
                }),
                run_s,
                details: Some(d),
            }
        }
        Err(e) => Outcome {
            recording: index,
            method,
            result: Err(format!("{e:#}")),
            run_s,
            details: None,
        },
    }
}

/// A method's trace, before it is scored.
struct Traced {
    /// The file traced (events or video).
    source: PathBuf,
    /// Seconds between estimates.
    step_s: f64,
    /// The ENF, Hz.
    enf_hz: Vec<f64>,
    /// Peak refinement used (the reference is traced with it).
    peak: PeakMethod,
    /// Grid the trace was made on.
    nominal_hz: f64,
    /// E-ENF's per-harmonic traces.
    trace: Option<EnfTrace>,
    /// E-ENF's spectrogram around 2f0.
    spectrogram: Option<Spectrogram>,
    /// The trace as `extract`/`video` write it.
    json: serde_json::Value,
}

/// E-ENF on the recording's events.
fn trace_events(rec: &Recording, s: &Settings, spectrum: bool) -> Result<Traced> {
    let hidden = Progress::hidden();
    let o = &s.extract;
    let (info, events, seq) = sample_file(&rec.path, o.sampling, o.dt_us, &hidden)?;
    let x = extract_sequence(&rec.path, info, events, &seq, o, &hidden)?;
    let f2 = 2.0 * x.params.nominal_hz;
    let spectrogram = spectrum.then(|| {
        let v: Vec<f64> = seq.values.iter().map(|&v| v as f64).collect();
        spectrogram(
            &v,
            seq.fs(),
            x.params.window_s,
            x.params.step_s,
            (f2 - 2.0, f2 + 2.0),
        )
    });
    Ok(Traced {
        source: rec.path.clone(),
        step_s: x.trace.step_s,
        enf_hz: x.trace.enf_hz.clone(),
        peak: x.params.peak,
        nominal_hz: x.params.nominal_hz,
        json: extraction_json(&x),
        trace: Some(x.trace),
        spectrogram,
    })
}

/// V-ENF on the recording's video from `camera`.
fn trace_video(rec: &Recording, camera: &str, s: &Settings) -> Result<Traced> {
    let path = rec.video(camera).with_context(|| {
        format!(
            "{}: no {camera} video beside it (<stem>_{camera}.y4m/.mp4/…)",
            rec.path.display()
        )
    })?;
    let mut source = FrameSource::open(path)?;
    let t = video_enf(&mut source, &s.video, |_| {})?;
    Ok(Traced {
        source: path.to_path_buf(),
        step_s: t.step_s,
        json: video_json(path, &t, &s.video),
        enf_hz: t.enf_hz,
        peak: s.video.params.peak,
        nominal_hz: t.nominal_hz,
        trace: None,
        spectrogram: None,
    })
}

fn run_method(rec: &Recording, method: Method, s: &Settings, spectrum: bool) -> Result<Details> {
    let t = match method.camera() {
        None => trace_events(rec, s, spectrum)?,
        Some(camera) => trace_video(rec, camera, s)?,
    };
    // the reference is traced as `compare` traces it for this trace: default tracker with the
    // trace's peak refinement
    let ref_params = eenf_dsp::EnfParams {
        peak: t.peak,
        ..eenf_dsp::EnfParams::default()
    };
    let (reference, offset) = Reference::resolve(&rec.reference, &rec.path, rec.offset_s)?;
    let comparison = compare(
        &crate::output::times(t.enf_hz.len(), t.step_s),
        &t.enf_hz,
        &t.source,
        &reference,
        offset,
        crate::pipeline::Nominal::Auto,
        &ref_params,
    )?;
    if let Some(f0) = comparison.nominal_hz {
        if f0 != t.nominal_hz {
            bail!(
                "{}: traced on a {} Hz grid, but the reference is on {f0} Hz (the flicker found is not the mains')",
                t.source.display(),
                t.nominal_hz
            );
        }
    }
    Ok(Details {
        comparison,
        trace: t.trace,
        spectrogram: t.spectrogram,
        nominal_hz: t.nominal_hz,
        json: t.json,
    })
}

/// Mean scores of one method over the recordings of one class.
#[derive(Debug, Clone, Serialize)]
pub struct ClassSummary {
    /// The class.
    pub class: String,
    /// The method.
    pub method: Method,
    /// Recordings scored.
    pub scored: usize,
    /// Recordings that failed.
    pub failed: usize,
    /// Mean CC over the scored recordings (NaN when none).
    pub cc: f64,
    /// Mean MAE, Hz.
    pub mae_hz: f64,
    /// Mean RMSE, Hz.
    pub rmse_hz: f64,
}

/// Means per class and method, classes in the paper's order.
pub fn summarize(
    recs: &[Recording],
    outcomes: &[Outcome],
    methods: &[Method],
) -> Vec<ClassSummary> {
    let mut classes: Vec<String> = recs.iter().map(|r| r.class.clone()).collect();
    classes.sort_by_key(|c| class_rank(c));
    classes.dedup();
    let mut out = Vec::new();
    for m in methods {
        for c in &classes {
            let of: Vec<&Outcome> = outcomes
                .iter()
                .filter(|o| o.method == *m && recs[o.recording].class == *c)
                .collect();
            let ok: Vec<Scores> = of
                .iter()
                .filter_map(|o| o.result.as_ref().ok().copied())
                .collect();
            let mean = |f: fn(&Scores) -> f64| {
                if ok.is_empty() {
                    f64::NAN
                } else {
                    ok.iter().map(f).sum::<f64>() / ok.len() as f64
                }
            };
            out.push(ClassSummary {
                class: c.clone(),
                method: *m,
                scored: ok.len(),
                failed: of.len() - ok.len(),
                cc: mean(|s| s.cc),
                mae_hz: mean(|s| s.mae_hz),
                rmse_hz: mean(|s| s.rmse_hz),
            });
        }
    }
    out
}

/// One run's results: its settings, the per-recording outcomes and the summary.
pub struct Run {
    /// The settings.
    pub settings: Settings,
    /// Every (recording, method), in dataset order.
    pub outcomes: Vec<Outcome>,
    /// Means per class and method.
    pub summary: Vec<ClassSummary>,
}

impl Run {
    /// The classes of the summary, in order, once each.
    pub fn classes(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for c in &self.summary {
            if !out.contains(&c.class) {
                out.push(c.class.clone());
            }
        }
        out
    }
}

fn fmt_cc(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.4}")
    } else {
        "—".into()
    }
}

fn fmt_mhz(v_hz: f64) -> String {
    if v_hz.is_finite() {
        format!("{:.2}", v_hz * 1e3)
    } else {
        "—".into()
    }
}

/// The Table 2 layout of one run: eenf's rows with the best per column in bold, the paper's
/// rows below.
pub fn markdown_table(run: &Run, methods: &[Method]) -> String {
    let classes = run.classes();
    let cell = |m: Method, c: &str| run.summary.iter().find(|s| s.method == m && s.class == c);
    let mut s = String::new();
    s.push_str(&format!(
        "### Table 2 layout: {}\n\n",
        run.settings.describe()
    ));
    s.push_str("| data, method |");
    for c in &classes {
        s.push_str(&format!(" {c} CC | {c} MAE (mHz) |"));
    }
    s.push_str("\n|---|");
    for _ in &classes {
        s.push_str("---|---|");
    }
    s.push('\n');
    // best per column among eenf's rows
    let best_cc = |c: &str| {
        methods
            .iter()
            .filter_map(|m| cell(*m, c).map(|x| x.cc))
            .filter(|v| v.is_finite())
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let best_mae = |c: &str| {
        methods
            .iter()
            .filter_map(|m| cell(*m, c).map(|x| x.mae_hz))
            .filter(|v| v.is_finite())
            .fold(f64::INFINITY, f64::min)
    };
    let bold = |text: String, best: bool| if best { format!("**{text}**") } else { text };
    for m in methods {
        s.push_str(&format!("| {} (eenf) |", m.label()));
        for c in &classes {
            match cell(*m, c) {
                Some(x) => {
                    let note = if x.failed > 0 {
                        format!(" ({}/{} failed)", x.failed, x.failed + x.scored)
                    } else {
                        String::new()
                    };
                    s.push_str(&format!(
                        " {}{note} | {} |",
                        bold(fmt_cc(x.cc), x.cc == best_cc(c)),
                        bold(fmt_mhz(x.mae_hz), x.mae_hz == best_mae(c))
                    ));
                }
                None => s.push_str(" — | — |"),
            }
        }
        s.push('\n');
    }
    for m in methods {
        s.push_str(&format!("| {} (paper, real EV-ENFD) |", m.label()));
        for c in &classes {
            match paper_value(*m, c) {
                Some((cc, mae)) => s.push_str(&format!(" *{cc:.4}* | *{mae:.1}* |")),
                None => s.push_str(" | |"),
            }
        }
        s.push('\n');
    }
    s
}

/// The Markdown report of one run: the Table 2 layout (eenf's rows with the best per column in
/// bold, the paper's rows below), the recordings scored and failed, the per-recording rows.
pub fn markdown_run(recs: &[Recording], run: &Run, methods: &[Method]) -> String {
    let mut s = markdown_table(run, methods);
    s.push_str("\nBold: best of eenf's rows per column. Means over the recordings scored; a recording where a method fails (no flicker found, no video, bad file) is counted as failed and left out of that mean.\n\n");
    s.push_str("| recording | method | CC | MAE (mHz) | RMSE (mHz) | max error (mHz) | seconds | run (s) | error |\n|---|---|---|---|---|---|---|---|---|\n");
    for o in &run.outcomes {
        let name = recs[o.recording].name();
        match &o.result {
            Ok(x) => s.push_str(&format!(
                "| {name} | {} | {} | {} | {} | {} | {} | {:.2} | |\n",
                o.method.name(),
                fmt_cc(x.cc),
                fmt_mhz(x.mae_hz),
                fmt_mhz(x.rmse_hz),
                fmt_mhz(x.max_err_hz),
                x.seconds,
                o.run_s
            )),
            Err(e) => s.push_str(&format!(
                "| {name} | {} | | | | | | {:.2} | {} |\n",
                o.method.name(),
                o.run_s,
                e.replace('|', "\\|")
            )),
        }
    }
    s.push('\n');
    s
}

/// The CSV header of `bench --csv`.
pub const CSV_HEADER: &str =
    "settings,recording,class,method,status,cc,mae_hz,rmse_hz,max_err_hz,seconds,run_s,error";

/// Writes the runs as CSV ([`CSV_HEADER`]): per run, one row per recording and method, then one
/// `mean` row per class and method (recording `mean:<class>`, seconds = recordings scored).
pub fn write_csv(w: &mut dyn std::io::Write, recs: &[Recording], runs: &[Run]) -> Result<()> {
    let mut out = csv::Writer::from_writer(w);
    out.write_record(CSV_HEADER.split(','))?;
    let num = |v: f64| {
        if v.is_finite() {
            format!("{v}")
        } else {
            String::new()
        }
    };
    for run in runs {
        let settings = run.settings.describe();
        for o in &run.outcomes {
            let r = &recs[o.recording];
            let (status, x, error) = match &o.result {
                Ok(x) => ("ok", Some(x), String::new()),
                Err(e) => ("failed", None, e.clone()),
            };
            let score = |f: fn(&Scores) -> f64| x.map(|x| num(f(x))).unwrap_or_default();
            out.write_record([
                settings.clone(),
                r.name(),
                r.class.clone(),
                o.method.name().to_string(),
                status.to_string(),
                score(|x| x.cc),
                score(|x| x.mae_hz),
                score(|x| x.rmse_hz),
                score(|x| x.max_err_hz),
                x.map(|x| x.seconds.to_string()).unwrap_or_default(),
                format!("{:.3}", o.run_s),
                error,
            ])?;
        }
        for c in &run.summary {
            out.write_record([
                settings.clone(),
                format!("mean:{}", c.class),
                c.class.clone(),
                c.method.name().to_string(),
                if c.scored > 0 { "ok" } else { "failed" }.to_string(),
                num(c.cc),
                num(c.mae_hz),
                num(c.rmse_hz),
                String::new(),
                c.scored.to_string(),
                String::new(),
                if c.failed > 0 {
                    format!("{} failed", c.failed)
                } else {
                    String::new()
                },
            ])?;
        }
    }
    out.flush()?;
    Ok(())
}

/// The JSON of a run.
pub fn json_run(recs: &[Recording], run: &Run) -> serde_json::Value {
    let rows: Vec<serde_json::Value> = run
        .outcomes
        .iter()
        .map(|o| {
            let r = &recs[o.recording];
            let mut v = serde_json::json!({
                "recording": r.name(),
                "path": r.path,
                "class": r.class,
                "method": o.method,
                "run_s": o.run_s,
            });
            match &o.result {
                Ok(x) => {
                    v["status"] = "ok".into();
                    v["scores"] = serde_json::to_value(x).unwrap_or_default();
                }
                Err(e) => {
                    v["status"] = "failed".into();
                    v["error"] = e.clone().into();
                }
            }
            v
        })
        .collect();
    let paper: Vec<serde_json::Value> = run
        .summary
        .iter()
        .filter_map(|c| {
            paper_value(c.method, &c.class).map(|(cc, mae)| {
                serde_json::json!({"method": c.method, "class": c.class, "cc": cc, "mae_hz": mae / 1e3})
            })
        })
        .collect();
    serde_json::json!({
        "settings": run.settings.describe(),
        "sweep": run.settings.label,
        "extract": {
            "sampling": run.settings.extract.sampling.name(),
            "dt_us": run.settings.extract.dt_us,
            "params": run.settings.extract.params,
        },
        "video": {
            "sampling": run.settings.video.sampling,
            "scene_removal": run.settings.video.scene_removal,
            "params": run.settings.video.params,
        },
        "summary": run.summary.iter().map(|c| serde_json::json!({
            "class": c.class, "method": c.method, "scored": c.scored, "failed": c.failed,
            "cc": c.cc.is_finite().then_some(c.cc),
            "mae_hz": c.mae_hz.is_finite().then_some(c.mae_hz),
            "rmse_hz": c.rmse_hz.is_finite().then_some(c.rmse_hz),
        })).collect::<Vec<_>>(),
        "paper": paper,
        "recordings": rows,
    })
}
