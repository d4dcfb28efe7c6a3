//! Decoding and extraction throughput on a DVXplorer-like recording: 2 M events/s, scan groups
//! of events sharing a timestamp, polarity following a 100 Hz flicker.
//!
//! The file is generated once into the target folder (`EENF_BENCH_SECONDS`, default 20 s =
//! 40 M events) and reused; `cargo bench -p eenf-bench` prints events/s ("elem/s").
#![allow(missing_docs)] // criterion_group! makes undocumented public functions

use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use eenf::extract::{extract_file, ExtractOptions};
use eenf::progress::Progress;
use eenf_core::Nominal;
use eenf_events::writers::{create, OutputFormat};
use eenf_events::{Compression, EventBatch};

const RATE: u64 = 2_000_000;
const SCAN_US: i64 = 200;

/// Writes (once) a flicker recording of `seconds` in `format`; returns its path and event count.
fn fixture(seconds: u64, format: OutputFormat) -> (PathBuf, u64) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let name = match format {
        OutputFormat::Aedat4(c) => format!("bench-{seconds}s-{}.aedat4", c.name()),
        OutputFormat::Evt2 => format!("bench-{seconds}s-evt2.raw"),
        OutputFormat::Evt3 => format!("bench-{seconds}s-evt3.raw"),
        OutputFormat::Dat => format!("bench-{seconds}s.dat"),
        OutputFormat::Text => format!("bench-{seconds}s.txt"),
    };
    let path = dir.join(name);
    let per_scan = (RATE * SCAN_US as u64 / 1_000_000) as usize;
    let scans = seconds * 1_000_000 / SCAN_US as u64;
    let total = scans * per_scan as u64;
    if path.exists() {
        return (path, total);
    }
    let mut w = create(&path, format, 640, 480).unwrap();
    let mut state = 0x2545f4914f6cdd1du64;
    let mut next = || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        state.wrapping_mul(0x2545f4914f6cdd1d)
    };
    let mut batch = EventBatch::with_capacity(per_scan * 5000);
    for s in 0..scans {
        let t = s as i64 * SCAN_US;
        // light ∝ cos²(2π·50.01·t): ON while it rises, OFF while it falls, 15 % noise
        let rising = (4.0 * std::f64::consts::PI * 50.01 * t as f64 * 1e-6).sin() < 0.0;
        for _ in 0..per_scan {
            let r = next();
            let noisy = (r >> 60) < 2;
            batch.push(
                1_660_723_800_000_000 + t,
                (r % 640) as u16,
                ((r >> 16) % 480) as u16,
                rising ^ noisy,
            );
        }
        if batch.len() >= per_scan * 5000 {
            w.write(&batch).unwrap();
            batch.clear();
        }
    }
    w.write(&batch).unwrap();
    w.finish().unwrap();
    (path, total)
}

fn benches(c: &mut Criterion) {
    let seconds: u64 = std::env::var("EENF_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    for format in [
        OutputFormat::Aedat4(Compression::Lz4),
        OutputFormat::Aedat4(Compression::Zstd),
        OutputFormat::Evt2,
        OutputFormat::Evt3,
        OutputFormat::Dat,
    ] {
        let (path, n) = fixture(seconds, format);
        let mut g = c.benchmark_group(format.to_string().replace(' ', "_"));
        g.sample_size(10);
        g.throughput(Throughput::Elements(n));
        g.bench_function("decode", |b| {
            b.iter(|| {
                let mut r = eenf_events::open(&path).unwrap();
                let mut count = 0usize;
                while let Some(batch) = r.next_batch().unwrap() {
                    count += batch.len();
                }
                assert_eq!(count as u64, n);
            })
        });
        if format == OutputFormat::Aedat4(Compression::Lz4) {
            let opts = ExtractOptions {
                nominal: Nominal::Grid(eenf_core::Grid::Hz50),
                ..ExtractOptions::default()
            };
            g.bench_function("extract_enf", |b| {
                b.iter(|| {
                    let x = extract_file(&path, &opts, &Progress::hidden()).unwrap();
                    assert_eq!(x.events().map(|e| e.events), Some(n));
                })
            });
        }
        g.finish();
    }
}

criterion_group!(pipeline, benches);
criterion_main!(pipeline);
