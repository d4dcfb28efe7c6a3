//! The method's parameters as command-line flags, shared by the commands that track the ENF.

use eenf_cli::pipeline::{ExtractOptions, Nominal};
use eenf_dsp::{EnfParams, HarmonicSelection, PeakMethod, SamplingMethod};

/// Harmonic-selection names for clap.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum Selection {
    /// The paper: the smoothest harmonic trace per segment.
    Smoothest,
    /// The smoothest among harmonics that agree with another one (within --agree-hz).
    Consensus,
}

/// Peak refinement names for clap.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum Peak {
    /// Maximise the window's DTFT magnitude (unbiased).
    Exact,
    /// Zero-padded FFT (0.005 Hz bins) + complex quadratic interpolation, as the paper.
    Paper,
}

impl From<Peak> for PeakMethod {
    fn from(p: Peak) -> Self {
        match p {
            Peak::Exact => PeakMethod::Exact,
            Peak::Paper => PeakMethod::Paper,
        }
    }
}

/// Sampling names for clap.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum Sampling {
    /// Events at the smallest timestamp ≥ t_n (the paper).
    Paper,
    /// The group at the largest timestamp in [t_n, t_n + Δt), previous sample when empty.
    Authors,
    /// Vote over all events in [t_n, t_n + Δt) (the journal version).
    Block,
}

impl From<Sampling> for SamplingMethod {
    fn from(s: Sampling) -> Self {
        match s {
            Sampling::Paper => SamplingMethod::Paper,
            Sampling::Authors => SamplingMethod::Authors,
            Sampling::Block => SamplingMethod::Block,
        }
    }
}

/// Tracker flags (shared by `extract` and `reference`).
#[derive(Debug, Clone, clap::Args)]
pub struct TrackerArgs {
    /// Nominal grid frequency: 50, 60, or auto (detected from the spectrum).
    #[arg(long, default_value = "auto")]
    pub nominal: Nominal,
    /// Peak refinement of each STFT window.
    #[arg(long, value_enum, default_value_t = Peak::Exact)]
    pub peak: Peak,
    /// STFT window length, s.
    #[arg(long, default_value_t = 16.0)]
    pub window: f64,
    /// STFT step, s (one estimate per step).
    #[arg(long, default_value_t = 1.0)]
    pub step: f64,
    /// Half width of the search band (and band-pass) around each line, Hz.
    #[arg(long, default_value_t = 2.0)]
    pub half_band: f64,
}

/// Event-method flags (`extract`).
#[derive(Debug, Clone, clap::Args)]
pub struct MethodArgs {
    #[command(flatten)]
    pub tracker: TrackerArgs,
    /// Temporal sampling variant.
    #[arg(long, value_enum, default_value_t = Sampling::Paper)]
    pub sampling: Sampling,
    /// Sampling interval Δt, µs.
    #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(i64).range(10..=1_000_000))]
    pub dt_us: i64,
    /// Number of flicker harmonics M (bands at 2m·f0, m = 1..M; those above Nyquist skipped).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub harmonics: u32,
    /// Butterworth order of the band-pass prototype.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=8))]
    pub filter_order: u32,
    /// Running-median length of the outlier correction (0 or 1 disables it).
    #[arg(long, default_value_t = 21)]
    pub median_len: usize,
    /// Outlier threshold on the 2f0 scale, Hz.
    #[arg(long, default_value_t = 0.02)]
    pub median_threshold: f64,
    /// Harmonic-selection segment length, in estimates.
    #[arg(long, default_value_t = 10)]
    pub segment: usize,
    /// Harmonic-selection rule.
    #[arg(long, value_enum, default_value_t = Selection::Consensus)]
    pub selection: Selection,
    /// Agreement tolerance of the consensus rule, Hz (on the ENF scale).
    #[arg(long, default_value_t = 0.005)]
    pub agree_hz: f64,
}

impl TrackerArgs {
    /// The tracker part of the parameters.
    pub fn params(&self) -> anyhow::Result<EnfParams> {
        if !(self.window > 0.0 && self.step > 0.0 && self.half_band > 0.0) {
            anyhow::bail!("--window, --step and --half-band must be positive");
        }
        Ok(EnfParams {
            peak: self.peak.into(),
            window_s: self.window,
            step_s: self.step,
            half_band_hz: self.half_band,
            ..EnfParams::default()
        })
    }
}

impl MethodArgs {
    /// The options of the extraction.
    pub fn options(&self) -> anyhow::Result<ExtractOptions> {
        let mut params = self.tracker.params()?;
        params.harmonics = self.harmonics as usize;
        params.filter_order = self.filter_order as usize;
        params.median_len = self.median_len;
        params.median_threshold_hz = self.median_threshold;
        params.segment_len = self.segment.max(1);
        params.selection = match self.selection {
            Selection::Smoothest => HarmonicSelection::Smoothest,
            Selection::Consensus => HarmonicSelection::Consensus(self.agree_hz),
        };
        Ok(ExtractOptions {
            sampling: self.sampling.into(),
            dt_us: self.dt_us,
            nominal: self.tracker.nominal,
            params,
        })
    }
}
