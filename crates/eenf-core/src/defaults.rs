//! The method's defaults (the paper's, see `docs/method.md`), written once: the tracker's
//! `EnfParams::default`, the command line's flags and the Python package's keyword arguments
//! all read them from here.

/// STFT window, s (the paper's 16 s).
pub const WINDOW_S: f64 = 16.0;
/// STFT step, s: one estimate per second.
pub const STEP_S: f64 = 1.0;
/// Half width of the search band (and band-pass) around each line, Hz.
pub const HALF_BAND_HZ: f64 = 2.0;
/// Flicker harmonics M: bands at 2m·f0, m = 1..M.
pub const HARMONICS: usize = 4;
/// Butterworth order of the band-pass prototype.
pub const FILTER_ORDER: usize = 4;
/// The paper's zero-padded FFT bin, Hz (`--peak paper`).
pub const PAPER_BIN_HZ: f64 = 0.005;
/// Running-median length of the outlier correction.
pub const MEDIAN_LEN: usize = 21;
/// Outlier threshold on the 2 f0 scale, Hz.
pub const MEDIAN_THRESHOLD_HZ: f64 = 0.02;
/// Harmonic-selection segment, in estimates.
pub const SEGMENT_LEN: usize = 10;
