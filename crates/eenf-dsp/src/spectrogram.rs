//! A power spectrogram over a narrow band, for looking at a flicker line and its wander.

use rayon::prelude::*;
use realfft::RealFftPlanner;

/// Power in dB over time and frequency: `power_db[i * freq_hz.len() + k]` is the power at
/// `time_s[i]`, `freq_hz[k]`, relative to the strongest cell.
#[derive(Debug, Clone)]
pub struct Spectrogram {
    /// Window centres, s from the signal's first sample.
    pub time_s: Vec<f64>,
    /// Bin frequencies inside the band, Hz.
    pub freq_hz: Vec<f64>,
    /// Power, dB (0 = strongest cell), time-major.
    pub power_db: Vec<f32>,
}

/// The spectrogram of `x` (sampled at `fs`) between `band.0` and `band.1` Hz: Hann windows of
/// `window_s` centred every `step_s` (zeros beyond the ends, as the tracker's windows), each
/// zero-padded to at least four times its length so the bins are finer than the resolution.
pub fn spectrogram(
    x: &[f64],
    fs: f64,
    window_s: f64,
    step_s: f64,
    band: (f64, f64),
) -> Spectrogram {
    let win = ((window_s * fs).round() as usize).max(2);
    let nfft = (4 * win).next_power_of_two();
    let bin = fs / nfft as f64;
    let lo = (band.0 / bin).ceil().max(0.0) as usize;
    let hi = ((band.1 / bin).floor() as usize).min(nfft / 2);
    let freq_hz: Vec<f64> = (lo..=hi.max(lo)).map(|k| k as f64 * bin).collect();
    let duration = x.len() as f64 / fs;
    let frames = if x.is_empty() || step_s <= 0.0 {
        0
    } else {
        (duration / step_s).floor() as usize + 1
    };
    let time_s: Vec<f64> = (0..frames).map(|i| i as f64 * step_s).collect();
    let hann: Vec<f64> = (0..win)
        .map(|n| 0.5 - 0.5 * (std::f64::consts::TAU * n as f64 / (win - 1) as f64).cos())
        .collect();
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(nfft);
    let mut power: Vec<f32> = time_s
        .par_iter()
        .flat_map_iter(|&t| {
            let mut input = fft.make_input_vec();
            let start = (t * fs).round() as isize - (win / 2) as isize;
            for (n, w) in hann.iter().enumerate() {
                let i = start + n as isize;
                if i >= 0 && (i as usize) < x.len() {
                    input[n] = x[i as usize] * w;
                }
            }
            let mut spec = fft.make_output_vec();
            fft.process(&mut input, &mut spec)
                .expect("sizes from the plan");
            let cells: Vec<f32> = (lo..=hi.max(lo))
                .map(|k| spec.get(k).map_or(0.0, |c| c.norm_sqr()) as f32)
                .collect();
            cells
        })
        .collect();
    let peak = power.iter().copied().fold(f32::MIN_POSITIVE, f32::max);
    for p in &mut power {
        *p = 10.0 * (*p / peak).max(1e-12).log10();
    }
    Spectrogram {
        time_s,
        freq_hz,
        power_db: power,
    }
}
