//! `eenf match`: when was this recorded?

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use eenf_cli::dataset::hourly_references;
use eenf_cli::output::read_trace;
use eenf_cli::pipeline::{reference_file, Nominal};
use eenf_cli::plot::plot_comparison;
use eenf_cli::progress::Progress;
use eenf_cli::refdb::{parse_time, tz_offset, utc, RefSeries, GAP};
use eenf_dsp::matching::{
    match_trace, resample, MatchOptions, ReferenceValues, ScaledSeries, Score, DEFAULT_ALPHA,
};
use eenf_dsp::EnfParams;

use super::refdb::wav_start;

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
    #[arg(long, value_enum, default_value_t = ScoreArg::Combined)]
    pub score: ScoreArg,
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

/// Score names for clap.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum ScoreArg {
    /// atanh(CC) − ln(RMSE).
    Combined,
    /// CC alone.
    Cc,
}

/// A reference series: start (Unix s, or 0 for relative), step, values, name.
struct Reference {
    name: String,
    start: f64,
    absolute: bool,
    step: f64,
    data: RefData,
}

/// Reference values: in Hz, or as stored (µHz from nominal), read in place.
enum RefData {
    Hz(Vec<f64>),
    Stored { values: Vec<i32>, nominal: f64 },
}

impl RefData {
    fn scaled(values: &[i32], nominal: f64) -> ScaledSeries<'_> {
        ScaledSeries {
            values,
            offset_hz: nominal,
            scale_hz: 1e-6,
            gap: GAP,
        }
    }

    fn len(&self) -> usize {
        match self {
            RefData::Hz(v) => v.len(),
            RefData::Stored { values, .. } => values.len(),
        }
    }

    fn get(&self, i: usize) -> f64 {
        match self {
            RefData::Hz(v) => v[i],
            RefData::Stored { values, nominal } => Self::scaled(values, *nominal).get(i),
        }
    }

    fn search(
        &self,
        q: &[f64],
        opts: &MatchOptions,
    ) -> Result<eenf_dsp::matching::MatchResult, eenf_dsp::matching::MatchError> {
        match self {
            RefData::Hz(v) => match_trace(q, &v[..], opts),
            RefData::Stored { values, nominal } => {
                match_trace(q, &Self::scaled(values, *nominal), opts)
            }
        }
    }
}

