//! What a recording holds, for `eenf info`: header, counts and span, and what E-ENF will see in
//! it (how its timestamps group, and the mains flicker line of each camera).

use std::path::Path;

use anyhow::Result;
use eenf_dsp::{flicker_line, FlickerLine, Grouping, SamplingMethod, TemporalSampler};
use eenf_events::{OpenOptions, StreamInfo, StreamStats};

use crate::extract::camera_line;

/// The flicker of one camera.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CameraFlicker {
    /// The camera, in a file with several.
    pub camera: Option<u8>,
    /// Its strongest line near 100/120 Hz in the signal E-ENF samples (`auto` sampling;
    /// `None`: shorter than a second, or no events).
    pub line: Option<FlickerLine>,
    /// The same in the 1 ms ON − OFF sums (the measure real recordings are calibrated with).
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
    let mut reader = eenf_events::open_with(path, open)?;
    let info = reader.info().clone();
    let mut stats = StreamStats::default();
    let mut sampler = TemporalSampler::new(SamplingMethod::Sum, 1000);
    let mut auto = TemporalSampler::new(SamplingMethod::Auto, 1000);
    let mut grouping = None;
    let mut wild = false;
    while let Some(b) = reader.next_batch()? {
        stats.add(&b);
        if grouping.is_none() && !b.is_empty() {
            grouping = Some(Grouping::measure(&b.t));
        }
        // a wild timestamp ends the flicker analysis, not the statistics
        wild = wild || sampler.push(&b).is_err() || auto.push(&b).is_err();
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
            out.push(CameraFlicker {
                camera: Some(c),
                line: camera_line(path, open, c, SamplingMethod::Auto)?,
                sum_line: camera_line(path, open, c, SamplingMethod::Sum)?,
            });
        }
        out
    } else {
        vec![CameraFlicker {
            camera: open.camera,
            line: if wild { None } else { line_of(auto) },
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
