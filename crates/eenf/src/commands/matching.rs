//! `eenf match`: when was this recorded?

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use eenf::plot::plot_comparison;
use eenf::progress::Progress;
use eenf::reference::ReferenceSeries;
use eenf::time::{parse_time, tz_offset};
use eenf::trace::Trace;
use eenf_dsp::matching::{resample, MatchOptions, Score, DEFAULT_ALPHA};

use super::args::one_of;

/// Arguments of `eenf match`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The trace to place (CSV or JSON from `eenf extract` or `eenf reference`).
    pub trace: PathBuf,
    /// Where to look: a store from `eenf refdb build`, a folder of hourly mains WAVs, a WAV,
    /// or a trace CSV.
    pub reference: PathBuf,
    /// Candidates to list.
    #[arg(long, default_value_t = 5)]
    pub top: usize,
    /// Check a claimed start time (e.g. 2022-08-17T16:10:00+08:00): its score, rank and
    /// significance.
    #[arg(long)]
    pub verify: Option<String>,
    /// Ranking score: `combined` (shape and level) or `cc` (shape only, robust to a bias).
    #[arg(long, default_value = "combined", value_parser = one_of::<Score>(&Score::NAMES))]
    pub score: Score,
    /// A candidate is a match when its p-value is below this.
    #[arg(long, default_value_t = DEFAULT_ALPHA)]
    pub alpha: f64,
    /// UTC offset of local times in WAV names.
    #[arg(long, default_value = "+00:00", allow_hyphen_values = true)]
    pub tz: String,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Plot the trace against the reference at the best candidate (.png or .svg).
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    let trace = Trace::read(&a.trace, None)?;
    if trace.enf_hz.len() < 2 {
        bail!("{}: too short to match", a.trace.display());
    }
    let step = trace.step_s;
    if step <= 0.0 {
        bail!("{}: times must increase", a.trace.display());
    }
    let nominal = trace.grid_hz().with_context(|| {
        format!(
            "{}: mean {:.3} Hz is neither a 50 nor a 60 Hz grid",
            a.trace.display(),
            trace.mean_hz()
        )
    })?;
    let tz = tz_offset(&a.tz)?;
    let refs = ReferenceSeries::load(&a.reference, nominal, tz, &progress)?;
    let started = std::time::Instant::now();
    let mut rows = Vec::new();
    let mut verification = None;
    for r in &refs {
        let q = resample(&trace.enf_hz, step, r.step);
        let verify = match &a.verify {
            Some(t) => {
                let at = if r.absolute {
                    parse_time(t)?
                } else {
                    t.parse::<f64>()
                        .context("--verify with a relative reference takes seconds")?
                };
                let k = ((at - r.start) / r.step).round();
                (k >= 0.0).then_some(k as usize)
            }
            None => None,
        };
        let opts = MatchOptions {
            top: a.top,
            score: a.score,
            verify,
            ..MatchOptions::default()
        };
        let res = r
            .values
            .search(&q, &opts)
            .map_err(|e| anyhow::anyhow!("{}: {e}", a.trace.display()))?;
        if let Some(v) = res.verification {
            verification = Some((r, v));
        }
        for c in res.candidates {
            rows.push((r, c));
        }
    }
    rows.sort_by(|x, y| {
        x.1.p_value
            .total_cmp(&y.1.p_value)
            .then(y.1.agreement.cc.total_cmp(&x.1.agreement.cc))
    });
    rows.truncate(a.top);
    let took = started.elapsed().as_secs_f64();
    let when = |r: &ReferenceSeries, offset: f64| r.time_label(offset);
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
                a.trace.file_name().unwrap_or_default().to_string_lossy(),
                when(r, c.offset),
                c.agreement.cc,
                c.p_value
            ),
            &t,
            &q[..n],
            &(k..k + n).map(|i| r.values.get(i)).collect::<Vec<_>>(),
        )?;
    }
    if a.json {
        let cands: Vec<_> = rows
            .iter()
            .map(|(r, c)| {
                serde_json::json!({"reference": r.name, "start": when(r, c.offset),
                    "start_s": r.start + c.offset * r.step, "offset_steps": c.offset,
                    "cc": c.agreement.cc, "mae_hz": c.agreement.mae_hz,
                    "rmse_hz": c.agreement.rmse_hz, "overlap": c.agreement.n,
                    "p_value": c.p_value, "match": c.p_value < a.alpha})
            })
            .collect();
        let v = serde_json::json!({
            "trace": a.trace, "nominal_hz": nominal, "alpha": a.alpha, "seconds": took,
            "candidates": cands,
            "verify": verification.map(|(r, v)| serde_json::json!({
                "time": when(r, v.offset as f64), "cc": v.agreement.cc,
                "mae_hz": v.agreement.mae_hz, "rmse_hz": v.agreement.rmse_hz, "rank": v.rank, "p_value": v.p_value,
                "best_fit": v.rank == 1, "consistent": v.rank == 1 && v.p_value < a.alpha})),
        });
        outln!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    outln!(
        "{} ({} values, {} Hz grid) searched in {took:.2} s",
        a.trace.display(),
        trace.enf_hz.len(),
        nominal
    );
    outln!(
        "{:>4}  {:<28} {:>8} {:>9} {:>9} {:>8} {:>9}",
        "rank",
        "start",
        "CC",
        "MAE mHz",
        "RMSE mHz",
        "overlap",
        "p"
    );
    for (i, (r, c)) in rows.iter().enumerate() {
        outln!(
            "{:>4}  {:<28} {:>8.4} {:>9.3} {:>9.3} {:>8} {:>9.1e}{}",
            i + 1,
            when(r, c.offset),
            c.agreement.cc,
            c.agreement.mae_hz * 1e3,
            c.agreement.rmse_hz * 1e3,
            c.agreement.n,
            c.p_value,
            if c.p_value < a.alpha { "  match" } else { "" }
        );
    }
    if let Some(t) = &a.verify {
        match verification {
            Some((r, v)) => outln!(
                "claimed {t} ({}): CC {:.4}, MAE {:.3} mHz, rank {}, p {:.1e}: {}",
                when(r, v.offset as f64),
                v.agreement.cc,
                v.agreement.mae_hz * 1e3,
                v.rank,
                v.p_value,
                match (v.rank == 1, v.p_value < a.alpha) {
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
