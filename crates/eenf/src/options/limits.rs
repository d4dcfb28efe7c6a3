//! The range of each numeric option, inclusive: the one place both the command line's parser
//! and [`super::OptionSet::check`] read them from.

/// STFT window, s.
pub const WINDOW_S: (f64, f64) = (0.01, 3600.0);
/// STFT step, s.
pub const STEP_S: (f64, f64) = (0.001, 3600.0);
/// Half width of a line's band, Hz.
pub const HALF_BAND_HZ: (f64, f64) = (0.01, 20.0);
/// Event sampling interval, µs.
pub const DT_US: (i64, i64) = (10, 1_000_000);
/// Flicker harmonics traced.
pub const HARMONICS: (u32, u32) = (1, 16);
/// Butterworth order.
pub const FILTER_ORDER: (u32, u32) = (1, 8);
/// Running-median length.
pub const MEDIAN_LEN: (usize, usize) = (0, 10_001);
/// Outlier threshold, Hz.
pub const MEDIAN_THRESHOLD_HZ: (f64, f64) = (0.0, 10.0);
/// Harmonic-selection segment, estimates.
pub const SEGMENT: (usize, usize) = (1, 100_000);
/// The journal rule's largest step and the consensus rule's tolerance, Hz.
pub const SELECTION_HZ: (f64, f64) = (0.0, 10.0);
/// Sensor readout time, ms.
pub const READOUT_MS: (f64, f64) = (0.0, 1000.0);
/// Virtual rows per frame period.
pub const VIRTUAL_ROWS: (f64, f64) = (0.0, 100_000.0);
/// Scale of simulated videos' frames.
pub const VIDEO_SCALE: (f64, f64) = (0.001, 1.0);
/// Length of a simulated recording, s.
pub const DURATION_S: (f64, f64) = (0.01, 86_400.0);
/// Seconds between the values of an `index,value` CSV.
pub const INDEX_STEP_S: (f64, f64) = (0.001, 3600.0);
/// Grid of a synthetic ENF, Hz (50 or 60 within it).
pub const GRID_HZ: (u32, u32) = (50, 60);
/// Light level of a simulated scene.
pub const ILLUMINATION: (f64, f64) = (0.0, 1e6);
/// Share of non-flickering light.
pub const AMBIENT: (f64, f64) = (0.0, 1.0);
/// Brightness of a lamp's pool or bulb over the rest.
pub const SPOT_GAIN: (f64, f64) = (0.0, 1e6);
/// Background events per pixel per second.
pub const NOISE_HZ: (f64, f64) = (0.0, 10_000.0);
/// Candidates listed by a match.
pub const TOP: (usize, usize) = (1, 10_000);
/// Significance level of a match.
pub const ALPHA: (f64, f64) = (1e-300, 1.0);
/// Longest side fitted by the edits test, s.
pub const SIDE_S: (f64, f64) = (1.0, 600.0);
/// Shortest stretch between two edits, s.
pub const MIN_GAP_S: (f64, f64) = (0.3, 600.0);
/// False alarms allowed per hour.
pub const FALSE_ALARMS: (f64, f64) = (1e-9, 100.0);
/// Smallest phase jump reported as unseen, degrees.
pub const WEAK_JUMP_DEG: (f64, f64) = (1.0, 180.0);
/// Frequency-step threshold, robust standard deviations.
pub const STEP_Z: (f64, f64) = (1.0, 1000.0);
