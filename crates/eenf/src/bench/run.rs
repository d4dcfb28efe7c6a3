//! Running methods on recordings: trace, score against the reference, summarise per class.

use crate::error::{fail, Context, Error, Missing, Result};
use eenf_dsp::{spectrogram, Agreement, Spectrogram};
use rayon::prelude::*;
use serde::Serialize;

use super::{class_rank, DatasetEntry, Method, Settings};
use crate::evaluate::{compare, Comparison, Reference};
use crate::extract::{extract_sampled, sample_file};
use crate::progress::Progress;
use crate::trace::Trace;
use eenf_core::Nominal;

/// What a method gave on a recording, kept for plots and trace files.
#[derive(Debug, Clone)]
pub struct Details {
    /// The trace against its reference.
    pub comparison: Comparison,
    /// The method's trace, with its per-harmonic parts and provenance.
    pub trace: Trace,
    /// The polarity sequence's spectrogram around 2f0 (E-ENF, when plots are asked for).
    pub spectrogram: Option<Spectrogram>,
}

/// One method on one recording.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Index of the recording in the dataset.
    pub recording: usize,
    /// The method.
    pub method: Method,
    /// Scores, or why there are none.
    pub result: std::result::Result<Agreement, String>,
    /// Seconds the method took (tracing and scoring).
    pub run_s: f64,
    /// The traces, when scored.
    pub details: Option<Details>,
}

/// Runs `method` on `rec` with `settings`; `spectrum` also computes the E-ENF spectrogram.
/// Errors are caught into the outcome: one bad recording does not stop a benchmark.
pub fn evaluate(
    index: usize,
    rec: &DatasetEntry,
    method: Method,
    settings: &Settings,
    spectrum: bool,
) -> Outcome {
    let started = std::time::Instant::now();
    let res = run_method(rec, method, settings, spectrum);
    let run_s = started.elapsed().as_secs_f64();
    match res {
        Ok(d) => Outcome {
            recording: index,
            method,
            result: Ok(d.comparison.agreement),
            run_s,
            details: Some(d),
        },
        Err(e) => Outcome {
            recording: index,
            method,
            result: Err(e.report()),
            run_s,
            details: None,
        },
    }
}

/// E-ENF on the recording's events.
fn trace_events(
    rec: &DatasetEntry,
    s: &Settings,
    spectrum: bool,
) -> Result<(Trace, Option<Spectrogram>)> {
    let hidden = Progress::hidden();
    let o = &s.extract;
    let sampled = sample_file(&rec.path, o, &hidden)?;
    let (signal, fs) = (
        spectrum.then(|| {
            sampled
                .seq
                .values
                .iter()
                .map(|&v| v as f64)
                .collect::<Vec<f64>>()
        }),
        sampled.seq.fs(),
    );
    let trace = extract_sampled(&rec.path, sampled, o, &hidden)?;
    let f2 = 2.0 * trace.nominal_hz.unwrap_or(o.params.nominal_hz);
    let window_s = trace
        .events()
        .map_or(o.params.window_s, |e| e.params.window_s);
    let spectrogram =
        signal.map(|v| spectrogram(&v, fs, window_s, o.params.step_s, (f2 - 2.0, f2 + 2.0)));
    Ok((trace, spectrogram))
}

/// V-ENF on the recording's video from `camera`.
fn trace_video(rec: &DatasetEntry, camera: &str, s: &Settings) -> Result<Trace> {
    let path = rec.video(camera).or_fail(Error::Input, || {
        format!(
            "{}: no {camera} video beside it (<stem>_{camera}.y4m/.mp4/…)",
            rec.path.display()
        )
    })?;
    crate::video::trace_video(path, &s.video, &Progress::hidden())
}

