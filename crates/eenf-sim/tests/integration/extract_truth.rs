//! The simulator against the E-ENF method: the trace extracted from a simulated recording
//! agrees with the simulator's ground truth.

use eenf_dsp::{agreement, extract_enf, EnfParams, SamplingMethod, TemporalSampler};
use eenf_sim::{simulate, MainsPhase, SimConfig, SyntheticEnf};

#[test]
fn extracted_enf_follows_the_truth() {
    let config = SimConfig {
        width: 32,
        height: 24,
        duration_s: 40.0,
        seed: 3,
        ..SimConfig::default()
    };
    let mains = MainsPhase::synthetic(50.0, config.duration_s, SyntheticEnf::default(), 11);
    let mut sampler = TemporalSampler::new(SamplingMethod::Paper, 1000);
    let t = std::time::Instant::now();
    let stats = simulate(&config, &mains, |b| sampler.push(b)).unwrap();
    eprintln!("{stats:?} in {:?}", t.elapsed());
    let seq = sampler.finish().unwrap();
    let trace = extract_enf(&seq, &EnfParams::default()).unwrap();
    let truth = mains.truth(config.duration_s);
    let m = agreement(&trace.enf_hz, &truth).unwrap();
    eprintln!("{m:?} selected {:?}", trace.selected);
    assert!(m.n >= 40);
    assert!(m.mae_hz < 0.002, "{m:?}");
    assert!(m.cc > 0.95, "{m:?}");
}
