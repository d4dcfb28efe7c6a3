//! Mains/audio recordings: WAV of any rate, integer or float samples; the first channel is used.

use std::path::Path;

use anyhow::{bail, Result};

/// Samples of a mono signal.
pub struct Signal {
    /// Sampling rate, Hz.
    pub fs: f64,
    /// Samples (scaled to ±1 for integer formats).
    pub samples: Vec<f64>,
}

/// Largest WAV accepted: 24 h of 48 kHz; a larger length field is taken as corrupt.
const MAX_FRAMES: u64 = 24 * 3600 * 48_000;

/// Reads a WAV file.
pub fn read_wav(path: &Path) -> Result<Signal> {
    let reader = hound::WavReader::open(path).map_err(|e| match e {
        hound::Error::IoError(io) => anyhow::anyhow!("{}: {io}", path.display()),
        other => anyhow::anyhow!("{}: not a readable WAV file ({other})", path.display()),
    })?;
    let spec = reader.spec();
    let frames = reader.duration() as u64;
    if frames > MAX_FRAMES {
        bail!(
            "{}: WAV header announces {frames} frames, more than eenf accepts",
            path.display()
        );
    }
    if spec.sample_rate == 0 || spec.channels == 0 {
        bail!(
            "{}: WAV header has a zero sample rate or no channels",
            path.display()
        );
    }
    let ch = spec.channels as usize;
    let mut samples = Vec::with_capacity(frames as usize);
    let bad = |e: hound::Error| anyhow::anyhow!("{}: damaged WAV data ({e})", path.display());
    match spec.sample_format {
        hound::SampleFormat::Int => {
            let scale = 1.0 / (1u64 << (spec.bits_per_sample.clamp(1, 32) - 1)) as f64;
            for (i, s) in reader.into_samples::<i32>().enumerate() {
                let s = s.map_err(bad)?;
                if i % ch == 0 {
                    samples.push(s as f64 * scale);
                }
            }
        }
        hound::SampleFormat::Float => {
            for (i, s) in reader.into_samples::<f32>().enumerate() {
                let s = s.map_err(bad)?;
                if i % ch == 0 {
                    samples.push(s as f64);
                }
            }
        }
    }
    if samples.is_empty() {
        bail!("{}: the WAV holds no samples", path.display());
    }
    Ok(Signal {
        fs: spec.sample_rate as f64,
        samples,
    })
}

/// Writes a mono 16-bit WAV (samples in ±1), whole or not at all.
pub fn write_wav(path: &Path, fs: u32, samples: &[f64]) -> Result<()> {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: fs,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let out = crate::output::AtomicFile::create(path)?;
    let res = (|| -> Result<()> {
        let mut w = hound::WavWriter::new(std::io::BufWriter::new(out.file()?), spec)?;
        for &s in samples {
            w.write_sample((s.clamp(-1.0, 1.0) * 32767.0).round() as i16)?;
        }
        w.finalize()?;
        Ok(())
    })();
    match res {
        Ok(()) => out.commit(),
        Err(e) => Err(e.context(format!("{}: cannot write WAV", path.display()))),
    }
}

/// True when `path` starts like a RIFF/WAVE file.
pub fn is_wav(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 12];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .map(|_| &head[..4] == b"RIFF" && &head[8..12] == b"WAVE")
        .unwrap_or(false)
}
