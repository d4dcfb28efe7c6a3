//! Matching speed: a 5-minute clip against 24 h and against a year of 1 s reference.

use criterion::{criterion_group, criterion_main, Criterion};
use eenf_dsp::matching::{match_trace, MatchOptions};
use eenf_sim::SyntheticEnf;

fn benches(c: &mut Criterion) {
    let year = SyntheticEnf::default().per_second(50.0, 365 * 86_400, 11);
    let at = 200_000_123;
    let at = at % (year.len() - 300);
    let clip: Vec<f64> = year[at..at + 300].iter().map(|v| v + 0.0003).collect();
    let mut g = c.benchmark_group("match_5min_clip");
    g.sample_size(10);
    let day = &year[..86_400];
    let day_clip = day[40_000..40_300].to_vec();
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
        })
    });
    g.finish();
}

criterion_group!(matching, benches);
criterion_main!(matching);
