//! Real sound with weak hum (`../shared/fixtures/real-audio`, its README says what each must
//! give), and a recording made like the ENF-WHU case: the real room noise of
//! `enfwhu_H0_01_no_enf_1kHz.wav` with a hum at 4 f0 (13.5 dB over its floor; 2 f0 and f0 far
//! weaker) that follows a real mains hour. `#[ignore]`d (needs the shared data); `.ci/run` runs
//! it with `--ignored`.

use std::path::{Path, PathBuf};

use eenf::audio::read_wav;
use eenf::audio::{AudioOptions, Sound};
use eenf::mains::{audio_trace, reference_file, sound_trace, HumOptions};
use eenf::trace::{Provenance, Trace};
use eenf_core::Nominal;
use eenf_dsp::{agreement, search_hum, EnfParams};
use eenf_sim::MainsPhase;

use crate::common;

fn real_audio(name: &str) -> PathBuf {
    common::shared("fixtures")
        .join("fixtures/real-audio")
        .join(name)
}

fn audio(path: &Path) -> eenf::Result<Trace> {
    audio_trace(
        path,
        &AudioOptions::default(),
        &HumOptions::default(),
        Nominal::Auto,
        &EnfParams::default(),
    )
}

fn flags(t: &Trace) -> Vec<String> {
    match &t.provenance {
        Some(Provenance::Mains(m)) => m
            .hum
            .as_ref()
            .map(|h| h.plausibility.flags.clone())
            .unwrap_or_default(),
        _ => Vec::new(),
    }
}

#[test]
#[ignore = "needs ../shared"]
fn real_recordings_with_hum_are_traced_on_60_hz_and_the_steady_line_is_flagged() {
    for (name, lo, hi) in [
        ("pyenf_room_34s.wav", 59.98, 60.05),
        ("pyenf_room_16s.wav", 59.95, 60.05),
        ("pyenf_new_record.wav", 59.85, 59.87),
    ] {
        let t = audio(&real_audio(name)).unwrap_or_else(|e| panic!("{name}: {}", e.report()));
        assert_eq!(t.nominal_hz, Some(60.0), "{name}");
        let finite: Vec<f64> = t.finite().collect();
        let mean = finite.iter().sum::<f64>() / finite.len() as f64;
        assert!((lo..=hi).contains(&mean), "{name}: mean {mean}");
        assert!(finite.len() + 2 >= t.enf_hz.len(), "{name}: gaps");
        let f = flags(&t);
        if name == "pyenf_new_record.wav" {
            // 139 mHz below 60 Hz, and steadier than any grid
            assert!(f.iter().any(|f| f.contains("139 mHz below")), "{f:?}");
            assert!(f.iter().any(|f| f.contains("steadier")), "{f:?}");
        } else {
            assert!(f.is_empty(), "{name}: {f:?}");
        }
    }
    let e = audio(&real_audio("enfwhu_H0_01_no_enf_1kHz.wav")).unwrap_err();
    assert!(e.report().contains("no mains line"), "{}", e.report());
}

#[test]
#[ignore = "needs ../shared"]
fn a_hum_at_four_f0_in_real_room_noise_follows_the_mains_reference() {
    let noise = read_wav(&real_audio("enfwhu_H0_01_no_enf_1kHz.wav")).unwrap();
    let fs = noise.fs;
    let secs = noise.samples.len() as f64 / fs;
    for (hour, offset) in [(0usize, 0usize), (2, 1800), (5, 1800)] {
        // the ENF of a real mains hour, per second, from `offset` on
        let wav = &common::reference_wavs()[hour];
        let reference = reference_file(
            wav,
            Nominal::Grid(eenf_core::Grid::Hz50),
            &EnfParams::default(),
        )
        .unwrap();
        let enf = &reference.enf_hz[offset..offset + secs as usize + 4];
        let phase = MainsPhase::from_frequency(50.0, enf, 1.0, 0.0, secs, 0.3);
        let at = |k: f64| -> Vec<f64> {
            (0..noise.samples.len())
                .map(|i| (k * phase.phase_at(i as f64 / fs) + 0.5 * k).cos())
                .collect()
        };
        let (h1, h2, h4) = (at(1.0), at(2.0), at(4.0));
        // amplitudes found so that the detector sees 13.5, 4.5 and 1.3 dB at 4, 2 and 1 f0
        let mut amp = [1.0e-3f64; 3];
        let mix = |amp: &[f64; 3]| -> Vec<f64> {
            (0..noise.samples.len())
                .map(|i| noise.samples[i] + amp[0] * h1[i] + amp[1] * h2[i] + amp[2] * h4[i])
                .collect()
        };
        for _ in 0..10 {
            let s = search_hum(&mix(&amp), fs, 1.0, &[50.0], 4).unwrap();
            for (j, (k, want)) in [(1, 1.3), (2, 4.5), (4, 13.5)].into_iter().enumerate() {
                let got = s.lines.iter().find(|l| l.harmonic == k).unwrap().db;
                amp[j] *= 10f64.powf((want - got) / 20.0 * 0.8);
            }
        }
        let x: Vec<f32> = mix(&amp).iter().map(|&v| v as f32).collect();
        let sound = Sound::Samples {
            name: Path::new("whu-like"),
            interleaved: &x,
            channels: 1,
            fs,
        };
        let t = sound_trace(
            &sound,
            &AudioOptions::default(),
            &HumOptions::default(),
            Nominal::Auto,
            &EnfParams::default(),
        )
        .unwrap();
        assert_eq!(t.nominal_hz, Some(50.0));
        let truth = &reference.enf_hz[offset..offset + t.enf_hz.len()];
        let a = agreement(&t.enf_hz, truth).unwrap();
        eprintln!(
            "hour {hour} from {offset} s: CC {:.4}, MAE {:.2} mHz over {} s",
            a.cc,
            a.mae_hz * 1e3,
            a.n
        );
        assert!(a.n >= 400 && a.cc >= 0.98, "{a:?}");
    }
}
