//! `eenf info`: what an event file holds.

use std::path::PathBuf;

use anyhow::Result;
use eenf::inspect::{inspect, CameraFlicker};
use eenf::time::clock_text;

use crate::args::InputArgs;

/// Arguments of `eenf info`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The event file (format found from its content).
    pub file: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub read: InputArgs,
}

/// `119.990 Hz (60 Hz grid), in the events E-ENF traces, as `extract` measures it: 38.2 dB
/// over its local floor and prominence …`, or why there is none.
fn flicker_text(f: &CameraFlicker) -> String {
    let who = f
        .camera
        .map(|c| format!("camera {c}: "))
        .unwrap_or_default();
    // the whole sensor's line too, where E-ENF traces only the tiles that flicker
    let whole = f
        .sum_line
        .filter(|w| Some(*w) != f.line)
        .map(|w| format!("; whole sensor: {:.3} Hz, {}", w.hz, w.strength()))
        .unwrap_or_default();
    match f.line {
        Some(l) if l.is_mains() => format!(
            "{who}{:.3} Hz ({} Hz grid), in the events E-ENF traces, as `extract` measures it: {}{whole}",
            l.hz,
            l.grid_hz,
            l.strength()
        ),
        Some(l) => format!(
            "{who}none: the strongest line near 100/120 Hz, {:.3} Hz, does not stand: {}{whole}",
            l.hz,
            l.strength()
        ),
        None => format!("{who}not measured (shorter than 1 s)"),
    }
}

/// Runs `eenf info`.
pub fn run(a: Args) -> Result<()> {
    let found = inspect(&a.file, &a.read.options())?;
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&found.to_json(&a.file))?);
        return Ok(());
    }
    let (info, stats) = (&found.info, &found.stats);
    let sampling = found.grouping.map(|g| g.choice());
    let (duration_s, rate) = found.duration_and_rate();
    let (width, height) = found.resolution();
    outln!("file        {}", a.file.display());
    match (&info.codec, &info.within) {
        (_, Some(w)) => outln!("format      {}, {w}", info.format),
        (Some(c), None) => outln!("format      {} (compression {c})", info.format),
        (None, None) => outln!("format      {}", info.format),
    }
    match (width, height) {
        (Some(w), Some(h)) => outln!("resolution  {w} x {h}"),
        _ => outln!("resolution  unknown"),
    }
    let topics: Vec<String> = info
        .streams
        .iter()
        .filter_map(|s| {
            let name = s
                .source
                .as_ref()
                .filter(|_| s.messages.is_some() || info.within.is_some())?;
            Some(match s.messages {
                Some(n) => format!("{name} {} ({n} messages)", s.kind),
                None => format!("{name} {}", s.kind),
            })
        })
        .collect();
    if !topics.is_empty() {
        outln!("topics      {}", topics.join("; "));
    } else if !info.streams.is_empty() {
        let list: Vec<String> = info
            .streams
            .iter()
            .map(|s| match (s.width, s.height) {
                (Some(w), Some(h)) => format!("{} {} {w}x{h}", s.id, s.kind),
                _ => format!("{} {}", s.id, s.kind),
            })
            .collect();
        outln!("streams     {}", list.join(", "));
    }
    outln!(
        "events      {} ({} ON, {} OFF)",
        stats.events,
        stats.on,
        stats.events - stats.on
    );
    if let (Some(f), Some(l)) = (stats.first_t, stats.last_t) {
        outln!("first t     {f} us ({})", clock_text(f));
        outln!("last t      {l} us ({})", clock_text(l));
        outln!("duration    {duration_s:.6} s");
        outln!("rate        {:.3} M events/s", rate / 1e6);
    }
    if !info.cameras.is_empty() {
        outln!("cameras     {}", info.cameras.join("; "));
    }
    if let Some((method, why)) = &sampling {
        outln!("sampling    auto → {method} ({why})");
    }
    for f in &found.flicker {
        outln!("flicker     {}", flicker_text(f));
    }
    for n in &info.notes {
        outln!("note        {n}");
    }
    if let Some(d) = &found.damage {
        outln!(
            "damage      {} at byte {}: the {} events before it are counted above",
            d.kind,
            d.offset,
            d.events_before
        );
        eprintln!("warning: {d}");
    }
    Ok(())
}
