//! Following a line that sweeps within the window.
//!
//! A window's DTFT peak is the line's mean frequency only while the line stays inside one bin.
//! At k·f0 the ENF sweeps k times as far: a swing of 1.5 mHz/s at f0 moves the 4 f0 line by
//! four bins of a 32 s window, its power spreads over them, and weak hum's peak then lands on
//! whichever lump the noise favours (steps of 10–30 mHz on the f0 scale where the ENF moves
//! fast). Dechirping each window by the sweep rate the neighbouring estimates show gathers the
//! line back into one lobe; its peak is then the frequency at the window's centre, as for a
//! line that holds still (Kay, *Fundamentals of Statistical Signal Processing* I, §13.6, for
//! the chirp model; on weak 4 f0 hum following a real grid it lowers the error from
//! 1.1–4.3 mHz to 0.6–1.1 mHz, see `crates/eenf/tests/integration/audio_harmonics.rs`).

use std::f64::consts::PI;

use rayon::prelude::*;
use realfft::num_complex::Complex64;

use crate::tracker::golden_section_max;

/// Sampling rate of the complex baseband the windows are dechirped at, Hz: the band-passed
/// line lies within ±`half_band` (2 Hz) of the centre, and block averaging to this rate
/// folds the rest (the image at −2·centre) far from it.
const BASEBAND_HZ: f64 = 32.0;

/// Each estimate of a band-passed line `y` (sampled at `fs`, centred on `center_hz`), made
/// by the centred tracker with `window_s` windows every `step_s` (`line_hz`, the line's own
/// frequency, NaN where none), re-estimated with the window dechirped: the sweep rate and the
/// starting point are the least-squares line through the estimates within half a window, and
/// the peak is sought within `reach_hz` of that line's value at the window's centre.
/// Estimates without three finite neighbours in reach are kept as they are.
/// This is done `passes` times, each pass fitting the sweeps to the last one's estimates (the
/// line in baseband is made once).
#[allow(clippy::too_many_arguments)]
pub fn follow_chirps(
    y: &[f64],
    fs: f64,
    center_hz: f64,
    line_hz: &[f64],
    window_s: f64,
    step_s: f64,
    reach_hz: f64,
    passes: usize,
) -> Vec<f64> {
    let q = baseband_block(fs);
    let base = baseband(y, 0, fs, center_hz, q);
    follow_in_baseband(
        &base, fs, center_hz, line_hz, window_s, step_s, reach_hz, passes,
    )
}

/// The samples (at `fs`) averaged into one baseband value of [`follow_chirps`].
pub fn baseband_block(fs: f64) -> usize {
    ((fs / BASEBAND_HZ).floor() as usize).max(1)
}

/// [`follow_chirps`] from the line's baseband (made whole, or a block at a time by
/// [`baseband`]).
#[allow(clippy::too_many_arguments)]
pub fn follow_in_baseband(
    base: &[Complex64],
    fs: f64,
    center_hz: f64,
    line_hz: &[f64],
    window_s: f64,
    step_s: f64,
    reach_hz: f64,
    passes: usize,
) -> Vec<f64> {
    let q = baseband_block(fs);
    let mut estimates = line_hz.to_vec();
    for _ in 0..passes {
        estimates = follow_once(
            base, q, fs, center_hz, &estimates, window_s, step_s, reach_hz,
        );
    }
    estimates
}

