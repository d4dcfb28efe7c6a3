//! The mains flicker line of a whole recording: where it is, which grid it belongs to, and how
//! far it stands above the noise.
//!
//! The measure is the one the real recordings were calibrated with (`shared/fixtures/README.md`):
//! the spectrum of the whole flicker signal under a Hann window, its peak near 100 Hz and near
//! 120 Hz, and the peak over the median of the spectrum in 80–140 Hz (the prominence).

use realfft::RealFftPlanner;

/// Lines between these frequencies (Hz) may be a 50 Hz grid's flicker: the grid may be off by
/// a few hundredths of a hertz, a camera's clock by a few tenths of a percent.
pub const BAND_50: (f64, f64) = (99.0, 101.0);
/// The same for a 60 Hz grid.
pub const BAND_60: (f64, f64) = (118.8, 121.2);
/// Where the noise floor is measured, Hz.
pub const NOISE_BAND: (f64, f64) = (80.0, 140.0);
/// A flicker line must stand this many times above the noise floor. Noise alone reaches about
/// 4 over a whole hour (the largest of ~10⁵ Rayleigh magnitudes over their median); the real
/// recordings that see a lamp stand at 10–20.
pub const MIN_FLICKER_PROMINENCE: f64 = 6.0;

/// The strongest flicker line of a recording.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FlickerLine {
    /// Its frequency, Hz (twice the ENF as the camera's clock sees it).
    pub hz: f64,
    /// The grid it belongs to: 50 or 60 Hz.
    pub grid_hz: f64,
    /// Peak magnitude over the median magnitude in 80–140 Hz.
    pub prominence: f64,
    /// The line's relative offset from twice the grid, as a share (a camera clock that runs
    /// off shows here: −0.0026 for a line at 119.69 Hz on a 60 Hz grid).
    pub offset: f64,
}

impl FlickerLine {
    /// The prominence in decibels (of magnitude).
    pub fn db(&self) -> f64 {
        20.0 * self.prominence.log10()
    }

    /// True when the line stands far enough above the noise to be the mains.
    pub fn is_mains(&self) -> bool {
        self.prominence >= MIN_FLICKER_PROMINENCE
    }
}

/// The magnitude spectrum of `x` under a Hann window, zero-padded `pad` times (at most 2^24
/// points), its bin width, and its median magnitude in [`NOISE_BAND`]. Plans are kept per
/// thread: a flicker map asks this of a thousand tiles.
fn spectrum(x: &[f64], fs: f64, pad: usize) -> Option<(Vec<f64>, f64, f64)> {
    if fs < 2.0 * NOISE_BAND.1 + 20.0 || (x.len() as f64) < fs {
        return None;
    }
    thread_local! {
        static PLANNER: std::cell::RefCell<RealFftPlanner<f64>> =
            std::cell::RefCell::new(RealFftPlanner::new());
    }
    let nfft = (pad * x.len())
        .next_power_of_two()
        .min(1 << 24)
        .max(x.len().next_power_of_two());
    let fft = PLANNER.with(|p| p.borrow_mut().plan_fft_forward(nfft));
    let mut input = fft.make_input_vec();
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    for (i, (d, s)) in input.iter_mut().zip(x).enumerate() {
        let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos();
        *d = (s - mean) * w;
    }
    let mut spec = fft.make_output_vec();
    fft.process(&mut input, &mut spec).ok()?;
    let df = fs / nfft as f64;
    let mag: Vec<f64> = spec.iter().map(|c| c.norm()).collect();
    let bin = |f: f64| ((f / df).round() as usize).min(mag.len() - 1);
    let mut noise: Vec<f64> = mag[bin(NOISE_BAND.0)..=bin(NOISE_BAND.1)].to_vec();
    let k = noise.len() / 2;
    let median = *noise.select_nth_unstable_by(k, f64::total_cmp).1;
    Some((mag, df, median))
}

/// How far `x` stands above its noise at `hz` (a line found elsewhere, e.g. over the whole
/// sensor): its magnitude there (the largest of the three nearest bins, unpadded) over the
/// median magnitude in 80–140 Hz. About 1 where there is no line.
pub fn line_strength_at(x: &[f64], fs: f64, hz: f64) -> Option<f64> {
    let (mag, df, median) = spectrum(x, fs, 1)?;
    let at = ((hz / df).round() as usize).min(mag.len() - 1);
    let peak = mag[at.saturating_sub(1)..=(at + 1).min(mag.len() - 1)]
        .iter()
        .fold(0.0f64, |a, &m| a.max(m));
    (median > 0.0).then(|| peak / median)
}

/// The stronger of the two [`flicker_lines`].
pub fn flicker_line(x: &[f64], fs: f64) -> Option<FlickerLine> {
    let [a, b] = flicker_lines(x, fs)?;
    Some(if a.prominence >= b.prominence { a } else { b })
}

/// The strongest line near 100 Hz (a 50 Hz grid) and near 120 Hz (60 Hz) in `x` sampled at
/// `fs` (at least 300 Hz; at least one second of signal). `None` when the signal is too short
/// or too slow.
pub fn flicker_lines(x: &[f64], fs: f64) -> Option<[FlickerLine; 2]> {
    let (mag, df, median) = spectrum(x, fs, 4)?;
    let bin = |f: f64| ((f / df).round() as usize).min(mag.len() - 1);
    let peak = |(lo, hi): (f64, f64)| {
        let (a, b) = (bin(lo), bin(hi));
        let (i, m) =
            mag[a..=b].iter().enumerate().fold(
                (0, 0.0),
                |best, (i, &m)| if m > best.1 { (i, m) } else { best },
            );
        let i = a + i;
        // parabolic refinement on the log magnitude (Hann: close to exact)
        let frac = if i > 0 && i + 1 < mag.len() && mag[i - 1] > 0.0 && mag[i + 1] > 0.0 {
            let (l, c, r) = (mag[i - 1].ln(), mag[i].ln(), mag[i + 1].ln());
            let den = l - 2.0 * c + r;
            if den < 0.0 {
                (0.5 * (l - r) / den).clamp(-0.5, 0.5)
            } else {
                0.0
            }
        } else {
            0.0
        };
        ((i as f64 + frac) * df, m)
    };
    let line = |band, grid_hz: f64| {
        let (hz, m) = peak(band);
        let prominence = if median > 0.0 {
            m / median
        } else if m > 0.0 {
            f64::INFINITY
        } else {
            0.0
        };
        FlickerLine {
            hz,
            grid_hz,
            prominence,
            offset: hz / (2.0 * grid_hz) - 1.0,
        }
    };
    Some([line(BAND_50, 50.0), line(BAND_60, 60.0)])
}

/// A line's relative offset from where the grid puts it beyond which it is not the grid's
/// doing: a grid strays by a few hundredths of a hertz, 0.1 % is 50 mHz at 50 Hz.
pub const CLOCK_NOTE_OFFSET: f64 = 1e-3;

/// What to tell the user when a flicker line measured at `line_hz` sits further from
/// `expected_hz` (twice the grid) than a grid strays: the camera's clock, which times the
/// samples, is off by that share, and so is every estimate.
pub fn clock_offset_note(line_hz: f64, expected_hz: f64) -> Option<String> {
    let offset = line_hz / expected_hz - 1.0;
    (offset.abs() > CLOCK_NOTE_OFFSET).then(|| {
        format!(
            "the flicker line is at {line_hz:.3} Hz, {:.2} % {} {expected_hz} Hz: the camera's clock (or the grid) is off by that much; the trace is reported as measured",
            100.0 * offset.abs(),
            if offset < 0.0 { "below" } else { "above" },
        )
    })
}
