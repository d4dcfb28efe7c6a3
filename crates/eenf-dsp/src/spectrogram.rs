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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chirp_shows_its_frequency_in_each_window() {
        // 100 Hz rising by 0.01 Hz/s, sampled at 1 kHz for 60 s
        let fs = 1000.0;
        let x: Vec<f64> = (0..60_000)
            .map(|i| {
                let t = i as f64 / fs;
                (std::f64::consts::TAU * (100.0 * t + 0.005 * t * t)).cos()
            })
            .collect();
        let s = spectrogram(&x, fs, 8.0, 1.0, (98.0, 102.0));
        assert_eq!(s.time_s.len(), 61);
        let nf = s.freq_hz.len();
        for i in [10usize, 30, 50] {
            let row = &s.power_db[i * nf..(i + 1) * nf];
            let k = (0..nf).max_by(|&a, &b| row[a].total_cmp(&row[b])).unwrap();
            let want = 100.0 + 0.01 * s.time_s[i];
            assert!(
                (s.freq_hz[k] - want).abs() < 0.05,
                "t {}: peak {} Hz, want {want}",
                s.time_s[i],
                s.freq_hz[k]
            );
        }
        assert!(s.power_db.iter().all(|p| *p <= 0.0));
    }
}
