//! Events and sound in memory (what the Python package hands over) give the traces of their
//! files: the same reader path, the same decimation.

use crate::cli;

use std::path::Path;
use std::sync::Arc;

use eenf::audio::{AudioOptions, Channel, Sound};
use eenf::extract::{extract, ExtractOptions};
use eenf::mains::{sound_trace, HumOptions, MainsLines};
use eenf::progress::Progress;
use eenf::recording::Recording;
use eenf_events::EventBatch;

fn same(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn events_in_memory_give_the_file_trace() {
    let dir = tempfile::tempdir().unwrap();
    let file = cli::simulate(dir.path(), "mem.aedat4", "12", &["--readout", "prophesee"]);
    let opts = ExtractOptions::default();
    let want = extract(&Recording::file(&file), &opts, &Progress::hidden()).unwrap();
    let mut r = eenf_events::open(&file).unwrap();
    let (w, h) = (r.info().width.unwrap(), r.info().height.unwrap());
    let mut all = EventBatch::default();
    while let Some(b) = r.next_batch().unwrap() {
        all.extend_from(&b);
    }
    let rec = Recording::Memory {
        name: "mem".into(),
        events: Arc::new(all),
        width: w,
        height: h,
    };
    let got = extract(&rec, &opts, &Progress::hidden()).unwrap();
    assert!(same(&got.enf_hz, &want.enf_hz));
    assert!(same(&got.snr_db, &want.snr_db));
    assert_eq!(got.events().unwrap().format, eenf_events::memory::FORMAT);
}

#[test]
fn samples_in_memory_give_the_wav_trace_and_nan_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let wav = dir.path().join("hum.wav");
    let fs = 1000u32;
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: fs,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut w = hound::WavWriter::create(&wav, spec).unwrap();
    let mut pcm = Vec::new();
    let mut phase = 0.0f64;
    for i in 0..(60 * fs) {
        let f = 50.0 + 0.02 * (i as f64 / fs as f64 / 30.0).sin();
        phase += 2.0 * std::f64::consts::PI * f / fs as f64;
        let v = (0.3 * phase.sin() * 32767.0).round() as i16;
        w.write_sample(v).unwrap();
        pcm.push(v as f32 / 32768.0);
    }
    w.finalize().unwrap();
    let (audio, params) = (
        AudioOptions {
            channel: Channel::Mix,
            top_hz: None,
        },
        eenf_dsp::EnfParams::default(),
    );
    let nominal = eenf_core::Nominal::Auto;
    let one = HumOptions {
        lines: MainsLines::UpTo(1),
        window_s: None,
    };
    let want = sound_trace(&Sound::File(&wav), &audio, &one, nominal, &params).unwrap();
    let in_memory = |pcm: &[f32]| {
        let sound = Sound::Samples {
            name: Path::new("pcm"),
            interleaved: pcm,
            channels: 1,
            fs: fs as f64,
        };
        sound_trace(&sound, &audio, &one, nominal, &params)
    };
    let got = in_memory(&pcm).unwrap();
    assert!(same(&got.enf_hz, &want.enf_hz));
    pcm[777] = f32::NAN;
    let e = in_memory(&pcm).unwrap_err();
    assert!(e.report().contains("sample 777"), "{}", e.report());
}
