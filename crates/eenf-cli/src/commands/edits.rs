//! `eenf edits`: was a recording edited? Cuts and insertions from the hum's phase and ENF.

use std::path::PathBuf;

use anyhow::Result;
use eenf::edits::file_edits;
use eenf::progress::Progress;

use crate::args::EditArgs;

/// Arguments of `eenf edits`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The recording: sound in any container `audio` reads, an event file, or an ENF trace
    /// (CSV or JSON: frequency steps alone).
    pub file: PathBuf,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write the report as JSON here.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Draw the phase deviation, the test against its threshold and the ENF, with the edits
    /// marked (.png or .svg).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    #[command(flatten)]
    pub edit: EditArgs,
}

/// Runs `eenf edits`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    let started = std::time::Instant::now();
    let spin = progress.spinner("testing the hum's phase");
    let report = file_edits(&a.file, &a.edit.options()?, &progress)?;
    spin.finish_and_clear();
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    if let Some(out) = &a.output {
        eenf::output::write_atomic(out, |w| Ok(w.write_all(report.to_json().as_bytes())?))?;
        if !eenf::output::is_stdout(out) {
            crate::terminal::announce("report", out);
        }
    }
    if let Some(plot) = &a.plot {
        let title = format!("{}: {}", eenf_figures::title_name(&a.file), report.verdict);
        eenf_figures::plot_edits(plot, &title, &report)?;
        crate::terminal::announce("plot", plot);
    }
    let lines: Vec<String> = report.lines_hz.iter().map(|f| format!("{f:.0}")).collect();
    eprintln!(
        "{}: {} ({:.0} s, {} Hz grid{}{}) tested in {:.2} s",
        a.file.display(),
        report.input,
        report.duration_s,
        report.grid_hz,
        if lines.is_empty() {
            String::new()
        } else {
            format!(", lines at {} Hz", lines.join(", "))
        },
        report
            .min_jump_deg
            .map_or(String::new(), |d| format!(", jumps from {d:.0}° show")),
        started.elapsed().as_secs_f64()
    );
    for s in &report.undecided {
        eprintln!("undecided {:.1}-{:.1} s: {}", s.start_s, s.end_s, s.why);
    }
    if a.json {
        outln!("{}", report.to_json().trim_end());
    } else {
        outln!("{}", report.verdict);
        for e in &report.edits {
            let mut parts = vec![format!("{:9.2} s  {}", e.time_s, e.kind)];
            if let Some(end) = e.end_s {
                parts.push(format!("to {end:.2} s"));
            }
            if let Some(j) = e.phase_jump_deg {
                parts.push(format!(
                    "{j:+.0}° at {:.0} Hz",
                    e.phase_jump_line_hz.unwrap_or(f64::NAN)
                ));
            }
            if let Some(f) = e.frequency_step_mhz {
                parts.push(format!("ENF step {f:+.1} mHz"));
            }
            parts.push(format!("strength {:.1}", e.strength));
            if e.false_alarms_per_hour.is_finite() {
                parts.push(format!(
                    "{} false alarms/h, p {}",
                    small(e.false_alarms_per_hour),
                    small(e.p_value)
                ));
            }
            outln!("{}", parts.join(", "));
            outln!("             {}", e.reading);
        }
    }
    Ok(())
}

/// A rate or a probability for the reader: two digits, and below 1e-12 only a bound (the
/// model says no more than that so far into its tail).
fn small(v: f64) -> String {
    if v < 1e-12 {
        "< 1e-12".to_string()
    } else {
        format!("{v:.1e}")
    }
}
