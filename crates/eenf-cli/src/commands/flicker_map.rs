//! `eenf flicker-map`: where in the view the mains flicker is.

use std::path::PathBuf;

use anyhow::Result;
use eenf::flicker_map::{flicker_map, MAP_SECONDS};
use eenf::progress::Progress;
use eenf_figures::plot_flicker_map;

use crate::args::InputArgs;

/// Arguments of `eenf flicker-map`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The event recording.
    pub file: PathBuf,
    /// The picture (.png or .svg). Default: `flicker-map.png`, or none with `--json`.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Tile side, pixels (default: at most 32 tiles across).
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..))]
    pub tile: Option<u16>,
    /// Print the map (every tile's line) as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub read: InputArgs,
}

/// Runs `eenf flicker-map`.
pub fn run(a: Args, progress: Progress) -> Result<()> {
    let rec = eenf::recording::Recording::file(&a.file);
    let map = flicker_map(&rec, &a.read.options(), a.tile, &progress)?;
    if let Some(d) = &map.damage {
        eprintln!("warning: {d}");
    }
    let whole = match map.whole {
        Some(l) => format!("{:.3} Hz over the whole sensor, {}", l.hz, l.strength()),
        None => "no line measured".to_string(),
    };
    let share = 100.0 * map.flickering_share();
    let title = eenf_figures::flicker_map_title(&eenf_figures::title_name(&a.file), &map);
    let picture = match (&a.output, a.json) {
        (Some(p), _) => Some(p.clone()),
        (None, false) => Some(PathBuf::from("flicker-map.png")),
        (None, true) => None,
    };
    if let Some(p) = &picture {
        plot_flicker_map(p, &title, &map)?;
    }
    eprintln!(
        "{}: {} x {} tiles of {} pixels over {:.1} s (at most {MAP_SECONDS} s): flicker {whole}; it stands out in {share:.0} % of the tiles",
        a.file.display(),
        map.cols,
        map.rows,
        map.tile,
        map.seconds
    );
    if let Some(p) = &picture {
        crate::terminal::announce("map", p);
    }
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&map)?);
    }
    Ok(())
}
