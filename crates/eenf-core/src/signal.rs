//! A sampled signal: what audio decoders, mains recordings and the simulator's references hand
//! to the signal processing.

/// Samples of a mono signal.
#[derive(Debug, Clone)]
pub struct Signal {
    /// Sampling rate, Hz.
    pub fs: f64,
    /// Samples (scaled to ±1 for integer formats).
    pub samples: Vec<f64>,
}
