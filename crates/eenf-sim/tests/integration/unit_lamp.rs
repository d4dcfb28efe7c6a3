//! Tests of eenf-sim's `lamp` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_sim::*;
use std::f64::consts::PI;

/// Light of `lamp` over one second at a steady 50 Hz, sampled at 20 kHz.
fn light(kind: LampKind) -> Vec<f64> {
    let mains = MainsPhase::from_frequency(50.0, &[50.0; 8], 1.0, 0.0, 4.0, 0.0);
    let mut bank = LampBank::new(
        &[Lamp {
            kind,
            phase_deg: 0.0,
            share: 1.0,
        }],
        &mains,
    );
    bank.advance_to(1.0, &mains);
    (0..20_000)
        .map(|i| {
            bank.advance_to(1.0 + i as f64 / 20_000.0, &mains);
            bank.light()[0]
        })
        .collect()
}

fn harmonic(x: &[f64], f: f64, fs: f64) -> f64 {
    let (mut re, mut im) = (0.0, 0.0);
    for (i, v) in x.iter().enumerate() {
        let a = 2.0 * PI * f * i as f64 / fs;
        re += v * a.cos();
        im += v * a.sin();
    }
    2.0 * (re * re + im * im).sqrt() / x.len() as f64
}

#[test]
fn lamps_have_unit_mean_and_their_kinds_modulation() {
    let inc = light(LampKind::named("incandescent").unwrap());
    let mean = inc.iter().sum::<f64>() / inc.len() as f64;
    assert!((mean - 1.0).abs() < 1e-3, "{mean}");
    // first-order low-pass of cos²: depth 1/sqrt(1 + (2π·100·τ)²)
    let depth = harmonic(&inc, 100.0, 20_000.0);
    let want = 1.0 / (1.0 + (2.0 * PI * 100.0 * 0.016f64).powi(2)).sqrt();
    assert!((depth - want).abs() < 0.01 * want, "{depth} vs {want}");

    let fl = light(LampKind::named("fluorescent").unwrap());
    let h: Vec<f64> = (1..=3)
        .map(|m| harmonic(&fl, 100.0 * m as f64, 20_000.0))
        .collect();
    // deep modulation with strong higher harmonics
    assert!(
        h[0] > 0.5 && h[1] > 0.1 * h[0] && h[2] > 0.02 * h[0],
        "{h:?}"
    );
    // a filament's light has (almost) no harmonics
    assert!(harmonic(&inc, 200.0, 20_000.0) < 0.01 * depth);
    // no line at the mains frequency itself: light follows power
    assert!(harmonic(&fl, 50.0, 20_000.0) < 1e-3);

    let s = light(LampKind::Sinusoid { depth: 0.5 });
    assert!((harmonic(&s, 100.0, 20_000.0) - 0.5).abs() < 1e-3);
    assert!(harmonic(&s, 200.0, 20_000.0) < 1e-3);
}

#[test]
fn three_phase_lamps_do_not_add_coherently() {
    let mains = MainsPhase::from_frequency(50.0, &[50.0; 8], 1.0, 0.0, 4.0, 0.0);
    let kind = LampKind::Sinusoid { depth: 0.5 };
    let lamps: Vec<Lamp> = [0.0, 120.0, 240.0]
        .iter()
        .map(|&p| Lamp {
            kind,
            phase_deg: p,
            share: 1.0,
        })
        .collect();
    let mut bank = LampBank::new(&lamps, &mains);
    let total: Vec<f64> = (0..2000)
        .map(|i| {
            bank.advance_to(1.0 + i as f64 / 20_000.0, &mains);
            bank.light().iter().sum::<f64>()
        })
        .collect();
    // 2φ offsets of 240° and 480° cancel the 100 Hz line of the sum
    let amp = harmonic(&total, 100.0, 20_000.0);
    assert!(amp < 1e-3, "{amp}");
}

#[test]
fn lamp_specs_parse() {
    let l = Lamp::parse("fluorescent@120*0.5").unwrap();
    assert_eq!(l.phase_deg, 120.0);
    assert_eq!(l.share, 0.5);
    assert!(matches!(l.kind, LampKind::Fluorescent { .. }));
    assert!(Lamp::parse("candle").is_none());
    assert!(Lamp::parse("led*-1").is_none());
}
