//! `eenf info`: what an event file holds.

use std::path::PathBuf;

use anyhow::Result;
use eenf::inspect::{inspect, CameraFlicker};
use eenf::time::utc_micros;

use super::args::InputArgs;

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

/// `flicker 119.99 Hz (60 Hz grid), 38 dB above the noise`, or why there is none.
fn flicker_text(f: &CameraFlicker) -> String {
    let who = f
        .camera
        .map(|c| format!("camera {c}: "))
        .unwrap_or_default();
    let sum = f
        .sum_line
        .map(|l| {
            format!(
                "; ON − OFF sums: {:.3} Hz, prominence {:.1}",
                l.hz, l.prominence
            )
        })
        .unwrap_or_default();
    match f.line {
        Some(l) if l.is_mains() => format!(
            "{who}{:.3} Hz ({} Hz grid), {:.0} dB above the noise (prominence {:.1}{sum})",
            l.hz,
            l.grid_hz,
            l.db(),
            l.prominence
        ),
        Some(l) => format!(
            "{who}none: the strongest line near 100/120 Hz, {:.3} Hz, stands {:.1}x above the noise{sum}",
            l.hz, l.prominence
        ),
        None => format!("{who}not measured (shorter than 1 s)"),
    }
}

pub fn run(a: Args) -> Result<()> {
    let found = inspect(&a.file, &a.read.options())?;
    let (info, stats, skipped) = (&found.info, &found.stats, &found.skipped);
    let sampling = found.grouping.map(|g| g.choice());
    let duration_s = match (stats.first_t, stats.last_t) {
        (Some(f), Some(l)) => (l - f) as f64 * 1e-6,
        _ => 0.0,
    };
    let rate = if duration_s > 0.0 {
        stats.events as f64 / duration_s
    } else {
        0.0
    };
    // resolution: header, else the data's extent
    let width = info.width.or(stats.x_range.map(|r| r.1 + 1));
    let height = info.height.or(stats.y_range.map(|r| r.1 + 1));
    if a.json {
        let streams: Vec<_> = info
            .streams
            .iter()
            .map(|s| {
                serde_json::json!({"id": s.id, "type": s.kind, "width": s.width,
                    "height": s.height, "source": s.source})
            })
            .collect();
        let v = serde_json::json!({
            "file": a.file, "format": info.format, "codec": info.codec,
            "width": width, "height": height, "streams": streams, "indexed": info.indexed,
            "events": stats.events, "on_events": stats.on,
            "first_t_us": stats.first_t, "last_t_us": stats.last_t,
            "duration_s": duration_s, "events_per_s": rate,
            "x_range": stats.x_range, "y_range": stats.y_range,
            "skipped": skipped.iter().map(|(k, n)| (k.to_string(), *n)).collect::<std::collections::BTreeMap<_, _>>(),
            "cameras": info.cameras, "notes": info.notes,
            "sampling": sampling.as_ref().map(|s| serde_json::json!({"auto": s.0, "why": s.1})),
            "flicker": found.flicker,
            "damage": found.damage.as_ref().map(|d| serde_json::json!({
                "kind": d.kind.to_string(), "offset": d.offset,
                "events_before": d.events_before, "message": d.message})),
        });
        outln!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    outln!("file        {}", a.file.display());
    match &info.codec {
        Some(c) => outln!("format      {} (compression {c})", info.format),
        None => outln!("format      {}", info.format),
    }
    match (width, height) {
        (Some(w), Some(h)) => outln!("resolution  {w} x {h}"),
        _ => outln!("resolution  unknown"),
    }
    if !info.streams.is_empty() {
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
        outln!("first t     {f} us ({})", utc_micros(f));
        outln!("last t      {l} us ({})", utc_micros(l));
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
