//! The mains flicker line of a whole recording: where it is, which grid it belongs to, and how
//! far it stands above the noise.
//!
//! A line stands as a sound's hum does ([`crate::hum`]): it must clear two bars. One is
//! statistical: its power over its local floor in Welch segments, in dB, against the height
//! noise alone reaches at a false-alarm rate of 10⁻³ over every bin searched
//! ([`search_flicker`], whose search reaches as far as a camera's clock may move the line).
//! The other is the floor measured on recordings without the thing sought (for sound, 6 dB
//! from recordings without hum): here the prominence, the measure the real recordings were
//! calibrated with (`shared/fixtures/README.md`), the peak near 100 or 120 Hz of the whole
//! signal's spectrum under a Hann window over the median of that spectrum in 80–140 Hz. Event
//! streams are bursty, and a scene without a lamp (a walker in daylight) puts lines of up to
//! 15 dB over their local floor into the 1 ms sums, but none above a prominence of 6.

use realfft::RealFftPlanner;

use crate::hum::{search_flicker, HumSearch};

/// Lines between these frequencies (Hz) may be a 50 Hz grid's flicker: the grid may be off by
/// a few hundredths of a hertz, a camera's clock by a few tenths of a percent.
pub const BAND_50: (f64, f64) = (99.0, 101.0);
/// The same for a 60 Hz grid.
pub const BAND_60: (f64, f64) = (118.8, 121.2);
/// Where the noise floor is measured, Hz.
pub const NOISE_BAND: (f64, f64) = (80.0, 140.0);
/// A flicker line must stand this many times above the noise floor (the prominence). Noise
/// alone reaches about 4 over a whole hour (the largest of ~10⁵ Rayleigh magnitudes over their
/// median), a walker in daylight 5.9 over 20 s (`cli_errors.rs`); the real recordings that see
/// a lamp stand at 10–20.
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
    /// The 2f0 line's power over its local floor, dB, in Welch segments: sound's measure
    /// (`None` where the signal is too short or too slow for it).
    #[serde(default)]
    pub floor_db: Option<f64>,
    /// What it must clear over its floor to stand, dB: the height noise alone reaches at a
    /// false-alarm rate of 10⁻³ over every bin searched, and at least 6 dB.
    #[serde(default)]
    pub threshold_db: Option<f64>,
    /// True when the line stands: over its floor by `threshold_db`, and with a prominence of
    /// [`MIN_FLICKER_PROMINENCE`].
    #[serde(default)]
    pub stands: bool,
}

impl FlickerLine {
    /// True when the line stands far enough above the noise to be the mains (see
    /// [`FlickerLine::stands`]).
    pub fn is_mains(&self) -> bool {
        self.stands
    }

    /// How the line stands, for the user: "18.9 dB over its local floor and prominence 15.8
    /// (8.0 dB and 6 needed)".
    pub fn strength(&self) -> String {
        match (self.floor_db, self.threshold_db) {
            (Some(db), Some(t)) => format!(
                "{db:.1} dB over its local floor and prominence {:.1} ({t:.1} dB and {MIN_FLICKER_PROMINENCE} needed)",
                self.prominence
            ),
            _ => format!(
                "prominence {:.1} ({MIN_FLICKER_PROMINENCE} needed)",
                self.prominence
            ),
        }
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

/// How a line ranks against another's (two cameras, two grids): one that stands first, then
/// the higher over its floor (the prominence where that is not measured).
pub fn rank(l: &FlickerLine) -> (bool, f64) {
    (l.stands, l.floor_db.unwrap_or(20.0 * l.prominence.log10()))
}

/// Of two grids' lines, the one that ranks higher ([`rank`]).
pub fn stronger([a, b]: [FlickerLine; 2]) -> FlickerLine {
    if rank(&a) >= rank(&b) {
        a
    } else {
        b
    }
}

/// The stronger of the two [`flicker_lines`].
pub fn flicker_line(x: &[f64], fs: f64) -> Option<FlickerLine> {
    flicker_lines(x, fs).map(stronger)
}

/// The strongest line near 100 Hz (a 50 Hz grid) and near 120 Hz (60 Hz) in `x` sampled at
/// `fs` (at least 300 Hz; at least one second of signal), each with how it stands (see
/// [`flicker_search`]). `None` when the signal is too short or too slow.
pub fn flicker_lines(x: &[f64], fs: f64) -> Option<[FlickerLine; 2]> {
    flicker_search(x, fs).map(|(lines, _)| lines)
}

/// [`flicker_lines`] and the search of their floors that decided whether they stand (`None`
/// inside where the signal is too short or too slow for Welch segments: the prominence alone
/// decides).
pub fn flicker_search(x: &[f64], fs: f64) -> Option<([FlickerLine; 2], Option<HumSearch>)> {
    let [mut fifty, mut sixty] = hann_lines(x, fs)?;
    let search = search_flicker(x, fs, &[50.0, 60.0], 1);
    for l in [&mut fifty, &mut sixty] {
        let measured = search
            .as_ref()
            .and_then(|s| s.of_grid(l.grid_hz).next().copied());
        l.floor_db = measured.map(|h| h.db);
        l.threshold_db = measured.map(|h| h.threshold_db);
        l.stands = l.prominence >= MIN_FLICKER_PROMINENCE && measured.is_none_or(|h| h.stands());
    }
    Some(([fifty, sixty], search))
}

/// The peaks near 100 and 120 Hz of the whole signal's Hann spectrum, and their prominence.
fn hann_lines(x: &[f64], fs: f64) -> Option<[FlickerLine; 2]> {
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
            floor_db: None,
            threshold_db: None,
            stands: false,
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
