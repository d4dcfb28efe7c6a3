//! `bench --plots`: the figures of a benchmark, PNG and SVG each: per recording, the methods
//! against the reference, the per-harmonic traces and the spectrogram around 2 f0; and one
//! summary per run.

use std::path::Path;

use eenf::bench::report::stem;
use eenf::bench::{paper_value, DatasetEntry, Method, Outcome, Run};
use eenf::error::{Context, Result};
use eenf::progress::Progress;

use crate::{plot_extraction, plot_methods, plot_spectrogram, plot_summary, Series, SummaryBar};

/// Writes each figure as PNG and SVG; returns how many files.
pub fn write_plots(
    dir: &Path,
    recs: &[DatasetEntry],
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
            if !d.trace.harmonics.is_empty() {
                let tr = &d.trace;
                let title = format!(
                    "{}: E-ENF per harmonic, selected per {} s",
                    r.name(),
                    tr.segment_s().unwrap_or(0.0)
                );
                written += both(&folder.join(format!("{}.harmonics", stem(r))), &|p| {
                    plot_extraction(p, &title, tr)
                })?;
            }
            if let Some(spec) = &d.spectrogram {
                let title = format!(
                    "{}: polarity sequence around 2f0 = {} Hz",
                    r.name(),
                    2.0 * d.trace.nominal_hz.unwrap_or(f64::NAN)
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
        let title = format!(
            "eenf on {} recordings ({}), beside the paper's Table 2",
            recs.len(),
            run.settings.describe()
        );
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
