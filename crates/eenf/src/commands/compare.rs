//! `eenf compare`: agreement of an ENF trace with a reference.

use std::path::{Path, PathBuf};

use anyhow::Result;
use eenf_cli::dataset::recording_start;
use eenf_cli::evaluate::{self, Comparison, Reference};
use eenf_cli::output::{read_trace, TraceFile};
use eenf_cli::pipeline::Nominal;
use eenf_cli::plot::plot_comparison;
use eenf_cli::progress::Progress;
use eenf_dsp::EnfParams;

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

/// The estimate's peak method, from its JSON metadata.
fn estimate_peak(path: &Path) -> Option<eenf_dsp::PeakMethod> {
    let text = std::fs::read_to_string(path).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    serde_json::from_value(v["params"]["peak"].clone()).ok()
}

/// Compares the trace file `est` (read from `est_path`) with the reference at `reference`.
pub fn compare(
    est: &TraceFile,
    est_path: &Path,
    reference: &Path,
    offset_s: f64,
    nominal: Nominal,
    params: &EnfParams,
) -> Result<Comparison> {
    let source = est.source.clone().unwrap_or_else(|| est_path.to_path_buf());
    // the recording's name, else the trace file's own, says when it started
    let named = if recording_start(&source).is_some() {
        source
    } else {
        est_path.to_path_buf()
    };
    let (reference, offset) = Reference::resolve(reference, &named, offset_s)?;
    evaluate::compare(
        &est.time_s,
        &est.enf_hz,
        est_path,
        &reference,
        offset,
        nominal,
        params,
    )
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
