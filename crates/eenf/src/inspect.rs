//! What a recording holds, for `eenf info`: header, counts and span, and what E-ENF will see in
//! it (how its timestamps group, and the mains flicker line of each camera).

use std::path::Path;

use crate::error::Result;
use eenf_dsp::{flicker_line, FlickerLine, Grouping, SamplingMethod, TemporalSampler};
use eenf_events::{OpenOptions, StreamInfo, StreamStats};

use crate::extract::{camera_line, traced_lines, ExtractOptions};
use crate::progress::Progress;
use crate::recording::Recording;

/// The flicker of one camera.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CameraFlicker {
    /// The camera, in a file with several.
    pub camera: Option<u8>,
    /// Its strongest line near 100/120 Hz in the events E-ENF traces (the tiles that flicker,
    /// where extraction keeps only those), measured as `extract` measures it: 1 ms ON − OFF
    /// sums (`None`: shorter than a second, or no events).
    pub line: Option<FlickerLine>,
    /// The same over the whole sensor: the measure real recordings are calibrated with.
    pub sum_line: Option<FlickerLine>,
}

/// A recording read to the end.
#[derive(Debug, Clone)]
pub struct Inspection {
    /// What the header said (and what the reader inferred: `notes`).
    pub info: StreamInfo,
    /// Counts, span and extent of the events.
    pub stats: StreamStats,
    /// Words or packets skipped, by kind.
    pub skipped: Vec<(&'static str, u64)>,
    /// How the first events' timestamps group, and so the sampling `auto` picks.
    pub grouping: Option<Grouping>,
    /// The flicker line of each camera.
    pub flicker: Vec<CameraFlicker>,
    /// What ended the readable part before the file's end (damage, a wild timestamp).
    pub damage: Option<eenf_events::Damage>,
}

/// Reads `path` (as `open` says) to the end: its statistics, and the flicker line (1 ms
/// ON − OFF sums) of each camera, or of the camera `open` names.
pub fn inspect(path: &Path, open: &OpenOptions) -> Result<Inspection> {
    let rec = Recording::file(path);
    let mut reader = rec.open(open)?;
    let info = reader.info().clone();
    let mut stats = StreamStats::default();
    let mut sampler = TemporalSampler::new(SamplingMethod::Sum, 1000);
    let mut grouping = None;
    let mut wild = false;
    while let Some(b) = reader.next_batch()? {
        stats.add(&b);
        if grouping.is_none() && !b.is_empty() {
            grouping = Some(Grouping::measure(&b.t));
        }
        // a wild timestamp ends the flicker analysis, not the statistics
        wild = wild || sampler.push(&b).is_err();
    }
    let skipped = reader.skipped();
    let damage = reader.damage().cloned();
    let line_of = |sampler: TemporalSampler| {
        let seq = sampler.finish().ok()?;
        flicker_line(&seq.signal(), seq.fs())
    };
    let flicker = if info.cameras.len() > 1 && open.camera.is_none() {
        // two clocks: each camera on its own
        let mut out = Vec::new();
        for c in 0..info.cameras.len().min(u8::MAX as usize) as u8 {
            let one = OpenOptions {
                camera: Some(c),
                ..open.clone()
            };
            out.push(CameraFlicker {
                camera: Some(c),
                line: traced_line(&rec, &one)?,
                sum_line: camera_line(&rec, open, c, SamplingMethod::Sum)?,
            });
        }
        out
    } else {
        vec![CameraFlicker {
            camera: open.camera,
            line: if wild { None } else { traced_line(&rec, open)? },
            sum_line: if wild { None } else { line_of(sampler) },
        }]
    };
    Ok(Inspection {
        info,
        stats,
        skipped,
        grouping,
        flicker,
        damage,
    })
}

/// The stronger of the lines `extract` would measure in `rec` opened as `open` says.
fn traced_line(rec: &Recording, open: &OpenOptions) -> Result<Option<FlickerLine>> {
    let opts = ExtractOptions {
        open: open.clone(),
        ..ExtractOptions::default()
    };
    let lines = traced_lines(rec, &opts, &Progress::hidden())?;
    Ok(lines.map(eenf_dsp::stronger))
}

impl Inspection {
    /// Seconds from the first event to the last, and events per second over them.
    pub fn duration_and_rate(&self) -> (f64, f64) {
        let s = &self.stats;
        let duration_s = match (s.first_t, s.last_t) {
            (Some(f), Some(l)) => (l - f) as f64 * 1e-6,
            _ => 0.0,
        };
        let rate = if duration_s > 0.0 {
            s.events as f64 / duration_s
        } else {
            0.0
        };
        (duration_s, rate)
    }

    /// Width and height: the header's, else the events' extent.
    pub fn resolution(&self) -> (Option<u16>, Option<u16>) {
        let (info, s) = (&self.info, &self.stats);
        (
            info.width.or(s.x_range.map(|r| r.1 + 1)),
            info.height.or(s.y_range.map(|r| r.1 + 1)),
        )
    }

    /// The inspection of `file` as `eenf info --json` prints it.
    pub fn to_json(&self, file: &Path) -> serde_json::Value {
        let (info, stats) = (&self.info, &self.stats);
        let (duration_s, rate) = self.duration_and_rate();
        let (width, height) = self.resolution();
        let sampling = self.grouping.map(|g| g.choice());
        let streams: Vec<_> = info
            .streams
            .iter()
            .map(|s| {
                serde_json::json!({"id": s.id, "type": s.kind, "width": s.width,
                    "height": s.height, "source": s.source, "messages": s.messages})
            })
            .collect();
        let skipped: std::collections::BTreeMap<String, u64> = self
            .skipped
            .iter()
            .map(|(k, n)| (k.to_string(), *n))
            .collect();
        serde_json::json!({
            "file": file, "format": info.format, "codec": info.codec, "within": info.within,
            "width": width, "height": height, "streams": streams, "indexed": info.indexed,
            "events": stats.events, "on_events": stats.on,
            "first_t_us": stats.first_t, "last_t_us": stats.last_t,
            "duration_s": duration_s, "events_per_s": rate,
            "x_range": stats.x_range, "y_range": stats.y_range,
            "skipped": skipped,
            "cameras": info.cameras, "notes": info.notes,
            "sampling": sampling.as_ref().map(|s| serde_json::json!({"auto": s.0, "why": s.1})),
            "flicker": self.flicker,
            "damage": self.damage.as_ref().map(|d| serde_json::json!({
                "kind": d.kind.to_string(), "offset": d.offset,
                "events_before": d.events_before, "message": d.message})),
        })
    }
}
