//! The options of reading event files, of the tracker, of E-ENF and of writing events.

use std::path::Path;

use eenf_core::spelling::option;
use eenf_core::{defaults, Nominal};
use eenf_dsp::{EnfParams, HarmonicSelection, PeakMethod, SamplingMethod};
use eenf_events::writers::OutputFormat;
use eenf_events::{Compression, OpenOptions};
use serde_json::Value;

use super::{counted, limits, maybe, named, number, rule, switch, text, whole, within};
use super::{OptionError, OptionSet};
use crate::extract::ExtractOptions;

/// How to read files that leave something open (`info`, `extract`, `convert`, `bench`).
#[derive(Debug, Clone)]
pub struct InputSettings {
    /// `chip`: the chip of a jAER AEDAT 2.0 file (default: from the header or the addresses).
    pub chip: Option<String>,
    /// `camera`: the camera to read in a file with several.
    pub camera: Option<u8>,
    /// `strict`: refuse a damaged or cut-short file instead of reading what comes before.
    pub strict: bool,
    /// `max_gap`: the largest step of the event time between two events, s.
    pub max_gap: f64,
    /// `topic`: the topic of a ROS bag to read.
    pub topic: Option<String>,
}

impl Default for InputSettings {
    fn default() -> Self {
        InputSettings {
            chip: None,
            camera: None,
            strict: false,
            max_gap: eenf_events::DEFAULT_MAX_GAP_US as f64 * 1e-6,
            topic: None,
        }
    }
}

impl OptionSet for InputSettings {
    fn set(&mut self, name: &str, v: &Value) -> Result<bool, OptionError> {
        match name {
            "chip" => self.chip = maybe("chip", v, text)?,
            "camera" => self.camera = maybe("camera", v, whole)?,
            "strict" => self.strict = switch("strict", v)?,
            "max_gap" => self.max_gap = number("max_gap", v)?,
            "topic" => self.topic = maybe("topic", v, text)?,
            _ => return Ok(false),
        }
        Ok(true)
    }

    fn check(&self) -> Result<(), OptionError> {
        Ok(())
    }
}

impl InputSettings {
    /// The reader options.
    pub fn open_options(&self) -> OpenOptions {
        OpenOptions {
            chip: self.chip.clone(),
            camera: self.camera,
            strict: self.strict,
            // NaN and negatives: no step is allowed; huge values: any is
            max_gap_us: Some((self.max_gap * 1e6).clamp(0.0, i64::MAX as f64) as i64),
            topic: self.topic.clone(),
        }
    }
}

/// The tracker's options (shared by `extract`, `reference`, `audio` and `bench`).
#[derive(Debug, Clone)]
pub struct TrackerSettings {
    /// `nominal`: the grid, 50, 60 or detected.
    pub nominal: Nominal,
    /// `peak`: how each window's peak is refined.
    pub peak: PeakMethod,
    /// `window`: STFT window, s (default: the paper's 16, one that fits a shorter recording,
    /// or twice that for a weak line).
    pub window: Option<f64>,
    /// `step`: STFT step, s.
    pub step: f64,
    /// `half_band`: half width of each line's band, Hz.
    pub half_band: f64,
}

impl Default for TrackerSettings {
    fn default() -> Self {
        TrackerSettings {
            nominal: Nominal::Auto,
            peak: PeakMethod::Exact,
            window: None,
            step: defaults::STEP_S,
            half_band: defaults::HALF_BAND_HZ,
        }
    }
}

impl OptionSet for TrackerSettings {
    fn set(&mut self, name: &str, v: &Value) -> Result<bool, OptionError> {
        match name {
            "nominal" => self.nominal = named("nominal", v)?,
            "peak" => self.peak = named("peak", v)?,
            "window" => self.window = maybe("window", v, number)?,
            "step" => self.step = number("step", v)?,
            "half_band" => self.half_band = number("half_band", v)?,
            _ => return Ok(false),
        }
        Ok(true)
    }

    fn check(&self) -> Result<(), OptionError> {
        if let Some(w) = self.window {
            within("window", w, limits::WINDOW_S)?;
        }
        within("step", self.step, limits::STEP_S)?;
        within("half_band", self.half_band, limits::HALF_BAND_HZ)
    }
}

impl TrackerSettings {
    /// The tracker part of the parameters.
    pub fn params(&self) -> Result<EnfParams, OptionError> {
        self.check()?;
        Ok(EnfParams {
            peak: self.peak,
            window_s: self.window.unwrap_or(defaults::WINDOW_S),
            step_s: self.step,
            half_band_hz: self.half_band,
            ..EnfParams::default()
        })
    }
}

/// The options of E-ENF from events (`extract`, `bench`, Python's `extract`).
#[derive(Debug, Clone)]
pub struct ExtractSettings {
    /// The tracker's options.
    pub tracker: TrackerSettings,
    /// `sampling`: the temporal sampling of the events.
    pub sampling: SamplingMethod,
    /// `dt_us`: the sampling interval, µs (default: the sampling method's).
    pub dt_us: Option<i64>,
    /// `harmonics`: flicker harmonics traced.
    pub harmonics: u32,
    /// `filter_order`: Butterworth order of the band-pass prototype.
    pub filter_order: u32,
    /// `median_len`: running-median length of the outlier correction.
    pub median_len: usize,
    /// `median_threshold`: outlier threshold, Hz.
    pub median_threshold: f64,
    /// `segment`: harmonic-selection segment, estimates.
    pub segment: usize,
    /// `selection`: the harmonic-selection rule.
    pub selection: HarmonicSelection,
    /// `jump_hz`: the journal rule's largest step, Hz.
    pub jump_hz: f64,
    /// `agree_hz`: the consensus rule's tolerance, Hz.
    pub agree_hz: f64,
    /// `all_pixels`: trace every pixel, not only the tiles whose flicker stands out.
    pub all_pixels: bool,
    /// How the file is read.
    pub input: InputSettings,
}

