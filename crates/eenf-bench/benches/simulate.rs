//! Simulation speed: events generated per second (both cores), for a DVXplorer-like readout at
//! 320×240 under the default LED, under a fluorescent tube, and for a moving hand-held scene.
//! `EENF_BENCH_SECONDS` sets the simulated length (default 2 s).
#![allow(missing_docs)] // criterion_group! makes undocumented public functions

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use eenf_sim::{simulate, Lamp, LampKind, MainsPhase, SceneKind, SimConfig, SyntheticEnf};

fn bench(c: &mut Criterion) {
    let seconds: f64 = std::env::var("EENF_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2.0);
    let mains = MainsPhase::synthetic(50.0, seconds + 1.0, SyntheticEnf::default(), 1);
    let base = SimConfig {
        width: 320,
        height: 240,
        duration_s: seconds,
        ..SimConfig::default()
    };
    let fluorescent = SimConfig {
        lamps: vec![Lamp {
            kind: LampKind::named("fluorescent").unwrap(),
            phase_deg: 0.0,
            share: 1.0,
        }],
        ..base.clone()
    };
    let moving = base
        .clone()
        .with_kinds(&[SceneKind::DynamicObject, SceneKind::DynamicCamera]);
    let mut group = c.benchmark_group("simulate_320x240");
    group.sample_size(10);
    for (name, config) in [
        ("led", base),
        ("fluorescent", fluorescent),
        ("moving_led", moving),
    ] {
        let events = simulate(&config, &mains, |_| Ok::<(), ()>(()))
            .unwrap()
            .events;
        group.throughput(Throughput::Elements(events));
        group.bench_function(name, |b| {
            b.iter(|| simulate(&config, &mains, |_| Ok::<(), ()>(())).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
