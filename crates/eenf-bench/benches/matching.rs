//! Matching speed: a 5-minute clip against 24 h and against a year of 1 s reference.
//!
//! The year is built from the three real 60 Hz days in `../shared/enf-traces-60hz` (or
//! `EENF_SHARED`) when they are there: each day of the year mixes two of them, rotated and
//! weighted at random, so that no stretch repeats. Without the data, the synthetic
//! ENF process stands in.
#![allow(missing_docs)] // criterion_group! makes undocumented public functions

use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};
use eenf_dsp::matching::{match_trace, MatchOptions};
use eenf_dsp::resample::resample;
use eenf_sim::SyntheticEnf;

const DAY: usize = 86_400;

/// xorshift64*, enough for perturbing copies.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (u, v) = (self.unit().max(1e-300), self.unit());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// The real 60 Hz days at 1 s, if the shared data is there.
fn real_days() -> Option<Vec<Vec<f64>>> {
    let dir = std::env::var_os("EENF_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared"))
        .join("enf-traces-60hz");
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .ok()?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "csv"))
        .collect();
    files.sort();
    let days: Vec<Vec<f64>> = files
        .iter()
        .map(|p| {
            let text = std::fs::read_to_string(p).expect("readable trace");
            let at_2s: Vec<f64> = text
                .lines()
                .filter_map(|l| l.split(',').nth(1)?.trim().parse().ok())
                .collect();
            let mut day = resample(&at_2s, 2.0, 1.0);
            day.resize(DAY, *day.last().expect("non-empty trace"));
            day
        })
        .collect();
    (!days.is_empty()).then_some(days)
}

/// A year at 1 s from the real days: each day of it mixes two of them (read forwards or
/// backwards, rotated by random amounts) with random weights of unit power, so that the
/// deviations keep their real spectrum and size but no stretch repeats.
fn year_from(days: &[Vec<f64>], rng: &mut Rng) -> Vec<f64> {
    let mut year = Vec::with_capacity(365 * DAY);
    let pick = |rng: &mut Rng| {
        let src = &days[(rng.unit() * days.len() as f64) as usize % days.len()];
        let backwards = rng.unit() < 0.5;
        let rotate = (rng.unit() * DAY as f64) as usize;
        move |i: usize| {
            let j = (i + rotate) % DAY;
            src[if backwards { DAY - 1 - j } else { j }] - 60.0
        }
    };
    for _ in 0..365 {
        let (a, b) = (pick(rng), pick(rng));
        let theta = rng.unit() * std::f64::consts::TAU;
        let (wa, wb) = (theta.cos(), theta.sin());
        for i in 0..DAY {
            // plus 0.5 mHz of measurement noise
            year.push(60.0 + wa * a(i) + wb * b(i) + 5e-4 * rng.normal());
        }
    }
    year
}

fn benches(c: &mut Criterion) {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (year, nominal) = match real_days() {
        Some(days) => (year_from(&days, &mut rng), 60.0),
        None => (
            SyntheticEnf::default().per_second(50.0, 365 * DAY, 11),
            50.0,
        ),
    };
    eprintln!(
        "reference: {} values at 1 s around {nominal} Hz",
        year.len()
    );
    let at = 200_000_123 % (year.len() - 300);
    let clip: Vec<f64> = year[at..at + 300]
        .iter()
        .map(|v| v + 3e-4 * rng.normal())
        .collect();
    let mut g = c.benchmark_group("match_5min_clip");
    g.sample_size(10);
    let day = &year[..DAY];
    let day_clip: Vec<f64> = day[40_000..40_300]
        .iter()
        .map(|v| v + 3e-4 * rng.normal())
        .collect();
    g.bench_function("24h_1s", |b| {
        b.iter(|| {
            let r = match_trace(&day_clip, day, &MatchOptions::default()).unwrap();
            assert_eq!(r.candidates[0].offset.round() as usize, 40_000);
        })
    });
    g.bench_function("1year_1s", |b| {
        b.iter(|| {
            let r = match_trace(&clip, &year[..], &MatchOptions::default()).unwrap();
            assert_eq!(r.candidates[0].offset.round() as usize, at);
            assert!(r.candidates[0].p_value < 1e-3);
        })
    });
    g.finish();
}

criterion_group!(matching, benches);
criterion_main!(matching);
