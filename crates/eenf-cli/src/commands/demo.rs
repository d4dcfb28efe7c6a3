//! `eenf demo`: simulate, extract, compare — the method end to end on a built-in scene.

use std::path::PathBuf;

use anyhow::{Context, Result};
use eenf::evaluate::compare_trace;
use eenf::extract::{extract_file, ExtractOptions};
use eenf::output::{sibling, write_atomic};
use eenf::progress::Progress;
use eenf::simulation::{simulate_recording, Recipe};
use eenf::trace::Trace;
use eenf_core::Nominal;
use eenf_dsp::EnfParams;
use eenf_figures::{plot_comparison, plot_extraction};
use eenf_sim::{SceneKind, SimConfig};

/// Arguments of `eenf demo`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder for the recording, traces and plots.
    #[arg(long, default_value = "eenf-demo")]
    pub out_dir: PathBuf,
    /// Length of the simulated recording, s.
    #[arg(long, default_value_t = 60.0, value_parser = crate::args::number_in((1.0, 3600.0)))]
    pub duration: f64,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// Runs `eenf demo`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    std::fs::create_dir_all(&a.out_dir).with_context(|| format!("{}", a.out_dir.display()))?;
    let recording = a.out_dir.join("demo.aedat4");
    outln!(
        "1/3 simulating {:.0} s of a lamp-lit scene on a 50 Hz grid...",
        a.duration
    );
    let config = SimConfig {
        duration_s: a.duration,
        seed: a.seed,
        ..SimConfig::default()
    }
    .with_kinds(&[SceneKind::Static]);
    let sim = simulate_recording(&Recipe::new(config, recording.clone()), &progress)?.sim;
    outln!(
        "    {} events in {:.1} s -> {}",
        sim.stats.events,
        sim.seconds,
        recording.display()
    );

    outln!("2/3 extracting the ENF from the events (E-ENF)...");
    let started = std::time::Instant::now();
    let opts = ExtractOptions {
        nominal: Nominal::Auto,
        ..ExtractOptions::default()
    };
    let trace = extract_file(&recording, &opts, &progress)?;
    let trace_csv = sibling(&recording, "enf.csv");
    let trace_json = sibling(&recording, "enf.json");
    for p in [&trace_csv, &trace_json] {
        write_atomic(p, |w| trace.write_for(p, w))?;
    }
    let extract_plot = sibling(&recording, "extract.png");
    plot_extraction(
        &extract_plot,
        "demo: ENF per harmonic and the selected harmonic",
        &trace,
    )?;
    outln!(
        "    detected a {} Hz grid; {} estimates in {:.2} s -> {}",
        trace.nominal_hz.unwrap_or(f64::NAN),
        trace.enf_hz.len(),
        started.elapsed().as_secs_f64(),
        trace_csv.display()
    );

    outln!("3/3 comparing with the simulator's ground truth...");
    let est = Trace::read(&trace_csv, None)?;
    let c = compare_trace(
        &est,
        &trace_csv,
        &sim.truth,
        0.0,
        eenf::trace::INDEX_STEP_S,
        Nominal::Grid(eenf_core::Grid::Hz50),
        &EnfParams::default(),
    )?;
    let compare_plot = sibling(&recording, "compare.png");
    let m = c.agreement;
    plot_comparison(
        &compare_plot,
        &format!(
            "demo: E-ENF vs truth, CC {:.4}, MAE {:.2} mHz",
            m.cc,
            m.mae_hz * 1e3
        ),
        &c.time_s,
        &c.estimate,
        &c.reference,
    )?;
    outln!();
    outln!("CC   {:.4}", m.cc);
    outln!(
        "MAE  {:.3} mHz  (RMSE {:.3} mHz, max {:.3} mHz, {} s compared)",
        m.mae_hz * 1e3,
        m.rmse_hz * 1e3,
        m.max_err_hz * 1e3,
        m.n
    );
    outln!();
    outln!("files in {}:", a.out_dir.display());
    for p in [
        &recording,
        &sim.truth,
        &trace_csv,
        &trace_json,
        &extract_plot,
        &compare_plot,
    ] {
        outln!("  {}", p.display());
    }
    Ok(())
}
