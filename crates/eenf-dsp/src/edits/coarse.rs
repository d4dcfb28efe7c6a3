//! The coarse ENF that turns each line's phase back before the test: harmonic-sum peaks of
//! 10 s windows, median-filtered, one value per block.

use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use rustfft::FftPlanner;

use super::Baseband;

/// Windows of the coarse ENF that turns the phase back, s (and their step).
const COARSE_WINDOW_S: f64 = 10.0;
const COARSE_STEP_S: f64 = 1.0;
/// How far the coarse ENF is looked for from the grid, Hz (a trace further off is refused).
const COARSE_SPAN_HZ: f64 = 0.25;
/// Steps of the coarse ENF's running median: a window that spans a phase jump misplaces its
/// peak, for the ±5 s around the jump, and the median over ±15 s passes over them.
const COARSE_MEDIAN: usize = 31;
/// FFT length of a coarse window (zero-padded): 2.4 mHz bins at the fundamental.
const COARSE_FFT: usize = 4096;

/// The coarse ENF, one value per block (Hz off `f0`): the harmonic-sum peak of Hann windows of
/// [`COARSE_WINDOW_S`] every [`COARSE_STEP_S`], median-filtered over [`COARSE_MEDIAN`] steps, held at the
/// ends and interpolated between steps.
pub fn coarse_offsets(bb: &Baseband) -> Vec<f64> {
    let n = bb.len();
    let tb = bb.block_s;
    let win = ((COARSE_WINDOW_S / tb).round() as usize).clamp(2, n.max(2));
    let step = ((COARSE_STEP_S / tb).round() as usize).max(1);
    if n < 2 {
        return vec![0.0; n];
    }
    let win = win.min(n);
    let centres: Vec<usize> = (0..)
        .map(|i| win / 2 + i * step)
        .take_while(|&c| c + (win - win / 2) <= n)
        .collect();
    let hann: Vec<f64> = (0..win)
        .map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * (i as f64 + 0.5) / win as f64).cos())
        .collect();
    let fft = FftPlanner::<f64>::new().plan_fft_forward(COARSE_FFT);
    let grid: Vec<f64> = {
        let k = (COARSE_SPAN_HZ / 0.0005).round() as i64;
        (-k..=k).map(|i| i as f64 * 0.0005).collect()
    };
    let raw: Vec<f64> = centres
        .par_iter()
        .map_init(
            || vec![Complex64::new(0.0, 0.0); COARSE_FFT],
            |buf, &c| {
                let lo = c - win / 2;
                let mut score = vec![0.0; grid.len()];
                let mut meds = Vec::with_capacity(bb.blocks.len());
                for (line, &m) in bb.blocks.iter().zip(&bb.multiples) {
                    buf.iter_mut().for_each(|v| *v = Complex64::new(0.0, 0.0));
                    for i in 0..win {
                        buf[i] = line[lo + i] * hann[i];
                    }
                    fft.process(buf);
                    let p: Vec<f64> = buf.iter().map(|v| v.norm_sqr()).collect();
                    let mut sorted = p.clone();
                    let mid = sorted.len() / 2;
                    let med = *sorted.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1;
                    let med = if med > 0.0 { med } else { 1.0 };
                    meds.push(med);
                    let per_bin = COARSE_FFT as f64 * tb;
                    for (s, &d) in score.iter_mut().zip(&grid) {
                        // the line's bin at m·δ (negative offsets wrap to the top of the FFT)
                        let pos = (m as f64 * d * per_bin).rem_euclid(COARSE_FFT as f64);
                        let i0 = pos.floor() as usize % COARSE_FFT;
                        let fr = pos - pos.floor();
                        let v = p[i0] * (1.0 - fr) + p[(i0 + 1) % COARSE_FFT] * fr;
                        *s += v / med;
                    }
                }
                let (best, _) =
                    score
                        .iter()
                        .enumerate()
                        .fold((0, f64::MIN), |a, (i, &v)| if v > a.1 { (i, v) } else { a });
                // refined on the exact spectrum (the zero-padded bins are 2.4 mHz apart):
                // parabolas through three points, 1 mHz then 0.25 mHz apart
                let exact = |d: f64| -> f64 {
                    bb.blocks
                        .iter()
                        .zip(&bb.multiples)
                        .zip(&meds)
                        .map(|((line, &m), &med)| {
                            let w = -std::f64::consts::TAU * m as f64 * d * tb;
                            let rot = Complex64::from_polar(1.0, w);
                            let mut ph = Complex64::new(1.0, 0.0);
                            let mut acc = Complex64::new(0.0, 0.0);
                            for i in 0..win {
                                acc += line[lo + i] * hann[i] * ph;
                                ph *= rot;
                            }
                            acc.norm_sqr() / med
                        })
                        .sum()
                };
                let mut at = grid[best];
                for h in [0.001, 0.00025] {
                    let (a, b, c) = (exact(at - h), exact(at), exact(at + h));
                    let den = a - 2.0 * b + c;
                    if den < 0.0 {
                        at += h * (0.5 * (a - c) / den).clamp(-1.0, 1.0);
                    }
                }
                at
            },
        )
        .collect();
    if raw.is_empty() {
        return vec![0.0; n];
    }

    let smooth: Vec<f64> = (0..raw.len())
        .map(|i| {
            // symmetric, shrinking at the ends: a ramp's median stays on it
            let r = (COARSE_MEDIAN / 2).min(i).min(raw.len() - 1 - i);
            let (lo, hi) = (i - r, i + r + 1);
            let mut w: Vec<f64> = raw[lo..hi].to_vec();
            w.sort_by(f64::total_cmp);
            w[w.len() / 2]
        })
        .collect();
    (0..n)
        .map(|b| {
            let first = centres[0];
            let last = *centres.last().unwrap_or(&first);
            if b <= first {
                smooth[0]
            } else if b >= last {
                smooth[smooth.len() - 1]
            } else {
                let i = (b - first) / step;
                let fr = (b - centres[i]) as f64 / step as f64;
                let j = (i + 1).min(smooth.len() - 1);
                smooth[i] * (1.0 - fr) + smooth[j] * fr
            }
        })
        .collect()
}