fn load_references(
    path: &Path,
    nominal: f64,
    tz: f64,
    progress: &Progress,
) -> Result<Vec<Reference>> {
    if path.is_dir() {
        let grids = RefSeries::grids(path)?;
        if !grids.is_empty() {
            let mut out = Vec::new();
            for g in grids {
                let meta = RefSeries::load_meta(path, &g)?;
                if meta.nominal_hz != nominal {
                    continue; // 50 and 60 Hz are never mixed
                }
                let s = RefSeries::load(path, &g)?;
                out.push(Reference {
                    name: g,
                    start: meta.start_unix_s,
                    absolute: true,
                    step: meta.step_s,
                    data: RefData::Stored {
                        values: s.values,
                        nominal,
                    },
                });
            }
            if out.is_empty() {
                bail!("{}: the store holds no {nominal} Hz grid", path.display());
            }
            return Ok(out);
        }
        // a folder of hourly WAVs, assembled in memory
        let files = hourly_references(path)?;
        let bar = progress.steps(files.len() as u64, "tracking the references");
        let mut series = RefSeries::new("folder", nominal, 1.0, 0.0);
        for (_, f) in &files {
            let (f0, trace) = reference_file(f, Nominal::Auto, &EnfParams::default())?;
            if f0 == nominal {
                series.merge(wav_start(f, tz)?, 1.0, &trace)?;
            }
            bar.inc(1);
        }
        bar.finish_and_clear();
        if series.values.is_empty() {
            bail!("{}: no {nominal} Hz references", path.display());
        }
        return Ok(vec![Reference {
            name: path.display().to_string(),
            start: series.meta.start_unix_s,
            absolute: true,
            step: 1.0,
            data: RefData::Hz(series.hz()),
        }]);
    }
    let mut head = [0u8; 4];
    let is_wav = std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut head))
        .map(|_| &head == b"RIFF")
        .unwrap_or(false);
    let (start, absolute, step, hz) = if is_wav {
        let (_, trace) = reference_file(path, Nominal::Hz(nominal), &EnfParams::default())?;
        match wav_start(path, tz) {
            Ok(s) => (s, true, 1.0, trace),
            Err(_) => (0.0, false, 1.0, trace),
        }
    } else {
        let t = read_trace(path)?;
        let step = if t.time_s.len() > 1 {
            t.time_s[1] - t.time_s[0]
        } else {
            1.0
        };
        (
            t.time_s.first().copied().unwrap_or(0.0),
            false,
            step,
            t.enf_hz,
        )
    };
    Ok(vec![Reference {
        name: path.display().to_string(),
        start,
        absolute,
        step,
        data: RefData::Hz(hz),
    }])
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    let trace = read_trace(&a.trace)?;
    if trace.enf_hz.len() < 2 {
        bail!("{}: too short to match", a.trace.display());
    }
    let step = trace.time_s[1] - trace.time_s[0];
    if step <= 0.0 {
        bail!("{}: times must increase", a.trace.display());
    }
    let finite: Vec<f64> = trace
        .enf_hz
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    let mean = finite.iter().sum::<f64>() / finite.len().max(1) as f64;
    let nominal = [50.0, 60.0]
        .into_iter()
        .find(|f| (mean - f).abs() < 1.0)
        .with_context(|| {
            format!(
                "{}: mean {mean:.3} Hz is neither a 50 nor a 60 Hz grid",
                a.trace.display()
            )
        })?;
    let tz = tz_offset(&a.tz)?;
    let refs = load_references(&a.reference, nominal, tz, &progress)?;
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
            score: match a.score {
                ScoreArg::Combined => Score::Combined,
                ScoreArg::Cc => Score::Cc,
            },
            verify,
            ..MatchOptions::default()
        };
        let res = r
            .data
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
            .then(y.1.cc.total_cmp(&x.1.cc))
    });
    rows.truncate(a.top);
    let took = started.elapsed().as_secs_f64();
    let when = |r: &Reference, offset: f64| {
        let t = r.start + offset * r.step;
        if r.absolute {
            utc(t)
        } else {
            format!("{t:.1} s")
        }
    };
    if let (Some(p), Some((r, c))) = (&a.plot, rows.first()) {
        let k = c.offset.round() as usize;
        let n = trace.enf_hz.len().min(r.data.len().saturating_sub(k));
        let q = resample(&trace.enf_hz, step, r.step);
        let n = n.min(q.len());
        let t: Vec<f64> = (0..n).map(|i| i as f64 * r.step).collect();
        plot_comparison(
            p,
            &format!(
                "{} at {}: CC {:.4}, p {:.1e}",
                a.trace.file_name().unwrap_or_default().to_string_lossy(),
                when(r, c.offset),
                c.cc,
                c.p_value
            ),
            &t,
            &q[..n],
            &(k..k + n).map(|i| r.data.get(i)).collect::<Vec<_>>(),
        )?;
    }
    if a.json {
        let cands: Vec<_> = rows
            .iter()
            .map(|(r, c)| {
                serde_json::json!({"reference": r.name, "start": when(r, c.offset),
                    "start_s": r.start + c.offset * r.step, "offset_steps": c.offset,
                    "cc": c.cc, "mae_hz": c.mae_hz, "rmse_hz": c.rmse_hz, "overlap": c.overlap,
                    "p_value": c.p_value, "match": c.p_value < a.alpha})
            })
            .collect();
        let v = serde_json::json!({
            "trace": a.trace, "nominal_hz": nominal, "alpha": a.alpha, "seconds": took,
            "candidates": cands,
            "verify": verification.map(|(r, v)| serde_json::json!({
                "time": when(r, v.offset as f64), "cc": v.cc, "mae_hz": v.mae_hz,
                "rmse_hz": v.rmse_hz, "rank": v.rank, "p_value": v.p_value,
                "best_fit": v.rank == 1, "consistent": v.rank == 1 && v.p_value < a.alpha})),
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    println!(
        "{} ({} values, {} Hz grid) searched in {took:.2} s",
        a.trace.display(),
        trace.enf_hz.len(),
        nominal
    );
    println!(
        "{:>4}  {:<28} {:>8} {:>9} {:>9} {:>8} {:>9}",
        "rank", "start", "CC", "MAE mHz", "RMSE mHz", "overlap", "p"
    );
    for (i, (r, c)) in rows.iter().enumerate() {
        println!(
            "{:>4}  {:<28} {:>8.4} {:>9.3} {:>9.3} {:>8} {:>9.1e}{}",
            i + 1,
            when(r, c.offset),
            c.cc,
            c.mae_hz * 1e3,
            c.rmse_hz * 1e3,
            c.overlap,
            c.p_value,
            if c.p_value < a.alpha { "  match" } else { "" }
        );
    }
    if let Some(t) = &a.verify {
        match verification {
            Some((r, v)) => println!(
                "claimed {t} ({}): CC {:.4}, MAE {:.3} mHz, rank {}, p {:.1e}: {}",
                when(r, v.offset as f64),
                v.cc,
                v.mae_hz * 1e3,
                v.rank,
                v.p_value,
                match (v.rank == 1, v.p_value < a.alpha) {
                    (true, true) => "consistent: the best fit in the reference, and significant".to_string(),
                    (true, false) => "the best fit in the reference, but not significant (the trace is too short or flat to tell)".to_string(),
                    (false, _) => format!("not supported: {} other places fit better", v.rank - 1),
                }
            ),
            None => println!("claimed {t}: outside the reference"),
        }
    }
    Ok(())
}
