//! `eenf simulate`: an event recording of a flickering scene, with its ground truth.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use eenf_cli::output::{times, write_atomic, write_trace_csv};
use eenf_cli::pipeline::{mains_nominal, Nominal};
use eenf_cli::progress::Progress;
use eenf_cli::wav::read_wav;
use eenf_events::writers::{create, OutputFormat};
use eenf_events::Compression;
use eenf_sim::{simulate, MainsPhase, SimConfig, SimStats, SyntheticEnf};

/// Arguments of `eenf simulate`.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {
    /// Length of the recording, s.
    #[arg(long, default_value_t = 60.0)]
    pub duration: f64,
    /// Where the ENF comes from: `synthetic` (a grid-like random process) or a mains WAV,
    /// optionally with a start second (`ref.wav:600`).
    #[arg(long, default_value = "synthetic")]
    pub enf: String,
    /// Grid frequency of a synthetic ENF: 50 or 60 (a WAV's own is detected).
    #[arg(long, default_value_t = 50)]
    pub grid: u32,
    /// Output recording; the format follows the extension (.aedat4, .raw = EVT 3.0, .dat,
    /// .txt) unless --format says. The truth goes beside it as NAME.truth.csv, the parameters
    /// as NAME.sim.json.
    #[arg(short, long, default_value = "simulated.aedat4")]
    pub output: PathBuf,
    /// Sensor resolution WxH.
    #[arg(long, default_value = "64x48")]
    pub resolution: String,
    /// Random seed (same seed, same recording).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// AEDAT4 packet compression: none, lz4, lz4_high, zstd, zstd_high.
    #[arg(long, default_value = "lz4")]
    pub compression: String,
    /// Output format: aedat4, evt2, evt3, dat, text (default: from the extension).
    #[arg(long)]
    pub format: Option<String>,
}

/// Paths and numbers of a finished simulation.
pub struct Simulated {
    /// Its ground truth trace.
    pub truth: PathBuf,
    /// What was generated.
    pub stats: SimStats,
    /// Seconds it took.
    pub seconds: f64,
}

/// NAME.ext → NAME.<suffix>
pub fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    path.with_file_name(format!("{stem}.{suffix}"))
}

fn parse_resolution(s: &str) -> Result<(u16, u16)> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .with_context(|| format!("--resolution {s:?}: expected WxH, e.g. 320x240"))?;
    let w: u16 = w
        .trim()
        .parse()
        .with_context(|| format!("--resolution {s:?}: bad width"))?;
    let h: u16 = h
        .trim()
        .parse()
        .with_context(|| format!("--resolution {s:?}: bad height"))?;
    if w == 0 || h == 0 || w > 4096 || h > 4096 {
        bail!("--resolution {s:?}: width and height must be 1..4096");
    }
    Ok((w, h))
}

/// Builds the mains phase from `--enf`.
fn mains(a: &Args) -> Result<MainsPhase> {
    if a.enf == "synthetic" {
        if a.grid != 50 && a.grid != 60 {
            bail!("--grid must be 50 or 60");
        }
        return Ok(MainsPhase::synthetic(
            a.grid as f64,
            a.duration,
            SyntheticEnf::default(),
            a.seed ^ 0x5eed,
        ));
    }
    // WAV[:START]; a colon followed by a number is the start second
    let (path, start) = match a.enf.rsplit_once(':') {
        Some((p, s)) if s.parse::<f64>().is_ok() => (PathBuf::from(p), s.parse::<f64>()?),
        _ => (PathBuf::from(&a.enf), 0.0),
    };
    let sig = read_wav(&path)?;
    let f0 = mains_nominal(&sig, Nominal::Auto, &path)?;
    MainsPhase::from_recording(&sig.samples, sig.fs, f0, start, a.duration)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

pub fn run(a: Args, progress: Progress) -> Result<Simulated> {
    if !(a.duration > 0.0 && a.duration <= 24.0 * 3600.0) {
        bail!("--duration must be between 0 and 86400 s");
    }
    let (width, height) = parse_resolution(&a.resolution)?;
    let codec = Compression::parse(&a.compression).with_context(|| {
        format!(
            "--compression {:?}: expected none, lz4, lz4_high, zstd or zstd_high",
            a.compression
        )
    })?;
    let started = std::time::Instant::now();
    let mains = mains(&a)?;
    let config = SimConfig {
        width,
        height,
        duration_s: a.duration,
        seed: a.seed,
        ..SimConfig::default()
    };
    let bar = progress.steps(
        (a.duration * 1e6 / config.scan_period_us as f64) as u64,
        "simulating",
    );
    let format = match &a.format {
        Some(f) => OutputFormat::parse(f, codec)
            .with_context(|| format!("--format {f:?}: expected aedat4, evt2, evt3, dat or text"))?,
        None => {
            OutputFormat::from_extension(&a.output, codec).unwrap_or(OutputFormat::Aedat4(codec))
        }
    };
    let mut writer = create(&a.output, format, width, height)?;
    let stats = simulate(&config, &mains, |b| {
        bar.inc(250);
        writer.write(b).map_err(anyhow::Error::from)
    })?;
    writer.finish()?;
    bar.finish_and_clear();
    let truth = mains.truth(a.duration);
    let truth_path = sibling(&a.output, "truth.csv");
    write_atomic(&truth_path, |w| {
        write_trace_csv(w, &times(truth.len(), 1.0), &truth)
    })?;
    let sidecar = serde_json::json!({
        "recording": a.output, "truth": truth_path, "enf": a.enf,
        "nominal_hz": mains.nominal_hz, "config": config, "stats": stats,
    });
    write_atomic(&sibling(&a.output, "sim.json"), |w| {
        serde_json::to_writer_pretty(&mut *w, &sidecar)?;
        Ok(())
    })?;
    let seconds = started.elapsed().as_secs_f64();
    eprintln!(
        "simulated {:.0} s at {width}x{height}: {} events ({:.1} M events/s generated) in {seconds:.1} s",
        a.duration,
        stats.events,
        stats.events as f64 / seconds / 1e6
    );
    eprintln!("recording  {}", a.output.display());
    eprintln!("truth      {}", truth_path.display());
    Ok(Simulated {
        truth: truth_path,
        stats,
        seconds,
    })
}
