//! Tests of eenf-dsp's `blocks`: a long signal tracked a block at a time gives what it gives
//! tracked whole.

use eenf_dsp::blocks::{enf_from_hum_lines_in, reference_enf_in, BlockSource};
use eenf_dsp::{enf_from_hum_lines, DspError, EnfParams};

use crate::test_noise as noise;

/// 70 minutes of hum at f0, 2 f0 and 3 f0 following a wandering ENF, in noise, at 400 Hz.
fn hum(fs: f64, seconds: f64) -> Vec<f64> {
    let mut draw = noise(0x5eed_0000_0000_0049);
    let n = (fs * seconds) as usize;
    let mut phase = 0.0f64;
    (0..n)
        .map(|i| {
            let t = i as f64 / fs;
            let f = 50.0 + 0.03 * (2.0 * std::f64::consts::PI * t / 600.0).sin();
            phase += 2.0 * std::f64::consts::PI * f / fs;
            0.02 * phase.sin()
                + 0.01 * (2.0 * phase).sin()
                + 0.004 * (3.0 * phase).sin()
                + 0.05 * draw()
        })
        .collect()
}

/// A signal that counts how much it is asked for at a time.
struct Counted<'a>(&'a [f64], std::sync::atomic::AtomicUsize);

impl BlockSource for Counted<'_> {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn read(&self, range: std::ops::Range<usize>) -> Result<Vec<f64>, DspError> {
        self.1
            .fetch_max(range.len(), std::sync::atomic::Ordering::Relaxed);
        Ok(self.0[range].to_vec())
    }
}

#[test]
fn blocks_give_what_the_whole_signal_gives() {
    let fs = 400.0;
    let x = hum(fs, 70.0 * 60.0);
    // 32 s windows: the 2nd and 3rd bands are followed through their sweep (the baseband)
    let p = EnfParams {
        nominal_hz: 50.0,
        window_s: 32.0,
        ..EnfParams::default()
    };
    let whole = enf_from_hum_lines(&x, fs, &p, &[1, 2, 3]).unwrap();
    let src = Counted(&x, Default::default());
    let blocks = enf_from_hum_lines_in(&src, fs, &p, &[1, 2, 3]).unwrap();
    // never more than a block (half an hour and its margins) read at once
    let most = src.1.load(std::sync::atomic::Ordering::Relaxed);
    assert!(most < x.len() / 2 && most > 0, "{most} of {}", x.len());
    assert_eq!(whole.enf_hz.len(), blocks.enf_hz.len());
    assert_eq!(whole.selected, blocks.selected);
    for (h, g) in whole.harmonics.iter().zip(&blocks.harmonics) {
        for (a, b) in h.enf_hz.iter().zip(&g.enf_hz) {
            assert!(
                a == b || (a - b).abs() < 1e-9,
                "band {}: {a} vs {b}",
                h.harmonic
            );
        }
        for (a, b) in h.snr_db.iter().zip(&g.snr_db) {
            assert!(
                a == b || (a - b).abs() < 1e-6,
                "band {}: {a} vs {b}",
                h.harmonic
            );
        }
    }
    // f0 alone, unfiltered: the tracker over the whole signal
    let band = (p.nominal_hz - p.half_band_hz, p.nominal_hz + p.half_band_hz);
    let (enf, snr): (Vec<f64>, Vec<f64>) =
        p.tracker(fs).track_with_snr(&x, band).into_iter().unzip();
    let (enf_b, snr_b) = reference_enf_in(&src, fs, &p).unwrap();
    assert_eq!(enf, enf_b);
    assert_eq!(snr, snr_b);
}
