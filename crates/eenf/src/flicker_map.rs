//! Where the flicker is: the mains line's strength in each tile of pixels, a picture in which a
//! person sees the lamp and the surfaces it lights.

use crate::error::{fail, Result};
use eenf_dsp::{flicker_lines, line_strength_at, FlickerLine};
use eenf_events::OpenOptions;
use rayon::prelude::*;

use crate::progress::Progress;
use crate::recording::Recording;

/// Seconds of the recording the map looks at (the line is steady; memory stays bounded).
pub const MAP_SECONDS: f64 = 64.0;
/// Bin of the tiles' ON − OFF sums, µs: 500 Hz sampling keeps 80–140 Hz below Nyquist.
const BIN_US: i64 = 2000;
/// Tiles across the longer side of the sensor, at most.
const MAX_TILES: u16 = 32;
/// A tile flickers when the recording's line stands this many times above the tile's noise
/// (11 dB; tiles of noise alone reach about 10 dB at most on the real recordings).
pub const MIN_TILE_STRENGTH: f64 = 3.5;

/// The flicker line in each tile of a recording.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FlickerMap {
    /// Sensor width and height, pixels.
    pub width: u16,
    /// See `width`.
    pub height: u16,
    /// Tile side, pixels.
    pub tile: u16,
    /// Tiles across and down.
    pub cols: usize,
    /// See `cols`.
    pub rows: usize,
    /// Events in each tile (row-major).
    pub events: Vec<u64>,
    /// In each tile (row-major), the magnitude at the whole sensor's line over the tile's
    /// noise (`None`: too few events, or no line over the whole sensor).
    pub strength: Vec<Option<f64>>,
    /// The whole sensor's line.
    pub whole: Option<FlickerLine>,
    /// Seconds looked at.
    pub seconds: f64,
    /// What ended the readable part early (damage, a wild timestamp), within those seconds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damage: Option<String>,
}

impl FlickerMap {
    /// Tiles whose line stands above the noise, as a share of all tiles.
    pub fn flickering_share(&self) -> f64 {
        let n = self.flickering().count();
        n as f64 / self.strength.len().max(1) as f64
    }

    /// The tiles (row-major indices) where the line stands out.
    pub fn flickering(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.strength.len())
            .filter(|&k| self.strength[k].is_some_and(|s| s >= MIN_TILE_STRENGTH))
    }
}

/// Maps the flicker of the recording `rec` (read as `open` says) over its first
/// [`MAP_SECONDS`]: tiles of `tile` pixels (default: at most 32 tiles across).
pub fn flicker_map(
    rec: &Recording,
    open: &OpenOptions,
    tile: Option<u16>,
    progress: &Progress,
) -> Result<FlickerMap> {
    flicker_map_of(rec.open(open)?, rec.name(), tile, progress)
}

