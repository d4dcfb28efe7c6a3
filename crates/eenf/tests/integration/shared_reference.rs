//! The reference tracker on the six real mains recordings in `../shared/enf-reference`.
//! `#[ignore]`d (needs the shared data); `.ci/run` runs it with `--ignored`.

use std::path::PathBuf;

use eenf::mains::reference_file;
use eenf_core::Nominal;
use eenf_dsp::{EnfParams, PeakMethod};

use crate::common;

fn shared() -> PathBuf {
    common::shared("enf-reference")
}

/// A 1-D little-endian float64 .npy file.
fn read_npy(path: &std::path::Path) -> Vec<f64> {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[..6], b"\x93NUMPY");
    let hl = u16::from_le_bytes([b[8], b[9]]) as usize;
    let header = String::from_utf8_lossy(&b[10..10 + hl]);
    assert!(header.contains("'<f8'"), "{header}");
    b[10 + hl..]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

#[test]
#[ignore = "needs ../shared"]
fn six_real_hours_match_the_datasets_own_references() {
    let wavs = common::reference_wavs();
    assert_eq!(wavs.len(), 6);
    for wav in &wavs {
        let params = EnfParams {
            peak: PeakMethod::Paper,
            ..EnfParams::default()
        };
        let r = reference_file(wav, Nominal::Auto, &params).unwrap();
        let (f0, trace) = (r.nominal_hz.unwrap(), r.enf_hz);
        assert_eq!(f0, 50.0);
        assert!(
            trace.len() == 3601 || trace.len() == 3602,
            "{}",
            trace.len()
        );
        let n = trace.len() as f64;
        let mean = trace.iter().sum::<f64>() / n;
        let sd = (trace.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
        assert!((mean - 50.0).abs() < 0.03, "{}: mean {mean}", wav.display());
        assert!(sd > 0.012 && sd < 0.035, "{}: std {sd}", wav.display());
        // The dataset's .npy traces come from the authors' code, whose (k + δ − 1) indexing
        // puts every estimate fs/NFFT = 5 mHz low (method.md). With that removed they agree
        // with ours except where two bins tie for the maximum and the biased interpolation
        // lands ~3.7 mHz apart.
        let authors = read_npy(&wav.with_extension("npy"));
        assert_eq!(authors.len(), trace.len());
        let close = trace
            .iter()
            .zip(&authors)
            .filter(|(a, b)| (*a - *b - 0.005).abs() <= 1e-4)
            .count();
        let share = close as f64 / n;
        println!(
            "{}: mean {mean:.5} Hz, std {:.2} mHz, {:.2}% within 0.1 mHz of the authors' + 5 mHz",
            wav.display(),
            sd * 1e3,
            share * 100.0
        );
        assert!(share >= 0.995, "{}: only {share}", wav.display());
        // the exact refinement differs from the paper's by the interpolation bias: about a
        // millisecond-hertz on average, a few at worst where the ENF moves within the window
        let exact = reference_file(
            wav,
            Nominal::Grid(eenf_core::Grid::Hz50),
            &EnfParams::default(),
        )
        .unwrap()
        .enf_hz;
        let diffs: Vec<f64> = exact
            .iter()
            .zip(&trace)
            .map(|(a, b)| (a - b).abs())
            .collect();
        let worst = diffs.iter().copied().fold(0.0, f64::max);
        let mean = diffs.iter().sum::<f64>() / n;
        println!(
            "  exact vs paper: mean {:.3} mHz, max {:.3} mHz",
            mean * 1e3,
            worst * 1e3
        );
        assert!(
            mean < 0.001 && worst < 0.005,
            "{}: exact vs paper mean {mean} max {worst}",
            wav.display()
        );
    }
}

#[test]
#[ignore = "needs ../shared"]
fn simulation_driven_by_a_real_hour_is_recovered() {
    use eenf::extract::{extract_file, ExtractOptions};
    use eenf::progress::Progress;
    use eenf_events::{Aedat4Writer, Compression};
    use eenf_sim::{simulate, MainsPhase, SimConfig};

    let wav = shared().join("enf-reference/2022_08_17_Wed_16_00_00.wav");
    let sig = eenf::audio::read_wav(&wav).unwrap();
    let start = 600.0;
    let config = SimConfig {
        duration_s: 120.0,
        ..SimConfig::default()
    };
    let mains =
        MainsPhase::from_recording(&sig.samples, sig.fs, 50.0, start, config.duration_s).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let rec = tmp.path().join("wav600.aedat4");
    let mut w = Aedat4Writer::create(&rec, Compression::Lz4, config.width, config.height).unwrap();
    simulate(&config, &mains, |b| w.write(b)).unwrap();
    w.finish().unwrap();
    let x = extract_file(&rec, &ExtractOptions::default(), &Progress::hidden()).unwrap();
    assert_eq!(x.nominal_hz, Some(50.0));
    // against the simulator's truth
    let truth = mains.truth(config.duration_s);
    let m = eenf_dsp::agreement(&x.enf_hz, &truth).unwrap();
    println!("vs truth: {m:?}");
    assert!(m.n >= 120 && m.cc >= 0.95 && m.mae_hz <= 0.002, "{m:?}");
    // and against the real hour's own reference trace, 600 s in
    let reference = reference_file(
        &wav,
        Nominal::Grid(eenf_core::Grid::Hz50),
        &EnfParams::default(),
    )
    .unwrap()
    .enf_hz;
    let m = eenf_dsp::agreement(&x.enf_hz, &reference[600..]).unwrap();
    println!("vs the WAV's reference at 600 s: {m:?}");
    assert!(m.cc >= 0.95 && m.mae_hz <= 0.002, "{m:?}");
}
