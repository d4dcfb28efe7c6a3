//! `eenf demo`: simulate, extract, compare — the method end to end on a built-in scene.

use std::path::PathBuf;

use anyhow::{Context, Result};
use eenf_cli::output::read_trace;
use eenf_cli::pipeline::{extract_file, ExtractOptions, Nominal};
use eenf_cli::plot::{plot_comparison, plot_extraction};
use eenf_cli::progress::Progress;
use eenf_dsp::EnfParams;

use super::compare::compare;
use super::simulate::{self, sibling};

/// Arguments of `eenf demo`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder for the recording, traces and plots.
    #[arg(long, default_value = "eenf-demo")]
    pub out_dir: PathBuf,
    /// Length of the simulated recording, s.
    #[arg(long, default_value_t = 60.0)]
    pub duration: f64,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

pub fn run(a: Args, progress: Progress) -> Result<()> {
    std::fs::create_dir_all(&a.out_dir).with_context(|| format!("{}", a.out_dir.display()))?;
    let recording = a.out_dir.join("demo.aedat4");
    println!(
        "1/3 simulating {:.0} s of a lamp-lit scene on a 50 Hz grid...",
        a.duration
    );
    let sim = simulate::run(
        simulate::Args {
            duration: a.duration,
            output: recording.clone(),
            seed: a.seed,
            ..simulate::Args::default()
        },
        progress,
    )?;
    println!(
        "    {} events in {:.1} s -> {}",
        sim.stats.events,
        sim.seconds,
        recording.display()
    );

    println!("2/3 extracting the ENF from the events (E-ENF)...");
    let started = std::time::Instant::now();
    let opts = ExtractOptions {
        nominal: Nominal::Auto,
        ..ExtractOptions::default()
    };
    let x = extract_file(&recording, &opts, &progress)?;
    let trace_csv = sibling(&recording, "enf.csv");
    let trace_json = sibling(&recording, "enf.json");
    super::extract::save(&x, &trace_csv)?;
    super::extract::save(&x, &trace_json)?;
    let extract_plot = sibling(&recording, "extract.png");
    plot_extraction(
        &extract_plot,
        "demo: ENF per harmonic and the selected harmonic",
        &x.trace,
    )?;
    println!(
        "    detected a {} Hz grid; {} estimates in {:.2} s -> {}",
        x.params.nominal_hz,
        x.trace.enf_hz.len(),
        started.elapsed().as_secs_f64(),
        trace_csv.display()
    );

    println!("3/3 comparing with the simulator's ground truth...");
    let est = read_trace(&trace_csv)?;
    let c = compare(
        &est,
        &trace_csv,
        &sim.truth,
        0.0,
        Nominal::Hz(50.0),
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
    println!();
    println!("CC   {:.4}", m.cc);
    println!(
        "MAE  {:.3} mHz  (RMSE {:.3} mHz, max {:.3} mHz, {} s compared)",
        m.mae_hz * 1e3,
        m.rmse_hz * 1e3,
        m.max_err_hz * 1e3,
        m.n
    );
    println!();
    println!("files in {}:", a.out_dir.display());
    for p in [
        &recording,
        &sim.truth,
        &trace_csv,
        &trace_json,
        &extract_plot,
        &compare_plot,
    ] {
        println!("  {}", p.display());
    }
    Ok(())
}
