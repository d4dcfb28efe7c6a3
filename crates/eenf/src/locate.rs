//! `match`: where a trace fits in long references, and when it was therefore recorded.

use eenf_core::spelling::option;
use eenf_core::Grid;
use std::path::Path;

use crate::error::{fail, Context, Error, Result};
use eenf_dsp::matching::{Candidate, MatchOptions, Score, Verification};
use eenf_dsp::resample::resample;

use crate::progress::Progress;
use crate::reference::ReferenceSeries;
use crate::trace::Trace;

/// What `match` asks of the references.
#[derive(Debug, Clone)]
pub struct MatchQuery {
    /// Candidates to list.
    pub top: usize,
    /// What ranks offsets.
    pub score: Score,
    /// A claimed start time to check (an absolute time, or seconds for a relative reference).
    pub verify: Option<String>,
    /// A candidate is a match when its p-value is below this.
    pub alpha: f64,
}

/// One place where the trace fits.
#[derive(Debug, Clone)]
pub struct Placement {
    /// The reference series (index into the searched list).
    pub series: usize,
    /// The candidate: offset in the series' steps, agreement, p-value.
    pub candidate: Candidate,
}

/// How the claimed time of [`MatchQuery::verify`] fits.
#[derive(Debug, Clone)]
pub struct Verified {
    /// The reference series holding the claimed time.
    pub series: usize,
    /// Its score, rank and significance.
    pub verification: Verification,
}

/// The outcome of `match`: the best places over every series, best first.
#[derive(Debug, Clone)]
pub struct MatchReport {
    /// The grid searched.
    pub grid: Grid,
    /// The best candidates over all series (lowest p-value, then highest CC).
    pub placements: Vec<Placement>,
    /// The claimed time's fit, when one was given and falls inside a series.
    pub verified: Option<Verified>,
    /// Seconds the search took.
    pub seconds: f64,
}

/// A trace placed in long references: the report, and the series it was searched in (which
/// give its candidates their names and times).
pub struct Located {
    /// The best places, and the claimed time's fit.
    pub report: MatchReport,
    /// The series searched, as [`Placement::series`] and [`Verified::series`] index them.
    pub references: Vec<ReferenceSeries>,
}

impl Located {
    /// The result as `eenf match --json` prints it.
    pub fn to_json(&self, trace: &Path, alpha: f64) -> serde_json::Value {
        self.report.to_json(trace, &self.references, alpha)
    }
}

/// Where `trace` (named `name` in messages) fits in the references at `reference` (a store, a
/// folder of hourly WAVs, a WAV, a grid archive or a trace; local times in hourly names and
/// archives are in `zone`), as `query` asks: the command's and the Python package's `match`.
pub fn locate(
    trace: &Trace,
    name: &Path,
    reference: &Path,
    zone: Option<&crate::time::Zone>,
    query: &MatchQuery,
    progress: &Progress,
) -> Result<Located> {
    let grid = match_grid(trace, name)?;
    let references = ReferenceSeries::load(reference, grid, zone, progress)?;
    let report = locate_in(trace, name, grid, &references, query)?;
    Ok(Located { report, references })
}

/// Where `trace` (named `name`, on the `grid` [`match_grid`] found) fits in the
/// series `refs`, as `query` asks.
pub fn locate_in(
    trace: &Trace,
    name: &Path,
    grid: Grid,
    refs: &[ReferenceSeries],
    query: &MatchQuery,
) -> Result<MatchReport> {
    let started = std::time::Instant::now();
    let mut placements = Vec::new();
    let mut verified = None;
    for (i, r) in refs.iter().enumerate() {
        let q = resample(&trace.enf_hz, trace.step_s, r.step);
        let verify = match &query.verify {
            Some(t) => {
                let at = if r.absolute {
                    crate::time::parse_time(t)?
                } else {
                    t.parse::<f64>().with_context(|| {
                        format!(
                            "{} with a relative reference takes seconds",
                            option("verify")
                        )
                    })?
                };
                let k = ((at - r.start) / r.step).round();
                (k >= 0.0).then_some(k as usize)
            }
            None => None,
        };
        let opts = MatchOptions {
            top: query.top,
            score: query.score,
            verify,
            ..MatchOptions::default()
        };
        let res = r
            .values
            .search(&q, &opts)
            .map_err(|e| Error::from(e).context(name.display()))?;
        if let Some(v) = res.verification {
            verified = Some(Verified {
                series: i,
                verification: v,
            });
        }
        placements.extend(res.candidates.into_iter().map(|candidate| Placement {
            series: i,
            candidate,
        }));
    }
    placements.sort_by(|x, y| {
        let (x, y) = (&x.candidate, &y.candidate);
        x.p_value
            .total_cmp(&y.p_value)
            .then(y.agreement.cc.total_cmp(&x.agreement.cc))
    });
    placements.truncate(query.top);
    Ok(MatchReport {
        grid,
        placements,
        verified,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// The grid of a trace to be matched: it must hold two values, rising times, and a mean on a
/// 50 or 60 Hz grid.
pub fn match_grid(trace: &Trace, name: &Path) -> Result<Grid> {
    if trace.enf_hz.len() < 2 {
        fail!(Input, "{}: too short to match", name.display());
    }
    if trace.step_s <= 0.0 {
        fail!(Input, "{}: times must increase", name.display());
    }
    trace.grid_or_err(name)
}

impl MatchReport {
    /// The report as `eenf match --json` prints it.
    pub fn to_json(&self, trace: &Path, refs: &[ReferenceSeries], alpha: f64) -> serde_json::Value {
        let cands: Vec<_> = self
            .placements
            .iter()
            .map(|p| {
                let (r, c) = (&refs[p.series], &p.candidate);
                serde_json::json!({"reference": r.name, "grid": r.grid, "start": r.time_label(c.offset),
                    "start_s": r.start + c.offset * r.step, "offset_steps": c.offset,
                    "start_utc": r.absolute.then(|| crate::time::utc(r.start + c.offset * r.step)),
                    "cc": c.agreement.cc, "mae_hz": c.agreement.mae_hz,
                    "rmse_hz": c.agreement.rmse_hz, "overlap": c.agreement.n,
                    "p_value": c.p_value, "match": c.p_value < alpha})
            })
            .collect();
        serde_json::json!({
            "trace": trace, "nominal_hz": self.grid.hz(), "alpha": alpha, "seconds": self.seconds,
            "searched": refs.iter().map(|r| &r.name).collect::<Vec<_>>(),
            "candidates": cands,
            "verify": self.verified.as_ref().map(|v| {
                let (r, v) = (&refs[v.series], &v.verification);
                serde_json::json!({
                "reference": r.name, "grid": r.grid,
                "time": r.time_label(v.offset as f64), "cc": v.agreement.cc,
                "mae_hz": v.agreement.mae_hz, "rmse_hz": v.agreement.rmse_hz, "rank": v.rank, "p_value": v.p_value,
                "best_fit": v.rank == 1, "consistent": v.rank == 1 && v.p_value < alpha})}),
        })
    }
}
