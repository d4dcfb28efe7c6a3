//! `eenf match`: when was this recorded?

use std::path::PathBuf;

use anyhow::Result;
use eenf::locate::locate;
use eenf::progress::Progress;
use eenf::reference::ReferenceSeries;
use eenf::trace::Trace;
use eenf_dsp::resample::resample;
use eenf_figures::plot_comparison;

use crate::args::MatchArgs;

/// Arguments of `eenf match`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The trace to place (CSV or JSON from `eenf extract` or `eenf reference`).
    pub trace: PathBuf,
    /// Where to look: a store from `eenf refdb build`, a folder of hourly mains WAVs, a WAV,
    /// or a trace CSV.
    pub reference: PathBuf,
    #[command(flatten)]
    pub search: MatchArgs,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Plot the trace against the reference at the best candidate (.png or .svg).
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

/// Runs `eenf match`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    let trace = Trace::read(&a.trace, None)?;
    let query = a.search.query()?;
    let located = locate(
        &trace,
        &a.trace,
        &a.reference,
        a.search.tz.as_ref(),
        &query,
        &progress,
    )?;
    for r in &located.references {
        for n in &r.notes {
            eprintln!("{n}");
        }
    }
    let (report, refs) = (&located.report, &located.references);
    let nominal = report.grid.hz();
    let rows: Vec<_> = report
        .placements
        .iter()
        .map(|p| (&refs[p.series], &p.candidate))
        .collect();
    let verification = report
        .verified
        .as_ref()
        .map(|v| (&refs[v.series], &v.verification));
    let took = report.seconds;
    let step = trace.step_s;
    // with several series searched (a store's grids), each place says which one
    let many = refs.len() > 1;
    let when = |r: &ReferenceSeries, offset: f64| {
        if many {
            format!("{} on {}", r.time_label(offset), r.name)
        } else {
            r.time_label(offset)
        }
    };
    if let (Some(p), Some((r, c))) = (&a.plot, rows.first()) {
        let k = c.offset.round() as usize;
        let n = trace.enf_hz.len().min(r.values.len().saturating_sub(k));
        let q = resample(&trace.enf_hz, step, r.step);
        let n = n.min(q.len());
        let t: Vec<f64> = (0..n).map(|i| i as f64 * r.step).collect();
        plot_comparison(
            p,
            &format!(
                "{} at {}: CC {:.4}, p {:.1e}",
                eenf_figures::title_name(&a.trace),
                when(r, c.offset),
                c.agreement.cc,
                c.p_value
            ),
            &t,
            &q[..n],
            &r.values.window(k, n)?,
        )?;
        crate::terminal::announce("plot", p);
    }
    if a.json {
        let v = located.to_json(&a.trace, query.alpha);
        outln!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    outln!(
        "{} ({} values, {} Hz grid) searched in {took:.2} s{}",
        a.trace.display(),
        trace.enf_hz.len(),
        nominal,
        if many {
            format!(
                " over {}",
                refs.iter()
                    .map(|r| r.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        } else {
            String::new()
        }
    );
    let labels: Vec<String> = rows.iter().map(|(r, c)| when(r, c.offset)).collect();
    let width = labels
        .iter()
        .map(|l| l.chars().count())
        .max()
        .unwrap_or(0)
        .max(28);
    outln!(
        "{:>4}  {:<width$} {:>8} {:>9} {:>9} {:>8} {:>9}",
        "rank",
        "start",
        "CC",
        "MAE mHz",
        "RMSE mHz",
        "overlap",
        "p"
    );
    for (i, ((_, c), label)) in rows.iter().zip(&labels).enumerate() {
        outln!(
            "{:>4}  {:<width$} {:>8.4} {:>9.3} {:>9.3} {:>8} {:>9.1e}{}",
            i + 1,
            label,
            c.agreement.cc,
            c.agreement.mae_hz * 1e3,
            c.agreement.rmse_hz * 1e3,
            c.agreement.n,
            c.p_value,
            if c.p_value < query.alpha {
                "  match"
            } else {
                ""
            }
        );
    }
    // the answer in one line: a table alone leaves a reader to judge rank 1 at CC 0.91
    match rows.first().zip(labels.first()) {
        Some(((_, c), label)) if c.p_value < query.alpha => outln!(
            "verdict: recorded at {label} (CC {:.4}, p {:.1e} < {})",
            c.agreement.cc,
            c.p_value,
            query.alpha
        ),
        Some(((_, c), _)) => outln!(
            "verdict: no significant match (the best place has p {:.1e}, not below {}): the trace does not tell when it was recorded",
            c.p_value,
            query.alpha
        ),
        None => outln!("verdict: no significant match (no place in the reference overlaps the trace)"),
    }
    if let Some(t) = &query.verify {
        match verification {
            Some((r, v)) => outln!(
                "claimed {t} ({}): CC {:.4}, MAE {:.3} mHz, rank {}, p {:.1e}: {}",
                when(r, v.offset as f64),
                v.agreement.cc,
                v.agreement.mae_hz * 1e3,
                v.rank,
                v.p_value,
                match (v.rank == 1, v.p_value < query.alpha) {
                    (true, true) => "consistent: the best fit in the reference, and significant".to_string(),
                    (true, false) => "the best fit in the reference, but not significant (the trace is too short or flat to tell)".to_string(),
                    (false, _) => format!("not supported: {} other places fit better", v.rank - 1),
                }
            ),
            None => outln!("claimed {t}: outside the reference"),
        }
    }
    Ok(())
}
