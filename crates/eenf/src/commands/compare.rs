//! `eenf compare`: agreement of an ENF trace with a reference.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use eenf_cli::dataset::recording_start;
use eenf_cli::output::{read_trace, times, TraceFile};
use eenf_cli::pipeline::{align, reference_file, reference_for_recording, Nominal};
use eenf_cli::plot::plot_comparison;
use eenf_cli::progress::Progress;
use eenf_cli::wav::is_wav;
use eenf_dsp::{agreement, Agreement, EnfParams};

use super::method::Peak;

/// Arguments of `eenf compare`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The estimated trace (CSV or JSON from `eenf extract`).
    pub estimate: PathBuf,
    /// The reference: a trace CSV/JSON, a mains WAV, or a folder of hourly WAVs named like
    /// `2022_08_17_Wed_16_00_00.wav` (the estimate's recording name `dvSave-…` then gives the
    /// offset).
    pub reference: PathBuf,
    /// Seconds to add to the estimate's times to reach the reference's times.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub offset_s: f64,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Plot both traces and the error (.png or .svg).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Nominal frequency of a WAV reference: 50, 60 or auto.
    #[arg(long, default_value = "auto")]
    pub nominal: Nominal,
    /// Peak refinement for a WAV reference (default: the estimate's, else exact).
    #[arg(long, value_enum)]
    pub peak: Option<Peak>,
}

/// The outcome of a comparison.
pub struct Comparison {
    /// Metrics over the common seconds.
    pub agreement: Agreement,
    /// Times (s from the recording start) compared.
    pub time_s: Vec<f64>,
    /// Estimate at those times.
    pub estimate: Vec<f64>,
    /// Reference at those times.
    pub reference: Vec<f64>,
}

/// The estimate's peak method, from its JSON metadata.
fn estimate_peak(path: &Path) -> Option<eenf_dsp::PeakMethod> {
    let text = std::fs::read_to_string(path).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    serde_json::from_value(v["params"]["peak"].clone()).ok()
}

/// Compares `est` with the reference at `reference`.
pub fn compare(
    est: &TraceFile,
    est_path: &Path,
    reference: &Path,
    offset_s: f64,
    nominal: Nominal,
    params: &EnfParams,
) -> Result<Comparison> {
    let (ref_t, ref_v, offset) = if reference.is_dir() {
        let source = est.source.clone().unwrap_or_else(|| est_path.to_path_buf());
        let start = recording_start(&source)
            .or_else(|| recording_start(est_path))
            .with_context(|| {
                format!(
                    "{}: cannot tell when the recording started: its name has no dvSave-YYYY_MM_DD_HH_MM_SS",
                    est_path.display()
                )
            })?;
        let step = params.step_s;
        let last = est.time_s.iter().copied().fold(0.0, f64::max);
        let seconds = ((last + offset_s) / step).floor() as usize + 1;
        let (_, trace) = reference_for_recording(reference, start, seconds, nominal, params)?;
        (times(trace.len(), step), trace, offset_s)
    } else if is_wav(reference) {
        let (_, trace) = reference_file(reference, nominal, params)?;
        (times(trace.len(), params.step_s), trace, offset_s)
    } else {
        let r = read_trace(reference)?;
        (r.time_s, r.enf_hz, offset_s)
    };
    let (t, e, r) = align(&est.time_s, &est.enf_hz, &ref_t, &ref_v, offset);
    let Some(agreement) = agreement(&e, &r) else {
        bail!(
            "{} and {} share fewer than two seconds at offset {offset} s",
            est_path.display(),
            reference.display()
        );
    };
    Ok(Comparison {
        agreement,
        time_s: t,
        estimate: e,
        reference: r,
    })
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    let est = read_trace(&a.estimate)?;
    let peak = a
        .peak
        .map(Into::into)
        .or_else(|| estimate_peak(&a.estimate))
        .unwrap_or(eenf_dsp::PeakMethod::Exact);
    let params = EnfParams {
        peak,
        ..EnfParams::default()
    };
    let spin = progress.spinner("comparing");
    let c = compare(
        &est,
        &a.estimate,
        &a.reference,
        a.offset_s,
        a.nominal,
        &params,
    )?;
    spin.finish_and_clear();
    let m = c.agreement;
    if let Some(p) = &a.plot {
        let title = format!(
            "{} vs {}: CC {:.4}, MAE {:.2} mHz",
            a.estimate.file_name().unwrap_or_default().to_string_lossy(),
            a.reference
                .file_name()
                .unwrap_or_default()
                .to_string_lossy(),
            m.cc,
            m.mae_hz * 1e3
        );
        plot_comparison(p, &title, &c.time_s, &c.estimate, &c.reference)?;
    }
    if a.json {
        let v = serde_json::json!({
            "estimate": a.estimate, "reference": a.reference, "offset_s": a.offset_s,
            "seconds": m.n, "cc": m.cc, "mae_hz": m.mae_hz, "rmse_hz": m.rmse_hz,
            "max_err_hz": m.max_err_hz, "plot": a.plot,
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        println!("estimate   {}", a.estimate.display());
        println!("reference  {}", a.reference.display());
        println!("seconds    {}", m.n);
        println!("CC         {:.4}", m.cc);
        println!("MAE        {:.3} mHz", m.mae_hz * 1e3);
        println!("RMSE       {:.3} mHz", m.rmse_hz * 1e3);
        println!("max error  {:.3} mHz", m.max_err_hz * 1e3);
        if let Some(p) = &a.plot {
            println!("plot       {}", p.display());
        }
    }
    Ok(())
}
