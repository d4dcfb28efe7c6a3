//! `eenf bench`: the paper's Table 2 on a dataset, every method, with reports and plots.

use std::path::PathBuf;

use anyhow::{bail, Result};
use eenf::bench::report::{
    json_run, markdown_report, markdown_table, write_csv, write_traces, ReportContext,
};
use eenf::bench::run::{jobs_for, run_all};
use eenf::bench::{discover, group_by_prominence, sweep, Method, Settings};
use eenf::output::write_atomic;
use eenf::progress::Progress;
use eenf_video::{IdleRows, RowSampling, SceneRemoval, VideoOptions};

use crate::args::{one_of, MethodArgs};

/// Arguments of `eenf bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// An EV-ENFD-like folder (one folder per class with event files, optional
    /// `<stem>_lr.*`/`<stem>_hr.*` videos, and `ENF_Reference/` with hourly WAVs), or a
    /// manifest CSV (`recording,class,reference,offset_s,videos`, paths relative to it).
    pub dataset: PathBuf,
    /// Methods to run, comma-separated: e-enf, v-enf-lr, v-enf-hr. Default: every method whose
    /// input the dataset has (the video methods need `<stem>_lr.*`/`<stem>_hr.*` videos).
    #[arg(long)]
    pub methods: Option<String>,
    /// Recordings processed at once (default: one per core, fewer if the memory budget says so).
    #[arg(long, value_parser = crate::args::count_in((1, 256)))]
    pub jobs: Option<usize>,
    /// Memory budget, MiB: bounds the recordings processed at once.
    #[arg(long, default_value_t = 4096, value_parser = clap::value_parser!(u64).range(64..=1 << 30))]
    pub memory_mb: u64,
    /// Write the Markdown report here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Print every number as JSON on stdout, instead of the tables.
    #[arg(long)]
    pub json: bool,
    /// Write every number as JSON here.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
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
    /// sampling, peak, window, dt-us, selection, tiles (flicker or all), segment, median-len,
    /// scene-removal, video-sampling.
    #[arg(long)]
    pub sweep: Vec<String>,
    /// V-ENF scene removal: paper, row-mean, none.
    #[arg(long, default_value = "paper", value_parser = one_of::<SceneRemoval>(&SceneRemoval::NAMES))]
    pub scene_removal: SceneRemoval,
    /// Group the recordings by `class` (their folder or manifest class) or by `prominence`
    /// (of their flicker line, from the manifest's `prominence` column: <10, 10-15, 15-20,
    /// >=20).
    #[arg(long, default_value = "class", value_parser = ["class", "prominence"])]
    pub by: String,
    #[command(flatten)]
    pub method: MethodArgs,
}

/// Runs `eenf bench`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    let started = std::time::Instant::now();
    let mut recs = discover(&a.dataset)?;
    let methods = match &a.methods {
        Some(list) => Method::parse_list(list)?,
        None => {
            let (run, left) = Method::available(&recs);
            if !left.is_empty() {
                eprintln!(
                    "{} not run: no recording has a video from that camera",
                    left.iter().map(|m| m.name()).collect::<Vec<_>>().join(", ")
                );
            }
            run
        }
    };
    if a.by == "prominence" {
        group_by_prominence(&mut recs)?;
    }
    let extract = a.method.options()?;
    let video = VideoOptions {
        nominal_hz: a.method.tracker.nominal.hz(),
        sampling: RowSampling::ZeroPad(IdleRows::Auto),
        scene_removal: a.scene_removal,
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
    let runs = run_all(
        &recs,
        &methods,
        settings,
        jobs,
        keep,
        a.traces.is_some(),
        a.plots.is_some(),
        &progress,
    )?;
    let wall_s = started.elapsed().as_secs_f64();

    // the tables (or JSON) on stdout; failures on stderr
    for run in &runs {
        if !a.json {
            outln!("{}", markdown_table(run, &methods));
        }
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
        let n = eenf_figures::write_plots(dir, &recs, &runs, &methods, &progress)?;
        eprintln!("{n} figures in {}", dir.display());
    }
    if let Some(p) = &a.report {
        let about = ReportContext {
            dataset: a.dataset.clone(),
            report: a.report.clone(),
            plots: a.plots.clone(),
            sweeps: a.sweep.clone(),
            jobs,
            wall_s,
        };
        let md = markdown_report(&about, &recs, &runs, &methods);
        write_atomic(p, |w| {
            w.write_all(md.as_bytes())?;
            Ok(())
        })?;
        crate::terminal::announce("report", p);
    }
    if let Some(p) = &a.csv {
        write_atomic(p, |w| write_csv(w, &recs, &runs))?;
        crate::terminal::announce("CSV", p);
    }
    let v = serde_json::json!({
        "dataset": a.dataset,
        "recordings": recs.len(),
        "methods": methods,
        "jobs": jobs,
        "wall_s": wall_s,
        "runs": runs.iter().map(|r| json_run(&recs, r)).collect::<Vec<_>>(),
    });
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&v)?);
    }
    if let Some(p) = &a.output {
        write_atomic(p, |w| {
            serde_json::to_writer_pretty(&mut *w, &v)?;
            writeln!(w)?;
            Ok(())
        })?;
        crate::terminal::announce("JSON", p);
    }
    if scored == 0 {
        bail!("no recording could be scored");
    }
    Ok(())
}