fn run_method(rec: &DatasetEntry, method: Method, s: &Settings, spectrum: bool) -> Result<Details> {
    let (t, spectrogram) = match method.camera() {
        None => trace_events(rec, s, spectrum)?,
        Some(camera) => (trace_video(rec, camera, s)?, None),
    };
    // the reference is traced as `compare` traces it for this trace: default tracker with the
    // trace's peak refinement
    let ref_params = eenf_dsp::EnfParams {
        peak: t.peak().unwrap_or(eenf_dsp::PeakMethod::Exact),
        ..eenf_dsp::EnfParams::default()
    };
    let source = t.file.clone().unwrap_or_else(|| rec.path.clone());
    let (reference, offset) = Reference::resolve(
        &rec.reference,
        &rec.path,
        rec.offset_s,
        crate::trace::INDEX_STEP_S,
    )?;
    let comparison = compare(
        &t.time_s,
        &t.enf_hz,
        &source,
        &reference,
        offset,
        Nominal::Auto,
        &ref_params,
    )?;
    let traced_on = t.nominal_hz.unwrap_or(f64::NAN);
    if let Some(f0) = comparison.nominal_hz {
        if f0 != traced_on {
            fail!(Method,
                "{}: traced on a {traced_on} Hz grid, but the reference is on {f0} Hz (the flicker found is not the mains')",
                source.display(),
            );
        }
    }
    Ok(Details {
        comparison,
        trace: t,
        spectrogram,
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
    recs: &[DatasetEntry],
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
            let ok: Vec<Agreement> = of
                .iter()
                .filter_map(|o| o.result.as_ref().ok().copied())
                .collect();
            let mean = |f: fn(&Agreement) -> f64| {
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

/// Recordings that fit the memory budget at once: the E-ENF sequence and its filtered copies
/// (~48 bytes a sample at 1/Δt), or a video's row means (2 × 8 bytes a row, up to 1080 rows
/// at 30 fps), whichever is larger; 600 s when the length is not known.
pub fn jobs_for(
    recs: &[DatasetEntry],
    settings: &[Settings],
    budget_mb: u64,
    asked: usize,
) -> usize {
    let longest = recs
        .iter()
        .map(|r| r.duration_s.unwrap_or(600.0))
        .fold(0.0, f64::max);
    let rate = settings
        .iter()
        .map(|s| 1e6 / s.extract.dt_us.unwrap_or(100) as f64)
        .fold(0.0, f64::max);
    let need = (longest * (rate * 48.0).max(1080.0 * 30.0 * 16.0)) / 1048576.0 + 64.0;
    ((budget_mb as f64 / need).floor() as usize).clamp(1, asked.max(1))
}

/// Runs every method on every recording under every setting, `jobs` recordings at a time;
/// `keep` keeps the traces of the first setting (all settings with `keep_all`), `spectrum`
/// computes its E-ENF spectrograms. One [`Run`] per setting, summarised.
#[allow(clippy::too_many_arguments)]
pub fn run_all(
    recs: &[DatasetEntry],
    methods: &[Method],
    settings: Vec<Settings>,
    jobs: usize,
    keep: bool,
    keep_all: bool,
    spectrum: bool,
    progress: &Progress,
) -> Result<Vec<Run>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .context("cannot start the worker threads")?;
    let tasks: Vec<(usize, usize)> = (0..settings.len())
        .flat_map(|s| (0..recs.len()).map(move |r| (s, r)))
        .collect();
    let bar = progress.steps(tasks.len() as u64, "recordings");
    let results: Vec<(usize, Vec<Outcome>)> = pool.install(|| {
        tasks
            .par_iter()
            .map(|&(s, r)| {
                // plots and spectrograms are drawn for the first setting only
                let spectrum = spectrum && s == 0;
                let outcomes = methods
                    .iter()
                    .map(|m| {
                        let mut o = evaluate(r, &recs[r], *m, &settings[s], spectrum);
                        if !keep || (s > 0 && !keep_all) {
                            o.details = None;
                        }
                        o
                    })
                    .collect();
                bar.inc(1);
                (s, outcomes)
            })
            .collect()
    });
    bar.finish_and_clear();
    let mut runs: Vec<Run> = settings
        .into_iter()
        .map(|s| Run {
            settings: s,
            outcomes: Vec::new(),
            summary: Vec::new(),
        })
        .collect();
    for (s, outcomes) in results {
        runs[s].outcomes.extend(outcomes);
    }
    for run in &mut runs {
        run.summary = summarize(recs, &run.outcomes, methods);
    }
    Ok(runs)
}
