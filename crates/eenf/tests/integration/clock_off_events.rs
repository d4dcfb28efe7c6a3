//! An event camera whose clock runs 0.26 % fast (as a real DVS128 recording's does: its 60 Hz
//! grid's flicker sits at 119.68 Hz): traced with the defaults, the offset named in the trace's
//! warnings, every estimate off by the clock's share as the warning says.

use std::path::Path;
use std::sync::Arc;

use eenf::extract::{extract, ExtractOptions};
use eenf::progress::Progress;
use eenf::recording::Recording;
use eenf_core::EventBatch;
use eenf_sim::{simulate, MainsPhase, Readout, SimConfig, SyntheticEnf};

#[test]
fn a_dvs128_whose_clock_runs_fast_is_traced_and_its_clock_named() {
    const FAST: f64 = 0.0026;
    let seconds = 23.5;
    let config = SimConfig {
        width: 32,
        height: 24,
        duration_s: seconds,
        readout: Readout::named("dvs128").unwrap(),
        // most of the light steady: the flicker is a small part of what the pixels see
        ambient: 0.97,
        ..SimConfig::default()
    };
    let mains = MainsPhase::synthetic(60.0, seconds + 1.0, SyntheticEnf::default(), 7);
    let mut events = EventBatch::default();
    simulate(&config, &mains, |b| {
        events.extend_from(b);
        Ok::<(), ()>(())
    })
    .unwrap();
    // the camera stamps each event by its own clock, which counts 1.0026 µs per µs
    let t0 = events.t.first().copied().unwrap_or(0);
    for t in &mut events.t {
        *t = t0 + ((*t - t0) as f64 * (1.0 + FAST)).round() as i64;
    }
    let rec = Recording::Memory {
        name: Path::new("dvs128_fast_clock").to_path_buf(),
        events: Arc::new(events),
        width: config.width,
        height: config.height,
    };
    let trace = extract(&rec, &ExtractOptions::default(), &Progress::hidden()).unwrap();
    assert_eq!(trace.nominal_hz, Some(60.0));
    let warned = trace.warnings.join("\n");
    println!("{warned}");
    assert!(
        warned.contains("% below 120 Hz") && warned.contains("camera's clock"),
        "{warned}"
    );
    // the line the warning names is twice the grid's mean seen through the fast clock
    let truth: Vec<f64> = mains
        .truth(seconds)
        .iter()
        .map(|f| f / (1.0 + FAST))
        .collect();
    let truth_mean = truth.iter().sum::<f64>() / truth.len() as f64;
    let named: f64 = warned
        .split("the flicker line is at ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap();
    assert!(
        (named - 2.0 * truth_mean).abs() < 0.02,
        "{named} vs {}",
        2.0 * truth_mean
    );
    let mean = trace.mean_hz();
    assert!(
        (mean - truth_mean).abs() < 0.005,
        "mean {mean} vs {truth_mean}"
    );
    let a = eenf_dsp::agreement(&trace.enf_hz, &truth).unwrap();
    println!(
        "mean {mean:.4} Hz; against the truth seen through the clock: CC {:.3}, MAE {:.2} mHz",
        a.cc,
        a.mae_hz * 1e3
    );
    assert!(a.mae_hz < 0.01, "MAE {} Hz", a.mae_hz);
}
