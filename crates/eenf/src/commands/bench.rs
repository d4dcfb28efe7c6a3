//! `eenf bench`: the paper's Table 2 on a dataset, every method, with reports and plots.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use eenf_cli::bench::{
    discover, evaluate, json_run, markdown_run, markdown_table, paper_value, summarize, sweep,
    write_csv, Method, Outcome, Recording, Run, Settings,
};
use eenf_cli::output::write_atomic;
use eenf_cli::pipeline::Nominal;
use eenf_cli::plot::{
    plot_extraction, plot_methods, plot_spectrogram, plot_summary, Series, SummaryBar,
};
use eenf_cli::progress::Progress;
use eenf_video::{IdleRows, RowSampling, SceneRemoval, VideoOptions};
use rayon::prelude::*;

use super::method::MethodArgs;

/// Arguments of `eenf bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// An EV-ENFD-like folder (one folder per class with event files, optional
    /// `<stem>_lr.*`/`<stem>_hr.*` videos, and `ENF_Reference/` with hourly WAVs), or a
    /// manifest CSV (`recording,class,reference,offset_s,videos`, paths relative to it).
    pub dataset: PathBuf,
    /// Methods to run, comma-separated: e-enf, v-enf-lr, v-enf-hr.
    #[arg(long, default_value = "e-enf,v-enf-lr,v-enf-hr")]
    pub methods: String,
    /// Recordings processed at once (default: one per core, fewer if the memory budget says so).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Memory budget, MiB: bounds the recordings processed at once.
    #[arg(long, default_value_t = 4096)]
    pub memory_mb: u64,
    /// Write the Markdown report here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Write every number as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write every number as CSV here (one row per recording and method, then the means).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Write figures (PNG and SVG) into this folder: per recording, the methods against the
    /// reference, the per-harmonic traces, the spectrogram around 2f0; and a summary.
    #[arg(long)]
    pub plots: Option<PathBuf>,
    /// Write every trace (JSON, as `extract`/`video` write them) into this folder.
    #[arg(long)]
    pub traces: Option<PathBuf>,
    /// Ablation: `key=v1,v2,…` (repeatable); one table per combination. Keys: harmonics,
    /// sampling, peak, window, dt-us, selection, segment, median-len, scene-removal,
    /// video-sampling.
    #[arg(long)]
    pub sweep: Vec<String>,
    /// V-ENF scene removal: paper, row-mean, none.
    #[arg(long, default_value = "paper", value_parser = ["paper", "row-mean", "none"])]
    pub scene_removal: String,
    #[command(flatten)]
    pub method: MethodArgs,
}

