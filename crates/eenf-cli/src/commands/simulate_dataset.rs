//! `eenf simulate-dataset`: a synthetic EV-ENFD, laid out like the paper's dataset.

use anyhow::Result;
use eenf::dataset_build::build_dataset;
use eenf::progress::Progress;

pub use crate::args::DatasetArgs as Args;

/// Runs `eenf simulate-dataset`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    let build = a.settings().build(a.out_dir.clone())?;
    let built = build_dataset(&build, &progress, &mut |note| eprintln!("{note}"))?;
    eprintln!(
        "{} recordings ({} events, {:.1} M events/s) in {:.0} s -> {}",
        built.recordings,
        built.events,
        built.events as f64 / built.seconds / 1e6,
        built.seconds,
        a.out_dir.display()
    );
    // the names carry local times without their zone, as the data set's do: say which
    eprintln!(
        "file names are in local time at UTC{} (--tz; give the same to `match` and `refdb build`)",
        a.tz
    );
    Ok(())
}
