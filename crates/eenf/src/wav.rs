//! WAV files: 16-bit mono WAVs written whole, and RIFF/WAVE recognised. Reading goes through
//! [`crate::audio`], which reads every container.

use std::path::Path;

use crate::error::Result;

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