impl Default for ExtractSettings {
    fn default() -> Self {
        ExtractSettings {
            tracker: TrackerSettings::default(),
            sampling: SamplingMethod::Auto,
            dt_us: None,
            harmonics: defaults::HARMONICS as u32,
            filter_order: defaults::FILTER_ORDER as u32,
            median_len: defaults::MEDIAN_LEN,
            median_threshold: defaults::MEDIAN_THRESHOLD_HZ,
            segment: defaults::SEGMENT_LEN,
            selection: HarmonicSelection::Consensus(HarmonicSelection::DEFAULT_AGREE_HZ),
            jump_hz: HarmonicSelection::DEFAULT_JUMP_HZ,
            agree_hz: HarmonicSelection::DEFAULT_AGREE_HZ,
            all_pixels: false,
            input: InputSettings::default(),
        }
    }
}

impl OptionSet for ExtractSettings {
    fn set(&mut self, name: &str, v: &Value) -> Result<bool, OptionError> {
        match name {
            "sampling" => self.sampling = named("sampling", v)?,
            "dt_us" => self.dt_us = maybe("dt_us", v, whole)?,
            "harmonics" => self.harmonics = whole("harmonics", v)?,
            "filter_order" => self.filter_order = whole("filter_order", v)?,
            "median_len" => self.median_len = whole("median_len", v)?,
            "median_threshold" => self.median_threshold = number("median_threshold", v)?,
            "segment" => self.segment = whole("segment", v)?,
            "selection" => self.selection = named("selection", v)?,
            "jump_hz" => self.jump_hz = number("jump_hz", v)?,
            "agree_hz" => self.agree_hz = number("agree_hz", v)?,
            "all_pixels" => self.all_pixels = switch("all_pixels", v)?,
            _ => return Ok(self.tracker.set(name, v)? || self.input.set(name, v)?),
        }
        Ok(true)
    }

    fn check(&self) -> Result<(), OptionError> {
        self.tracker.check()?;
        if let Some(dt) = self.dt_us {
            counted("dt_us", dt, limits::DT_US)?;
        }
        counted("harmonics", self.harmonics, limits::HARMONICS)?;
        counted("filter_order", self.filter_order, limits::FILTER_ORDER)?;
        counted(
            "median_len",
            self.median_len as u64,
            widen(limits::MEDIAN_LEN),
        )?;
        within(
            "median_threshold",
            self.median_threshold,
            limits::MEDIAN_THRESHOLD_HZ,
        )?;
        counted("segment", self.segment as u64, widen(limits::SEGMENT))?;
        within("jump_hz", self.jump_hz, limits::SELECTION_HZ)?;
        within("agree_hz", self.agree_hz, limits::SELECTION_HZ)?;
        self.input.check()
    }
}

/// A `usize` range as `u64` (whole numbers are compared as `i128`).
pub(crate) fn widen((lo, hi): (usize, usize)) -> (u64, u64) {
    (lo as u64, hi as u64)
}

impl ExtractSettings {
    /// The options of the extraction.
    pub fn options(&self) -> Result<ExtractOptions, OptionError> {
        self.check()?;
        let mut params = self.tracker.params()?;
        params.harmonics = self.harmonics as usize;
        params.filter_order = self.filter_order as usize;
        params.median_len = self.median_len;
        params.median_threshold_hz = self.median_threshold;
        params.segment_len = self.segment.max(1);
        params.selection = match self.selection {
            HarmonicSelection::Consensus(_) => HarmonicSelection::Consensus(self.agree_hz),
            HarmonicSelection::Journal(_) => HarmonicSelection::Journal(self.jump_hz),
            other => other,
        };
        Ok(ExtractOptions {
            sampling: self.sampling,
            dt_us: self.dt_us,
            nominal: self.tracker.nominal,
            params,
            open: self.input.open_options(),
            flicker_tiles: !self.all_pixels,
            window_given: self.tracker.window.is_some(),
        })
    }
}

/// How events are written (`convert`, `simulate`, Python's `write_events`).
#[derive(Debug, Clone)]
pub struct EventOutputSettings {
    /// `format`: the output format (default: from the file's extension).
    pub format: Option<OutputFormat>,
    /// `compression`: AEDAT4 packet compression.
    pub compression: Compression,
}

impl Default for EventOutputSettings {
    fn default() -> Self {
        EventOutputSettings {
            format: None,
            compression: Compression::Lz4,
        }
    }
}

impl OptionSet for EventOutputSettings {
    fn set(&mut self, name: &str, v: &Value) -> Result<bool, OptionError> {
        match name {
            "format" => self.format = maybe("format", v, named)?,
            "compression" => self.compression = named("compression", v)?,
            _ => return Ok(false),
        }
        Ok(true)
    }

    fn check(&self) -> Result<(), OptionError> {
        Ok(())
    }
}

impl EventOutputSettings {
    /// The format for `path`: the one asked for, else its extension's, else `fallback`.
    pub fn format_for(
        &self,
        path: &Path,
        fallback: Option<OutputFormat>,
    ) -> Result<OutputFormat, OptionError> {
        let f = match self.format {
            Some(f) => f,
            None => OutputFormat::from_extension(path, self.compression)
                .or(fallback)
                .ok_or_else(|| {
                    rule(
                        "format",
                        format!(
                            "{}: cannot tell the output format from the name; pass {} aedat4|evt2|evt3|dat|text",
                            path.display(),
                            option("format")
                        ),
                    )
                })?,
        };
        Ok(f.with_compression(self.compression))
    }
}