/// Maps the flicker of the events `reader` gives (the recording `path`), as [`flicker_map`].
pub fn flicker_map_of(
    mut reader: Box<dyn eenf_events::EventReader>,
    path: &std::path::Path,
    tile: Option<u16>,
    progress: &Progress,
) -> Result<FlickerMap> {
    let info = reader.info().clone();
    let (Some(width), Some(height)) = (info.width, info.height) else {
        fail!(
            Method,
            "{}: the header gives no sensor size to lay tiles on",
            path.display()
        );
    };
    let tile = tile
        .unwrap_or_else(|| width.max(height).div_ceil(MAX_TILES))
        .max(1);
    let (cols, rows) = (
        width.div_ceil(tile) as usize,
        height.div_ceil(tile) as usize,
    );
    let bins = (MAP_SECONDS * 1e6 / BIN_US as f64) as usize;
    // ON − OFF per tile and bin, tile-major
    let mut sums = vec![0i16; cols * rows * bins];
    let mut whole = vec![0i32; bins];
    let mut events = vec![0u64; cols * rows];
    let mut t0 = None;
    let mut last_bin = 0usize;
    let bar = progress.events(info.event_count, "mapping the flicker");
    'read: while let Some(b) = reader.next_batch()? {
        let start = *t0.get_or_insert(b.t.first().copied().unwrap_or(0));
        for i in 0..b.len() {
            let bin = (b.t[i] - start).max(0) / BIN_US;
            if bin as usize >= bins {
                break 'read;
            }
            let bin = bin as usize;
            last_bin = last_bin.max(bin);
            let (x, y) = (b.x[i] / tile, b.y[i] / tile);
            if x as usize >= cols || y as usize >= rows {
                continue;
            }
            let k = y as usize * cols + x as usize;
            let v: i16 = if b.p[i] { 1 } else { -1 };
            let s = &mut sums[k * bins + bin];
            *s = s.saturating_add(v);
            whole[bin] += i32::from(v);
            events[k] += 1;
        }
        bar.inc(b.len() as u64);
    }
    bar.finish_and_clear();
    let damage = reader.damage().map(|d| d.to_string());
    let used = last_bin + 1;
    let fs = 1e6 / BIN_US as f64;
    let whole_x: Vec<f64> = whole[..used].iter().map(|&v| v as f64).collect();
    let whole_line = flicker_lines(&whole_x, fs).map(eenf_dsp::stronger);
    let strength: Vec<Option<f64>> = (0..cols * rows)
        .into_par_iter()
        .map(|k| {
            let line = whole_line?;
            if events[k] < 100 {
                return None;
            }
            let x: Vec<f64> = sums[k * bins..k * bins + used]
                .iter()
                .map(|&v| v as f64)
                .collect();
            line_strength_at(&x, fs, line.hz)
        })
        .collect();
    Ok(FlickerMap {
        width,
        height,
        tile,
        cols,
        rows,
        events,
        strength,
        whole: whole_line,
        seconds: used as f64 / fs,
        damage,
    })
}

/// The tiles of a [`FlickerMap`] that extraction keeps: those whose line stands out. Events
/// elsewhere (people, moving objects, noise) only add noise to the flicker signal.
#[derive(Debug, Clone)]
pub struct TileMask {
    tile: u16,
    cols: usize,
    rows: usize,
    keep: Vec<bool>,
    /// Tiles kept.
    pub kept: usize,
    /// Share of the mapped events in the kept tiles.
    pub event_share: f64,
}

impl TileMask {
    /// The flickering tiles of `map`, or `None` when none flickers or the flicker is
    /// everywhere (nothing to leave out: every tile with events flickers).
    pub fn from_map(map: &FlickerMap) -> Option<Self> {
        let mut keep = vec![false; map.strength.len()];
        for k in map.flickering() {
            keep[k] = true;
        }
        let kept = keep.iter().filter(|&&k| k).count();
        let active = (0..keep.len()).filter(|&k| map.events[k] >= 100).count();
        if kept == 0 || kept >= active {
            return None;
        }
        let total: u64 = map.events.iter().sum();
        let inside: u64 = (0..keep.len())
            .filter(|&k| keep[k])
            .map(|k| map.events[k])
            .sum();
        Some(TileMask {
            tile: map.tile,
            cols: map.cols,
            rows: map.rows,
            keep,
            kept,
            event_share: inside as f64 / total.max(1) as f64,
        })
    }

    /// Whether the event at pixel (`x`, `y`) is kept.
    pub fn keeps(&self, x: u16, y: u16) -> bool {
        let (c, r) = ((x / self.tile) as usize, (y / self.tile) as usize);
        c < self.cols && r < self.rows && self.keep[r * self.cols + c]
    }

    /// Copies the events of `batch` in kept tiles into `out` (cleared first).
    pub fn filter(&self, batch: &eenf_events::EventBatch, out: &mut eenf_events::EventBatch) {
        out.clear();
        for i in 0..batch.len() {
            if self.keeps(batch.x[i], batch.y[i]) {
                out.push(batch.t[i], batch.x[i], batch.y[i], batch.p[i]);
            }
        }
    }

    /// What was kept, in words.
    pub fn describe(&self) -> String {
        format!(
            "flicker map: {} of {} tiles ({}x{} px) flicker; their {:.1} % of the events are traced, the rest left out",
            self.kept,
            self.keep.len(),
            self.tile,
            self.tile,
            100.0 * self.event_share
        )
    }
}
