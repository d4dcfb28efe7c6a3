//! Tracking a signal too long to hold in memory (a day of decimated sound kept on disk), a
//! block at a time, giving what tracking it whole gives.
//!
//! Each band's windows are tracked half an hour at a time. A block holds the samples its
//! windows read, and where its band-pass runs, enough more on either side for the filter to
//! settle: the forward-backward filter's response to what lies beyond a block's edge has
//! died away (below rounding) by the time it reaches the windows. Where a block touches the
//! recording's start or end, the filter meets that edge as it does whole.

use std::ops::Range;

use rayon::prelude::*;

use crate::chirp::{baseband, baseband_block};
use crate::enf::{
    bands_of, check_near_nominal, finish_bands, BandTrack, DspError, EnfEstimates, EnfParams,
    FOLLOW_MIN_WINDOWS,
};
use crate::filtfilt::sosfiltfilt;
use crate::tracker::PeakMethod;

/// A signal read a block at a time.
pub trait BlockSource: Sync {
    /// Its length, in samples.
    fn len(&self) -> usize;
    /// Samples `range`.
    fn read(&self, range: Range<usize>) -> Result<Vec<f64>, DspError>;
    /// True when it holds no sample.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl BlockSource for &[f64] {
    fn len(&self) -> usize {
        <[f64]>::len(self)
    }
    fn read(&self, range: Range<usize>) -> Result<Vec<f64>, DspError> {
        Ok(self[range].to_vec())
    }
}

/// Windows tracked per block: half an hour of one-second steps.
const BLOCK_FRAMES: usize = 1800;

/// Samples a band-pass needs on either side of what it is read for: its slowest pole decays
/// within a few tenths of a second at the default ±2 Hz (order 4), and 40 time constants of
/// it bring what lies beyond a block's edge below rounding; 30 s more for good measure.
fn settle_len(fs: f64, p: &EnfParams) -> usize {
    let slowest_s = p.filter_order.max(1) as f64 / (std::f64::consts::PI * p.half_band_hz);
    ((30.0 + 40.0 * slowest_s) * fs).ceil() as usize
}

/// [`crate::enf_from_hum_lines`] over a signal read a block at a time.
pub fn enf_from_hum_lines_in(
    x: &dyn BlockSource,
    fs: f64,
    p: &EnfParams,
    harmonics: &[usize],
) -> Result<EnfEstimates, DspError> {
    let long_enough = x.len() as f64 / fs >= FOLLOW_MIN_WINDOWS * p.window_s;
    let follow = p.peak == PeakMethod::Exact && long_enough;
    let bands = bands_of(x.len(), fs, p, 1.0, harmonics)?;
    let tracks = bands
        .par_iter()
        .map(|&m| track_band(x, fs, p, BandTrack::new(m, p, 1.0, follow), true))
        .collect::<Result<Vec<_>, _>>()?;
    finish_bands(tracks, fs, p, 1.0)
}

/// The reference ENF of a mains (or audio) signal: the same tracker at the fundamental f0,
/// searched within f0 ± `half_band_hz`. No filtering, as in the method's definition.
pub fn reference_enf(x: &[f64], fs: f64, p: &EnfParams) -> Result<Vec<f64>, DspError> {
    reference_enf_with_snr(x, fs, p).map(|(enf, _)| enf)
}

/// [`reference_enf`], with each window's line strength over its band's median, dB (see
/// [`StftTracker::track_with_snr`]).
pub fn reference_enf_with_snr(
    x: &[f64],
    fs: f64,
    p: &EnfParams,
) -> Result<(Vec<f64>, Vec<f64>), DspError> {
    // the block path over the slice: one tracker and one set of checks for both
    reference_enf_in(&x, fs, p)
}

/// [`crate::reference_enf_with_snr`] (f0 alone, unfiltered) over a signal read a block at a
/// time.
pub fn reference_enf_in(
    x: &dyn BlockSource,
    fs: f64,
    p: &EnfParams,
) -> Result<(Vec<f64>, Vec<f64>), DspError> {
    crate::enf::check_reference(x.len(), fs, p)?;
    let b = BandTrack::new(1, p, 1.0, false);
    let band = b.band;
    let (enf, snr_db): (Vec<f64>, Vec<f64>) =
        track_band(x, fs, p, b, false)?.tracked.into_iter().unzip();
    if enf.iter().all(|v| !v.is_finite()) {
        return Err(DspError::NoTone(format!(
            "no line inside {:.2}-{:.2} Hz (each window's peak sat at the band's edge)",
            band.0, band.1
        )));
    }
    check_near_nominal(&enf, p.nominal_hz)?;
    Ok((enf, snr_db))
}

/// Tracks band `b` of `x` block by block (through its band-pass when `filtered`), with the
/// line's baseband when the band is followed.
fn track_band(
    x: &dyn BlockSource,
    fs: f64,
    p: &EnfParams,
    mut b: BandTrack,
    filtered: bool,
) -> Result<BandTrack, DspError> {
    let tracker = p.tracker(fs);
    let len = x.len();
    let frames = tracker.frame_count(len);
    let step = tracker.step_len();
    let q = baseband_block(fs);
    let sos = b.filter(fs, p);
    let settle = if filtered { settle_len(fs, p) } else { 0 };
    let mut base = Vec::new();
    for f0 in (0..frames).step_by(BLOCK_FRAMES) {
        let f1 = (f0 + BLOCK_FRAMES).min(frames);
        let span = tracker.frames_span(f0..f1, len);
        // the baseband's averages that start in this block's steps (the last block: to the end)
        let c0 = (f0 * step).div_ceil(q);
        let c1 = if f1 == frames {
            len.div_ceil(q)
        } else {
            (f1 * step).div_ceil(q)
        };
        let bb = (c0 * q).min(len)..(c1 * q).min(len);
        let lo = span.start.min(bb.start).saturating_sub(settle);
        let hi = (span.end.max(bb.end) + settle).min(len);
        let block = x.read(lo..hi)?;
        let y = if filtered {
            sosfiltfilt(&sos, &block)
        } else {
            block
        };
        b.tracked
            .extend(tracker.track_frames(&y, lo, len, f0..f1, b.band));
        if b.follows && bb.start < bb.end {
            base.extend(baseband(
                &y[bb.start - lo..bb.end - lo],
                bb.start,
                fs,
                b.center_hz,
                q,
            ));
        }
    }
    b.base = b.follows.then_some(base);
    Ok(b)
}
