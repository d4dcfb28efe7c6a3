//! The results of a benchmark as people read them: the Table 2 layout, the Markdown report,
//! CSV, JSON and trace files (the command line draws the figures).

use std::path::{Path, PathBuf};

use crate::error::{Context, Result};
use eenf_dsp::Agreement;

use super::{paper_value, DatasetEntry, Method, Run};
use crate::output::write_atomic;

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
pub fn markdown_run(recs: &[DatasetEntry], run: &Run, methods: &[Method]) -> String {
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
                x.n,
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
pub fn write_csv(w: &mut dyn std::io::Write, recs: &[DatasetEntry], runs: &[Run]) -> Result<()> {
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
            let score = |f: fn(&Agreement) -> f64| x.map(|x| num(f(x))).unwrap_or_default();
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
                x.map(|x| x.n.to_string()).unwrap_or_default(),
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
pub fn json_run(recs: &[DatasetEntry], run: &Run) -> serde_json::Value {
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
            "sampling": run.settings.extract.sampling,
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

/// What the Markdown report says about the run besides its results.
pub struct ReportContext {
    /// The dataset.
    pub dataset: PathBuf,
    /// Where the report goes (the summary figure is linked relative to it).
    pub report: Option<PathBuf>,
    /// Where the figures go.
    pub plots: Option<PathBuf>,
    /// The `--sweep` arguments.
    pub sweeps: Vec<String>,
    /// Recordings processed at once.
    pub jobs: usize,
    /// Wall time of the run, s.
    pub wall_s: f64,
}

/// The whole Markdown report.
pub fn markdown_report(
    about: &ReportContext,
    recs: &[DatasetEntry],
    runs: &[Run],
    methods: &[Method],
) -> String {
    let (jobs, wall_s) = (about.jobs, about.wall_s);
    let mut s = format!(
        "# eenf bench: {}\n\n{} recordings, methods {}, {} setting(s); {wall_s:.1} s wall time with {jobs} at a time (eenf {}).\n\n",
        about.dataset.display(),
        recs.len(),
        methods.iter().map(|m| m.name()).collect::<Vec<_>>().join(", "),
        runs.len(),
        env!("CARGO_PKG_VERSION"),
    );
    if let (Some(plots), Some(report)) = (&about.plots, &about.report) {
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
        if methods.contains(&Method::EEnf) {
            s.push_str(&format!(
                "- E-ENF: sampling {}, Δt {}; {}\n",
                e.sampling,
                e.dt_us.map_or(
                    "auto (1000 µs for scan groups, 100 µs otherwise)".into(),
                    |d| format!("{d} µs")
                ),
                describe_params(&e.params, true)
            ));
        }
        if methods.iter().any(|m| m.camera().is_some()) {
            let v = &run.settings.video;
            s.push_str(&format!(
                "- V-ENF: row sampling {}, scene removal {}; {}\n",
                v.sampling,
                v.scene_removal,
                describe_params(&v.params, false)
            ));
        }
    }
    s.push_str("- References: traced as `eenf compare` traces them (default tracker, the estimate's peak refinement); recordings placed by their `dvSave-` name or the manifest's reference and offset, continuing into the next hour's WAV when they run past the hour.\n");
    if !about.sweeps.is_empty() {
        s.push_str(&format!("- Sweeps: `{}`\n", about.sweeps.join("` `")));
    }
    s.push_str("- Paper: Table 2 of *Seeing Electric Network Frequency from Events* (CVPR 2023), real EV-ENFD; italic rows.\n");
    s
}

/// A recording's file name without its extension: what its figures and traces are named by.
pub fn stem(r: &DatasetEntry) -> String {
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

/// Writes every kept trace as JSON into `dir` (one folder per run when there are several).
pub fn write_traces(dir: &Path, recs: &[DatasetEntry], runs: &[Run]) -> Result<()> {
    for (k, run) in runs.iter().enumerate() {
        for o in &run.outcomes {
            let Some(d) = &o.details else { continue };
            let r = &recs[o.recording];
            let folder = run_dir(dir, runs, k).join(&r.class);
            std::fs::create_dir_all(&folder).with_context(|| format!("{}", folder.display()))?;
            let path = folder.join(format!("{}.{}.json", stem(r), o.method.name()));
            write_atomic(&path, |w| d.trace.write_json(w))?;
        }
    }
    Ok(())
}

/// A tracker's parameters in words, as a report lists them (`harmonics`: whether the method
/// tracks several flicker lines and selects among them, as E-ENF does; V-ENF tracks 2f0).
fn describe_params(p: &eenf_dsp::EnfParams, harmonics: bool) -> String {
    let mut s = format!(
        "STFT window {} s, step {} s, peak refinement {}, band ±{} Hz (Butterworth order {}), \
         running median of {} over {} Hz",
        p.window_s,
        p.step_s,
        p.peak,
        p.half_band_hz,
        p.filter_order,
        p.median_len,
        p.median_threshold_hz
    );
    if harmonics {
        s.push_str(&format!(
            "; {} flicker line{} (2m·f0), selection {} per {} estimates",
            p.harmonics,
            if p.harmonics == 1 { "" } else { "s" },
            p.selection,
            p.segment_len
        ));
    }
    s
}