/// One pass of [`follow_chirps`] over the baseband `base` (blocks of `q` samples).
#[allow(clippy::too_many_arguments)]
fn follow_once(
    base: &[Complex64],
    q: usize,
    fs: f64,
    center_hz: f64,
    line_hz: &[f64],
    window_s: f64,
    step_s: f64,
    reach_hz: f64,
) -> Vec<f64> {
    let dt = q as f64 / fs;
    // the centroid time of block j
    let t0 = (q as f64 - 1.0) / 2.0 / fs;
    let half = window_s / 2.0;
    let half_frames = (half / step_s).floor() as usize;
    (0..line_hz.len())
        .into_par_iter()
        .map(|i| {
            let tc = i as f64 * step_s;
            let Some((rate, at_centre)) = fit_line(line_hz, i, half_frames, step_s) else {
                return line_hz[i];
            };
            // blocks whose centroid lies in [tc − W/2, tc + W/2)
            let lo = (((tc - half - t0) / dt).ceil().max(0.0)) as usize;
            let hi = ((((tc + half - t0) / dt).ceil().max(0.0)) as usize).min(base.len());
            if hi <= lo + 2 {
                return line_hz[i];
            }
            let first_t = t0 + lo as f64 * dt - tc;
            let dechirped: Vec<Complex64> = base[lo..hi]
                .iter()
                .enumerate()
                .map(|(j, z)| {
                    let t = first_t + j as f64 * dt;
                    z * Complex64::from_polar(1.0, -PI * rate * t * t)
                })
                .collect();
            let offset = at_centre - center_hz;
            let peak = dechirped_peak(
                &dechirped,
                first_t,
                dt,
                (offset - reach_hz, offset + reach_hz),
                window_s,
            );
            center_hz + peak
        })
        .collect()
}

/// `y` shifted down by `center_hz` and averaged over blocks of `q` samples; `y`'s first
/// sample is the signal's sample `start` (a multiple of `q`), so that a long signal's
/// baseband can be made a part at a time.
pub fn baseband(y: &[f64], start: usize, fs: f64, center_hz: f64, q: usize) -> Vec<Complex64> {
    let w = -2.0 * PI * center_hz / fs;
    y.par_chunks(q)
        .enumerate()
        .map(|(b, chunk)| {
            let start = start + b * q;
            // the phasor is computed afresh per block, so rounding does not accumulate
            let mut rot = Complex64::from_polar(1.0, w * start as f64);
            let step = Complex64::from_polar(1.0, w);
            let mut sum = Complex64::new(0.0, 0.0);
            for &v in chunk {
                sum += rot * v;
                rot *= step;
            }
            sum / chunk.len() as f64
        })
        .collect()
}

/// Slope (Hz/s) and value at estimate `i` of the least-squares line through the finite
/// estimates within `half` steps of it; None with fewer than three, or all on one side.
fn fit_line(v: &[f64], i: usize, half: usize, step_s: f64) -> Option<(f64, f64)> {
    let lo = i.saturating_sub(half);
    let hi = (i + half + 1).min(v.len());
    let (mut n, mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (j, &y) in v.iter().enumerate().take(hi).skip(lo) {
        if !y.is_finite() {
            continue;
        }
        let x = (j as f64 - i as f64) * step_s;
        n += 1.0;
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    let det = n * sxx - sx * sx;
    if n < 3.0 || det <= 0.0 {
        return None;
    }
    let slope = (n * sxy - sx * sy) / det;
    let intercept = (sy - slope * sx) / n;
    Some((slope, intercept))
}

/// |Σ z_j e^{−i2πf·t_j}|² for t_j = `first_t` + j·`dt`.
fn power_at(z: &[Complex64], first_t: f64, dt: f64, f: f64) -> f64 {
    let w = -2.0 * PI * f;
    let mut rot = Complex64::from_polar(1.0, w * first_t);
    let step = Complex64::from_polar(1.0, w * dt);
    let mut sum = Complex64::new(0.0, 0.0);
    for v in z {
        sum += v * rot;
        rot *= step;
    }
    sum.norm_sqr()
}

/// The frequency in `bracket` where the dechirped window's power peaks: a grid of an eighth
/// of a bin, then golden-section search between the best point's neighbours.
fn dechirped_peak(
    z: &[Complex64],
    first_t: f64,
    dt: f64,
    bracket: (f64, f64),
    window_s: f64,
) -> f64 {
    let step = 1.0 / (8.0 * window_s);
    let points = ((bracket.1 - bracket.0) / step).ceil().max(1.0) as usize;
    let (best, _) = (0..=points)
        .map(|g| bracket.0 + g as f64 * (bracket.1 - bracket.0) / points as f64)
        .map(|f| (f, power_at(z, first_t, dt, f)))
        .fold((bracket.0, -1.0), |b, c| if c.1 > b.1 { c } else { b });
    golden_section_max(
        |f| power_at(z, first_t, dt, f),
        (best - step, best + step),
        1e-7,
    )
    .0
}
