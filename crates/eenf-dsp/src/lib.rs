//! # eenf-dsp
//!
//! The signal processing of eenf, free of I/O: the temporal sampler that turns events into a
//! polarity sequence, zero-phase Butterworth band-passes (scipy-compatible), the centred STFT
//! peak tracker with two peak refinements, outlier correction, harmonic selection, and the
//! metrics that compare traces. `docs/method.md` (in the shared folder) explains every step.
//!
//! ```
//! use eenf_dsp::{reference_enf, EnfParams, PeakMethod};
//! // 40 s of a 50.01 Hz tone sampled at 400 Hz
//! let fs = 400.0;
//! let x: Vec<f64> = (0..16_000)
//!     .map(|i| (2.0 * std::f64::consts::PI * 50.01 * i as f64 / fs).cos())
//!     .collect();
//! let trace = reference_enf(&x, fs, &EnfParams::default()).unwrap();
//! assert_eq!(trace.len(), 41);
//! assert!((trace[20] - 50.01).abs() < 1e-5);
//! ```

// `unsafe` only in `simd`, to run hot loops built for the processor's AVX2.
#![deny(unsafe_code)]

pub mod blocks;
pub mod butter;
pub mod chirp;
pub mod decimate;
pub mod edits;
pub mod enf;
pub mod filtfilt;
pub mod flicker;
pub mod hum;
pub mod matching;
pub mod metrics;
pub mod postprocess;
pub mod resample;
pub mod sampling;
pub mod simd;
pub mod spectrogram;
pub mod tracker;

pub use blocks::{reference_enf, reference_enf_with_snr};
pub use butter::{butter_bandpass, butter_lowpass, sos_to_ba, Section};
pub use chirp::follow_chirps;
pub use decimate::{decimate, decimation_for, StreamDecimator};
pub use enf::{
    check_line, detect_nominal, enf_from_flicker, enf_from_harmonics, enf_from_hum_lines,
    enf_from_lines, extract_enf, line_prominence, DspError, EnfEstimates, EnfParams,
    HarmonicEstimates,
};
pub use filtfilt::sosfiltfilt;
pub use flicker::{
    clock_offset_note, flicker_line, flicker_lines, flicker_search, line_strength_at, stronger,
    FlickerLine, MIN_FLICKER_PROMINENCE,
};
pub use hum::{
    check_holds_line, choose_window, plausibility, search_flicker, search_hum, HumLine, HumSearch,
    HumVerdict, Plausibility,
};
pub use metrics::{agreement, robust_spread, Agreement};
pub use postprocess::{
    median_correct, select_audible_harmonics, select_harmonics, HarmonicSelection,
};
pub use sampling::{Grouping, PolaritySequence, SamplingError, SamplingMethod, TemporalSampler};
pub use spectrogram::{spectrogram, Spectrogram};
pub use tracker::{PeakMethod, StftTracker, NOISE_LEVEL_DB};
