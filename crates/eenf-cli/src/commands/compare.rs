//! `eenf compare`: agreement of an ENF trace with a reference.

use std::path::PathBuf;

use anyhow::Result;
use eenf::evaluate::compare_trace;
use eenf::progress::Progress;
use eenf::trace::Trace;
use eenf_core::Nominal;
use eenf_dsp::{EnfParams, PeakMethod};
use eenf_figures::plot_comparison;

use crate::args::one_of;

/// Arguments of `eenf compare`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The estimated trace (CSV or JSON from `eenf extract`).
    pub estimate: PathBuf,
    /// The reference: a trace CSV/JSON, a mains WAV, or a folder of hourly WAVs named like
    /// `2022_08_17_Wed_16_00_00.wav` (the estimate's recording name `dvSave-…` then gives the
    /// offset).
    pub reference: PathBuf,
    /// Seconds to add to the estimate's times to reach the reference's times. Against one
    /// hourly WAV or a folder of them, the default places the recording by its `dvSave-…` name.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = crate::args::number_in((-1e9, 1e9)))]
    pub offset_s: f64,
    /// Seconds between the rows of an `index,value` CSV (estimate or reference), such as the
    /// published 60 Hz ENF traces.
    #[arg(long, default_value_t = eenf::trace::INDEX_STEP_S, value_parser = crate::args::number_in(eenf::options::limits::INDEX_STEP_S))]
    pub index_step: f64,
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
    #[arg(long, value_parser = one_of::<PeakMethod>(&PeakMethod::NAMES))]
    pub peak: Option<PeakMethod>,
}

/// Runs `eenf compare`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    if a.index_step.is_nan() || a.index_step <= 0.0 {
        anyhow::bail!("--index-step must be positive");
    }
    let est = Trace::read(&a.estimate, Some(a.index_step))?;
    let params = EnfParams {
        peak: a.peak.or_else(|| est.peak()).unwrap_or(PeakMethod::Exact),
        ..EnfParams::default()
    };
    let spin = progress.spinner("comparing");
    let c = compare_trace(
        &est,
        &a.estimate,
        &a.reference,
        a.offset_s,
        a.index_step,
        a.nominal,
        &params,
    )?;
    spin.finish_and_clear();
    let m = c.agreement;
    if let Some(p) = &a.plot {
        let title = format!(
            "{} vs {}: CC {:.4}, MAE {:.2} mHz",
            eenf_figures::title_name(&a.estimate),
            a.reference
                .file_name()
                .unwrap_or_default()
                .to_string_lossy(),
            m.cc,
            m.mae_hz * 1e3
        );
        plot_comparison(p, &title, &c.time_s, &c.estimate, &c.reference)?;
        crate::terminal::announce("plot", p);
    }
    if a.json {
        let mut v = c.summary_json(a.offset_s);
        v["estimate"] = serde_json::json!(a.estimate);
        v["reference"] = serde_json::json!(a.reference);
        v["plot"] = serde_json::json!(a.plot);
        outln!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        outln!("estimate   {}", a.estimate.display());
        outln!("reference  {}", a.reference.display());
        outln!("seconds    {}", m.n);
        outln!("CC         {:.4}", m.cc);
        outln!("MAE        {:.3} mHz", m.mae_hz * 1e3);
        outln!("RMSE       {:.3} mHz", m.rmse_hz * 1e3);
        outln!("max error  {:.3} mHz", m.max_err_hz * 1e3);
        if let Some(p) = &a.plot {
            outln!("plot       {}", p.display());
        }
    }
    Ok(())
}