/// Recordings that fit the memory budget at once: the E-ENF sequence and its filtered copies
/// (~48 bytes a sample at 1/Δt), or a video's row means (2 × 8 bytes a row, up to 1080 rows
/// at 30 fps), whichever is larger; 600 s when the length is not known.
fn jobs_for(recs: &[Recording], settings: &[Settings], budget_mb: u64, asked: usize) -> usize {
    let longest = recs
        .iter()
        .map(|r| r.duration_s.unwrap_or(600.0))
        .fold(0.0, f64::max);
    let rate = settings
        .iter()
        .map(|s| 1e6 / s.extract.dt_us as f64)
        .fold(0.0, f64::max);
    let need = (longest * (rate * 48.0).max(1080.0 * 30.0 * 16.0)) / 1048576.0 + 64.0;
    ((budget_mb as f64 / need).floor() as usize).clamp(1, asked.max(1))
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    let started = std::time::Instant::now();
    let methods = Method::parse_list(&a.methods)?;
    let recs = discover(&a.dataset)?;
    let extract = a.method.options()?;
    let video = VideoOptions {
        nominal_hz: match a.method.tracker.nominal {
            Nominal::Hz(f) => Some(f),
            Nominal::Auto => None,
        },
        sampling: RowSampling::ZeroPad(IdleRows::Auto),
        scene_removal: SceneRemoval::parse(&a.scene_removal).expect("checked by clap"),
        params: eenf_dsp::EnfParams {
            peak: extract.params.peak,
            window_s: extract.params.window_s,
            step_s: extract.params.step_s,
            half_band_hz: extract.params.half_band_hz,
            ..eenf_dsp::EnfParams::default()
        },
    };
    let base = Settings {
        label: Vec::new(),
        extract,
        video,
    };
    let settings = sweep(&base, &a.sweep)?;
    let cores = std::thread::available_parallelism().map_or(2, |n| n.get());
    let jobs = jobs_for(&recs, &settings, a.memory_mb, a.jobs.unwrap_or(cores));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .context("cannot start the worker threads")?;
    eprintln!(
        "{}: {} recordings, methods {}, {} setting{}, {jobs} at a time",
        a.dataset.display(),
        recs.len(),
        methods
            .iter()
            .map(|m| m.name())
            .collect::<Vec<_>>()
            .join(","),
        settings.len(),
        if settings.len() == 1 { "" } else { "s" }
    );
    let keep = a.plots.is_some() || a.traces.is_some();
    let tasks: Vec<(usize, usize)> = (0..settings.len())
        .flat_map(|s| (0..recs.len()).map(move |r| (s, r)))
        .collect();
    let bar = progress.steps(tasks.len() as u64, "recordings");
    let results: Vec<(usize, Vec<Outcome>)> = pool.install(|| {
        tasks
            .par_iter()
            .map(|&(s, r)| {
                // plots and spectrograms are drawn for the first setting only
                let spectrum = a.plots.is_some() && s == 0;
                let outcomes = methods
                    .iter()
                    .map(|m| {
                        let mut o = evaluate(r, &recs[r], *m, &settings[s], spectrum);
                        if !keep || (s > 0 && a.traces.is_none()) {
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
        run.summary = summarize(&recs, &run.outcomes, &methods);
    }
    let wall_s = started.elapsed().as_secs_f64();

    // the tables on stdout; failures on stderr
    for run in &runs {
        println!("{}", markdown_table(run, &methods));
        for o in run.outcomes.iter() {
            if let Err(e) = &o.result {
                eprintln!(
                    "failed: {} {}: {e}",
                    recs[o.recording].name(),
                    o.method.name()
                );
            }
        }
    }
    let scored: usize = runs
        .iter()
        .flat_map(|r| &r.outcomes)
        .filter(|o| o.result.is_ok())
        .count();
    let total: usize = runs.iter().map(|r| r.outcomes.len()).sum();
    eprintln!("{scored} of {total} traces scored in {wall_s:.1} s ({jobs} at a time)");

    if let Some(dir) = &a.traces {
        write_traces(dir, &recs, &runs)?;
        eprintln!("traces in {}", dir.display());
    }
    if let Some(dir) = &a.plots {
        let n = write_plots(dir, &recs, &runs, &methods, &progress)?;
        eprintln!("{n} figures in {}", dir.display());
    }
    if let Some(p) = &a.report {
        let md = report(&a, &recs, &runs, &methods, jobs, wall_s);
        write_atomic(p, |w| {
            w.write_all(md.as_bytes())?;
            Ok(())
        })?;
        eprintln!("report written to {}", p.display());
    }
    if let Some(p) = &a.csv {
        write_atomic(p, |w| write_csv(w, &recs, &runs))?;
        eprintln!("CSV written to {}", p.display());
    }
    if let Some(p) = &a.json {
        let v = serde_json::json!({
            "dataset": a.dataset,
            "recordings": recs.len(),
            "methods": methods,
            "jobs": jobs,
            "wall_s": wall_s,
            "runs": runs.iter().map(|r| json_run(&recs, r)).collect::<Vec<_>>(),
        });
        write_atomic(p, |w| {
            serde_json::to_writer_pretty(&mut *w, &v)?;
            writeln!(w)?;
            Ok(())
        })?;
        eprintln!("JSON written to {}", p.display());
    }
    if scored == 0 {
        bail!("no recording could be scored");
    }
    Ok(())
}

/// The whole Markdown report.
fn report(
    a: &Args,
    recs: &[Recording],
    runs: &[Run],
    methods: &[Method],
    jobs: usize,
    wall_s: f64,
) -> String {
    let mut s = format!(
        "# eenf bench: {}\n\n{} recordings, methods {}, {} setting(s); {wall_s:.1} s wall time with {jobs} at a time (eenf {}).\n\n",
        a.dataset.display(),
        recs.len(),
        methods.iter().map(|m| m.name()).collect::<Vec<_>>().join(", "),
        runs.len(),
        env!("CARGO_PKG_VERSION"),
    );
    if let (Some(plots), Some(report)) = (&a.plots, &a.report) {
        // the figure's path as seen from the report's folder
        let img = plots.join("summary.png");
        let base = report.parent().unwrap_or(Path::new(""));
        let shown = if base.as_os_str().is_empty() {
            img.clone()
        } else if let Ok(rel) = img.strip_prefix(base) {
            rel.to_path_buf()
        } else {
            std::fs::canonicalize(plots)
                .map(|p| p.join("summary.png"))
                .unwrap_or(img)
        };
        s.push_str(&format!(
            "![CC and MAE per class and method]({})\n\n",
            shown.display()
        ));
    }
    for run in runs {
        s.push_str(&markdown_run(recs, run, methods));
    }
    s.push_str("## Parameters\n\n");
    if let Some(run) = runs.first() {
        let e = &run.settings.extract;
        s.push_str(&format!(
            "- E-ENF: sampling `{}`, Δt {} µs, parameters `{}`\n",
            e.sampling.name(),
            e.dt_us,
            serde_json::to_string(&e.params).unwrap_or_default()
        ));
        let v = &run.settings.video;
        s.push_str(&format!(
            "- V-ENF: row sampling `{}`, scene removal `{}`, parameters `{}`\n",
            serde_json::to_string(&v.sampling).unwrap_or_default(),
            serde_json::to_string(&v.scene_removal).unwrap_or_default(),
            serde_json::to_string(&v.params).unwrap_or_default()
        ));
    }
    s.push_str("- References: traced as `eenf compare` traces them (default tracker, the estimate's peak refinement); recordings placed by their `dvSave-` name or the manifest's reference and offset, continuing into the next hour's WAV when they run past the hour.\n");
    if !a.sweep.is_empty() {
        s.push_str(&format!("- Sweeps: `{}`\n", a.sweep.join("` `")));
    }
    s.push_str("- Paper: Table 2 of *Seeing Electric Network Frequency from Events* (CVPR 2023), real EV-ENFD; italic rows.\n");
    s
}

fn stem(r: &Recording) -> String {
    r.path
        .file_stem()
        .unwrap_or_default()
        .to_string_lossy()
        .to_string()
}

/// The folder of run `k` inside `dir` (the folder itself when there is one run).
fn run_dir(dir: &Path, runs: &[Run], k: usize) -> PathBuf {
    if runs.len() == 1 {
        dir.to_path_buf()
    } else {
        dir.join(format!("run{}", k + 1))
    }
}

fn write_traces(dir: &Path, recs: &[Recording], runs: &[Run]) -> Result<()> {
    for (k, run) in runs.iter().enumerate() {
        for o in &run.outcomes {
            let Some(d) = &o.details else { continue };
            let r = &recs[o.recording];
            let folder = run_dir(dir, runs, k).join(&r.class);
            std::fs::create_dir_all(&folder).with_context(|| format!("{}", folder.display()))?;
            let path = folder.join(format!("{}.{}.json", stem(r), o.method.name()));
            write_atomic(&path, |w| {
                serde_json::to_writer_pretty(&mut *w, &d.json)?;
                writeln!(w)?;
                Ok(())
            })?;
        }
    }
    Ok(())
}

/// Writes each figure as PNG and SVG; returns how many files.
fn write_plots(
    dir: &Path,
    recs: &[Recording],
    runs: &[Run],
    methods: &[Method],
    progress: &Progress,
) -> Result<usize> {
    std::fs::create_dir_all(dir).with_context(|| format!("{}", dir.display()))?;
    let mut written = 0;
    // `name` has no extension yet (file names hold dots: NAME.methods.png)
    let both = |name: &Path, draw: &dyn Fn(&Path) -> Result<()>| -> Result<usize> {
        for ext in ["png", "svg"] {
            let mut file = name.as_os_str().to_os_string();
            file.push(".");
            file.push(ext);
            draw(Path::new(&file))?;
        }
        Ok(2)
    };
    let first = &runs[0];
    let bar = progress.steps(recs.len() as u64, "figures");
    for (i, r) in recs.iter().enumerate() {
        let mine: Vec<&Outcome> = first.outcomes.iter().filter(|o| o.recording == i).collect();
        let folder = dir.join(&r.class);
        std::fs::create_dir_all(&folder).with_context(|| format!("{}", folder.display()))?;
        let series: Vec<Series> = mine
            .iter()
            .filter_map(|o| {
                let d = o.details.as_ref()?;
                let x = o.result.as_ref().ok()?;
                Some(Series {
                    label: format!(
                        "{} (CC {:.3}, MAE {:.2} mHz)",
                        o.method.label(),
                        x.cc,
                        x.mae_hz * 1e3
                    ),
                    time_s: &d.comparison.time_s,
                    estimate: &d.comparison.estimate,
                    reference: &d.comparison.reference,
                    colour: methods.iter().position(|m| *m == o.method).unwrap_or(0),
                })
            })
            .collect();
        if !series.is_empty() {
            let title = format!("{}: ENF against the reference", r.name());
            written += both(&folder.join(format!("{}.methods", stem(r))), &|p| {
                plot_methods(p, &title, &series)
            })?;
        }
        if let Some(d) = mine
            .iter()
            .find(|o| o.method == Method::EEnf)
            .and_then(|o| o.details.as_ref())
        {
            if let Some(tr) = &d.trace {
                let title = format!(
                    "{}: E-ENF per harmonic, selected per {} s",
                    r.name(),
                    tr.segment_len as f64 * tr.step_s
                );
                written += both(&folder.join(format!("{}.harmonics", stem(r))), &|p| {
                    plot_extraction(p, &title, tr)
                })?;
            }
            if let Some(spec) = &d.spectrogram {
                let title = format!(
                    "{}: polarity sequence around 2f0 = {} Hz",
                    r.name(),
                    2.0 * d.nominal_hz
                );
                let twice: Vec<f64> = d.comparison.reference.iter().map(|f| 2.0 * f).collect();
                written += both(&folder.join(format!("{}.spectrogram", stem(r))), &|p| {
                    plot_spectrogram(p, &title, spec, Some((&d.comparison.time_s, &twice)), -40.0)
                })?;
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    for (k, run) in runs.iter().enumerate() {
        let classes = run.classes();
        let bars: Vec<SummaryBar> = run
            .summary
            .iter()
            .map(|s| SummaryBar {
                class: s.class.clone(),
                method: s.method.label().to_string(),
                method_index: methods.iter().position(|m| *m == s.method).unwrap_or(0),
                cc: s.cc,
                mae_mhz: s.mae_hz * 1e3,
                paper: paper_value(s.method, &s.class),
            })
            .collect();
        let names: Vec<String> = methods.iter().map(|m| m.label().to_string()).collect();
        let title = format!("{} recordings, {}", recs.len(), run.settings.describe());
        let name = if runs.len() == 1 {
            "summary".to_string()
        } else {
            format!("summary-run{}", k + 1)
        };
        written += both(&dir.join(name), &|p| {
            plot_summary(p, &title, &classes, &names, &bars)
        })?;
    }
    Ok(written)
}
