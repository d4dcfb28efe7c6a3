//! `eenf simulate`: an event recording of a flickering scene, with its ground truth.

use crate::args::SimulateArgs;
use anyhow::Result;
use eenf::dataset::{recording_name, recording_start};
use eenf::progress::Progress;
use eenf::simulation::simulate_recording;

/// Arguments of `eenf simulate`.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub sim: SimulateArgs,
}

/// Runs `eenf simulate`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    let a = a.sim;
    let recipe = a.recipe()?;
    let r = simulate_recording(&recipe, &progress)?;
    let (sim, config) = (&r.sim, &r.config);
    for n in &r.notes {
        eprintln!("note: {n}");
    }
    eprintln!(
        "simulated {:.0} s at {}x{}: {} events ({:.1} M events/s generated) in {:.1} s",
        a.duration,
        config.width,
        config.height,
        sim.stats.events,
        sim.stats.events as f64 / sim.seconds / 1e6,
        sim.seconds
    );
    if sim.stats.dropped_events + sim.stats.delayed_events > 0 {
        eprintln!(
            "readout: {} events delayed, {} dropped (bandwidth)",
            sim.stats.delayed_events, sim.stats.dropped_events
        );
    }
    eprintln!("recording  {}", a.output.display());
    eprintln!("truth      {}", sim.truth.display());
    for p in &r.videos {
        eprintln!("video      {}", p.display());
    }
    for p in &r.references {
        eprintln!("reference  {}", p.display());
    }
    // a recording named like the dataset's must carry its own start time
    if let Some(t) = recording_start(&a.output) {
        if (t.local_seconds() as f64 - r.local_start.floor()).abs() > 0.5 {
            eprintln!(
                "note: the name says {}, the recording starts at local second {:.0} of the day",
                recording_name(&t, "…"),
                r.local_start.rem_euclid(86_400.0)
            );
        }
    }
    Ok(())
}
